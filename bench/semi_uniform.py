"""The structure of Table 1 of Dyken, Reimers and Seland, "Semi-uniform adaptive patch
tessellation" (CGF 2009; /work/shared/SEEDS.md section 1.2) with cltess's semi-uniform patterns
on PN triangle meshes of the paper's base sizes (0.2k .. 97k triangles), at maximum levels
M = 3 and 5: the triangle counts base -> uniform -> adaptive, and the speed of each method.

    python bench/semi_uniform.py [--device NAME] [--levels 3 5] [--sizes 200 800 ...]
                                 [--pixels 0.5] [--repeat 5] [--json OUT]

The meshes are tori of about the base size with smooth radial bumps (so that the levels vary),
each seen from a random viewpoint (seeded) by a 1024x768, 45 degree camera framing it, the
criterion the screen-space error bound at ``--pixels`` (the paper used silhouetteness; cltess's
error bound plays its part: each edge's level is ceil(log2) of its factor, capped at M).
Methods (the paper's letters where one matches):

  uniform      every patch at level M (P^M), patch-parallel, FD          (A/B: uniform)
  snap         adaptive levels with the snap, patch-parallel, FD         (D)
  snap direct  the same, direct evaluation
  levels       the same, stage 4 by level: queues by compaction scans,   (G/H: queues built on
               one launch per level over (slot, template point)           the device, instanced)
  transition   the transition pattern at the same tolerance, factors <= 2^M (CudaTess)

Times: device milliseconds of the stages (OpenCL profiling events, their spans summed; stages
1-3 included, the read-back to the host not), median of --repeat runs after one warm-up; Mtri/s
= output triangles / that time.  "sat" is the share of patches whose bound needs more than 2^M
(capped).  Hanging-node tessellation (the paper's C) is not a cltess mode: it cracks.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))

from cltess.backends.opencl.levels import emit_by_level, plan_by_level  # noqa: E402
from cltess.bench.scenes import framing_camera, random_rotation  # noqa: E402
from cltess.request import Request  # noqa: E402
from cltess.scene import Scene  # noqa: E402

PAPER_SIZES = (200, 800, 1000, 1500, 4000, 6100, 23000, 97000)  # Table 1's base meshes


def bumpy_torus(faces: int, seed: int):
    """A torus of about ``faces`` triangles (major sections twice the minor), its tube radius
    modulated by smooth bumps, with vertex normals; and a random viewpoint camera."""
    import trimesh

    from cltess.bench.scenes import vertex_normals

    minor = max(3, round(math.sqrt(faces / 4)))
    mesh = trimesh.creation.torus(major_radius=2.0, minor_radius=0.7, major_sections=2 * minor,
                                  minor_sections=minor)
    rng = np.random.default_rng(seed)
    vertices = np.array(mesh.vertices)
    ring = vertices * [1, 1, 0]
    ring = 2.0 * ring / np.linalg.norm(ring, axis=1, keepdims=True)
    tube = vertices - ring
    angle, height = np.arctan2(vertices[:, 1], vertices[:, 0]), np.arctan2(vertices[:, 2], np.linalg.norm(
        vertices[:, :2], axis=1) - 2.0)
    bumps = 1 + 0.25 * np.sin(3 * angle + rng.uniform(0, 6)) * np.cos(2 * height + rng.uniform(0, 6))
    vertices = ring + tube * bumps[:, None]
    faces_ = np.asarray(mesh.faces)
    mesh = trimesh.Trimesh(vertices, faces_, vertex_normals=vertex_normals(vertices, faces_), process=False)
    direction = random_rotation(rng)[:, 0]
    camera = framing_camera(*mesh.bounds, direction, distance_scale=0.6)
    return Scene.from_trimesh(mesh, camera=camera, name=f"torus {len(faces_)}")


def device_ms(tess) -> float:
    return sum(ms for stage, ms in tess.stage_ms.items() if stage != "total_wall")


def timed(run, repeat: int):
    """(median device ms, median wall ms, last result) of ``repeat`` runs after a warm-up."""
    run()
    device, wall, result = [], [], None
    for _ in range(repeat):
        started = time.perf_counter()
        result = run()
        wall.append((time.perf_counter() - started) * 1e3)
        device.append(device_ms(result))
    return float(np.median(device)), float(np.median(wall)), result


def methods(tessellator, scene, pixels: float, level: int):
    """name -> a function running that method once (returns a Tessellation)."""
    cap = 1 << level
    adaptive = Request.of(pixels=pixels, pattern="semi_uniform", max_level=level, max_factor=max(cap, 64))
    # every patch at level M: a tolerance no patch meets below it
    uniform = Request.of(pixels=1e-3, pattern="semi_uniform", max_level=level, max_factor=max(cap, 64))
    transition = Request.of(pixels=pixels, max_factor=cap)

    def plan_emit(request, fd=True):
        plan = tessellator.plan(scene, request)
        return tessellator.emit(plan, 0, plan.num_patches, fd)

    return {
        "uniform": lambda: plan_emit(uniform),
        "snap": lambda: plan_emit(adaptive),
        "snap direct": lambda: plan_emit(adaptive, False),
        "levels": lambda: emit_by_level(tessellator, plan_by_level(tessellator, scene, adaptive)),
        "transition": lambda: plan_emit(transition),
    }


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--device", help="OpenCL device (default: as cltess tessellate)")
    parser.add_argument("--levels", type=int, nargs="+", default=[3, 5], help="maximum levels M (default 3 5)")
    parser.add_argument("--sizes", type=int, nargs="+", default=list(PAPER_SIZES),
                        help="base mesh sizes in triangles (default: Table 1's)")
    parser.add_argument("--pixels", type=float, default=0.5, help="screen-space tolerance (default 0.5)")
    parser.add_argument("--repeat", type=int, default=5, help="timed runs per method (default 5)")
    parser.add_argument("--seed", type=int, default=11)
    parser.add_argument("--json", help="also write every measurement here")
    args = parser.parse_args(argv)

    from cltess.pipeline import Tessellator

    tessellator = Tessellator(args.device)
    print(f"device: {tessellator.device.name.strip()}; {args.pixels} px, 1024x768, median of {args.repeat}")
    rows = []
    for size in args.sizes:
        scene = bumpy_torus(size, args.seed + size)
        base = scene.num_patches
        for level in args.levels:
            row = {"scene": scene.name, "base": base, "M": level, "methods": {}}
            for name, run in methods(tessellator, scene, args.pixels, level).items():
                ms, wall, tess = timed(run, args.repeat)
                row["methods"][name] = {"triangles": tess.num_triangles, "device_ms": ms, "wall_ms": wall,
                                        "saturated": tess.stats["saturated"], "stage_ms": tess.stage_ms}
                if name == "levels":
                    row["level_queues"] = tess.stats["level_queues"]
            rows.append(row)
            print_row(row, header=len(rows) == 1)
    if args.json:
        Path(args.json).write_text(json.dumps({"device": tessellator.device.name.strip(), "pixels": args.pixels,
                                               "repeat": args.repeat, "rows": rows}, indent=1))
    return 0


def print_row(row: dict, header: bool) -> None:
    names = list(row["methods"])
    if header:
        print(f"{'base':>6} {'M':>2} {'uniform tris':>12} {'adaptive tris':>13} {'sat':>5}  "
              + "  ".join(f"{name + ' ms (Mtri/s)':>24}" for name in names) + "  levels 0..M")
    m = row["methods"]
    cells = "  ".join(f"{m[n]['device_ms']:>11.2f} ({m[n]['triangles'] / m[n]['device_ms'] / 1e3:>9.1f})"
                      for n in names)
    print(f"{row['base']:>6} {row['M']:>2} {m['uniform']['triangles']:>12} {m['snap']['triangles']:>13} "
          f"{m['snap']['saturated'] / row['base']:>5.0%}  {cells}  {row['level_queues']}", flush=True)


if __name__ == "__main__":
    sys.exit(main())
