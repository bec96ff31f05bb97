"""Issue 15 on a GPU: stage 5 beside stage 4 on a second queue, against one in-order queue.

    python bench/gpu_overlap.py --device nvidia [--frames 20] [--rounds 4] [--copies 1000] [--json F]

Stage 5 (the triangles) needs only stage 3's offsets, not stage 4's vertices.  On one in-order
queue it waits for all of stage 4, whose one wave of work-groups (uniform level 16 on the H200:
1,000 one-warp groups at 254 registers) leaves the SMs half idle while its last groups finish.
Variant "beside" enqueues a marker on the engine's queue before stage 4, launches stage 5 on a
second queue of the same context behind that marker, and makes the engine's queue wait for
stage 5 (a barrier on its event) before anything after it, such as the read-back or the next frame.

Per variant, rounds alternating the order: a ``Session`` frame of uniform level 16
(``frame_loop.teapots``) hashed (positions, normals, uv, ids, triangles: "same bits" against the
first variant), then ``--frames`` frames one at a time: the device span from the first event's
start (stage 1) to the last event's end, and the sum of the stages' spans (what
``bench/gpu_stage45.py`` reports); then ``--frames`` frames overlapped (``wait=False``, at most two
in flight, as ``bench/frame_loop.py`` runs them): wall per frame.  Every frame is asked with the
request's own ``max_factor`` as an override, so that it is made the normal way (plan_on and
emit_async, where the variant's queues are chosen) rather than replayed from a recorded frame
(cltess/backends/opencl/recorded.py enqueues every launch on the engine's one queue); the
overlapped loop's host time per frame is therefore the normal path's, not a replay's.  The fill kernel's bandwidth
is measured in the same run; % of fill = bytes written / span / fill.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import statistics
import sys
import time
from pathlib import Path

import numpy as np
import pyopencl as cl

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import frame_loop  # noqa: E402

import cltess  # noqa: E402
from cltess.backends.opencl import Tessellator  # noqa: E402

_START, _END = cl.profiling_info.START, cl.profiling_info.END


class BesideTessellator(Tessellator):
    """Stage 5 on a second queue, behind a marker of stages 1-3 only (module docstring)."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.second = cl.CommandQueue(self.context, properties=cl.command_queue_properties.PROFILING_ENABLE)
        self._before_stage4 = None

    def stage_vertices(self, *args, **kwargs):
        self._before_stage4 = cl.enqueue_marker(self.queue)
        self.queue.flush()
        return super().stage_vertices(*args, **kwargs)

    def stage_indices(self, *args, **kwargs):
        first_queue = self.queue
        cl.enqueue_barrier(self.second, wait_for=[self._before_stage4])
        self.queue = self.second
        try:
            triangles, events = super().stage_indices(*args, **kwargs)
        finally:
            self.queue = first_queue
        self.second.flush()
        if events:
            cl.enqueue_barrier(first_queue, wait_for=events)
        return triangles, events


class Recording:
    """Keeps the last emit's events (stages 1-5) of a tessellator."""

    def __init__(self, tessellator):
        self.jobs = []
        emit_async = tessellator.emit_async

        def recorded(*args, **kwargs):
            job = emit_async(*args, **kwargs)
            job.totals_copies = list(job.plan._pending[2]) if job.plan._pending else []  # (gone once settled)
            self.jobs.append(job)
            return job

        tessellator.emit_async = recorded


def make(variant: str, device: str | None):
    tessellator = (BesideTessellator if variant == "beside" else Tessellator)(device, work="rows-prep")
    recording = Recording(tessellator)
    return tessellator, recording


def frame_numbers(recording) -> tuple[float, float]:
    """(span ms from stage 1's start to the last end, sum of the stages' spans) of the last job."""
    job = recording.jobs[-1]
    events = [e for evs in job.events.values() for e in evs]
    starts = [e.get_profiling_info(_START) for e in events]
    ends = [e.get_profiling_info(_END) for e in events]
    span = (max(ends) - min(starts)) * 1e-6
    stages = sum((evs[-1].get_profiling_info(_END) - evs[0].get_profiling_info(_START)) * 1e-6
                 for evs in job.events.values() if evs)
    return span, stages


def timeline(recording) -> list:
    """[(what, start µs, end µs)] of the last job's commands (stages and stage 3's totals copy),
    from the first start."""
    job = recording.jobs[-1]
    named = [(stage, e) for stage, evs in job.events.items() for e in evs]
    named += [("totals copy", e) for e in job.totals_copies]
    first = min(e.get_profiling_info(_START) for _, e in named)
    rows = [(what, (e.get_profiling_info(_START) - first) * 1e-3, (e.get_profiling_info(_END) - first) * 1e-3)
            for what, e in named]
    return sorted(rows, key=lambda row: row[1])


def digest_of(frame) -> str:
    digest = hashlib.blake2b(digest_size=8)
    for field in ("positions", "normals", "uv", "patch_ids", "object_ids", "triangles"):
        digest.update(np.ascontiguousarray(getattr(frame, field)).tobytes())
    return digest.hexdigest()


def fill_rate(tessellator) -> float:
    fill = cl.Program(tessellator.context, frame_loop.FILL_SOURCE).build().fill
    count = (512 << 20) // 16
    buffer = cl.Buffer(tessellator.context, cl.mem_flags.READ_WRITE, count * 16)
    times = []
    for _ in range(6):
        event = fill(tessellator.queue, (-(-count // 256) * 256,), (256,), buffer, np.zeros(4, np.float32),
                     np.uint64(count))
        event.wait()
        times.append((event.profile.end - event.profile.start) * 1e-9)
    return count * 16 / min(times[1:])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--device")
    parser.add_argument("--frames", type=int, default=20)
    parser.add_argument("--rounds", type=int, default=4)
    parser.add_argument("--copies", type=int, default=1000)
    parser.add_argument("--level", type=int, default=16)
    parser.add_argument("--json")
    args = parser.parse_args(argv)
    scene = frame_loop.teapots(args.copies)
    request = frame_loop.uniform_request(args.level)
    made = {name: make(name, args.device) for name in ("one queue", "beside")}
    sessions = {name: cltess.Session(scene, tessellator=t, **request) for name, (t, _) in made.items()}
    first = next(iter(made.values()))[0]
    record = {"device": f"{first.device.name} ({first.device.platform.name}, driver {first.device.driver_version})",
              "fill_bytes_per_s": fill_rate(first), "date": time.strftime("%Y-%m-%d %H:%M:%S %z"),
              "variants": {}}
    for name, session in sessions.items():
        frame = session.tessellate().fetch()
        record["variants"][name] = {"digest": digest_of(frame), "span_ms": [], "stages_ms": [], "loop_ms": []}
        record["bytes"] = frame.num_vertices * 40 + frame.num_triangles * 12
        del frame
    names = list(sessions)
    for round_ in range(args.rounds):
        for name in names if round_ % 2 == 0 else names[::-1]:
            session, (_, recording), out = sessions[name], made[name], record["variants"][name]
            for _ in range(args.frames):
                session.tessellate(max_factor=args.level).finish()
                span, stages = frame_numbers(recording)
                out["span_ms"].append(span)
                out["stages_ms"].append(stages)
                out["timeline"] = timeline(recording)
                recording.jobs.clear()
            started = time.perf_counter()
            pending = [session.tessellate(wait=False, max_factor=args.level)]
            for _ in range(args.frames - 1):
                pending.append(session.tessellate(wait=False, max_factor=args.level))
                pending.pop(0).finish()
            for frame in pending:
                frame.finish()
            out["loop_ms"].append((time.perf_counter() - started) * 1e3 / args.frames)
            recording.jobs.clear()
    base = record["variants"][names[0]]["digest"]
    fill, size = record["fill_bytes_per_s"] / 1e9, record["bytes"] / 1e6
    print(f"{record['device']}; fill {fill:.0f} GB/s; {size:.0f} MB a frame")
    print("| variant | span ms (median) | sum of stage spans | % of fill (span) | overlapped loop ms/frame "
          "| same bits |")
    print("|---|---|---|---|---|---|")
    for name, out in record["variants"].items():
        span = statistics.median(out["span_ms"])
        out["summary"] = {"span_ms": span, "stages_ms": statistics.median(out["stages_ms"]),
                          "loop_ms": statistics.median(out["loop_ms"]),
                          "percent_of_fill": 100 * record["bytes"] / (span * 1e-3) / record["fill_bytes_per_s"]}
        s = out["summary"]
        print(f"| {name} | {span:.3f} [{min(out['span_ms']):.3f}-{max(out['span_ms']):.3f}] | {s['stages_ms']:.3f} | "
              f"{s['percent_of_fill']:.1f}% | {s['loop_ms']:.3f} | {'yes' if out['digest'] == base else 'NO'} |")
    for name, out in record["variants"].items():
        print(f"{name}, the last frame's commands (µs from the first start):")
        for what, start, end in out["timeline"]:
            print(f"    {what:12s} {start:8.1f} {end:8.1f}")
    if args.json:
        Path(args.json).write_text(json.dumps(record, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
