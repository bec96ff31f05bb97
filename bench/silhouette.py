"""The structure of Fig. 9 of Dyken, Reimers and Seland, "Real-time GPU silhouette refinement using
adaptively blended Bezier patches" (CGF 2008; /work/shared/SEEDS.md section 3.2) with cltess's
silhouette refinement (cltess.backends.opencl.silhouette), and the silhouette error in pixels
against triangle count.

    python bench/silhouette.py [--device NAME] [--sizes 200 1000 ...] [--level 3] [--views 5]
                               [--repeat 3] [--quality] [--json OUT]

Meshes: tori of about the base size with smooth radial bumps (as bench/semi_uniform.py), PN
triangles, seen from ``--views`` seeded random viewpoints (a 1024x768, 45 degree camera framing
the mesh from a random direction).  Per size and viewpoint, per frame:

  uniform          every patch at level M (the semi-uniform pattern's P^M), stages 4-5 of a
                   plan made once (forward differencing): the per-patch uniform baseline [BS05]
  adaptive static  SilhouetteRefiner.frame: alpha per edge, levels, crack-free max, counts and
                   scan, blended vertices, indices (control points made once)
  adaptive dynamic the same with stage 1 (the PN control points) rerun each frame
  no blend         adaptive static with blend=False (every vertex F(p) at its integer level)
  alpha            the silhouetteness kernel alone, and the NumPy brute-force pass (Fig. 9a)

Times: device milliseconds of the frame's kernels (OpenCL profiling events, their spans summed;
the read-back of the output to the host not included) and the wall time of the call (with the
read-back), medians over views x repeats after one warm-up frame.  --quality: for M = 1 .. 4,
the largest and mean distance in pixels between the outline (coverage boundary) of the adaptive
and of the uniform mesh and that of a dense uniform reference (level 5) from the same camera,
rasterised at 4096x3072 (cltess.render's z-buffer at 2048x1536, supersampled 2x; distances in
pixels of a 1024x768 image, so quantised to 0.25 px), against their triangle counts.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))

from cltess.backends.opencl.silhouette import SilhouetteRefiner  # noqa: E402
from cltess.bench import scenes  # noqa: E402
from cltess.bench.scenes import framing_camera, random_rotation  # noqa: E402
from cltess.criteria.silhouette import silhouetteness  # noqa: E402
from cltess.scene import Scene  # noqa: E402

PAPER_SIZES = (200, 1000, 5000, 20000, 100000)  # Fig. 9's range: 200 .. 100k triangles


def bumpy_torus(faces: int, seed: int) -> Scene:
    """cltess.bench.scenes.bumpy_torus as a scene."""
    mesh = scenes.bumpy_torus(faces, seed)
    return Scene.from_trimesh(mesh, name=f"torus {len(mesh.faces)}")


def cameras_for(scene: Scene, views: int, seed: int):
    rng = np.random.default_rng(seed)
    lo, hi = scene.bounding_box()
    return [framing_camera(lo, hi, random_rotation(rng)[:, 0]) for _ in range(views)]


def device_ms(stage_ms: dict) -> float:
    return sum(ms for stage, ms in stage_ms.items() if stage != "total_wall")


def measure(run, cameras, repeat: int):
    """(median device ms, median wall ms, median triangles) of run(camera) over cameras x repeat,
    after one warm-up."""
    run(cameras[0])
    device, wall, triangles = [], [], []
    for camera in cameras:
        for _ in range(repeat):
            started = time.perf_counter()
            tess = run(camera)
            wall.append((time.perf_counter() - started) * 1e3)
            device.append(device_ms(tess.stage_ms))
            triangles.append(tess.num_triangles)
    return float(np.median(device)), float(np.median(wall)), int(np.median(triangles))


def timing(tessellator, sizes, level: int, views: int, repeat: int) -> list[dict]:
    rows = []
    for size in sizes:
        scene = bumpy_torus(size, seed=size)
        cameras = cameras_for(scene, views, seed=size + 1)
        static = SilhouetteRefiner(tessellator, scene, max_level=level, phi=20.0)
        dynamic = SilhouetteRefiner(tessellator, scene, max_level=level, phi=20.0, recompute_controls=True)
        uniform_plan = tessellator.plan(scene, eps=1e-12, pattern="semi_uniform", max_level=level)
        row = {"base": scene.num_triangles, "level": level}
        methods = {
            "uniform": lambda camera: tessellator.emit(uniform_plan, 0, uniform_plan.num_patches),
            "adaptive static": lambda camera: static.frame(camera).tessellation,
            "adaptive dynamic": lambda camera: dynamic.frame(camera).tessellation,
            "no blend": lambda camera: static.frame(camera, blend=False).tessellation,
        }
        for name, run in methods.items():
            row[name] = dict(zip(("device_ms", "wall_ms", "triangles"), measure(run, cameras, repeat)))
        # Fig. 9a: silhouetteness on the device (the kernel's span) against NumPy brute force
        alpha_ms, numpy_ms = [], []
        for camera in cameras:
            event = static._run_alpha(np.asarray(camera.eye, float))
            static.tessellator.queue.finish()
            alpha_ms.append((event[0].profile.end - event[0].profile.start) * 1e-6)
            started = time.perf_counter()
            silhouetteness(static.edges, camera.eye)
            numpy_ms.append((time.perf_counter() - started) * 1e3)
        row["alpha"] = {"device_ms": float(np.median(alpha_ms)), "numpy_ms": float(np.median(numpy_ms)),
                        "edges": int(static.edges.num_groups)}
        row["prepare_ms"] = static.prepare_ms
        rows.append(row)
        print(json.dumps(row), file=sys.stderr)
    return rows


def outline(tess, camera, width: int = 2048) -> np.ndarray:
    """Boolean coverage mask of a mesh seen from a camera (cltess.render's z-buffer)."""
    from cltess.render import Rasteriser, View

    height = round(width * camera.height / camera.width)
    raster = Rasteriser(View(camera.view_matrix(), camera.fov_y_deg, width // 2, height // 2))
    raster.add(tess.positions, tess.triangles)
    return (raster.inverse_depth > 0).reshape(raster.height, raster.width)


def _nearest(points: np.ndarray, image: np.ndarray, reach: int) -> np.ndarray:
    """Distance from each point (N, 2) (row, column) to the nearest set pixel of image, searched
    over offsets in order of length up to ``reach`` (farther: reach)."""
    offsets = np.array([(dy, dx) for dy in range(-reach, reach + 1) for dx in range(-reach, reach + 1)
                        if dy * dy + dx * dx <= reach * reach])
    lengths = np.hypot(offsets[:, 0], offsets[:, 1])
    order = np.argsort(lengths, kind="stable")
    padded = np.pad(image, reach)
    out = np.full(len(points), float(reach))
    todo = np.arange(len(points))
    for k in order:
        if not len(todo):
            break
        dy, dx = offsets[k]
        hit = padded[points[todo, 0] + reach + dy, points[todo, 1] + reach + dx]
        out[todo[hit]] = lengths[k]
        todo = todo[~hit]
    return out


def outline_distance(mask, reference, pixel_scale: float, reach: int = 48) -> tuple[float, float]:
    """(largest, mean) distance from the boundary pixels of each mask to the other's boundary,
    in pixels of the reported image (pixel_scale: raster pixels per reported pixel; distances
    beyond ``reach`` raster pixels count as reach)."""

    def boundary(m):
        inner = m.copy()
        inner[1:-1, 1:-1] &= m[:-2, 1:-1] & m[2:, 1:-1] & m[1:-1, :-2] & m[1:-1, 2:]
        return m & ~inner

    a, b = boundary(mask), boundary(reference)
    distances = np.concatenate([_nearest(np.argwhere(a), b, reach), _nearest(np.argwhere(b), a, reach)])
    return float(distances.max()) / pixel_scale, float(distances.mean()) / pixel_scale


def quality(tessellator, size: int, views: int) -> list[dict]:
    scene = bumpy_torus(size, seed=size)
    cameras = cameras_for(scene, views, seed=size + 1)
    reference_refiner = SilhouetteRefiner(tessellator, scene, max_level=5)
    ones = np.ones(reference_refiner.edges.num_groups, np.float32)
    references = [outline(reference_refiner.frame(camera, alpha=ones).tessellation, camera) for camera in cameras]
    rows = []
    for level in range(1, 5):
        refiner = SilhouetteRefiner(tessellator, scene, max_level=level, phi=20.0)
        for name in ("uniform", "adaptive", "adaptive no blend"):
            errors, means, triangles = [], [], []
            for camera, reference in zip(cameras, references):
                if name == "uniform":
                    tess = refiner.frame(camera, alpha=np.ones(refiner.edges.num_groups, np.float32)).tessellation
                else:
                    tess = refiner.frame(camera, blend=name == "adaptive").tessellation
                largest, mean = outline_distance(outline(tess, camera), reference, 2048 / 1024 * 2)
                errors.append(largest)
                means.append(mean)
                triangles.append(tess.num_triangles)
            row = {"base": scene.num_triangles, "level": level, "method": name,
                   "triangles": int(np.mean(triangles)), "max_px": float(np.mean(errors)),
                   "mean_px": float(np.mean(means))}
            rows.append(row)
            print(json.dumps(row), file=sys.stderr)
    return rows


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--device", help="OpenCL device (substring), as for cltess")
    parser.add_argument("--sizes", type=int, nargs="+", default=list(PAPER_SIZES))
    parser.add_argument("--level", type=int, default=3, help="M (default 3, the paper's)")
    parser.add_argument("--views", type=int, default=5)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--quality", action="store_true", help="also the silhouette error curve")
    parser.add_argument("--quality-size", type=int, default=1000)
    parser.add_argument("--json", help="write the rows here")
    args = parser.parse_args(argv)
    from cltess.pipeline import Tessellator

    tessellator = Tessellator(device=args.device)
    print(f"device: {tessellator.device.name.strip()}")
    rows = timing(tessellator, args.sizes, args.level, args.views, args.repeat)
    names = ("uniform", "adaptive static", "adaptive dynamic", "no blend")
    print(f"\nM = {args.level}, {args.views} seeded views x {args.repeat}: device ms per frame (triangles)")
    print("| base | " + " | ".join(names) + " | adaptive/uniform | blend cost | alpha device / NumPy |")
    print("|---" * (len(names) + 4) + "|")
    for row in rows:
        cells = [f"{row[n]['device_ms']:.2f} ({row[n]['triangles']})" for n in names]
        ratio = row["adaptive static"]["device_ms"] / row["uniform"]["device_ms"]
        blend = row["adaptive static"]["device_ms"] / row["no blend"]["device_ms"]
        print(f"| {row['base']} | " + " | ".join(cells) + f" | {ratio:.2f} | {blend:.2f} | "
              f"{row['alpha']['device_ms']:.3f} / {row['alpha']['numpy_ms']:.3f} ms |")
    print("\nwall ms per frame (with the read-back): " + ", ".join(
        f"{row['base']}: " + "/".join(f"{row[n]['wall_ms']:.1f}" for n in names) for row in rows))
    out = {"device": tessellator.device.name.strip(), "timing": rows}
    if args.quality:
        out["quality"] = quality(tessellator, args.quality_size, args.views)
        print(f"\nsilhouette error against a level-5 uniform reference (base {out['quality'][0]['base']}):")
        print("| M | method | triangles | largest px | mean px |\n|---|---|---|---|---|")
        for row in out["quality"]:
            print(f"| {row['level']} | {row['method']} | {row['triangles']} | {row['max_px']:.2f} | "
                  f"{row['mean_px']:.3f} |")
    if args.json:
        Path(args.json).write_text(json.dumps(out, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
