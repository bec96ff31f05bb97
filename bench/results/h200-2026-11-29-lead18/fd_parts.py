"""Session 18: which step leaves a /dev/nvidiactl descriptor per closed GL/Vulkan session?
Each step done 4 times, the count after each."""
import ctypes
import gc
import os
import sys

sys.path.insert(0, "tests")
import pyopencl as cl  # noqa: E402
from cltess.backends.opencl import Tessellator  # noqa: E402
from cltess.backends.opencl.share_cuda import OpenCLExternalMemory, SharedAllocation, _Cuda  # noqa: E402
from cltess.backends.opencl.share_gl import OpenCLSemaphores  # noqa: E402
from cltess.backends.opencl.vulkan import ExportableSemaphores  # noqa: E402
from cltess.backends.opencl import share_vulkan  # noqa: E402
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
semaphores = ExportableSemaphores(reader.vk, reader.device)
cl_semaphores = OpenCLSemaphores(opencl, tessellator.device, "vulkan")
queue = tessellator.queue


def step(name, body):
    counts = [nvidiactl()]
    for _ in range(4):
        body()
        gc.collect()
        counts.append(nvidiactl())
    print(f"{name}: {counts}", flush=True)


def vk_only():
    s = semaphores.make()
    semaphores.destroy(s)


def vk_export_close():
    s = semaphores.make()
    os.close(semaphores.fd(s))
    semaphores.destroy(s)


def cl_import_release():
    s = semaphores.make()
    c = cl_semaphores.import_fd(semaphores.fd(s))
    cl_semaphores.release(c)
    semaphores.destroy(s)


def cl_import_signal_wait_release():
    s = semaphores.make()
    c = cl_semaphores.import_fd(semaphores.fd(s))
    cl_semaphores.enqueue("signal", queue, c)
    cl_semaphores.enqueue("wait", queue, c)
    queue.finish()
    cl_semaphores.release(c)
    semaphores.destroy(s)


def cuda_alloc():
    a = SharedAllocation(cuda, opencl, queue, 1 << 21)
    del a


def cuda_alloc_vk_import():
    a = SharedAllocation(cuda, opencl, queue, 1 << 21)
    vk = reader.vk
    fd = a.export_fd()
    imported = share_vulkan.ImportMemoryFdInfo(share_vulkan.VK_STRUCTURE_TYPE_IMPORT_MEMORY_FD_INFO_KHR, None, 1, fd)
    allocate = share_vulkan.MemoryAllocateInfo(share_vulkan.VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO,
                                               share_vulkan.pointer_to(imported), a.nbytes, 0)
    memory = ctypes.c_uint64()
    r = vk.vkAllocateMemory(reader.device, ctypes.byref(allocate), None, ctypes.byref(memory))
    assert r == 0, r
    vk.vkFreeMemory(reader.device, memory, None)
    del a


for name, body in [("vk semaphore made, destroyed", vk_only), ("vk semaphore, fd exported and closed", vk_export_close),
                   ("cl import + release", cl_import_release),
                   ("cl import + signal/wait + release", cl_import_signal_wait_release),
                   ("cuda allocation (cl import)", cuda_alloc), ("cuda allocation + vulkan import", cuda_alloc_vk_import)]:
    try:
        step(name, body)
    except Exception as error:  # noqa: BLE001
        print(f"{name}: failed {error!r}", flush=True)
reader.close()
