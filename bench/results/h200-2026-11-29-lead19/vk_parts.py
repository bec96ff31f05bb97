"""Where frame.vulkan()'s host time goes (session 19): a share="vulkan" Session's frames with every
step of the hand-over timed on the host (perf_counter around each call), against share="cuda".
Run from the checkout root on the GPU machine with PYTHONPATH including bench/ and tests/."""
import statistics
import sys
import time
from collections import defaultdict

sys.path[:0] = ["bench", "tests"]
import frame_loop  # noqa: E402

import cltess  # noqa: E402
from cltess.backends.opencl import handover, share_cuda, share_vulkan  # noqa: E402
from cltess.backends.opencl.share_cuda import OpenCLExternalMemory  # noqa: E402
from cltess.backends.opencl.tessellator import Tessellator  # noqa: E402
from support.vulkan_reader import VulkanReader  # noqa: E402
from cltess.backends.opencl import output, plan, recorded, tessellator as tessellator_module  # noqa: E402

spent = defaultdict(list)


def timed(owner, name, label):
    original = getattr(owner, name)

    def wrapper(*args, **kwargs):
        started = time.perf_counter()
        try:
            return original(*args, **kwargs)
        finally:
            spent[label].append((time.perf_counter() - started) * 1e3)
    setattr(owner, name, wrapper)


timed(share_vulkan.VulkanOutputBuffers, "_signal_done", "vk submit release+done")
timed(share_vulkan.VulkanOutputBuffers, "_wait_ready", "vk submit wait+acquire")
timed(handover.OpenCLSemaphores, "enqueue", "cl semaphore enqueue")
timed(share_cuda.OpenCLExternalMemory, "enqueue", "cl acquire/release enqueue")
timed(handover.HandedOverBuffers, "_reclaim", "_reclaim (all)")
timed(handover.HandedOverBuffers, "_hand_over", "_hand_over (all)")

timed(plan.Plan, "settle", "plan.settle")
timed(plan.Plan, "totals_ready", "plan.totals_ready")
timed(recorded.RecordedFrame, "replay", "recorded.replay")
timed(output.OutputBuffers, "reserve", "output.reserve")
timed(share_cuda.CudaOutputBuffers, "take", "cuda take")
timed(tessellator_module.PendingEmit, "result", "pending.result")
timed(cltess.Session, "request_for", "session.request_for")
tessellator = Tessellator("nvidia")
vulkan = VulkanReader(OpenCLExternalMemory(tessellator.context, tessellator.device).uuid)
for key, scene, request in (("tea_table", frame_loop.suite_scene("tea_table"), {"pixels": frame_loop.PIXELS}),
                            ("1000 teapots", frame_loop.teapots(1000), frame_loop.uniform_request(16))):
    cameras = list(frame_loop.orbit(scene.camera, 20)) if key == "tea_table" else [None] * 20
    for share in ("cuda", "vulkan"):
        extra = {"vulkan": vulkan.queue_for_session()} if share == "vulkan" else {}
        session = cltess.Session(scene, tessellator=tessellator, share=share, **extra, **request)
        for camera in cameras[:3]:
            getattr(session.tessellate(camera=camera), share)()
            vulkan.wait_idle()
        spent.clear()
        walls = defaultdict(list)
        for camera in cameras:
            started = time.perf_counter()
            frame = session.tessellate(camera=camera)
            walls["tessellate()"].append((time.perf_counter() - started) * 1e3)
            started = time.perf_counter()
            getattr(frame, share)()
            walls[f"frame.{share}()"].append((time.perf_counter() - started) * 1e3)
            started = time.perf_counter()
            vulkan.wait_idle()
            walls["vkQueueWaitIdle"].append((time.perf_counter() - started) * 1e3)
        print(f"{key}, share={share}: " + "; ".join(
            f"{label} {statistics.median(values):.3f}" for label, values in {**walls, **spent}.items())
            + " (median ms per call)", flush=True)
        if share == "vulkan":
            session.close()
vulkan.close()
