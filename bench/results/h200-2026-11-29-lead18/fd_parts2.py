"""Session 18: which part of a share="vulkan" Session keeps a /dev/nvidiactl per session."""
import gc
import os
import sys

sys.path.insert(0, "tests")
sys.path.insert(0, "bench")
import cltess  # noqa: E402
from cltess.backends.opencl import Tessellator  # noqa: E402
from cltess.backends.opencl.share_cuda import OpenCLExternalMemory  # noqa: E402
from support.vulkan_reader import VulkanReader  # noqa: E402
import frame_loop  # noqa: E402


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
scene = frame_loop.suite_scene("tea_table")


def step(name, body):
    counts = [nvidiactl()]
    for _ in range(3):
        body()
        gc.collect()
        reader.wait_idle()
        counts.append(nvidiactl())
    print(f"{name}: {counts}", flush=True)


def session(share, frames, hand):
    def body():
        extra = {"vulkan": reader.queue_for_session()} if share == "vulkan" else {}
        with cltess.Session(scene, tessellator=tessellator, pixels=0.5, share=share, **extra) as s:
            for _ in range(frames):
                f = s.tessellate(camera=scene.camera)
                if hand:
                    getattr(f, share)()
                else:
                    f.finish()
    return body


for share in ("cuda", "vulkan"):
    for frames, hand in ((0, False), (1, False), (1, True), (3, True)):
        step(f"{share}: {frames} frames, handed {hand}", session(share, frames, hand))
reader.close()
