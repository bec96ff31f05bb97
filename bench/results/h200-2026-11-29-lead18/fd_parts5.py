"""Session 18: the import of fd_parts3.py with VulkanOutputBuffers' memory type, and with its
semaphores alive: which keeps a /dev/nvidiactl."""
import ctypes
import gc
import os
import sys

sys.path.insert(0, "tests")
from cltess.backends.opencl import Tessellator  # noqa: E402
from cltess.backends.opencl.share_cuda import OpenCLExternalMemory, SharedAllocation, _Cuda  # noqa: E402
from cltess.backends.opencl.share_gl import OpenCLSemaphores  # noqa: E402
from cltess.backends.opencl.vulkan import ExportableSemaphores  # noqa: E402
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
types = reader.memory_types
print("memory types:", [(k, types.memoryTypes[k].propertyFlags, types.memoryTypes[k].heapIndex)
                        for k in range(types.memoryTypeCount)], flush=True)
semaphores = ExportableSemaphores(vk, device)
cl_semaphores = OpenCLSemaphores(opencl, tessellator.device, "vulkan")


def imported(a, kind):
    fd = a.export_fd()
    external = sv.ExternalMemoryBufferCreateInfo(sv.VK_STRUCTURE_TYPE_EXTERNAL_MEMORY_BUFFER_CREATE_INFO, None, 1)
    create = sv.BufferCreateInfo(sv.VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO, sv.pointer_to(external), 0, a.nbytes,
                                 sv.BUFFER_USAGE, 0, 0, None)
    memory, buffer = ctypes.c_uint64(), ctypes.c_uint64()
    assert vk.vkCreateBuffer(device, ctypes.byref(create), None, ctypes.byref(buffer)) == 0
    needs = sv.MemoryRequirements()
    vk.vkGetBufferMemoryRequirements(device, buffer, ctypes.byref(needs))
    if kind is None:
        kind = next(k for k in range(types.memoryTypeCount) if needs.memoryTypeBits >> k & 1
                    and types.memoryTypes[k].propertyFlags & 1)
    info = sv.ImportMemoryFdInfo(sv.VK_STRUCTURE_TYPE_IMPORT_MEMORY_FD_INFO_KHR, None, 1, fd)
    allocate = sv.MemoryAllocateInfo(sv.VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, sv.pointer_to(info), a.nbytes, kind)
    assert vk.vkAllocateMemory(device, ctypes.byref(allocate), None, ctypes.byref(memory)) == 0
    assert vk.vkBindBufferMemory(device, buffer, memory, ctypes.c_uint64(0)) == 0
    return memory, buffer, kind, needs.memoryTypeBits


def variant(kind, with_semaphores, nbytes=1 << 21, semaphores_last=False, kept=None):
    def body():
        made_semaphores = []
        if with_semaphores:
            for _ in range(2):
                s = semaphores.make()
                made_semaphores.append((s, cl_semaphores.import_fd(semaphores.fd(s))))
        allocations = [SharedAllocation(cuda, opencl, queue, nbytes) for _ in range(6)]
        made = [imported(a, kind) for a in allocations]
        body.kinds = {m[2:] for m in made}
        buffers = [a.buffer for a in allocations]
        opencl.enqueue("Acquire", queue, buffers)
        if kept:
            cl_semaphores.enqueue("signal", queue, kept[0][1])
            cl_semaphores.enqueue("wait", queue, kept[0][1])
        opencl.enqueue("Release", queue, buffers)
        queue.finish()
        for memory, buffer, _, _ in made:
            vk.vkDestroyBuffer(device, buffer, None)
            vk.vkFreeMemory(device, memory, None)
        if semaphores_last:
            del allocations, buffers
            gc.collect()
        for s, c in made_semaphores:
            cl_semaphores.release(c)
            semaphores.destroy(s)
    return body


def step(name, body):
    counts = [nvidiactl()]
    for _ in range(3):
        body()
        gc.collect()
        counts.append(nvidiactl())
    print(f"{name}: {counts}; (memory type, allowed bits) {getattr(body, 'kinds', None)}", flush=True)


step("device-local type, semaphores released while the memory lives (as close() does)", variant(None, True))
step("device-local type, semaphores released after the memory is freed", variant(None, True, semaphores_last=True))
kept = []
for _ in range(2):
    s = semaphores.make()
    kept.append((s, cl_semaphores.import_fd(semaphores.fd(s))))
step("semaphores imported once and kept (used each time), memory sets come and go", variant(None, False, kept=kept))
step("again, and released at the end", variant(None, False, kept=kept))
for s, c in kept:
    cl_semaphores.release(c)
    semaphores.destroy(s)
gc.collect()
print("after releasing the kept pair:", nvidiactl(), flush=True)
reader.close()
