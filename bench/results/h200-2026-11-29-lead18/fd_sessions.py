"""Session 18: /dev/nvidiactl descriptors after N closed sessions of each share= kind (the
driver's one per closed GL session, session 17): does it stay one per session, or grow?"""
import gc
import os
import sys

sys.path.insert(0, "tests")
import cltess  # noqa: E402
from cltess.backends.opencl import Tessellator  # noqa: E402
from cltess.backends.opencl.share_cuda import OpenCLExternalMemory  # noqa: E402
from support.egl import HeadlessGL  # noqa: E402
from support.vulkan_reader import VulkanReader  # noqa: E402
import frame_loop  # noqa: E402

def nvidiactl():
    return sum(os.readlink(f"/proc/self/fd/{fd}") == "/dev/nvidiactl" for fd in os.listdir("/proc/self/fd")
               if os.path.exists(f"/proc/self/fd/{fd}"))

tessellator = Tessellator("nvidia")
gl = HeadlessGL()
reader = VulkanReader(OpenCLExternalMemory(tessellator.context, tessellator.device).uuid)
scene = frame_loop.suite_scene("tea_table")
for share in ("cuda", "gl", "vulkan", "gl", "vulkan"):
    extra = {"vulkan": reader.queue_for_session()} if share == "vulkan" else {}
    counts = [nvidiactl()]
    for k in range(4):
        with cltess.Session(scene, tessellator=tessellator, pixels=0.5, share=share, **extra) as session:
            for _ in range(3):
                frame = session.tessellate(camera=scene.camera)
                getattr(frame, share)()
        del session, frame
        gc.collect()
        gl.finish()
        reader.wait_idle()
        counts.append(nvidiactl())
    print(share, "nvidiactl after 0..4 closed sessions:", counts, flush=True)
reader.close()
