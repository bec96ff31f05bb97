"""The structure of Tables 1-2 of Amresh and Fünfzig, "Semi-uniform, 2-different tessellation of
triangular parametric surfaces" (/work/shared/SEEDS.md section 2.2) with cltess's SD-2 pattern:
silhouette refinement with factor b = 7 on crossed edges and a on the others (the paper's
classes: ``silhouette_band=0``; cltess's default ramp refines a band around them), on PN meshes of
the paper's base sizes, against uniform factor 7 (exactly 49 x base) and the transition
pattern (the paper's stitching [7]) on the same integer factors.

    python bench/sd2.py [--device NAME] [--low 1 3 5] [--repeat 5] [--json OUT]

Meshes: the icosphere of 320 faces (the paper's sphere exactly), and for the violin case
(2,120) and the cow (5,804), which are not available, tori with smooth radial bumps of
2,120 and 5,796 faces; each seen by a 1024x768, 45 degree camera framing it from a fixed
direction (the paper gives neither a nor its cameras).  Columns:

  triangles  output triangles; ratios against uniform and against transition
  strip B    bytes of the strip indices (uint32, restart markers included); list B = 12 x tris
  ms         device milliseconds of the stages (OpenCL profiling events, each stage's span,
             summed: level functions and stages 1-5, strips included for SD-2, the read-back
             not), median of --repeat runs after one warm-up
  error      the largest |surface - mesh| measured at 15 barycentric points of every triangle
             (stage 6, Tessellator.verify with eps = 1: the ratio is the distance itself);
             transition: the float64 host mirror cltess.bound.worst_bound_ratio
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

from cltess.bench.scenes import framing_camera, vertex_normals  # noqa: E402
from cltess.patterns import TRI_TRANSITION  # noqa: E402
from cltess.scene import Scene, TriangleMesh  # noqa: E402
from cltess.tessellation import Tessellation  # noqa: E402

UNIFORM = 7  # the paper's b and uniform factor
VIEW = np.array([-1.0, -2.0, -0.8])


def sphere_320() -> Scene:
    import trimesh

    return Scene.from_trimesh(trimesh.creation.icosphere(2), name="sphere-320")


def bumpy_torus(major: int, minor: int, name: str) -> Scene:
    """A torus of 2 major minor faces whose tube radius varies smoothly (so the silhouette is
    not a circle), with area-weighted vertex normals."""
    import trimesh

    mesh = trimesh.creation.torus(major_radius=2.0, minor_radius=0.7, major_sections=major, minor_sections=minor)
    vertices = np.array(mesh.vertices)
    angle = np.arctan2(vertices[:, 1], vertices[:, 0])
    centre = 2.0 * np.stack([np.cos(angle), np.sin(angle), np.zeros_like(angle)], axis=1)
    tube = vertices - centre
    scale = 1.0 + 0.25 * np.sin(3 * angle) * np.cos(2 * np.arctan2(tube[:, 2], np.linalg.norm(tube[:, :2], axis=1)))
    vertices = centre + tube * scale[:, None]
    faces = np.array(mesh.faces)
    return Scene.from_meshes([TriangleMesh(vertices, faces, vertex_normals(vertices, faces), 0, name)], name=name)


def scenes() -> list[Scene]:
    out = [sphere_320(), bumpy_torus(53, 20, "torus-2120"), bumpy_torus(63, 46, "torus-5796")]
    for scene in out:
        mesh = scene.meshes[0]
        lo, hi = mesh.vertices.min(axis=0), mesh.vertices.max(axis=0)
        scene.camera = framing_camera(lo, hi, VIEW)
    return out


def device_ms(stage_ms: dict) -> float:
    return sum(ms for stage, ms in stage_ms.items() if stage != "total_wall")


def median_run(run, repeat: int):
    run()  # warm-up: builds, caches
    results = [run() for _ in range(repeat)]
    times = sorted(device_ms(r[0].stage_ms) if isinstance(r, tuple) else device_ms(r.stage_ms) for r in results)
    return results[-1], times[len(times) // 2]


def transition_on(tessellator, plan, factors: np.ndarray):
    """Stages 3-5 of the transition pattern on the given whole factors (P, 4) with the plan's PN
    control points; (Tessellation, device ms of stages 3-5)."""
    import pyopencl.array as cl_array

    from cltess.backends.opencl.events import span_ms

    queue = tessellator.queue
    part = plan.parts[0]
    device = cl_array.to_device(queue, np.ascontiguousarray(factors, np.int32))
    count = len(factors)
    vertex_offsets, index_offsets, counts = tessellator.stage_counts(device, [(TRI_TRANSITION, 0, count)])
    vertices, indices = int(vertex_offsets[count].get()), int(index_offsets[count].get())
    out, vertex_events = tessellator.stage_vertices(part.data["controls"], device, vertex_offsets, plan.objects,
                                                    (0, vertices), (0, count), True, kind=part.kind,
                                                    pattern=TRI_TRANSITION)
    triangles, index_events = tessellator.stage_indices(device, vertex_offsets, index_offsets, (0, indices),
                                                        (0, count), kind=TRI_TRANSITION)
    queue.finish()
    ms = sum(span_ms(e) for e in (counts[:1], counts[1:], vertex_events, index_events) if e)
    tess = Tessellation(triangles=triangles.get(), factors=factors, stage_ms={"stages 3-5": ms},
                        **{k: a.get() for k, a in out.items()})
    return tess, ms


def measure(tessellator, scene: Scene, low: list[float], repeat: int) -> list[dict]:
    from cltess.bound import worst_bound_ratio

    base = scene.num_triangles
    rows = []
    uniform, ms = median_run(lambda: tessellator.tessellate(scene, eps=1e-7, max_factor=UNIFORM), repeat)
    assert (uniform.factors[:, :3] == UNIFORM).all(), "uniform: every edge at the cap"
    plan = tessellator.plan(scene, eps=1.0, max_factor=UNIFORM)
    error = tessellator.verify(scene, plan, uniform)["verify_ratio"]
    rows.append(dict(scene=scene.name, base=base, method=f"uniform {UNIFORM}", triangles=uniform.num_triangles,
                     strip_bytes=None, list_bytes=12 * uniform.num_triangles, ms=ms, error=error))
    for a in low:
        options = dict(eps=1.0, pattern="sd2", level_function="silhouette", level_factors=(a, UNIFORM),
                       max_factor=UNIFORM, silhouette_band=0.0)  # the paper's classes (docs/sd2.md 2)
        sd2, ms = median_run(lambda: tessellator.tessellate(scene, **options), repeat)
        plan = tessellator.plan(scene, **options)
        error = tessellator.verify(scene, plan, sd2)["verify_ratio"]
        crossed = int((sd2.real_factors[:, :3] == UNIFORM).any(axis=1).sum())
        rows.append(dict(scene=scene.name, base=base, method=f"sd2 a={a:g}", triangles=sd2.num_triangles,
                         strip_bytes=4 * len(sd2.strips), list_bytes=12 * sd2.num_triangles, ms=ms, error=error,
                         silhouette_triangles=crossed))
        # the transition pattern on the same whole factors (a's odd ceiling, and 7)
        (stitch, stitch_ms), _ = (transition_on(tessellator, plan, sd2.factors), None)
        times = sorted(transition_on(tessellator, plan, sd2.factors)[1] for _ in range(repeat))
        level_ms = device_ms({k: v for k, v in sd2.stage_ms.items() if k in ("factors", "crack_free")})
        rows.append(dict(scene=scene.name, base=base, method=f"transition a={a:g}", triangles=stitch.num_triangles,
                         strip_bytes=None, list_bytes=12 * stitch.num_triangles,
                         ms=level_ms + times[len(times) // 2],
                         error=worst_bound_ratio(scene, stitch, eps=1.0, max_triangles=200_000)))
    return rows


def table(rows: list[dict]) -> str:
    lines = ["| scene (base) | method | triangles | x uniform | x transition | strip B | list B | ms | error |",
             "|---|---|---:|---:|---:|---:|---:|---:|---:|"]
    for row in rows:
        uniform = next(r for r in rows if r["scene"] == row["scene"] and r["method"].startswith("uniform"))
        suffix = row["method"].split(" ", 1)[1] if " " in row["method"] else ""
        stitch = next((r for r in rows if r["scene"] == row["scene"] and r["method"] == f"transition {suffix}"), None)
        vs_stitch = f"{row['triangles'] / stitch['triangles']:.2f}" if stitch and row["method"].startswith("sd2") else ""
        strip = f"{row['strip_bytes']:,}" if row["strip_bytes"] else ""
        lines.append(f"| {row['scene']} ({row['base']:,}) | {row['method']} | {row['triangles']:,} | "
                     f"{row['triangles'] / uniform['triangles']:.2f} | {vs_stitch} | {strip} | "
                     f"{row['list_bytes']:,} | {row['ms']:.2f} | {row['error']:.4f} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--device", help="OpenCL device (substring; default: cltess's choice)")
    parser.add_argument("--low", type=float, nargs="+", default=[1.0, 3.0, 5.0],
                        help="the factors a of edges off the silhouette (default 1 3 5)")
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--json", type=Path, help="also write the rows as JSON")
    args = parser.parse_args(argv)

    from cltess.pipeline import Tessellator

    tessellator = Tessellator(device=args.device)
    started = time.perf_counter()
    rows = []
    for scene in scenes():
        rows += measure(tessellator, scene, args.low, args.repeat)
    print(f"device: {tessellator.device.name.strip()} ({tessellator.device.platform.name.strip()}); "
          f"{time.perf_counter() - started:.0f} s")
    print(table(rows))
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
