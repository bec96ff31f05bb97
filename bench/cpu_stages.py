"""Issue 15, the CPU line: what bounds stages 4-5 on a CPU device, measured in one process.

    python bench/cpu_stages.py [--device pocl] [--copies 1000] [--repeat 5] [--rounds 2] [--baseline-kernels DIR]
                               [--work patch rows-prep ...] [--local-sizes 1 8 64] [--scene KEY] [--no-probes]
                               [--json out.json]

Uniform level 16 (``frame_loop.teapots``: 1,000 teapots, 32,000 patches, every edge factor
16; 16.3 M triangles, 565 MB written), stages 1-3 planned once by the engine, then on the same
plan's device buffers, each kernel launched alone ``--repeat`` times:

* **fill**: the plain fill kernel of ``bench/frame_loop.py`` over a buffer of the output's size
  or ``--fill-mib`` (default 512 MiB), whichever is larger: the memory-write rate.  (A fill of
  the output's size alone measured the caches as well below about 100 MB: 44.7 GB/s at 36 MB
  on this VM's 32 MiB L3, against 29-37 above; bench/RESULTS.md "Session 15, lead".)
* **stage 4** (the engine's ``vertices``, a work-item per patch) and **stage 5** (``indices``);
* probes of stage 4 (``bench/kernels/cpu_stage4_probe.cl``): the ring alone and the interior
  rows alone (the engine's own ``put_ring`` / ``put_rows``), the ring 8 points at a time in
  float8 lanes (``ring_soa8``), and the rows 8 at a time in float8
  lanes (``rows_soa8``, with Intel's builtin forms, on Intel's runtime only: PoCL 3.0 crashed
  running it), with its stores, with the same bytes stored as whole float8 vectors (not the
  output's layout: what the stores would cost after a transpose) and without stores;
  ring + rows, ring + rows_soa8 and ring_soa8 + rows_soa8 are hashed against the engine's stage 4
  ("same bits");
* with ``--baseline-kernels DIR`` (a kernels/ folder of another tree, e.g. ``git archive`` of
  main), its stage 4 and 5 built from there too, side by side;
* with ``--work W ...``: stages 4 and 5 of each work distribution W (tessellator.py
  ``WORK_DISTRIBUTIONS``) through the engine's own ``stage_vertices`` / ``stage_indices``
  (a stage of several launches timed from the first one's start to the last one's end), from
  this tree and, with ``--baseline-kernels``, from that one (a second Tessellator whose programs
  are built from it), each hashed against the per-patch kernels' output ("same bits");
* with ``--local-sizes N ...``: this tree's stage 4 and 5 kernels launched with work-group size
  N too (stages 4 and 5 are otherwise launched as the engine launches them: with 64 on PoCL,
  programs.py ``names_local_size``, where PoCL's own choice, 4,000 here, overflows its threads'
  8 MB stacks with the row lanes' private data; elsewhere with none, so the runtime picks);
* ``--scene KEY``: a scene of the paper's suite (cltess.bench.suite, one kind) at its camera and
  0.5 px instead of uniform level 16; ``--no-probes`` leaves the probes out; ``--rounds N``: N
  interleaved rounds of every launch (the minimum over all of them is reported).

Two clocks per launch: the device time (OpenCL profiling span: wall time on the runtime's
threads, which this shared VM's load stretches) and the **process CPU time** (``getrusage``:
user + system seconds of every thread of this process, the runtime's worker threads included)
over the launch and its wait: the work done, much less disturbed by other processes' load.
Each figure: the minimum over the repeats (and the median).  "% of fill" = the fill kernel's
time for the bytes a kernel writes (565 MB for stages 4 + 5; 40 bytes a vertex, 4 an index) /
the kernel's time: by device time and by CPU time.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import os
import resource
import statistics
import sys
import time
from pathlib import Path

import numpy as np
import pyopencl as cl
import pyopencl.array as cl_array

sys.path.insert(0, str(Path(__file__).resolve().parent))
import frame_loop  # noqa: E402  (teapots, uniform_request, FILL_SOURCE)

from cltess.backends.opencl import Tessellator  # noqa: E402
from cltess.backends.opencl import programs as programs_module  # noqa: E402
from cltess.backends.opencl.programs import (Programs, composition, correctly_rounded_division, kernel_dir,  # noqa: E402
                                            named_local_size, names_local_size)
from cltess.bench.suite import device_info, machine_info  # noqa: E402
from cltess.kinds import BEZIER  # noqa: E402
from cltess.tessellation import VERTEX_RECORD  # noqa: E402

PROBE = Path(__file__).resolve().parent / "kernels" / "cpu_stage4_probe.cl"


def cpu_seconds() -> float:
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def timed(launch, repeat: int) -> dict:
    """Device ms and process CPU ms of ``launch()`` (returns an event, or the list of events of
    a stage launched as several kernels: its device time runs from the first one's start to the
    last one's end), each repeat waited."""
    device, cpu = [], []
    for _ in range(repeat):
        started = cpu_seconds()
        events = launch()
        events = events if isinstance(events, list) else [events]
        events[-1].wait()
        cpu.append((cpu_seconds() - started) * 1e3)
        device.append((events[-1].profile.end - events[0].profile.start) * 1e-6)
    return {"device_ms": min(device), "device_ms_median": statistics.median(device),
            "cpu_ms": min(cpu), "cpu_ms_median": statistics.median(cpu)}


def build(context, device, folder: Path, stage_source: str, stage: str, pattern, defines=(), kind=BEZIER) -> cl.Program:
    headers, _ = composition(stage, kind=kind, pattern=pattern)
    # NAME or NAME=VALUE, before the headers so that they see them too
    source = "".join(f"#define {d.replace('=', ' ', 1)}\n" for d in defines)
    source += "".join(f'#include "{header}"\n' for header in ("common.h", *headers)) + stage_source
    options = ["-I", str(folder)] + correctly_rounded_division(device)
    return cl.Program(context, source).build(options=options)


def digest(arrays) -> str:
    hashed = hashlib.blake2b(digest_size=8)
    for array in arrays:
        hashed.update(array.get().tobytes())
    return hashed.hexdigest()


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--device", help="OpenCL device (substring; default as cltess picks)")
    parser.add_argument("--copies", type=int, default=1000, help="teapots (32 patches each)")
    parser.add_argument("--scene", help="a suite scene (cltess.bench.suite) at 0.5 px instead of uniform level 16")
    parser.add_argument("--pixels", type=float, help="--scene's pixel tolerance (default frame_loop.PIXELS, 0.5)")
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--baseline-kernels", help="a kernels/ folder to build stages 4-5 from too")
    parser.add_argument("--work", nargs="*", default=[],
                        help="work distributions (tessellator.py WORK_DISTRIBUTIONS) whose stages 4 and 5 to measure "
                             "through the engine's stage functions, from each tree")
    parser.add_argument("--local-sizes", type=int, nargs="*", default=[],
                        help="also launch this tree's stage 4 and 5 kernels with these work-group sizes (each divides 64)")
    parser.add_argument("--rounds", type=int, default=2, help="rounds of every launch, interleaved (at least 2)")
    parser.add_argument("--no-probes", action="store_true", help="leave out the stage 4 probes")
    parser.add_argument("--fill-mib", type=int, default=512,
                        help="the fill's buffer: at least this many MiB (and at least the output's size)")
    parser.add_argument("--json")
    args = parser.parse_args(argv)

    tessellator = Tessellator(args.device, work="patch")
    context, queue, device = tessellator.context, tessellator.queue, tessellator.device
    intel = "Intel" in device.platform.name
    record = {"device": device_info(device), "machine": machine_info(), "command": " ".join(sys.argv),
              "date": time.strftime("%Y-%m-%d %H:%M:%S %z"), "load_before": [round(x, 1) for x in os.getloadavg()]}
    if args.scene:  # a scene of the paper's suite at its camera, 0.5 px (as bench/frame_loop.py)
        scene = frame_loop.suite_scene(args.scene)
        plan = tessellator.plan(scene, pixels=args.pixels or frame_loop.PIXELS)
        if len(plan.parts) != 1:
            parser.error(f"--scene {args.scene}: {len(plan.parts)} kinds; this script runs a scene of one")
        record["scene"] = args.scene
    else:
        scene = frame_loop.teapots(args.copies)
        plan = tessellator.plan(scene, **frame_loop.uniform_request(16))
    part = plan.parts[0]
    patches, vertices = plan.num_patches, plan.num_vertices
    output_bytes = vertices * 40 + plan.num_indices * 4
    record.update(patches=patches, vertices=vertices, triangles=plan.num_indices // 3, output_bytes=output_bytes)
    out = [cl_array.empty(queue, (vertices, *shape), dtype) for _, dtype, shape in VERTEX_RECORD]
    triangles = cl_array.empty(queue, (plan.num_indices,), np.uint32)
    common = (part.data["controls"].data, plan.factors.data, plan.vertex_offsets.data, plan.objects.data,
              np.uint32(0), np.uint32(patches), np.uint32(0), np.uint64(0), np.int32(1))
    per_patch = (-(-patches // 64) * 64,)
    buffers = [a.data for a in out]

    fill = cl.Program(context, frame_loop.FILL_SOURCE).build().fill
    fill_bytes = max(output_bytes, args.fill_mib << 20) // 16 * 16
    record["fill_bytes"] = fill_bytes
    count = fill_bytes // 16
    fill_buffer = cl.Buffer(context, cl.mem_flags.READ_WRITE, count * 16)
    rows = {}

    def measure(name, launch):
        rows[name] = timed(launch, args.repeat)
        print(f"{name}: device {rows[name]['device_ms']:.1f} ms (median {rows[name]['device_ms_median']:.1f}), "
              f"CPU {rows[name]['cpu_ms']:.0f} ms (median {rows[name]['cpu_ms_median']:.0f})", file=sys.stderr, flush=True)

    folders = [("", kernel_dir())] + ([("baseline ", Path(args.baseline_kernels))] if args.baseline_kernels else [])
    kernels = {}
    for label, folder in folders:
        kernels[label] = (
            build(context, device, folder, (folder / "stages" / "vertices.cl").read_text(), "vertices", part.pattern, kind=part.kind).vertices,
            build(context, device, folder, (folder / "stages" / "indices.cl").read_text(), "indices", part.pattern, kind=part.kind).indices)
    engines = {"": tessellator}
    if args.baseline_kernels and args.work:  # a Tessellator whose programs are built from the baseline's kernels/
        engines["baseline "] = Tessellator(args.device, work="patch")
        engines["baseline "].programs = Programs(context)
    vertex_out = dict(zip((name for name, _, _ in VERTEX_RECORD), out))

    def work_stage4(engine, work):
        return lambda: engine.stage_vertices(part.data["controls"], plan.factors, plan.vertex_offsets, plan.objects,
                                             (0, vertices), (0, patches), kind=part.kind, out=vertex_out,
                                             pattern=part.pattern, work=work)[1]

    def work_stage5(engine, work):
        return lambda: engine.stage_indices(plan.factors, plan.vertex_offsets, plan.index_offsets,
                                            (0, plan.num_indices), (0, patches), kind=part.pattern,
                                            out=triangles, work=work)[1]

    for label, engine in engines.items():  # build every distribution's kernels now, from its tree
        folder = Path(args.baseline_kernels) if label else kernel_dir()
        saved, programs_module.kernel_dir = programs_module.kernel_dir, (lambda folder=folder: folder)
        try:
            for work in args.work:
                work_stage4(engine, work)()[-1].wait()
                work_stage5(engine, work)()[-1].wait()
        finally:
            programs_module.kernel_dir = saved
    forms = ("INTEL_FORMS",) if intel else ()
    if not args.no_probes:
        probe_source = PROBE.read_text()
        probe = build(context, device, kernel_dir(), probe_source, "vertices", part.pattern, forms)
        sink = build(context, device, kernel_dir(), probe_source, "vertices", part.pattern, forms + ("SINK_ONLY",))
        lanes_stored = build(context, device, kernel_dir(), probe_source, "vertices", part.pattern, forms + ("STORE_LANES",))
    octets = (16 - 1 + 7) // 8  # rows of a level-16 patch, 8 per work-item

    engine_local = named_local_size(per_patch) if names_local_size(device) else None  # as the engine launches

    def launch_stage4(kernel, local=engine_local):  # the engine's kernel takes its output's capacity (batch_fits); a tree before not
        capacity = (np.uint64(vertices),) if kernel.num_args == len(common) + 1 + len(buffers) else ()
        return lambda: kernel(queue, per_patch, local, *common, *capacity, *buffers)

    def launch_stage5(kernel, local=engine_local):
        capacity = (np.uint64(plan.num_indices),) if kernel.num_args == 8 else ()
        return lambda: kernel(queue, per_patch, local, plan.factors.data, plan.vertex_offsets.data,
                              plan.index_offsets.data, np.uint32(0), np.uint32(patches), np.uint64(0), *capacity,
                              triangles.data)

    for rep in range(args.rounds):  # rounds, interleaved, so that the load's drift touches every figure
        suffix = "" if rep == 0 else " (again)" if rep == 1 else f" (round {rep + 1})"
        measure("fill" + suffix, lambda: fill(queue, (-(-count // 256) * 256,), (256,), fill_buffer,
                                              np.zeros(4, np.float32), np.uint64(count)))
        for label, (vertices_kernel, indices_kernel) in kernels.items():
            measure(f"{label}stage 4 (vertices){suffix}", launch_stage4(vertices_kernel))
            record.setdefault("digests", {})[f"{label}stage 4"] = digest(out)
            measure(f"{label}stage 5 (indices){suffix}", launch_stage5(indices_kernel))
            record["digests"][f"{label}stage 5"] = digest([triangles])
        for local in args.local_sizes:  # this tree's kernels with a work-group size given
            vertices_kernel, indices_kernel = kernels[""]
            measure(f"stage 4 (vertices), local {local}{suffix}", launch_stage4(vertices_kernel, (local,)))
            record["digests"][f"stage 4, local {local}"] = digest(out)
            measure(f"stage 5 (indices), local {local}{suffix}", launch_stage5(indices_kernel, (local,)))
            record["digests"][f"stage 5, local {local}"] = digest([triangles])
        for work in args.work:
            for label, engine in engines.items():
                for buffer in buffers + [triangles.data]:  # so that the digests show this launch's writes
                    cl.enqueue_fill_buffer(queue, buffer, np.zeros(1, np.uint8), 0, buffer.size)
                queue.finish()  # the baseline engine launches on its own queue: the fills must be done first
                measure(f"{label}{work}: stage 4{suffix}", work_stage4(engine, work))
                record["digests"][f"{label}{work}: stage 4{suffix}"] = digest(out)
                measure(f"{label}{work}: stage 5{suffix}", work_stage5(engine, work))
                record["digests"][f"{label}{work}: stage 5{suffix}"] = digest([triangles])
        if args.no_probes:
            continue
        for buffer in buffers:
            cl.enqueue_fill_buffer(queue, buffer, np.zeros(1, np.uint8), 0, buffer.size)
        measure(f"ring only{suffix}", launch_stage4(probe.ring_only))
        measure(f"rows only{suffix}", launch_stage4(probe.rows_only))
        record["digests"]["ring + rows"] = digest(out)
        if not intel:  # PoCL 3.0 crashed (SIGSEGV) running rows_soa8 here; its builtins' forms are not known
            continue
        measure(f"rows, 8 in float8 lanes{suffix}", lambda: probe.rows_soa8(
            queue, (-(-patches * octets // 64) * 64,), None, *common, np.uint32(octets), *buffers))
        record["digests"]["ring + rows_soa8"] = digest(out)
        measure(f"ring, 8 points in float8 lanes{suffix}", lambda: probe.ring_soa8(
            queue, (-(-patches * 4 * 2 // 64) * 64,), None, *common, np.uint32(2), *buffers))
        record["digests"]["ring_soa8 + rows_soa8"] = digest(out)
        measure(f"rows, 8 in float8 lanes, stored as float8{suffix}", lambda: lanes_stored.rows_soa8(
            queue, (-(-patches * octets // 64) * 64,), None, *common, np.uint32(octets), *buffers))
        measure(f"rows, 8 in float8 lanes, no stores{suffix}", lambda: sink.rows_soa8(
            queue, (-(-patches * octets // 64) * 64,), None, *common, np.uint32(octets), *buffers))
    record["figures"] = rows
    record["load_after"] = [round(x, 1) for x in os.getloadavg()]

    def best(name, key):
        return min(rows[n][key] for n in rows if n == name or n.startswith(name + " (again)")
                   or n.startswith(name + " (round "))

    fill_device, fill_cpu = best("fill", "device_ms"), best("fill", "cpu_ms")
    lines = [f"{record['device']}; {patches:,} patches, {vertices:,} vertices, {plan.num_indices // 3:,} triangles, "
             f"{output_bytes / 1e6:.0f} MB; load {record['load_before']} -> {record['load_after']}; "
             f"fill {fill_bytes / fill_device / 1e6:.1f} GB/s by device time ({fill_bytes / 1e6:.0f} MB)", "",
             "| kernel | MB it writes | device ms (min) | CPU ms (min) | % of fill, device | % of fill, CPU |",
             "|---|---|---|---|---|---|"]
    ring_vertices = patches * 64  # 4 edges of 16 points a patch
    written = {"fill": fill_bytes, "stage 4 (vertices)": vertices * 40, "stage 5 (indices)": plan.num_indices * 4,
               "ring only": ring_vertices * 40, "rows only": (vertices - ring_vertices) * 40,
               "rows, 8 in float8 lanes": (vertices - ring_vertices) * 40,
               "rows, 8 in float8 lanes, stored as float8": (vertices - ring_vertices) * 40,
               "ring, 8 points in float8 lanes": ring_vertices * 40}
    for label in kernels:
        written[f"{label}stage 4 (vertices)"] = written["stage 4 (vertices)"]
        written[f"{label}stage 5 (indices)"] = written["stage 5 (indices)"]
    for local in args.local_sizes:
        written[f"stage 4 (vertices), local {local}"] = written["stage 4 (vertices)"]
        written[f"stage 5 (indices), local {local}"] = written["stage 5 (indices)"]
    for label in engines:
        for work in args.work:
            written[f"{label}{work}: stage 4"] = written["stage 4 (vertices)"]
            written[f"{label}{work}: stage 5"] = written["stage 5 (indices)"]
    names = [n for n in rows if not n.endswith("(again)") and " (round " not in n]
    for name in names:  # % of fill: the fill kernel's time for the bytes this kernel writes / its time
        device_ms, cpu_ms = best(name, "device_ms"), best(name, "cpu_ms")
        size = written.get(name)
        share = "" if size is None else (f"{100 * fill_device * size / fill_bytes / device_ms:.0f}% | "
                                         f"{100 * fill_cpu * size / fill_bytes / cpu_ms:.0f}%")
        lines.append(f"| {name} | {'' if size is None else f'{size / 1e6:.0f}'} | {device_ms:.1f} | {cpu_ms:.0f} | "
                     f"{share or ' | '} |")
    for label in kernels:
        device_ms = best(f"{label}stage 4 (vertices)", "device_ms") + best(f"{label}stage 5 (indices)", "device_ms")
        cpu_ms = best(f"{label}stage 4 (vertices)", "cpu_ms") + best(f"{label}stage 5 (indices)", "cpu_ms")
        lines.append(f"| {label}stages 4 + 5 | {output_bytes / 1e6:.0f} | {device_ms:.1f} | {cpu_ms:.0f} | "
                     f"{100 * fill_device * output_bytes / fill_bytes / device_ms:.1f}% | "
                     f"{100 * fill_cpu * output_bytes / fill_bytes / cpu_ms:.1f}% |")
    for work in args.work:
        for label in engines:
            device_ms = best(f"{label}{work}: stage 4", "device_ms") + best(f"{label}{work}: stage 5", "device_ms")
            cpu_ms = best(f"{label}{work}: stage 4", "cpu_ms") + best(f"{label}{work}: stage 5", "cpu_ms")
            lines.append(f"| {label}{work}: stages 4 + 5 | {output_bytes / 1e6:.0f} | {device_ms:.1f} | {cpu_ms:.0f} | "
                         f"{100 * fill_device * output_bytes / fill_bytes / device_ms:.1f}% | "
                         f"{100 * fill_cpu * output_bytes / fill_bytes / cpu_ms:.1f}% |")
    lines += ["", "bits: " + ", ".join(f"{k} {v}" for k, v in record["digests"].items())]
    same = record["digests"]["stage 4"]
    soa8 = record["digests"].get("ring + rows_soa8")
    for local in args.local_sizes:
        lines.append(f"local {local} same bits as stages 4, 5: "
                     f"{'yes' if record['digests'][f'stage 4, local {local}'] == same else 'NO'}, "
                     f"{'yes' if record['digests'][f'stage 5, local {local}'] == record['digests']['stage 5'] else 'NO'}")
    for work in args.work:
        for label in engines:
            lines.append(f"{label}{work} same bits as stages 4, 5 (patch), both rounds: " + ", ".join(
                'yes' if record['digests'][f'{label}{work}: stage {stage}{suffix}'] == record['digests'][f'stage {stage}']
                else 'NO' for stage in (4, 5) for suffix in ('', ' (again)')))  # the first two rounds
    if args.no_probes:
        lines.append("probes: not run (--no-probes)")
    else:
        lines.append(f"ring + rows same bits as stage 4: {'yes' if record['digests']['ring + rows'] == same else 'NO'}; "
                     f"ring + rows_soa8 (Intel's forms): "
                     f"{'not run (Intel only)' if soa8 is None else 'yes' if soa8 == same else 'NO'}; "
                     f"ring_soa8 + rows_soa8: {'not run' if soa8 is None else 'yes' if record['digests']['ring_soa8 + rows_soa8'] == same else 'NO'}")
    print("\n".join(lines))
    if args.json:
        Path(args.json).write_text(json.dumps(record, indent=1, default=float) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
