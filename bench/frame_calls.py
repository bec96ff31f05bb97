"""Issue 15, a frame's host cost by call: how many OpenCL commands one ``Session`` frame enqueues
(kernel launches, reads, buffer copies, maps and unmaps, markers, flushes, waits, event queries),
and where its Python time goes (cProfile), on any device.  The counts are what a frame costs any
runtime (on NVIDIA's a launch costs the host 13.7 µs, a read 14.5-22 µs: bench/enqueue_cost.py),
so they carry over from a CPU device to a GPU.

    python bench/frame_calls.py [--device NAME] [--frames 20] [--scenes tea_table ...]
                                [--profile N] [--json out.json]

Per scene: a ``cltess.Session`` at 0.5 px on ``bench/frame_loop.py``'s circle of cameras (one
warm-up pass), then three loops over the cameras, counting the calls per frame:

* "on device": ``session.tessellate(camera=...)`` (waits for the stages);
* "host arrays": ``session.tessellate(camera=...).fetch()``;
* "overlapped": ``session.tessellate(camera=..., wait=False)``, the last frame finished.

``--as-gpu`` makes the frames a GPU makes (work "point", stage 3 in one launch up to
``FUSED_OFFSETS_MAX_PATCHES``) on this device, to count their calls here.

The counts wrap pyopencl's entry points in this process (``pyopencl._cl.enqueue_nd_range_kernel``,
``_enqueue_read_buffer``, ``_enqueue_copy_buffer``, ``enqueue_map_buffer``, ``MemoryMap.release``,
markers, ``CommandQueue.flush``, ``wait_for_events``, ``Event.wait``, event status and profiling
queries), so they also count on a tree before this one (``PYTHONPATH=TREE``).  "Python" per
frame: the host thread's CPU time (``time.thread_time_ns``) over a loop less its CPU time inside
those calls, the median of ``--rounds`` loops: the frame's own host work, which a GPU's host pays
as well, measured by CPU time so that the device's threads on the same cores do not count.  ``--profile N``
prints, instead of the counts, cProfile's top N functions by own time over ``--profile-rounds`` overlapped loops (its own overhead
inflates every Python figure about 2x: read it for the split, not for totals).
"""
from __future__ import annotations

import argparse
import collections
import cProfile
import inspect
import json
import pstats
import statistics
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import pyopencl as cl  # noqa: E402
import pyopencl._cl as _cl  # noqa: E402

import cltess  # noqa: E402
import frame_loop as fl  # noqa: E402

COUNTS: collections.Counter = collections.Counter()
#: The host thread's CPU ns inside the counted calls (``time.thread_time_ns``), so that a loop's
#: CPU time less this is its Python: what a GPU's host pays the same, whatever the runtime.
IN_CALLS = [0]
clock = time.thread_time_ns


def _counted(owner, name: str, label: str) -> None:
    original = getattr(owner, name)

    def call(*args, **kwargs):
        COUNTS[label] += 1
        started = clock()
        try:
            return original(*args, **kwargs)
        finally:
            IN_CALLS[0] += clock() - started

    setattr(owner, name, call)


def _counted_property(cls, name: str, label: str) -> None:
    prop = getattr(cls, name)

    def get(self):
        COUNTS[label] += 1
        started = clock()
        try:
            return prop.__get__(self)
        finally:
            IN_CALLS[0] += clock() - started

    setattr(cls, name, property(get))


def install() -> None:
    """Count the calls (see the module's notes)."""
    _counted(_cl, "enqueue_nd_range_kernel", "launches")
    _counted(cl, "enqueue_nd_range_kernel", "launches")
    for name in ("_enqueue_read_buffer", "_enqueue_read_buffer_rect"):
        _counted(_cl, name, "reads")
    for name in ("_enqueue_copy_buffer", "_enqueue_copy_buffer_rect"):
        _counted(_cl, name, "buffer copies")
    for name in ("_enqueue_write_buffer", "_enqueue_fill_buffer"):
        _counted(_cl, name, "writes and fills")
    for owner in (_cl, cl):
        _counted(owner, "enqueue_map_buffer", "maps")
    _counted(cl.MemoryMap, "release", "unmaps")
    for owner in (_cl, cl):
        for name in ("_enqueue_marker", "enqueue_marker", "_enqueue_marker_with_wait_list",
                     "enqueue_marker_with_wait_list", "_enqueue_barrier", "enqueue_barrier"):
            if hasattr(owner, name):
                _counted(owner, name, "markers and barriers")
    _counted(cl.CommandQueue, "flush", "flushes")
    _counted(cl.CommandQueue, "finish", "finishes")
    _counted(cl, "wait_for_events", "waits")
    _counted(cl.Event, "wait", "waits")
    _counted(cl.Event, "get_profiling_info", "profiling queries")
    _counted_property(cl.Event, "command_execution_status", "status queries")
    _counted(cl.Buffer, "__init__", "buffers made")


def loop(session, path, mode: str) -> tuple[dict, float, float]:
    """(calls per frame by label, wall ms per frame, Python µs per frame) of one loop over the
    cameras; Python: the host thread's CPU time outside the counted OpenCL calls."""
    COUNTS.clear()
    IN_CALLS[0] = 0
    started, cpu = time.perf_counter(), clock()
    if mode == "overlapped":
        kept = [session.tessellate(camera=camera, wait=False) for camera in path]
        kept[-1].finish()
    else:
        for camera in path:
            frame = session.tessellate(camera=camera)
            if mode == "host arrays":
                frame.fetch()
    python = (clock() - cpu - IN_CALLS[0]) / len(path) / 1e3
    wall = (time.perf_counter() - started) / len(path) * 1e3
    return {label: n / len(path) for label, n in sorted(COUNTS.items())}, wall, python


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--device")
    parser.add_argument("--frames", type=int, default=20)
    parser.add_argument("--scenes", nargs="*", default=["tea_table", "double_torus", "killeroo", "spheres", "model_zoo"])
    parser.add_argument("--profile", type=int, default=0, metavar="N")
    parser.add_argument("--profile-rounds", type=int, default=5, help="loops over the cameras profiled")
    parser.add_argument("--rounds", type=int, default=3, help="loops over the cameras per mode (median of their Python)")
    parser.add_argument("--as-gpu", action="store_true",
                        help="count the calls a GPU's frame makes (work 'point', stage 3 fused up to "
                             "FUSED_OFFSETS_MAX_PATCHES) on this device; its times mean nothing")
    parser.add_argument("--json")
    args = parser.parse_args()
    import warnings

    warnings.simplefilter("ignore")
    from cltess.backends.opencl import Tessellator
    from cltess.bench.suite import resolve_scenes

    if not args.profile:  # (the counting wrappers would show up in the profile)
        install()
    tessellator = Tessellator(args.device, work="point" if args.as_gpu else None)
    if args.as_gpu:
        tessellator.fused_offsets, tessellator.tiled_offsets, tessellator._cpu = True, True, False
    overlaps = "wait" in inspect.signature(cltess.Session.tessellate).parameters
    print(f"{tessellator.device.name.strip()} ({tessellator.device.platform.name.strip()}); cltess from "
          f"{cltess.__file__}; calls per frame, mean over {args.frames} cameras")
    record = []
    for key in resolve_scenes(args.scenes):
        scene = fl.suite_scene(key)
        session = cltess.Session(scene, tessellator=tessellator, pixels=fl.PIXELS)
        path = list(fl.orbit(scene.camera, args.frames))
        for camera in path:
            session.tessellate(camera=camera).fetch()
        print(f"{key} ({scene.num_patches if hasattr(scene, 'num_patches') else ''} patches, "
              f"work {tessellator.work}, fused stage 3 {tessellator.fused_offsets}):")
        entry = {"scene": key}
        for mode in () if args.profile else ("on device", "host arrays") + (("overlapped",) if overlaps else ()):
            loops = [loop(session, path, mode) for _ in range(args.rounds)]
            counts, wall = loops[0][0], statistics.median(w for _, w, _ in loops)
            python = statistics.median(p for _, _, p in loops)
            entry[mode] = {"calls": counts, "wall_ms": wall, "python_us": python, "python_us_rounds": [p for *_, p in loops]}
            print(f"  {mode:12s} wall {wall:7.3f} ms, Python {python:6.1f} µs: "
                  + ", ".join(f"{label} {n:g}" for label, n in counts.items()))
        if args.profile:
            profile = cProfile.Profile()
            profile.enable()
            for _ in range(args.profile_rounds):
                loop(session, path, "overlapped" if overlaps else "on device")
            profile.disable()
            stats = pstats.Stats(profile)
            stats.sort_stats("tottime").print_stats(args.profile)
        record.append(entry)
    if args.json:
        Path(args.json).write_text(json.dumps(record, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
