"""Session 18: a CUDA allocation imported into Vulkan, with a VkBuffer bound, with OpenCL's
acquire and release, apart: which keeps a /dev/nvidiactl."""
import ctypes
import gc
import os
import sys

import numpy as np
import pyopencl as cl

sys.path.insert(0, "tests")
from cltess.backends.opencl import Tessellator  # noqa: E402
from cltess.backends.opencl.share_cuda import OpenCLExternalMemory, SharedAllocation, _Cuda  # noqa: E402
from cltess.backends.opencl import share_vulkan as sv  # noqa: E402
from support.vulkan_reader import VulkanReader  # noqa: E402


def nvidiactl():
    n = 0
    for fd in os.listdir("/proc/self/fd"):
        try:
            n += os.readlink(f"/proc/self/fd/{fd}") == "/dev/nvidiactl"
        except OSError:
            pass
    return n


tessellator = Tessellator("nvidia")
opencl = OpenCLExternalMemory(tessellator.context, tessellator.device)
cuda = _Cuda(opencl.uuid)
reader = VulkanReader(opencl.uuid)
vk, device, queue = reader.vk, reader.device, tessellator.queue


def imported(a, with_buffer):
    fd = a.export_fd()
    info = sv.ImportMemoryFdInfo(sv.VK_STRUCTURE_TYPE_IMPORT_MEMORY_FD_INFO_KHR, None, 1, fd)
    allocate = sv.MemoryAllocateInfo(sv.VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, sv.pointer_to(info), a.nbytes, 0)
    memory, buffer = ctypes.c_uint64(), ctypes.c_uint64()
    if with_buffer:
        external = sv.ExternalMemoryBufferCreateInfo(sv.VK_STRUCTURE_TYPE_EXTERNAL_MEMORY_BUFFER_CREATE_INFO, None, 1)
        create = sv.BufferCreateInfo(sv.VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO, sv.pointer_to(external), 0, a.nbytes,
                                     sv.BUFFER_USAGE, 0, 0, None)
        assert vk.vkCreateBuffer(device, ctypes.byref(create), None, ctypes.byref(buffer)) == 0
    assert vk.vkAllocateMemory(device, ctypes.byref(allocate), None, ctypes.byref(memory)) == 0
    if with_buffer:
        assert vk.vkBindBufferMemory(device, buffer, memory, ctypes.c_uint64(0)) == 0
    return memory, buffer


def release(memory, buffer):
    if buffer.value:
        vk.vkDestroyBuffer(device, buffer, None)
    vk.vkFreeMemory(device, memory, None)


def step(name, body):
    counts = [nvidiactl()]
    for _ in range(3):
        body()
        gc.collect()
        counts.append(nvidiactl())
    print(f"{name}: {counts}", flush=True)


def variant(count, with_buffer, acquire, fill=False, vulkan=True, vulkan_last=False):
    def body():
        allocations = [SharedAllocation(cuda, opencl, queue, 1 << 21) for _ in range(count)]
        made = [imported(a, with_buffer) for a in allocations] if vulkan else []
        if acquire:
            buffers = [a.buffer for a in allocations]
            opencl.enqueue("Acquire", queue, buffers)
            if fill:
                for b in buffers:
                    cl.enqueue_fill_buffer(queue, b, np.zeros(1, np.uint32), 0, 1 << 21)
            opencl.enqueue("Release", queue, buffers)
            queue.finish()
        if not vulkan_last:
            for m in made:
                release(*m)
        del allocations
        gc.collect()
        for m in made if vulkan_last else []:
            release(*m)
    return body


for count, with_buffer, acquire, fill, vulkan, last in (
        (1, True, True, True, False, False), (1, True, True, True, True, False), (1, True, True, True, True, True),
        (1, False, True, True, True, False), (6, True, True, True, True, False)):
    step(f"{count} allocations, VkBuffer {with_buffer}, acquire {acquire}, OpenCL fill {fill}, Vulkan import {vulkan}, "
         f"Vulkan freed last {last}", variant(count, with_buffer, acquire, fill, vulkan, last))
reader.close()
