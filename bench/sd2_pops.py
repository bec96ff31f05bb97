"""Pops along a camera path with SD-2's depth level function (issue 13; docs/sd2.md section 5):
the Hausdorff distance between consecutive frames' meshes, at a step and at half that step.
Without pops it is O(step): halving the step about halves the worst distance.

    python bench/sd2_pops.py [--device NAME] [--mesh icosphere|torus] [--sweep 20] [--steps 10]
                             [--low 1] [--high 6] [--json OUT]

An orbit (cltess.io.camera_path.orbit, radius 3, 20 degrees up) over --sweep degrees in --steps
steps and in 2 x --steps steps; each frame tessellated with ``level_function="depth"``, linear
map from ``depth_range`` (1.5, 4.5) onto factors --high .. --low.  Columns per step size:

  worst    the largest Hausdorff distance between consecutive frames' meshes, patch by patch,
           both ways, sampled at 7 points of every triangle (corners, centroid, edge midpoints)
  relaid   patches laid out afresh between consecutive frames, summed over the steps
  median   the median over the steps of each step's largest
  jumps    steps where some patch moved more than 4 x the median step (a pop's signature)
  tips     steps where some patch's tip moved to another corner (its shape changed)
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))

from cltess.io.camera_path import orbit  # noqa: E402
from cltess.patterns.fractional import to_fixed  # noqa: E402
from cltess.patterns.sd2 import sd2_shape  # noqa: E402
from cltess.scene import Scene  # noqa: E402

def _segment(p, a, b):
    ab = b - a
    t = np.clip(np.einsum("...k,...k", p - a, ab) / np.maximum(np.einsum("...k,...k", ab, ab), 1e-300), 0, 1)
    return np.linalg.norm(p - (a + t[..., None] * ab), axis=-1)


def one_way(points: np.ndarray, corners: np.ndarray) -> float:
    """The largest distance from points (S, 3) to the nearest of triangles (T, 3, 3): the plane's
    distance where the foot lies inside, else the nearest edge's."""
    p = points[:, None, :]
    a, b, c = (corners[None, :, k, :] for k in range(3))
    normal = np.cross(b - a, c - a)
    length = np.linalg.norm(normal, axis=-1)
    unit = normal / np.maximum(length, 1e-300)[..., None]
    height = np.einsum("...k,...k", p - a, unit)
    foot = p - height[..., None] * unit
    inside = np.broadcast_to(length > 1e-18, height.shape).copy()
    for x, y in ((a, b), (b, c), (c, a)):
        inside &= np.einsum("...k,...k", np.cross(y - x, foot - x), normal) >= 0
    edge = np.minimum(np.minimum(_segment(p, a, b), _segment(p, b, c)), _segment(p, c, a))
    return float(np.where(inside, np.abs(height), edge).min(axis=1).max())


#: barycentric points of every triangle where the Hausdorff distance is sampled: corners,
#: centroid, edge midpoints (an estimate from below of the distance, exact at the corners)
WEIGHTS = np.array([(1, 0, 0), (0, 1, 0), (0, 0, 1), (1 / 3, 1 / 3, 1 / 3), (0.5, 0.5, 0), (0, 0.5, 0.5),
                    (0.5, 0, 0.5)])


def _patch_triangles(tess, p) -> np.ndarray:
    tri = tess.triangles.reshape(-1, 3)
    mine = tri[tess.patch_ids[tri[:, 0]] == p]
    return tess.positions.astype(np.float64)[mine]


def layout_key(record) -> tuple:
    from cltess.patterns.sd2 import _Layout
    lay = _Layout(record)
    return lay.shape, lay.tip, getattr(lay, "zone", False), tuple(lay.n)


def frame_distance(a, b, records_a, records_b) -> tuple[np.ndarray, int]:
    """((P,) per patch, the Hausdorff distance between two frames' meshes, both ways, from WEIGHTS'
    points of every triangle to the other frame's triangles of the patch (the meshes' distance is
    at most the largest); how many patches changed layout (shape, tip, tie zone, segments))."""
    out, changed = np.zeros(len(records_a)), 0
    for p in range(len(records_a)):
        if records_a[p][0] <= 0:
            continue
        changed += layout_key(records_a[p]) != layout_key(records_b[p])
        ta, tb = _patch_triangles(a, p), _patch_triangles(b, p)
        pa, pb = np.einsum("wk,tkd->twd", WEIGHTS, ta).reshape(-1, 3), np.einsum("wk,tkd->twd", WEIGHTS, tb).reshape(-1, 3)
        out[p] = max(one_way(pa, tb), one_way(pb, ta))
    return out, changed


def shapes(tess) -> list:
    return [sd2_shape(f) for f in to_fixed(tess.real_factors[:, :3])]


def mesh(name: str) -> Scene:
    import trimesh
    if name == "icosphere":
        return Scene.from_trimesh(trimesh.creation.icosphere(1), name="icosphere")
    return Scene.from_trimesh(trimesh.creation.torus(1.0, 0.4, 16, 8), name="torus")


def measure(tessellator, scene, sweep: float, steps: int, low: float, high: float) -> dict:
    """Per step count (steps, 2 steps): worst, median, jumps, tips (module docstring)."""
    out = {}
    for count in (steps, 2 * steps):
        frames, records = [], []
        for camera in orbit([0, 0, 0], 3.0, count + 1, sweep_deg=sweep):
            plan = tessellator.plan(scene, eps=1e-3, pattern="sd2", level_function="depth", camera=camera,
                                    level_factors=(low, high), depth_range=(1.5, 4.5))
            records.append(np.abs(plan.host_factors()))
            frames.append(tessellator.emit(plan, 0, plan.num_patches))
        measured = [frame_distance(a, b, ra, rb) for a, b, ra, rb in zip(frames, frames[1:], records, records[1:])]
        distances = [d for d, _ in measured]
        step_worst = np.array([d.max() for d in distances])
        median = float(np.median(step_worst))
        tips = sum(any(x != y for x, y in zip(shapes(a), shapes(b))) for a, b in zip(frames, frames[1:]))
        relaid = sum(changed for _, changed in measured)
        out[count] = {"step_deg": sweep / count, "worst": float(step_worst.max()), "median": median,
                      "jumps": int(np.count_nonzero(step_worst > 4 * median)), "tips": int(tips), "steps": count,
                      "relaid": int(relaid)}
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--device", default=None, help="OpenCL device (cltess's device names)")
    parser.add_argument("--mesh", choices=["icosphere", "torus"], default="icosphere")
    parser.add_argument("--sweep", type=float, default=20.0)
    parser.add_argument("--steps", type=int, default=10)
    parser.add_argument("--low", type=float, default=1.0)
    parser.add_argument("--high", type=float, default=6.0)
    parser.add_argument("--json", default=None)
    args = parser.parse_args(argv)
    from cltess.backends.opencl import Tessellator
    tessellator = Tessellator(device=args.device)
    result = measure(tessellator, mesh(args.mesh), args.sweep, args.steps, args.low, args.high)
    print(f"{args.mesh}, depth factors {args.low:g}..{args.high:g}, {args.sweep:g} degree orbit, "
          f"device {tessellator.device.name.strip()}")
    print(f"{'step deg':>9} {'worst':>9} {'median':>9} {'jumps':>6} {'tips':>5} {'relaid':>7}")
    for row in result.values():
        print(f"{row['step_deg']:9.3f} {row['worst']:9.5f} {row['median']:9.5f} {row['jumps']:6d} {row['tips']:5d}"
              f" {row['relaid']:7d}")
    fine, coarse = result[2 * args.steps]["worst"], result[args.steps]["worst"]
    print(f"worst at half the step / worst at the step: {fine / coarse:.3f}")
    if args.json:
        Path(args.json).write_text(json.dumps({"mesh": args.mesh, "rows": list(result.values())}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
