"""The structure of Table 1 of Dyken, Reimers and Seland, "Semi-uniform adaptive patch
tessellation" (CGF 2009; /work/shared/SEEDS.md section 1.2) with cltess's semi-uniform patterns
on PN triangle meshes of the paper's base sizes (0.2k .. 97k triangles), at maximum levels
M = 3 and 5, each mesh seen from --views seeded random viewpoints: the triangle counts
base -> uniform -> adaptive, and the speed of each method.

    python bench/semi_uniform.py [--device NAME] [--levels 3 5] [--sizes 200 1000 ...] [--views 3]
                                 [--pixels 0.5] [--repeat 5] [--max-uniform-triangles N] [--json OUT]
    python bench/semi_uniform.py --emit-table OUT.json   # stages 4-5 alone, from a run's JSON

The meshes are tori of about the base size with smooth radial bumps (so that the levels vary);
each view is a 1024x768, 45 degree camera framing the mesh from a random direction (seeded by
--seed, the size and the view number).  The criterion is the screen-space error bound at
--pixels (the paper used silhouetteness, which cltess does not have yet: each edge's level is
ceil(log2) of its crack-free factor, capped at M).  Methods, with the paper's letters:

  uniform        A/B  every patch at level M (P^M, 4^M triangles each: uniform = 4^M x base
                      exactly, whatever the view), patch-parallel, forward differencing
  no snap        C    adaptive levels, every edge at its patch's level (hanging nodes: cracks;
                      a bench-only stage-3-5 rerun on the same plan), patch-parallel, FD
  snap           D    adaptive levels with the snap (--pattern semi-uniform), patch-parallel, FD
  snap direct         the same, direct evaluation (what "by level" computes)
  by level      G/H   the same, stages 4-5 by level (--emit by-level): queues by one compaction
                      scan on the device, per level one launch over (slot, template point), one
                      over (slot, interior template triangle) and one per slot for the band
  transition          CudaTess's transition pattern at the same tolerance, factors <= 2^M

Times: device milliseconds of stages 1-5 (OpenCL profiling events, each stage's span from its
first launch's start to its last one's end, summed; "by level" adds its queue scan; the
read-back of the mesh is not included), summed over the views, median of --repeat runs after
one warm-up.  Mtri/s = output triangles of all views / that time.  The JSON also holds the
minimum, and stages 4-5 alone ("emit_ms", what by level changes: the queue scan, vertices,
indices), printed by --emit-table.  A uniform run whose output
would exceed --max-uniform-triangles per view is not run (its count is still given).  "sat" is
the share of patches whose bound needs more than 2^M (capped).  The "by level" output is
checked equal to "snap direct" (bitwise) on every view.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))

from cltess.bench import scenes as scenes_module  # noqa: E402
from cltess.bench.scenes import framing_camera, random_rotation  # noqa: E402
from cltess.request import Request  # noqa: E402
from cltess.scene import Scene  # noqa: E402

PAPER_SIZES = (200, 800, 1000, 1500, 4000, 6100, 23000, 97000)  # Table 1's base meshes
METHODS = ("uniform", "no snap", "snap", "snap direct", "by level", "transition")


def bumpy_torus(faces: int, seed: int, views: int) -> list[Scene]:
    """cltess.bench.scenes.bumpy_torus, one Scene per seeded random viewpoint."""
    mesh = scenes_module.bumpy_torus(faces, seed)
    faces_ = mesh.faces
    scenes = []
    for view in range(views):
        direction = random_rotation(np.random.default_rng([seed, view]))[:, 0]
        camera = framing_camera(*mesh.bounds, direction, distance_scale=0.6)
        scenes.append(Scene.from_trimesh(mesh, camera=camera, name=f"torus {len(faces_)} view {view}"))
    return scenes


def device_ms(tess) -> float:
    return sum(ms for stage, ms in tess.stage_ms.items() if stage != "total_wall")


def unsnapped(tessellator, plan):
    """The plan with every edge at its patch's level (method C: hanging nodes, so cracks): the
    same stages 1-2, stage 3 rerun on the new records; its device events replace the counts'."""
    import pyopencl.array as cl_array

    stored = plan.host_factors()
    size = np.abs(stored).max(axis=1, keepdims=True)
    factors = np.where(stored != 0, np.sign(stored) * size, 0).astype(np.int32)
    device_factors = cl_array.to_device(tessellator.queue, factors)
    vertex_offsets, index_offsets, events = tessellator.stage_counts(
        device_factors, [(part.pattern, part.base, part.count) for part in plan.parts])
    return replace(plan, factors=device_factors, vertex_offsets=vertex_offsets, index_offsets=index_offsets,
                   num_vertices=int(vertex_offsets[-1].get()), num_indices=int(index_offsets[-1].get()),
                   events=dict(plan.events, counts=events), _host={"factors": factors})


def requests(level: int, pixels: float) -> dict:
    """name -> (request, forward differencing) of each method but "no snap" (which is "snap"'s
    plan, unsnapped)."""
    cap = 1 << level
    adaptive = Request.of(pixels=pixels, pattern="semi_uniform", max_level=level, max_factor=max(cap, 64))
    return {
        # every patch at level M: an object-space tolerance no patch meets below it (no culling)
        "uniform": (Request.of(eps=1e-30, pattern="semi_uniform", max_level=level, max_factor=max(cap, 64)), True),
        "snap": (adaptive, True),
        "snap direct": (adaptive, False),
        "by level": (replace(adaptive, emit="by_level"), False),
        "transition": (Request.of(pixels=pixels, max_factor=cap), True),
    }


def run_method(tessellator, scene, name: str, level: int, pixels: float):
    if name == "no snap":
        request, fd = requests(level, pixels)["snap"]
        plan = unsnapped(tessellator, tessellator.plan(scene, request))
    else:
        request, fd = requests(level, pixels)[name]
        plan = tessellator.plan(scene, request)
    return tessellator.emit(plan, 0, plan.num_patches, fd)


EMIT_STAGES = ("queues", "vertices", "indices")


def emit_ms(tesses) -> float:
    """Device ms of stages 4-5 (the queue scan, vertices, indices) summed over the views."""
    return sum(tess.stage_ms.get(stage, 0.0) for tess in tesses for stage in EMIT_STAGES)


def timed(run, repeat: int) -> dict:
    """Median and minimum of the device ms (stages 1-5, and 4-5 alone) and wall ms of ``repeat``
    runs after a warm-up, and the last run's results; ``run`` returns a list of Tessellations
    (one per view).  The minimum is the figure least disturbed by other work on the machine."""
    run()
    device, emit, wall, result = [], [], [], None
    for _ in range(repeat):
        started = time.perf_counter()
        result = run()
        wall.append((time.perf_counter() - started) * 1e3)
        device.append(sum(device_ms(tess) for tess in result))
        emit.append(emit_ms(result))
    return {"device_ms": float(np.median(device)), "device_ms_min": float(np.min(device)),
            "emit_ms": float(np.median(emit)), "emit_ms_min": float(np.min(emit)),
            "wall_ms": float(np.median(wall)), "result": result}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--device", help="OpenCL device (default: as cltess tessellate)")
    parser.add_argument("--levels", type=int, nargs="+", default=[3, 5], help="maximum levels M (default 3 5)")
    parser.add_argument("--sizes", type=int, nargs="+", default=list(PAPER_SIZES),
                        help="base mesh sizes in triangles (default: Table 1's)")
    parser.add_argument("--views", type=int, default=3, help="seeded random viewpoints per mesh (default 3)")
    parser.add_argument("--pixels", type=float, default=0.5, help="screen-space tolerance (default 0.5)")
    parser.add_argument("--repeat", type=int, default=5, help="timed runs per method (default 5)")
    parser.add_argument("--methods", nargs="+", choices=METHODS, default=list(METHODS))
    parser.add_argument("--max-uniform-triangles", type=int, default=30_000_000,
                        help="skip timing a uniform run above this many triangles per view (default 3e7)")
    parser.add_argument("--seed", type=int, default=11)
    parser.add_argument("--json", help="also write every measurement here")
    parser.add_argument("--emit-table", metavar="JSON",
                        help="print the stages 4-5 table of a --json file (no run) and exit")
    args = parser.parse_args(argv)
    if args.emit_table:
        print_emit_table(json.loads(Path(args.emit_table).read_text()))
        return 0

    from cltess.pipeline import Tessellator

    tessellator = Tessellator(args.device)
    print(f"device: {tessellator.device.name.strip()}; {args.pixels} px, 1024x768, {args.views} views, "
          f"device ms of stages 1-5 summed over the views, median of {args.repeat}")
    rows = []
    for size in args.sizes:
        scenes = bumpy_torus(size, args.seed + size, args.views)
        base = scenes[0].num_patches
        for level in args.levels:
            row = {"base": base, "M": level, "uniform_triangles": 4 ** level * base, "methods": {}}
            for name in args.methods:
                if name == "uniform" and 4 ** level * base > args.max_uniform_triangles:
                    continue
                times = timed(lambda: [run_method(tessellator, s, name, level, args.pixels) for s in scenes],
                              args.repeat)
                tesses = times.pop("result")
                row["methods"][name] = dict(
                    times, triangles=sum(t.num_triangles for t in tesses),
                    saturated=sum(t.stats["saturated"] for t in tesses),
                    stage_ms=[t.stage_ms for t in tesses])  # of the last timed run
                if name == "uniform":
                    assert all(t.num_triangles == row["uniform_triangles"] for t in tesses), "uniform != 4^M x base"
                if name == "by level":
                    row["level_queues"] = [t.stats["level_queues"] for t in tesses]
                    check_same(tesses, [run_method(tessellator, s, "snap direct", level, args.pixels)
                                        for s in scenes])
            rows.append(row)
            print_row(row, args.views, header=len(rows) == 1)
    if args.json:
        Path(args.json).write_text(json.dumps({"device": tessellator.device.name.strip(), "pixels": args.pixels,
                                               "views": args.views, "repeat": args.repeat, "rows": rows}, indent=1))
    return 0


def check_same(got, expected) -> None:
    for a, b in zip(got, expected):
        for field in ("positions", "normals", "uv", "triangles"):
            assert np.array_equal(getattr(a, field), getattr(b, field)), f"by level != snap direct: {field}"


def print_row(row: dict, views: int, header: bool) -> None:
    names = list(row["methods"])
    if header:
        print(f"{'base':>6} {'M':>2} {'uniform':>10} {'adaptive':>9} {'sat':>4}  "
              + "  ".join(f"{name:>18}" for name in METHODS) + "  levels 0..M (view 0)")
        print(f"{'':>6} {'':>2} {'tris/view':>10} {'tris/view':>9} {'':>4}  "
              + "  ".join(f"{'ms (Mtri/s)':>18}" for _ in METHODS))
    m = row["methods"]
    cells = "  ".join((f"{m[n]['device_ms']:>8.2f} ({m[n]['triangles'] / m[n]['device_ms'] / 1e3:>7.1f})"
                       if n in m else f"{'-':>18}") for n in METHODS)
    snap = m.get("snap") or m.get("by level") or next(iter(m.values()))
    print(f"{row['base']:>6} {row['M']:>2} {row['uniform_triangles']:>10} {snap['triangles'] // views:>9} "
          f"{snap['saturated'] / row['base'] / views:>4.0%}  {cells}  {row.get('level_queues', [[]])[0]}",
          flush=True)


def print_emit_table(data: dict) -> None:
    """Stages 4-5 alone (the queue scan, vertices, indices; device ms summed over the views,
    median and minimum of the runs) for the methods that share a plan: what by level changes."""
    names = ("snap", "snap direct", "by level")
    print(f"device: {data['device']}; stages 4-5 device ms summed over {data['views']} views, "
          f"median / min of {data['repeat']} (Mtri/s of the min)")
    print(f"{'base':>6} {'M':>2} " + "  ".join(f"{n:>24}" for n in names) + "  by level / snap direct (min)")
    for row in data["rows"]:
        cells, best = [], {}
        for name in names:
            method = row["methods"].get(name)
            if method is None:
                cells.append(f"{'-':>24}")
                continue
            best[name] = method["emit_ms_min"]
            cells.append(f"{method['emit_ms']:>7.2f} / {best[name]:>6.2f} ({method['triangles'] / best[name] / 1e3:>6.1f})")
        ratio = best["by level"] / best["snap direct"] if {"by level", "snap direct"} <= best.keys() else float("nan")
        print(f"{row['base']:>6} {row['M']:>2} " + "  ".join(cells) + f"  {ratio:>8.2f}")


if __name__ == "__main__":
    sys.exit(main())
