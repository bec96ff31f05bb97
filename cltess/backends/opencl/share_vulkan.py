"""A Session's output handed to the caller's Vulkan device without a copy: ``Session(scene,
device="nvidia", share="vulkan", vulkan=VulkanQueue(device, physical_device, queue, family))``,
then ``frame.vulkan()``: the frame's fields as ``VkBuffer``s of that device, to draw or compute
from.

The memory is share_cuda.py's (CUDA allocates and exports it, OpenCL imports it), imported once
more by the caller's device (``VK_KHR_external_memory_fd``: a ``VkDeviceMemory`` per field and a
``VkBuffer`` bound to all of it).  The hand-over is handover.py's: its two binary semaphores
(made by the process's own Vulkan device, imported into OpenCL, kept for the context) are
imported by the caller's device too (``VK_KHR_external_semaphore_fd``), and the caller's queue
does the other API's side:

* ``ready``: ``frame.vulkan()`` enqueues OpenCL's release of the buffers and a signal of
  ``ready``, then submits to the caller's queue a batch that waits for ``ready`` and acquires the
  buffers from ``VK_QUEUE_FAMILY_EXTERNAL`` (buffer barriers: the queue family ownership transfer
  that external memory needs).  Commands submitted to that queue after the call see the frame: a
  semaphore wait's and a barrier's second scope include every later command in submission order.
  The host waits for nothing.
* ``done``: the next time OpenCL needs the buffers (the next frame's stages, a read-back, growing,
  ``close``), a batch on the caller's queue releases them to ``VK_QUEUE_FAMILY_EXTERNAL`` and
  signals ``done`` after every command submitted before it, and OpenCL waits for that.

So the caller submits its work on the buffers to that queue between ``frame.vulkan()`` and the
next ``tessellate``, and does not submit to that queue from another thread meanwhile (Vulkan
wants a queue's submissions externally synchronized).  The caller's device needs
``VK_KHR_external_memory_fd`` and ``VK_KHR_external_semaphore_fd`` (``NEEDED_VK_EXTENSIONS``) and must
be on the session's GPU (matched by UUID).  ``Session.close()`` (or the ``with`` block's end)
destroys the buffers, memory, semaphores and command pool it made in the caller's device: close
the Session before destroying that device.
"""
from __future__ import annotations

import ctypes
import os
from dataclasses import dataclass

import pyopencl as cl

from .handover import HandedOverBuffers
from .share_cuda import SharedBuffer, SharedFields, SharingUnavailable
from .vulkan import (NEEDED_VK_EXTENSIONS, VK_ACCESS_MEMORY_READ_BIT, VK_ACCESS_MEMORY_WRITE_BIT,
                     VK_BUFFER_USAGE_INDEX_BUFFER_BIT, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                     VK_BUFFER_USAGE_TRANSFER_DST_BIT, VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                     VK_BUFFER_USAGE_VERTEX_BUFFER_BIT, VK_COMMAND_BUFFER_USAGE_SIMULTANEOUS_USE_BIT,
                     VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT,
                     VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT,
                     VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_QUEUE_FAMILY_EXTERNAL,
                     VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO, VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER,
                     VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO, VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO,
                     VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO, VK_STRUCTURE_TYPE_EXTERNAL_MEMORY_BUFFER_CREATE_INFO,
                     VK_STRUCTURE_TYPE_IMPORT_MEMORY_FD_INFO_KHR, VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, VK_WHOLE_SIZE,
                     BufferCreateInfo, BufferMemoryBarrier, CommandBufferAllocateInfo, CommandBufferBeginInfo,
                     CommandPoolCreateInfo, ExternalMemoryBufferCreateInfo, ImportMemoryFdInfo,
                     MemoryAllocateInfo, MemoryRequirements, check, check_extensions, device_uuid,
                     imported_semaphore, loader, memory_type, pointer_to, submit)

_u32, _u64, _ptr = ctypes.c_uint32, ctypes.c_uint64, ctypes.c_void_p

#: What the buffers may be used for in the caller's device.
BUFFER_USAGE = (VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT
                | VK_BUFFER_USAGE_INDEX_BUFFER_BIT | VK_BUFFER_USAGE_VERTEX_BUFFER_BIT)


def _handle(value) -> int:
    """A Vulkan handle as an integer: an int, a ctypes pointer, or anything int() takes."""
    value = getattr(value, "value", value)
    return int(value or 0)


@dataclass(frozen=True)
class VulkanQueue:
    """Where ``Session(share="vulkan")`` hands its output: the caller's ``VkDevice``, its
    ``VkPhysicalDevice``, a ``VkQueue`` of it and that queue's family index.  Handles as integers
    (or ctypes pointers; from the ``vulkan`` package's cffi handles:
    ``int(ffi.cast("uintptr_t", handle))``).  The device must have been made with
    ``NEEDED_VK_EXTENSIONS`` enabled."""

    device: int
    physical_device: int
    queue: int
    family: int


class VulkanBuffer(SharedBuffer):
    """One output field as a ``VkBuffer`` of the caller's device (``buffer``, bound at offset 0
    to ``memory``), laid out as SharedBuffer says (triangles: ``VK_INDEX_TYPE_UINT32``).  Usable as
    a vertex, index, storage and transfer buffer."""

    def __init__(self, buffer: int, memory: int, rows: int, shape: tuple, dtype):
        super().__init__(rows, shape, dtype)
        self.buffer, self.memory = buffer, memory

    def __repr__(self) -> str:
        return (f"VulkanBuffer(buffer={self.buffer:#x}, rows={self.rows}, components={self.components}, "
                f"dtype={self.dtype})")


class VulkanBuffers(SharedFields):
    """A frame's output as ``VulkanBuffer``s."""


class VulkanOutputBuffers(HandedOverBuffers):
    """CudaOutputBuffers that the caller's Vulkan device imports too, handed over by semaphores
    (handover.py) and queue family ownership transfers on the caller's queue (the module's
    notes)."""

    shares = "vulkan"

    def __init__(self, tessellator, pinned: bool = False, vulkan: VulkanQueue | None = None):
        if not isinstance(vulkan, VulkanQueue):
            raise ValueError("share=\"vulkan\" needs vulkan=VulkanQueue(device, physical_device, queue, family): "
                             f"got {vulkan!r}")
        super().__init__(tessellator, pinned)
        vk = self.vk = loader("vulkan")
        self.device, self.physical_device = _ptr(_handle(vulkan.device)), _ptr(_handle(vulkan.physical_device))
        self.vk_queue, self.family = _ptr(_handle(vulkan.queue)), int(vulkan.family)
        if device_uuid(vk, self.physical_device) != self.opencl.uuid:
            raise SharingUnavailable(f"the Vulkan device is not on the session's GPU (UUID "
                                     f"{self.opencl.uuid.hex()})")
        check_extensions(vk, self.device)
        self._vk_semaphore = {}  # "ready" / "done" -> the caller's device's semaphore
        self._vk_objects: dict = {}  # name -> (VkBuffer, VkDeviceMemory)
        self._pool = None  # the command pool of the transfers (made with them)
        self._transfers = None  # (acquire, release) command buffers for the current buffers
        self._borrow_semaphores()

    def _import_semaphores(self) -> None:
        for role, (vulkan_semaphore, _) in self._lent.items():
            self._vk_semaphore[role] = imported_semaphore(self.vk, self.device,
                                                          self.cl_semaphores.vulkan.fd(vulkan_semaphore))

    def _new_buffer(self, name: str, nbytes: int) -> cl.Buffer:
        self._delete_vulkan(name)
        buffer = super()._new_buffer(name, nbytes)
        allocation, vk = self._allocations[name], self.vk
        external = ExternalMemoryBufferCreateInfo(VK_STRUCTURE_TYPE_EXTERNAL_MEMORY_BUFFER_CREATE_INFO, None,
                                                  VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT)
        create = BufferCreateInfo(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO, pointer_to(external), 0, allocation.nbytes,
                                  BUFFER_USAGE, 0, 0, None)
        vk_buffer, memory = _u64(), _u64()
        check("vkCreateBuffer", vk.vkCreateBuffer(self.device, ctypes.byref(create), None, ctypes.byref(vk_buffer)))
        needs = MemoryRequirements()
        vk.vkGetBufferMemoryRequirements(self.device, vk_buffer, ctypes.byref(needs))
        fd = allocation.export_fd()
        imported = ImportMemoryFdInfo(VK_STRUCTURE_TYPE_IMPORT_MEMORY_FD_INFO_KHR, None,
                                      VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT, fd)
        allocate = MemoryAllocateInfo(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, pointer_to(imported),
                                      max(allocation.nbytes, needs.size),
                                      memory_type(vk, self.physical_device, needs.memoryTypeBits,
                                                  preferred=VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT))
        result = vk.vkAllocateMemory(self.device, ctypes.byref(allocate), None, ctypes.byref(memory))
        if result:  # (Vulkan takes the fd over only when the import succeeds)
            os.close(fd)
            vk.vkDestroyBuffer(self.device, vk_buffer, None)
            raise RuntimeError(f"Vulkan vkAllocateMemory importing {name}'s memory ({allocation.nbytes} bytes) "
                               f"failed: {result}")
        self._vk_objects[name] = (vk_buffer.value, memory.value)
        check("vkBindBufferMemory", vk.vkBindBufferMemory(self.device, vk_buffer, memory, _u64(0)))
        self._free_transfers()
        return buffer

    def _delete_vulkan(self, name: str) -> None:
        if name in self._vk_objects:
            vk_buffer, memory = self._vk_objects.pop(name)
            self.vk.vkDestroyBuffer(self.device, _u64(vk_buffer), None)
            self.vk.vkFreeMemory(self.device, _u64(memory), None)

    def _free_transfers(self) -> None:
        """Drop the recorded ownership transfers (the buffers changed; none is pending then: OpenCL
        waited for ``done``, signalled after them)."""
        if self._transfers is not None:
            self.vk.vkFreeCommandBuffers(self.device, self._pool, 2, self._transfers)
            self._transfers = None

    def _record_transfers(self):
        """Two command buffers for the current buffers: acquire from ``VK_QUEUE_FAMILY_EXTERNAL``
        into the caller's family, and release back (each a buffer barrier per field)."""
        vk, commands = self.vk, (_ptr * 2)()
        if self._pool is None:
            pool, made = CommandPoolCreateInfo(VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO, None, 0, self.family), _u64()
            check("vkCreateCommandPool", vk.vkCreateCommandPool(self.device, ctypes.byref(pool), None,
                                                                ctypes.byref(made)))
            self._pool = made
        allocate = CommandBufferAllocateInfo(VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO, None, self._pool, 0, 2)
        check("vkAllocateCommandBuffers", vk.vkAllocateCommandBuffers(self.device, ctypes.byref(allocate), commands))
        access = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT
        for command, (source, target, before, after, stages) in zip(commands, (
                (VK_QUEUE_FAMILY_EXTERNAL, self.family, 0, access,
                 (VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT)),
                (self.family, VK_QUEUE_FAMILY_EXTERNAL, access, 0,
                 (VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT)))):
            barriers = (BufferMemoryBarrier * len(self._vk_objects))(*(
                BufferMemoryBarrier(VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER, None, before, after, source, target,
                                    vk_buffer, 0, VK_WHOLE_SIZE) for vk_buffer, _ in self._vk_objects.values()))
            begin = CommandBufferBeginInfo(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO, None,
                                           VK_COMMAND_BUFFER_USAGE_SIMULTANEOUS_USE_BIT, None)
            check("vkBeginCommandBuffer", vk.vkBeginCommandBuffer(command, ctypes.byref(begin)))
            vk.vkCmdPipelineBarrier(command, stages[0], stages[1], 0, 0, None, len(barriers), barriers, 0, None)
            check("vkEndCommandBuffer", vk.vkEndCommandBuffer(command))
        self._transfers = commands
        return commands

    def _signal_done(self) -> None:  # (released by the caller's queue after its commands)
        submit(self.vk, self.vk_queue, command_buffer=self._transfers[1], signal=self._vk_semaphore["done"])

    def _wait_ready(self) -> None:
        transfers = self._transfers if self._transfers is not None else self._record_transfers()
        submit(self.vk, self.vk_queue, wait=self._vk_semaphore["ready"], command_buffer=transfers[0])

    def share(self, num_vertices: int, num_triangles: int) -> VulkanBuffers:
        """The current output handed to the caller's queue (HandedOverBuffers._hand_over: no
        host wait), the buffers acquired there."""
        self._hand_over()
        return self._shared_fields(VulkanBuffers(), num_vertices, num_triangles,
                                   lambda name, *layout: VulkanBuffer(*self._vk_objects[name], *layout))

    def _close_api(self) -> None:
        """What was made in the caller's device goes (its queue is past every batch made here:
        OpenCL waited for done, or none was submitted)."""
        self._free_transfers()
        for name in list(self._vk_objects):
            self._delete_vulkan(name)
        if self._pool is not None:
            self.vk.vkDestroyCommandPool(self.device, self._pool, None)
            self._pool = None
        for semaphore in self._vk_semaphore.values():
            self.vk.vkDestroySemaphore(self.device, _u64(semaphore), None)
        self._vk_semaphore = {}


__all__ = ["NEEDED_VK_EXTENSIONS", "VulkanBuffer", "VulkanBuffers", "VulkanOutputBuffers", "VulkanQueue"]
