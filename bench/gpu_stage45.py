"""Issue 15 on a GPU: stages 4-5 of uniform level 16, variants of the kernels side by side, in one run.

    python bench/gpu_stage45.py --device nvidia [--repeat 10] [--json out.json] [--ptx DIR]
        --variant LABEL WORK TREE OPTIONS [--variant ...]

Uniform level 16 (``frame_loop.teapots``: 1,000 teapots, 32,000 patches, every edge factor 16;
16.3 M triangles, 565 MB written), as ``bench/frame_loop.py`` measures it:

* **fill**: the plain fill kernel of ``bench/frame_loop.py`` over 512 MiB: the write bandwidth
  (best of 5 after one warm-up, profiling events);
* **probes** (``bench/kernels/gpu_stage45_probe.cl``): stand-alone kernels writing the same
  bytes in the same layout with the simplest work (direct evaluation from the controls on a
  17 x 17 grid per patch, no ring, no pattern; a work-item per triangle of the grid): what a
  kernel of this output can reach (median of ``--repeat``);
* **variants**: each in a child process (the engine's programs are built once per process),
  ``WORK`` a work distribution as ``frame_loop.py --work`` takes it ("point-prep",
  "point-prep/8", ":direct"; "rows-prep/8": 8 patches per work-group of stage 4), ``TREE`` the source tree it runs from ("." this one; another
  ``git archive`` for a before/after in the same run), ``OPTIONS`` extra compiler options
  (``CLTESS_BUILD_OPTIONS``; "-" none; written ``opt:-DX=1`` so that argparse takes it as a
  value), e.g. ``opt:-DSTAGE4_RELOAD=1`` to pick a kernel variant.
  A ``Session`` frame first (builds, uploads; its output hashed: "same bits" compares the
  variants with the same evaluation), then ``--repeat`` frames: median device ms of each
  stage (profiling spans) and of stages 1-5 (a label starting "diag": a measurement-only
  variant, left out of "same bits"); % of fill = 565 MB / stages 1-5 / the fill rate.
  With NVIDIA's compiler, each variant's stage 4-5 kernels are built again with
  ``-cl-nv-verbose``: registers and spill bytes per kernel; ``--ptx DIR`` keeps their PTX.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import os
import re
import statistics
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
STAGES = ("factors", "crack_free", "counts", "vertices", "indices")


def child(args) -> dict:
    """One variant in this process (cwd: its tree, cltess from there)."""
    import numpy as np
    import pyopencl as cl

    sys.path.insert(0, str(HERE))
    import frame_loop

    import cltess
    from cltess.backends.opencl import Tessellator
    from cltess.backends.opencl import programs as programs_module

    spec, _, evaluation = args.work.partition(":")
    work, _, per_item = spec.partition("/")
    tessellator = Tessellator(args.device, work=work)
    if work == "rows-prep":  # "rows-prep/8": patches per work-group of stage 4
        tessellator.patches_per_group = int(per_item) if per_item else None
    else:
        tessellator.records_per_item = int(per_item) if per_item else None
    scene = frame_loop.teapots(args.copies)
    request = dict(frame_loop.uniform_request(16), forward_differencing=evaluation != "direct")
    session = cltess.Session(scene, tessellator=tessellator, **request)
    first = session.tessellate().fetch()
    digest = hashlib.blake2b(digest_size=8)
    for field in ("positions", "normals", "uv", "patch_ids", "object_ids", "triangles"):
        digest.update(np.ascontiguousarray(getattr(first, field)).tobytes())
    size = first.num_vertices * 40 + first.num_triangles * 12
    record = {"digest": digest.hexdigest(), "bytes": size, "vertices": first.num_vertices,
              "triangles": first.num_triangles}
    del first
    runs = [session.tessellate() for _ in range(args.repeat)]
    record["stage_ms"] = {stage: statistics.median(r.stage_ms.get(stage, 0.0) for r in runs) for stage in STAGES}
    record["device_ms"] = statistics.median(sum(r.stage_ms.get(s, 0.0) for s in STAGES) for r in runs)
    record["stage4_spread"] = [min(r.stage_ms["vertices"] for r in runs), max(r.stage_ms["vertices"] for r in runs)]
    del runs, session
    # registers: the variant's stage 4-5 programs again, with -cl-nv-verbose (NVIDIA only)
    device = tessellator.device
    if "NVIDIA" in device.platform.name:
        from cltess.kinds import BEZIER
        record["registers"] = {}
        stages = {"point": ("vertex_points", "triangles"), "point-prep": ("prepared_points", "triangles"),
                  "rows-prep": ("prepared_points", "triangles"), "patch": ("vertices", "indices")}.get(work, ())
        for stage in stages:
            headers, defines = programs_module.composition(stage, kind=BEZIER, pattern=BEZIER.pattern)
            source, options = programs_module.program_text(stage, headers, defines)
            options += programs_module.correctly_rounded_division(device) + programs_module.extra_build_options()
            program = cl.Program(tessellator.context, source).build(options=options + ["-cl-nv-verbose"])
            log = program.get_build_info(device, cl.program_build_info.LOG)
            for name, regs in re.findall(r"Function properties for (\w+)[\s\S]*?Used (\d+) registers", log):
                record["registers"][name] = int(regs)
            for name, stack, stored, loaded in re.findall(
                    r"Function properties for (\w+)\s*\n[^\n]*?(\d+) bytes stack frame, (\d+) bytes spill stores, "
                    r"(\d+) bytes spill loads", log):
                record.setdefault("spills", {})[name] = [int(stack), int(stored), int(loaded)]
            record.setdefault("logs", {})[stage] = log[-3000:]
            if args.ptx:
                Path(args.ptx).mkdir(parents=True, exist_ok=True)
                (Path(args.ptx) / f"{args.label.replace('/', '_')}-{stage}.ptx").write_bytes(program.binaries[0])
    return record


def probes(args) -> dict:
    """Fill bandwidth and the stand-alone kernels, in this process."""
    import numpy as np
    import pyopencl as cl
    import pyopencl.array as cl_array

    sys.path.insert(0, str(HERE))
    import frame_loop

    from cltess.backends.opencl import Tessellator
    from cltess.backends.opencl.programs import composition, correctly_rounded_division, kernel_dir
    from cltess.kinds import BEZIER

    tessellator = Tessellator(args.device, work="point")
    context, queue, device = tessellator.context, tessellator.queue, tessellator.device
    fill = cl.Program(context, frame_loop.FILL_SOURCE).build().fill
    count = (512 << 20) // 16
    buffer = cl.Buffer(context, cl.mem_flags.READ_WRITE, count * 16)
    times = []
    for _ in range(6):
        event = fill(queue, (-(-count // 256) * 256,), (256,), buffer, np.zeros(4, np.float32), np.uint64(count))
        event.wait()
        times.append((event.profile.end - event.profile.start) * 1e-9)
    del buffer
    out = {"device": f"{device.name} ({device.platform.name}, driver {device.driver_version})",
           "fill_bytes_per_s": count * 16 / min(times[1:])}
    scene = frame_loop.teapots(args.copies)
    plan = tessellator.plan(scene, **frame_loop.uniform_request(16))
    controls = plan.parts[0].data["controls"]
    patches, f = plan.num_patches, 16
    headers, _ = composition("vertices", kind=BEZIER, pattern=BEZIER.pattern)
    source = "".join(f'#include "{h}"\n' for h in ("common.h", *headers))
    source += (HERE / "kernels" / "gpu_stage45_probe.cl").read_text()
    program = cl.Program(context, source).build(
        options=["-I", str(kernel_dir())] + correctly_rounded_division(device))
    vertices, triangles = patches * (f + 1) ** 2, patches * 2 * f * f
    arrays = [cl_array.empty(queue, n, dtype) for n, dtype in
              ((3 * vertices, np.float32), (3 * vertices, np.float32), (2 * vertices, np.float32),
               (vertices, np.int32), (vertices, np.int32))]
    indices = cl_array.empty(queue, 3 * triangles, np.uint32)

    def timed(launch) -> float:
        spans = []
        for _ in range(args.repeat + 1):
            event = launch()
            event.wait()
            spans.append((event.profile.end - event.profile.start) * 1e-6)
        return statistics.median(spans[1:])

    out["probe_stage4_ms"] = timed(lambda: program.grid_vertices(
        queue, (-(-vertices // 64) * 64,), (64,), controls.data, np.uint32(patches), np.int32(f),
        *(a.data for a in arrays)))
    out["probe_stage5_ms"] = timed(lambda: program.grid_triangles(
        queue, (-(-triangles // 64) * 64,), (64,), np.uint32(patches), np.int32(f), indices.data))
    out["probe_bytes"] = vertices * 40 + triangles * 12
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--device", help="OpenCL device (substring)")
    parser.add_argument("--copies", type=int, default=1000)
    parser.add_argument("--repeat", type=int, default=10)
    parser.add_argument("--variant", nargs=4, action="append", default=[], metavar=("LABEL", "WORK", "TREE", "OPTIONS"))
    parser.add_argument("--json")
    parser.add_argument("--ptx", help="keep the variants' stage 4-5 PTX here (NVIDIA)")
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--work", help=argparse.SUPPRESS)
    parser.add_argument("--label", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        print("RESULT " + json.dumps(child(args)), flush=True)
        return 0
    record = {"command": " ".join(sys.argv), "date": time.strftime("%Y-%m-%d %H:%M:%S %z"),
              "load_before": [round(x, 1) for x in os.getloadavg()]}
    print("probes and fill", file=sys.stderr, flush=True)
    record.update(probes(args))
    record["variants"] = []
    for label, work, tree, options in args.variant:
        tree_path = Path(tree).resolve()
        options = options.removeprefix("opt:").strip()
        env = dict(os.environ, CLTESS_BUILD_OPTIONS="" if options == "-" else options,
                   PYTHONPATH=os.pathsep.join(p for p in (os.environ.get("PYTHONPATH", ""),) if p))
        paths = [p for p in env["PYTHONPATH"].split(os.pathsep) if p and Path(p).resolve() != Path.cwd().resolve()]
        env["PYTHONPATH"] = os.pathsep.join([str(tree_path)] + paths)
        command = [sys.executable, str(Path(__file__).resolve()), "--child", "--work", work, "--label", label,
                   "--repeat", str(args.repeat), "--copies", str(args.copies)]
        command += ["--device", args.device] if args.device else []
        command += ["--ptx", str(Path(args.ptx).resolve())] if args.ptx else []
        print(f"variant {label}: {work} from {tree} with {options!r}", file=sys.stderr, flush=True)
        started = time.perf_counter()
        done = subprocess.run(command, cwd=tree_path, env=env, capture_output=True, text=True)
        lines = [line for line in done.stdout.splitlines() if line.startswith("RESULT ")]
        if done.returncode or not lines:
            print(done.stdout[-2000:], done.stderr[-4000:], file=sys.stderr)
            record["variants"].append({"label": label, "work": work, "tree": tree, "options": options, "failed": True})
            continue
        row = json.loads(lines[-1][len("RESULT "):])
        row.update(label=label, work=work, tree=tree, options=options, seconds=round(time.perf_counter() - started, 1))
        record["variants"].append(row)
        print(f"  {row['seconds']} s: stage 4 {row['stage_ms']['vertices']:.3f} ms, stage 5 "
              f"{row['stage_ms']['indices']:.3f}, registers {row.get('registers')}", file=sys.stderr, flush=True)
    record["load_after"] = [round(x, 1) for x in os.getloadavg()]
    fill = record["fill_bytes_per_s"]
    lines = [f"{record['device']}; fill {fill / 1e9:.1f} GB/s; load {record['load_before']} -> {record['load_after']}",
             "", f"Probes (same output layout, simplest work; {record['probe_bytes'] / 1e6:.0f} MB): stage 4 "
             f"{record['probe_stage4_ms']:.3f} ms, stage 5 {record['probe_stage5_ms']:.3f} ms", "",
             "| variant | work | tree | options | stages 1-5 ms | stage 3 | stage 4 (min-max) | stage 5 | 4 + 5 | "
             "% of fill (1-5) | % of fill (4+5) | registers | same bits |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for row in record["variants"]:
        if row.get("failed"):
            lines.append(f"| {row['label']} | {row['work']} | {row['tree']} | {row['options']} | failed |")
            continue
        direct = row["work"].endswith(":direct")
        peers = {r["digest"] for r in record["variants"] if not r.get("failed") and r["work"].endswith(":direct") == direct
                 and not r["label"].startswith("diag")}
        same = "(diagnostic)" if row["label"].startswith("diag") else "yes" if len(peers) == 1 else "NO"
        s = row["stage_ms"]
        s45 = s["vertices"] + s["indices"]
        regs = ", ".join(f"{k} {v}" for k, v in row.get("registers", {}).items() if k != "kind_patch_size")
        lines.append(f"| {row['label']} | {row['work']} | {row['tree']} | {row['options']} | {row['device_ms']:.3f} | "
                     f"{s['counts']:.3f} | {s['vertices']:.3f} ({row['stage4_spread'][0]:.3f}-"
                     f"{row['stage4_spread'][1]:.3f}) | {s['indices']:.3f} | {s45:.3f} | "
                     f"{100 * row['bytes'] / (row['device_ms'] / 1e3) / fill:.1f}% | "
                     f"{100 * row['bytes'] / (s45 / 1e3) / fill:.1f}% | {regs} | {same} |")
    print("\n".join(lines))
    if args.json:
        Path(args.json).write_text(json.dumps(record, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
