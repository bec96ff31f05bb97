"""Issue 15: a Session's output handed without a copy to CUDA, OpenGL and Vulkan
(``Session(share="cuda" | "gl" | "vulkan")``: cltess/backends/opencl/share_cuda.py, share_gl.py,
share_vulkan.py), against the same frames kept on the OpenCL device and read back to host
arrays, side by side in one run on one tessellator.

    python bench/gpu_share.py --device nvidia [--frames 10] [--scenes tea_table killeroo ...] [--copies 1000]
                              [--no-gl] [--no-vulkan]

Per scene, for each camera of an orbit (frame_loop.orbit), these frames in turn:

* **resident**: a plain Session frame, waited for (``tessellate`` then ``finish``): the output
  on the OpenCL device;
* **cuda**: a ``share="cuda"`` Session frame and ``frame.cuda()``: until the caller holds CUDA
  device arrays (the buffers released by OpenCL and the release waited for);
* **host**: a plain Session frame for host arrays (``tessellate(host=True)``: pinned copies);
* **gl** (where a headless GL context can be made: tests/support/egl.py): a ``share="gl"``
  Session frame, ``frame.gl()``, then ``glFinish``: until GL has executed its wait for the
  frame (``frame.gl()`` itself returns without waiting; its time is given apart);
* **vulkan** (where a Vulkan device on the GPU can be made: tests/support/vulkan_reader.py): a
  ``share="vulkan"`` Session frame, ``frame.vulkan()``, then ``vkQueueWaitIdle`` of the queue it
  was handed to: until that queue has waited for the frame and acquired the buffers
  (``frame.vulkan()`` itself returns without waiting; its time is given apart).

Each figure is the median over the frames of the host wall clock (``time.perf_counter``) from
the call until the caller holds that output, and of the device time of stages 1-5
(``stage_ms``).  ``--copies`` adds uniform level 16 on that many teapots (``eps`` far below what
any factor reaches, ``max_factor`` 16; no camera, the same frame each time).  Each scene's last
frames are compared bitwise against the host frame's arrays: the CUDA arrays (copied to the host
by CUDA), the GL buffers (by GL's copy), the Vulkan buffers (by the queue's copy).
"""
from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import frame_loop  # noqa: E402  (suite_scene, orbit, teapots, uniform_request, device_ms)

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

import cltess  # noqa: E402
from cltess.backends.opencl import Tessellator  # noqa: E402
from cltess.backends.opencl.output import OutputBuffers  # noqa: E402

FIELDS = list(OutputBuffers.FIELDS)  # the output buffers: the vertex record and the triangles


def timed(call):
    started = time.perf_counter()
    frame = call()
    return frame, (time.perf_counter() - started) * 1e3


def compare(shared: dict, host_frame) -> bool:
    return all(np.array_equal(shared[name].get(), getattr(host_frame, name)) for name in FIELDS)


@dataclass
class Receiver:
    """An API that waits on the device for a handed frame: its Session, how it reads a buffer by
    its own GPU copy (``reader``, ``handle``), and how the host waits until it has waited
    (``settle``)."""

    key: str
    api: str
    reader: object
    settle: Callable[[], None]
    handle: Callable[[object], int]
    session: object

    def same(self, buffers: dict, host_frame) -> bool:
        return all(np.array_equal(self.reader.read(self.handle(buffers[name]), buffers[name].nbytes,
                                                   getattr(host_frame, name).dtype, getattr(host_frame, name).shape),
                                  getattr(host_frame, name)) for name in FIELDS)


def receivers(tessellator, scene, request: dict, gl=None, vulkan=None) -> list:
    found = []
    if gl:
        found.append(Receiver("gl", "gl", gl, gl.finish, lambda buffer: buffer.name,
                              cltess.Session(scene, tessellator=tessellator, share="gl", **request)))
    if vulkan:
        found.append(Receiver("vk", "vulkan", vulkan, vulkan.wait_idle, lambda buffer: buffer.buffer,
                              cltess.Session(scene, tessellator=tessellator, share="vulkan",
                                             vulkan=vulkan.queue_for_session(), **request)))
    return found


def scene_rows(tessellator, name: str, scene, cameras, request: dict, gl=None, vulkan=None) -> dict:
    plain = cltess.Session(scene, tessellator=tessellator, **request)
    shared = cltess.Session(scene, tessellator=tessellator, share="cuda", **request)
    handed = receivers(tessellator, scene, request, gl, vulkan)
    for camera in cameras:  # builds, uploads, the buffers at the size the path needs
        plain.tessellate(camera=camera).finish()
        shared.tessellate(camera=camera).cuda()
        for receiver in handed:
            getattr(receiver.session.tessellate(camera=camera), receiver.api)()
            receiver.settle()
    kinds = ["resident", "cuda", "host"] + [kind for r in handed for kind in (r.key, f"{r.key}_call")]
    rows = {kind: [] for kind in kinds}
    device = {kind: [] for kind in kinds}
    same = True
    for camera in cameras:
        frame, wall = timed(lambda: plain.tessellate(camera=camera).finish())
        rows["resident"].append(wall)
        device["resident"].append(frame_loop.device_ms(frame))
        frame, wall = timed(lambda: shared.tessellate(camera=camera))
        started = time.perf_counter()
        arrays = frame.cuda()
        rows["cuda"].append(wall + (time.perf_counter() - started) * 1e3)
        device["cuda"].append(frame_loop.device_ms(frame))
        host_frame, wall = timed(lambda: plain.tessellate(camera=camera, host=True))
        rows["host"].append(wall)
        device["host"].append(frame_loop.device_ms(host_frame))
        same &= compare(arrays, host_frame)
        for receiver in handed:
            started = time.perf_counter()
            frame = receiver.session.tessellate(camera=camera)
            buffers = getattr(frame, receiver.api)()
            rows[f"{receiver.key}_call"].append((time.perf_counter() - started) * 1e3)
            receiver.settle()
            rows[receiver.key].append((time.perf_counter() - started) * 1e3)
            device[receiver.key].append(frame_loop.device_ms(frame))
            device[f"{receiver.key}_call"].append(device[receiver.key][-1])
            same &= receiver.same(buffers, host_frame)
    for receiver in handed:
        receiver.session.close()
    return {"scene": name, "frames": len(cameras), "triangles": host_frame.num_triangles,
            "bytes": frame_loop.output_bytes(host_frame), "same_bits": bool(same),
            **{f"{kind}_wall_ms": statistics.median(values) for kind, values in rows.items()},
            **{f"{kind}_device_ms": statistics.median(values) for kind, values in device.items()}}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--device", default="nvidia")
    parser.add_argument("--frames", type=int, default=10)
    parser.add_argument("--scenes", nargs="*", default=["tea_table", "killeroo", "herd", "spheres"])
    parser.add_argument("--copies", type=int, default=1000, help="teapots at uniform level 16 (0: none)")
    parser.add_argument("--json", help="write the rows here too")
    parser.add_argument("--no-gl", action="store_true", help="leave out the share=\"gl\" frames")
    parser.add_argument("--no-vulkan", action="store_true", help="leave out the share=\"vulkan\" frames")
    args = parser.parse_args(argv)
    gl = vulkan = None
    if not args.no_gl:
        from support.egl import HeadlessGL
        try:
            gl = HeadlessGL()
        except RuntimeError as error:
            print(f"no gl column: {error}")
    tessellator = Tessellator(args.device)
    if not args.no_vulkan:
        from cltess.backends.opencl.share_cuda import OpenCLExternalMemory, SharingUnavailable
        from support.vulkan_reader import VulkanReader
        try:
            vulkan = VulkanReader(OpenCLExternalMemory(tessellator.context, tessellator.device).uuid)
        except (SharingUnavailable, RuntimeError) as error:
            print(f"no vulkan column: {error}")
    print(f"{tessellator.device.name} ({tessellator.device.platform.name}, {tessellator.device.driver_version}); "
          f"work {tessellator.work}", flush=True)
    rows = []
    for key in args.scenes:
        scene = frame_loop.suite_scene(key)
        rows.append(scene_rows(tessellator, key, scene, list(frame_loop.orbit(scene.camera, args.frames)),
                               {"pixels": frame_loop.PIXELS}, gl, vulkan))
        print(rows[-1], flush=True)
    if args.copies:
        scene = frame_loop.teapots(args.copies)
        rows.append(scene_rows(tessellator, f"{args.copies} teapots, level 16", scene, [None] * args.frames,
                               frame_loop.uniform_request(16), gl, vulkan))
        print(rows[-1], flush=True)
    print("\n| scene | triangles | MB | device ms (resident / cuda / host) | wall ms: resident | cuda "
          "(until `frame.cuda()` returns) | host arrays | gl (until GL has waited) | of which until "
          "`frame.gl()` returns | vulkan (until the queue has waited) | of which until `frame.vulkan()` "
          "returns | same bits |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        gl_cells = (f"{r['gl_wall_ms']:.3f} | {r['gl_call_wall_ms']:.3f}" if "gl_wall_ms" in r else "- | -")
        vk_cells = (f"{r['vk_wall_ms']:.3f} | {r['vk_call_wall_ms']:.3f}" if "vk_wall_ms" in r else "- | -")
        print(f"| {r['scene']} | {r['triangles']:,} | {r['bytes'] / 1e6:.1f} | {r['resident_device_ms']:.3f} / "
              f"{r['cuda_device_ms']:.3f} / {r['host_device_ms']:.3f} | {r['resident_wall_ms']:.3f} | "
              f"{r['cuda_wall_ms']:.3f} | {r['host_wall_ms']:.3f} | {gl_cells} | {vk_cells} | "
              f"{'yes' if r['same_bits'] else 'NO'} |")
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1))
    if vulkan:
        vulkan.close()
    return 0 if all(r["same_bits"] for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
