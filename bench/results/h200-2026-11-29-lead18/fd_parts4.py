"""Session 18: VulkanOutputBuffers alone (take, then close) with parts changed: which keeps a
/dev/nvidiactl per closed set."""
import gc
import os
import sys

sys.path.insert(0, "tests")
from cltess.backends.opencl import Tessellator  # noqa: E402
from cltess.backends.opencl.share_cuda import CudaOutputBuffers, OpenCLExternalMemory  # noqa: E402
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
reader = VulkanReader(OpenCLExternalMemory(tessellator.context, tessellator.device).uuid)


class LetGoFirst(sv.VulkanOutputBuffers):
    def close(self):
        self._reclaim()
        self._let_go()
        self.queue.finish()
        super().close()


def step(name, make, take=True, pinned=True):
    counts = [nvidiactl()]
    for _ in range(3):
        buffers = make(tessellator, pinned=pinned, **({} if make is CudaOutputBuffers else
                                                      {"vulkan": reader.queue_for_session()}))
        if take:
            buffers.take(100_000, 200_000)
        buffers.close()
        del buffers
        gc.collect()
        counts.append(nvidiactl())
    print(f"{name}: {counts}", flush=True)


step("cuda, take", CudaOutputBuffers)
step("vulkan, no take", sv.VulkanOutputBuffers, take=False)
step("vulkan, take", sv.VulkanOutputBuffers)
step("vulkan, take, not pinned", sv.VulkanOutputBuffers, pinned=False)
step("vulkan, take, let go before the Vulkan objects go", LetGoFirst)
reader.close()
