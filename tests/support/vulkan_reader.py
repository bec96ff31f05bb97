"""A renderer's Vulkan device, as a test plays it, for share="vulkan"
(cltess/backends/opencl/share_vulkan.py) in tests/test_share_handover.py and bench/gpu_share.py:
a device on the OpenCL device's GPU with the extensions sharing needs, its ``VulkanQueue``, and
``read``: a buffer's bytes as that queue's own GPU copy sees them (vkCmdCopyBuffer into a
host-visible buffer, submitted after frame.vulkan(), waited for by a fence)."""
from __future__ import annotations

import ctypes

import numpy as np

from cltess.backends.opencl.share_vulkan import VulkanQueue
from cltess.backends.opencl.vulkan import (VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                           VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT,
                                           VK_MEMORY_PROPERTY_HOST_COHERENT_BIT, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT,
                                           VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO,
                                           VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO,
                                           VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO,
                                           VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO,
                                           VK_STRUCTURE_TYPE_FENCE_CREATE_INFO, VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO,
                                           BufferCopy, BufferCreateInfo, CommandBufferAllocateInfo,
                                           CommandBufferBeginInfo, CommandPoolCreateInfo, FenceCreateInfo,
                                           MemoryAllocateInfo, MemoryRequirements, VulkanDevice, check,
                                           memory_type, submit)

_u64, _ptr = ctypes.c_uint64, ctypes.c_void_p


class VulkanReader(VulkanDevice):
    """A Vulkan device on the GPU with this UUID, playing the renderer: ``queue()`` to give a
    Session, ``read(buffer, nbytes, dtype, shape)``, ``wait_idle()``, ``close()``."""

    def __init__(self, uuid: bytes):
        super().__init__(uuid, api="vulkan")
        vk = self.vk
        pool = CommandPoolCreateInfo(VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO, None, 0, self.family)
        self.pool = _u64()
        check("vkCreateCommandPool", vk.vkCreateCommandPool(self.device, ctypes.byref(pool), None,
                                                            ctypes.byref(self.pool)))
        fence = FenceCreateInfo(VK_STRUCTURE_TYPE_FENCE_CREATE_INFO, None, 0)
        self.fence = _u64()
        check("vkCreateFence", vk.vkCreateFence(self.device, ctypes.byref(fence), None, ctypes.byref(self.fence)))

    def queue_for_session(self) -> VulkanQueue:
        return VulkanQueue(self.device.value, self.physical_device.value, self.queue.value, self.family)

    def _host_buffer(self, nbytes: int):
        vk = self.vk
        create = BufferCreateInfo(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO, None, 0, nbytes,
                                  VK_BUFFER_USAGE_TRANSFER_DST_BIT, 0, 0, None)
        buffer, memory = _u64(), _u64()
        check("vkCreateBuffer", vk.vkCreateBuffer(self.device, ctypes.byref(create), None, ctypes.byref(buffer)))
        needs = MemoryRequirements()
        vk.vkGetBufferMemoryRequirements(self.device, buffer, ctypes.byref(needs))
        kind = memory_type(vk, self.physical_device, needs.memoryTypeBits,
                           required=VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT)
        allocate = MemoryAllocateInfo(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, None, needs.size, kind)
        check("vkAllocateMemory", vk.vkAllocateMemory(self.device, ctypes.byref(allocate), None, ctypes.byref(memory)))
        check("vkBindBufferMemory", vk.vkBindBufferMemory(self.device, buffer, memory, _u64(0)))
        return buffer, memory

    def read(self, buffer: int, nbytes: int, dtype, shape) -> np.ndarray:
        """The first ``nbytes`` of ``buffer`` (a VkBuffer of this device) as this queue's copy
        sees them, as an array (submitted now: after the frame.vulkan() that handed it over)."""
        out = np.empty(shape, dtype)
        assert out.nbytes == nbytes
        if not nbytes:
            return out
        vk = self.vk
        host, memory = self._host_buffer(nbytes)
        command = (_ptr * 1)()
        allocate = CommandBufferAllocateInfo(VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO, None, self.pool, 0, 1)
        check("vkAllocateCommandBuffers", vk.vkAllocateCommandBuffers(self.device, ctypes.byref(allocate), command))
        begin = CommandBufferBeginInfo(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO, None,
                                       VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT, None)
        check("vkBeginCommandBuffer", vk.vkBeginCommandBuffer(command[0], ctypes.byref(begin)))
        region = BufferCopy(0, 0, nbytes)
        vk.vkCmdCopyBuffer(command[0], _u64(buffer), host, 1, ctypes.byref(region))
        check("vkEndCommandBuffer", vk.vkEndCommandBuffer(command[0]))
        submit(vk, self.queue, command_buffer=command[0], fence=self.fence.value)
        check("vkWaitForFences", vk.vkWaitForFences(self.device, 1, ctypes.byref(self.fence), 1, _u64(10 ** 10)))
        check("vkResetFences", vk.vkResetFences(self.device, 1, ctypes.byref(self.fence)))
        mapped = _ptr()
        check("vkMapMemory", vk.vkMapMemory(self.device, memory, _u64(0), _u64(nbytes), 0, ctypes.byref(mapped)))
        ctypes.memmove(out.ctypes.data, mapped.value, nbytes)
        vk.vkUnmapMemory(self.device, memory)
        vk.vkFreeCommandBuffers(self.device, self.pool, 1, command)
        vk.vkDestroyBuffer(self.device, host, None)
        vk.vkFreeMemory(self.device, memory, None)
        return out

    def wait_idle(self) -> None:
        check("vkQueueWaitIdle", self.vk.vkQueueWaitIdle(self.queue))

    def close(self) -> None:
        if getattr(self, "device", None):
            self.wait_idle()
            self.vk.vkDestroyFence(self.device, self.fence, None)
            self.vk.vkDestroyCommandPool(self.device, self.pool, None)
        super().close()
