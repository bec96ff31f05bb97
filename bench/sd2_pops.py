"""Pops along a camera path with SD-2's level functions (issue 13; docs/sd2.md sections 2 and 5):
how far the mesh moves between consecutive frames, at a step and at half that step.  Without
pops it is O(step): halving the step about halves the worst distance, and no step stands out.

    python bench/sd2_pops.py [--device NAME] [--mesh icosphere|torus|sphere-320|torus-2120|torus-5796]
                             [--level-function depth|silhouette|bound] [--measure parametric|hausdorff]
                             [--sweep 20] [--steps 10] [--low 1] [--high 6] [--band 0.25] [--json OUT]

An orbit (cltess.io.camera_path.orbit, 20 degrees up) about the mesh's bounding-box centre at
radius 3 for the icosphere and torus (3 bounding radii for the others: ``setting``) over --sweep
degrees in --steps steps and in 2 x --steps steps; each frame tessellated with the level
function: depth (linear map of the fixed depth range centre -/+ bounding radius, 1.5 .. 4.5 for
the icosphere, onto --high .. --low), silhouette (--low, --high, ramp width --band; 0: the
paper's classes), bound (the error bound kept at --pixels of the frame's camera: the factors
are odd whole numbers by design).  The meshes sphere-320, torus-2120 and torus-5796 are
bench/sd2.py's (the paper's sphere, and its violin case and cow sizes).  Columns per step size:

  worst    the largest distance between consecutive frames' meshes, patch by patch:
           parametric (default): |a(u, v) - b(u, v)| at 36 domain points of every patch (the
           meshes' piecewise-linear surfaces at the same domain point; an upper bound of their
           distance there, tangential sliding included); hausdorff: both ways, sampled at 7
           points of every triangle (corners, centroid, edge midpoints; slow: small meshes only)
  relaid   patches laid out afresh between consecutive frames, summed over the steps
  median   the median over the steps of each step's largest
  jumps    steps whose largest is more than 4 x the median step (a pop's signature)
  tips     steps where some patch's tip moved to another corner (its shape changed)
  triple   steps whose worst patch is near a triple tie (its three corners' factors within one
           factor unit of each other, in either frame: docs/sd2.md section 5, "Triple ties")
  worst other  the worst over the patches not near a triple tie
  no blend the worst over the patches whose tie zone does not blend two tie configurations
           (0 < lam < 1, docs/sd2.md section 5) in either frame: what is left without the
           triple-tie blends, which this fan cannot make proportional (docs/sd2.md, "Third pass")
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
from cltess.patterns.fractional import FIXED_ONE, to_fixed  # noqa: E402
from cltess.patterns.sd2 import sd2_shape  # noqa: E402
from cltess.scene import Scene  # noqa: E402

def one_way(points: np.ndarray, corners: np.ndarray) -> float:
    """The largest distance from points (S, 3) to the nearest of triangles (T, 3, 3): the plane's
    distance where the foot lies inside, else the nearest edge's."""
    return float(one_way_batch(points[None], corners[None])[0])


def one_way_batch(points: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """(B,) one_way of B patches at once: points (B, S, 3), triangles (B, T, 3, 3).  Each triangle
    in its own frame (e1 along its first edge, n its normal): the point's height over the plane,
    and in the plane its distance to the 2D triangle (0 inside); triangles of no area (3D points
    on a line, where the tie zone collapses points) are left out (their points are other
    triangles' too)."""
    a, b, c = corners[:, :, 0], corners[:, :, 1], corners[:, :, 2]
    ab, ac = b - a, c - a
    normal = np.cross(ab, ac)
    area2 = np.linalg.norm(normal, axis=-1)
    flat = area2 <= 1e-14 * np.maximum(np.einsum("btk,btk->bt", ab, ab), 1e-300)
    n = normal / np.where(flat, 1.0, area2)[..., None]
    bx = np.linalg.norm(ab, axis=-1)
    e1 = ab / np.where(bx > 0, bx, 1.0)[..., None]
    e2 = np.cross(n, e1)
    cx, cy = np.einsum("btk,btk->bt", ac, e1), np.einsum("btk,btk->bt", ac, e2)
    frame = lambda e: np.matmul(points, e.transpose(0, 2, 1)) - np.einsum("btk,btk->bt", a, e)[:, None, :]
    x, y, h = frame(e1), frame(e2), frame(n)
    bx, cx, cy = bx[:, None, :], cx[:, None, :], cy[:, None, :]

    def segment2(px, py, qx, qy):  # squared distance of (x, y) to segment p q
        dx, dy = qx - px, qy - py
        t = np.clip(((x - px) * dx + (y - py) * dy) / np.maximum(dx * dx + dy * dy, 1e-300), 0.0, 1.0)
        ex, ey = x - px - t * dx, y - py - t * dy
        return ex * ex + ey * ey

    zero = np.zeros_like(bx)
    inside = (y >= 0) & ((cx - bx) * (y - 0) - cy * (x - bx) >= 0) & (-cx * (y - cy) + cy * (x - cx) >= 0)
    plane = np.where(inside, 0.0, np.minimum(np.minimum(segment2(zero, zero, bx, zero), segment2(bx, zero, cx, cy)),
                                             segment2(cx, cy, zero, zero)))
    distance = np.sqrt(h * h + plane)
    distance = np.where(flat[:, None, :], np.inf, distance)
    return distance.min(axis=2).max(axis=1)


#: barycentric points of every triangle where the Hausdorff distance is sampled: corners,
#: centroid, edge midpoints (an estimate from below of the distance, exact at the corners)
WEIGHTS = np.array([(1, 0, 0), (0, 1, 0), (0, 0, 1), (1 / 3, 1 / 3, 1 / 3), (0.5, 0.5, 0), (0, 0.5, 0.5),
                    (0.5, 0, 0.5)])


def layout_key(record) -> tuple:
    from cltess.patterns.sd2 import _Layout
    lay = _Layout(record)
    return lay.shape, lay.tip, getattr(lay, "zone", False), tuple(lay.n)


def patch_triangles(tess) -> list[np.ndarray]:
    """Per patch its triangles' corners (T_p, 3, 3) float64."""
    tri = tess.triangles.reshape(-1, 3)
    patch = tess.patch_ids[tri[:, 0]]
    order = np.argsort(patch, kind="stable")
    corners = tess.positions.astype(np.float64)[tri[order]]
    ends = np.cumsum(np.bincount(patch, minlength=len(tess.factors)))
    return np.split(corners, ends[:-1])


def patch_vertices(tess) -> list[np.ndarray]:
    """Per patch its vertices (V_p, 3) float64 (a patch's vertices are consecutive)."""
    ends = np.cumsum(np.bincount(tess.patch_ids, minlength=len(tess.factors)))
    return np.split(tess.positions.astype(np.float64), ends[:-1])


def _padded(groups: list[np.ndarray], size: int, fill) -> np.ndarray:
    out = np.empty((len(groups), size) + groups[0].shape[1:])
    for k, g in enumerate(groups):
        out[k, :len(g)] = g
        out[k, len(g):] = fill(g)
    return out


def hausdorff_per_patch(tris_a: list, tris_b: list, points_a: list | None = None, points_b: list | None = None,
                        budget: int = 1 << 20) -> np.ndarray:
    """(P,) per patch max(one_way(a's points, b's triangles), one_way(b's points, a's)), the
    points WEIGHTS' of every triangle unless given (points_a, points_b: per patch (S_p, 3));
    patches of similar size batched (points padded with a copy of a point, triangles with one
    far away)."""
    if points_a is None:
        points_a = [np.einsum("wk,tkd->twd", WEIGHTS, t).reshape(-1, 3) for t in tris_a]
        points_b = [np.einsum("wk,tkd->twd", WEIGHTS, t).reshape(-1, 3) for t in tris_b]
    out = np.zeros(len(tris_a))
    live = [p for p in range(len(tris_a)) if len(tris_a[p]) and len(tris_b[p])]
    for src, dst in ((points_a, tris_b), (points_b, tris_a)):
        order = sorted(live, key=lambda p: (len(src[p]), len(dst[p])))
        start = 0
        while start < len(order):
            s_max, t_max = len(src[order[start]]), len(dst[order[start]])
            stop = start
            while stop < len(order):
                s_max, t_max = max(s_max, len(src[order[stop]])), max(t_max, len(dst[order[stop]]))
                if (stop - start + 1) * s_max * t_max > budget and stop > start:
                    break
                stop += 1
            batch = order[start:stop]
            points = [src[p] for p in batch]
            s_max, t_max = max(len(x) for x in points), max(len(dst[p]) for p in batch)
            far = lambda g: g[0] + 1e6  # a triangle a million units away: never the nearest
            value = one_way_batch(_padded(points, s_max, lambda g: g[0]), _padded([dst[p] for p in batch], t_max, far))
            out[batch] = np.maximum(out[batch], value)
            start = stop
    return out


def frame_distance(a, b, records_a, records_b) -> tuple[np.ndarray, int]:
    """((P,) per patch, the Hausdorff distance between two frames' meshes, both ways, from WEIGHTS'
    points of every triangle to the other frame's triangles of the patch (the meshes' distance is
    at most the largest); how many patches changed layout (shape, tip, tie zone, segments))."""
    changed = sum(layout_key(x) != layout_key(y) for x, y in zip(records_a, records_b) if x[0] > 0)
    return hausdorff_per_patch(patch_triangles(a), patch_triangles(b)), int(changed)


def vertex_distance(a, b, records_a, records_b) -> tuple[np.ndarray, int]:
    """As frame_distance with each patch's vertices as the points (about 14 x fewer: for
    large meshes; a pop moves vertices off the other frame's surface, or the other frame's)."""
    changed = sum(layout_key(x) != layout_key(y) for x, y in zip(records_a, records_b) if x[0] > 0)
    return hausdorff_per_patch(patch_triangles(a), patch_triangles(b), patch_vertices(a),
                               patch_vertices(b)), int(changed)


def shapes(tess) -> list:
    return [sd2_shape(f) for f in to_fixed(tess.real_factors[:, :3])]


#: domain points (u, v) of every patch where the parametric distance is taken: a triangular
#: grid of 36 points shrunk into the domain's inside
SAMPLES = np.array([(i / 7, j / 7) for i in range(8) for j in range(8 - i)]) * 0.9 + 0.03


def surface_at(tess, samples: np.ndarray = SAMPLES, chunk: int = 8192) -> np.ndarray:
    """(P, S, 3) float64: the mesh's points at domain points samples (S, 2) of every patch, from
    the triangle of the patch's pattern holding each (barycentric interpolation; zero-area
    triangles skipped; a patch without triangles: NaN)."""
    tri = tess.triangles.reshape(-1, 3).astype(np.int64)
    patch = tess.patch_ids[tri[:, 0]]
    p = tess.positions.astype(np.float64)
    uv = tess.uv.astype(np.float64)
    out = np.full((len(tess.factors), len(samples), 3), np.nan)
    for first in range(0, len(tri), chunk):
        t = tri[first:first + chunk]
        a, b, c = (uv[t[:, k]] for k in range(3))
        e1, e2, q = b - a, c - a, samples[None, :, :] - a[:, None, :]
        den = e1[:, 0] * e2[:, 1] - e2[:, 0] * e1[:, 1]
        ok = np.abs(den) > 1e-12
        den = np.where(ok, den, 1.0)[:, None]
        l1 = (q[..., 0] * e2[:, None, 1] - e2[:, None, 0] * q[..., 1]) / den
        l2 = (e1[:, None, 0] * q[..., 1] - q[..., 0] * e1[:, None, 1]) / den
        l0 = 1 - l1 - l2
        inside = ok[:, None] & (l0 >= -1e-5) & (l1 >= -1e-5) & (l2 >= -1e-5)
        k, s = np.nonzero(inside)
        out[patch[first + k], s] = (l0[k, s, None] * p[t[k, 0]] + l1[k, s, None] * p[t[k, 1]]
                                    + l2[k, s, None] * p[t[k, 2]])
    return out


def parametric_distance(a, b, records_a, records_b) -> tuple[np.ndarray, int]:
    """((P,) per patch the largest |a(u, v) - b(u, v)| over SAMPLES, how many patches changed
    layout (shape, tip, tie zone, segments))."""
    changed = sum(layout_key(x) != layout_key(y) for x, y in zip(records_a, records_b) if x[0] > 0)
    distance = np.linalg.norm(surface_at(a) - surface_at(b), axis=2).max(axis=1)
    return np.nan_to_num(distance, nan=0.0), int(changed)


MESHES = ("icosphere", "torus", "sphere-320", "torus-2120", "torus-5796")


def mesh(name: str) -> Scene:
    import trimesh
    if name == "icosphere":
        return Scene.from_trimesh(trimesh.creation.icosphere(1), name="icosphere")
    if name == "torus":
        return Scene.from_trimesh(trimesh.creation.torus(1.0, 0.4, 16, 8), name="torus")
    sys.path.insert(0, str(REPO / "bench"))
    from sd2 import scenes  # the SD-2 benchmark's meshes (bench/sd2.py)
    return {scene.name: scene for scene in scenes()}[name]


def setting(scene) -> tuple[np.ndarray, float, tuple]:
    """(orbit centre, orbit radius, depth range) of a mesh: the icosphere and torus as before
    (centre 0, radius 3, depths 1.5 .. 4.5); others: the bounding box's centre, 3 bounding
    radii, depths radius -/+ 1.5 bounding radii (the whole mesh inside, little clamping)."""
    if scene.name in ("icosphere", "torus"):
        return np.zeros(3), 3.0, (1.5, 4.5)
    vertices = np.concatenate([m.vertices for m in scene.meshes])
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    bound = float(np.linalg.norm(hi - lo) / 2)
    return (lo + hi) / 2, 3 * bound, (1.5 * bound, 4.5 * bound)


def near_triple_tie(records: np.ndarray) -> np.ndarray:
    """(P,) bool: the patch's three corner factors phi lie within one factor unit (the tie zone's
    width) of each other: the largest factor less the hint's smallest phi (docs/sd2.md section 5,
    "Triple ties"); without a hint, the largest factor less the smallest."""
    f = records[:, :3].astype(np.int64)
    hint = np.abs(records[:, 3].astype(np.int64))
    smallest = np.where(hint > 0, hint >> 2, f.min(axis=1))
    return (f[:, 0] > 0) & (f.max(axis=1) - smallest < FIXED_ONE)


def blending(records: np.ndarray) -> np.ndarray:
    """(P,) bool: the patch's fan is in the tie zone with 0 < lam < 1 (a blend of two tie
    configurations; cltess/patterns/sd2.py sd2_morph)."""
    from cltess.patterns.sd2 import _Layout
    out = np.zeros(len(records), bool)
    for k, record in enumerate(records):
        if record[0] > 0:
            layout = _Layout(record)
            out[k] = bool(layout.zone) and layout.lam < 1
    return out


def frame_options(level_function: str, camera, low: float, high: float, band: float, depth_range, pixels: float):
    if level_function == "bound":  # the error bound at a screen-space tolerance of this frame's camera
        return dict(pixels=pixels, pattern="sd2", level_function="bound", max_factor=64)
    options = dict(eps=1e-3, pattern="sd2", level_function=level_function, camera=camera, level_factors=(low, high),
                   depth_range=depth_range)
    return dict(options, silhouette_band=band) if level_function == "silhouette" else options


def measure(tessellator, scene, sweep: float, steps: int, low: float, high: float, level_function: str = "depth",
            band: float = 0.25, how: str = "hausdorff", pixels: float = 0.5, depth_range=None) -> dict:
    """Per step count (steps, 2 steps): worst, median, jumps, tips (module docstring); depth_range:
    instead of ``setting``'s (a narrow one clamps: plateaus of low and high)."""
    centre, radius, default_range = setting(scene)
    depth_range = default_range if depth_range is None else depth_range
    distance = {"hausdorff": frame_distance, "vertices": vertex_distance, "parametric": parametric_distance}[how]
    out = {}
    for count in (steps, 2 * steps):
        frames, records = [], []
        for camera in orbit(centre, radius, count + 1, sweep_deg=sweep):
            scene.camera = camera
            plan = tessellator.plan(scene, **frame_options(level_function, camera, low, high, band, depth_range,
                                                           pixels))
            records.append(np.abs(plan.host_factors()))
            frames.append(tessellator.emit(plan, 0, plan.num_patches))
        measured = [distance(a, b, ra, rb) for a, b, ra, rb in zip(frames, frames[1:], records, records[1:])]
        near = [near_triple_tie(ra) | near_triple_tie(rb) for ra, rb in zip(records, records[1:])]
        others = np.array([np.where(n, 0.0, d).max() for (d, _), n in zip(measured, near)])
        triple = sum(bool(n[np.argmax(d)]) and d.max() > 0 for (d, _), n in zip(measured, near))
        blends = [blending(ra) | blending(rb) for ra, rb in zip(records, records[1:])]
        no_blend = max(float(np.where(b, 0.0, d).max()) for (d, _), b in zip(measured, blends))
        distances = [d for d, _ in measured]
        step_worst = np.array([d.max() for d in distances])
        median = float(np.median(step_worst))
        tips = sum(any(x != y for x, y in zip(shapes(a), shapes(b))) for a, b in zip(frames, frames[1:]))
        relaid = sum(changed for _, changed in measured)
        out[count] = {"step_deg": sweep / count, "worst": float(step_worst.max()), "median": median,
                      "jumps": int(np.count_nonzero(step_worst > 4 * median)), "tips": int(tips), "steps": count,
                      "relaid": int(relaid), "triangles": int(np.mean([f.num_triangles for f in frames])),
                      "triple": int(triple), "worst_other": float(others.max()), "no_blend": no_blend,
                      "step_worst": [float(x) for x in step_worst]}
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--device", default=None, help="OpenCL device (cltess's device names)")
    parser.add_argument("--mesh", choices=MESHES, default="icosphere")
    parser.add_argument("--level-function", choices=["depth", "silhouette", "bound"], default="depth")
    parser.add_argument("--measure", choices=["vertices", "hausdorff", "parametric"], default="vertices")
    parser.add_argument("--band", type=float, default=0.25, help="silhouette ramp width (0: the paper's classes)")
    parser.add_argument("--pixels", type=float, default=0.5, help="bound: the screen-space tolerance")
    parser.add_argument("--depth-range", type=float, nargs=2, default=None, metavar=("NEAR", "FAR"),
                        help="depth: the range mapped onto high .. low (default: see setting)")
    parser.add_argument("--sweep", type=float, default=20.0)
    parser.add_argument("--steps", type=int, default=10)
    parser.add_argument("--low", type=float, default=1.0)
    parser.add_argument("--high", type=float, default=6.0)
    parser.add_argument("--json", default=None)
    args = parser.parse_args(argv)
    from cltess.backends.opencl import Tessellator
    tessellator = Tessellator(device=args.device)
    scene = mesh(args.mesh)
    result = measure(tessellator, scene, args.sweep, args.steps, args.low, args.high, args.level_function,
                     args.band, args.measure, args.pixels, args.depth_range)
    what = (f"{args.pixels:g} pixel bound" if args.level_function == "bound" else
            f"{args.level_function} factors {args.low:g}..{args.high:g}"
            + (f", band {args.band:g}" if args.level_function == "silhouette" else ""))
    print(f"{args.mesh} ({scene.num_triangles} faces), {what}, {args.sweep:g} degree orbit, {args.measure} "
          f"distance, device {tessellator.device.name.strip()}")
    print(f"{'step deg':>9} {'worst':>9} {'median':>9} {'jumps':>6} {'tips':>5} {'relaid':>7} {'triangles':>10}"
          f" {'triple':>6} {'worst other':>11} {'no blend':>9}")
    for row in result.values():
        print(f"{row['step_deg']:9.3f} {row['worst']:9.5f} {row['median']:9.5f} {row['jumps']:6d} {row['tips']:5d}"
              f" {row['relaid']:7d} {row['triangles']:10d} {row['triple']:6d} {row['worst_other']:11.5f}"
              f" {row['no_blend']:9.5f}")
    fine, coarse = result[2 * args.steps], result[args.steps]
    print(f"worst at half the step / worst at the step: {fine['worst'] / coarse['worst']:.3f}")
    if coarse["no_blend"] > 0:
        print(f"the same without tie-configuration blends: {fine['no_blend'] / coarse['no_blend']:.3f}")
    if args.json:
        Path(args.json).write_text(json.dumps({"mesh": args.mesh, "level_function": args.level_function,
                                               "measure": args.measure, "rows": list(result.values())}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
