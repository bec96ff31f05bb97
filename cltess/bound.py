"""The error bound, measured: the worst |surface(u,v) - mesh(u,v)| / tolerance of a mesh.

README "The error bound": the factors make the distance from the surface to the mesh, at the
same (u, v), at most the patch's tolerance.  This samples every (or every k-th) output triangle
at barycentric points of order ``order`` (edges included), interpolates the triangle's vertex
positions and (u, v), and evaluates the surface there in float64 with the NumPy reference
(``surfaces.bezier.surface_points`` for Bézier patches, ``surfaces.pn.pn_surface_points`` for
PN triangles).  A ratio above 1 means the bound is missed (e.g. saturated patches).
"""
from __future__ import annotations

import numpy as np

from .criteria.filip import pn_tolerances
from .criteria.tolerance import factor_tolerances, patch_tolerances
from .surfaces.bezier import surface_points
from .surfaces.pn import pn_control_points, pn_surface_points

SAMPLES_PER_CHUNK = 100_000  # bounds the memory of one evaluation (a (n, 4, 4, 4) gather)


def _surfaces(scene, sharp_edges: str):
    """(first scene patch number, float64 evaluator (ids, u, v) -> points) per kind."""
    from .kinds import PN

    surfaces = []
    if scene.num_bezier:
        patches = np.asarray(scene.patches, float)
        surfaces.append((0, lambda ids, u, v: surface_points(patches, ids, u, v)))
    if scene.num_triangles:
        controls = _pn_controls(scene, sharp_edges)
        base = scene.num_bezier
        surfaces.append((base, lambda ids, u, v: pn_surface_points(controls, ids - base, u, v)))
    return surfaces


def _pn_controls(scene, sharp_edges: str) -> np.ndarray:
    from .kinds import PN

    source = scene.prepared((PN.name, sharp_edges), lambda: PN.prepare(scene, sharp_edges)).source
    return pn_control_points(np.asarray(source, float))


def scene_tolerances(scene, eps: float | None = None, pixels: float | None = None,
                     sharp_edges: str = "straight", for_factors: bool = False) -> np.ndarray:
    """(P,) float64: every patch's tolerance in scene numbering (Bézier patches, then PN
    triangles), as stage 1 computes it (criteria.tolerance.patch_tolerances, filip.pn_tolerances);
    for_factors: what its factors may spend of it (less the float32 rounding allowance,
    criteria.tolerance.factor_tolerances)."""
    tolerances = []
    if scene.num_bezier:
        patches = np.asarray(scene.patches, float)
        points = (patches[..., :3] / patches[..., 3:]).reshape(len(patches), -1, 3)
        tolerances.append((patch_tolerances(patches, eps, pixels, scene.camera)[0], points))
    if scene.num_triangles:
        controls = _pn_controls(scene, sharp_edges)
        tolerances.append((pn_tolerances(controls, eps, pixels, scene.camera)[0], np.asarray(controls, float)[:, :10, :3]))
    if for_factors:
        tolerances = [(factor_tolerances(points.min(axis=1), points.max(axis=1), tolerance), points)
                      for tolerance, points in tolerances]
    return np.concatenate([tolerance for tolerance, _ in tolerances]) if tolerances else np.zeros(0)


def worst_bound_ratio(scene, mesh, eps: float | None = None, pixels: float | None = None,
                      sharp_edges: str = "straight", order: int = 4, max_triangles: int | None = None) -> float:
    """The worst ratio over samples inside the triangles of ``mesh`` (anything with positions,
    uv, patch_ids and triangles, e.g. a Tessellation) made from ``scene`` with the tolerance
    ``eps`` or ``pixels`` (per patch, ``criteria.tolerance.patch_tolerances``).  ``max_triangles``: sample
    only every k-th triangle so that at most about this many are measured.  0.0 for no triangles.
    """
    surfaces, tolerance = _surfaces(scene, sharp_edges), scene_tolerances(scene, eps, pixels, sharp_edges)
    triangles = np.asarray(mesh.triangles, np.int64)
    if max_triangles and len(triangles) > max_triangles:
        triangles = triangles[::-(-len(triangles) // max_triangles)]
    ij = [(i, j) for i in range(order + 1) for j in range(order + 1 - i)]
    bary = np.array([(i, j, order - i - j) for i, j in ij], float) / order  # (S, 3)
    positions, uv = np.asarray(mesh.positions, float), np.asarray(mesh.uv, float)
    patch_ids = np.asarray(mesh.patch_ids, np.int64)
    worst = 0.0
    step = max(1, SAMPLES_PER_CHUNK // len(bary))
    for start in range(0, len(triangles), step):
        chunk = triangles[start:start + step]
        ids = np.repeat(patch_ids[chunk[:, 0]], len(bary))
        points = np.einsum("sk,tkc->tsc", bary, positions[chunk]).reshape(-1, 3)
        params = np.einsum("sk,tkc->tsc", bary, uv[chunk]).reshape(-1, 2)
        exact = np.empty_like(points)
        for number, (base, surface) in enumerate(surfaces):
            end = surfaces[number + 1][0] if number + 1 < len(surfaces) else len(tolerance)
            mine = (ids >= base) & (ids < end)
            exact[mine] = surface(ids[mine], params[mine, 0], params[mine, 1])
        worst = max(worst, float((np.linalg.norm(exact - points, axis=1) / tolerance[ids]).max()))
    return worst


def tolerances_below_float32(scene, eps: float | None = None, pixels: float | None = None,
                             sharp_edges: str = "straight") -> str | None:
    """Why some visible patch's tolerance (as stage 1 computes it: criteria.tolerance.box_tolerances
    of its control points' box) is below what float32 output coordinates resolve where the patch
    lies (limits.EPS_FLOAT32_STEPS float32 steps at its largest coordinate), or None.  For
    ``--pixels`` the tolerance shrinks with the depth, so the scene-wide eps check
    (limits.eps_below_float32) does not apply; far from the origin a fine pixel tolerance can ask
    for less than float32 can hold."""
    from .criteria.tolerance import FLOAT32_TOLERANCE_STEPS, box_tolerances, float32_tolerance_floor
    from .limits import EPS_FLOAT32_STEPS

    boxes = []
    if scene.num_bezier:
        points = (scene.patches[..., :3] / scene.patches[..., 3:]).reshape(scene.num_bezier, -1, 3)
        boxes.append((points.min(axis=1), points.max(axis=1)))
    if scene.num_triangles:
        points = _pn_controls(scene, sharp_edges)[:, :10, :3]
        boxes.append((points.min(axis=1), points.max(axis=1)))
    if not boxes:
        return None
    lo, hi = (np.concatenate(side) for side in zip(*boxes))
    tolerance, culled = box_tolerances(lo, hi, eps, pixels, scene.camera)
    largest = np.maximum(np.abs(lo), np.abs(hi)).max(axis=1)
    floor = EPS_FLOAT32_STEPS * np.spacing(largest.astype(np.float32)).astype(np.float64)
    below = np.flatnonzero(~culled & (tolerance < floor))
    if not len(below):
        return None
    worst = below[np.argmin(tolerance[below] / floor[below])]
    asked = f"--pixels {pixels:g}" if pixels is not None else f"eps {eps:g}"
    raised = np.count_nonzero(tolerance[below] <= float32_tolerance_floor(lo[below], hi[below]))
    raised = (f"; {raised} of them get {FLOAT32_TOLERANCE_STEPS:g} float32 steps instead of a finer tolerance"
              if raised else "")
    return (f"{asked} gives {len(below)} patch(es) a tolerance below {EPS_FLOAT32_STEPS} float32 steps where they "
            f"lie (patch {worst}: {tolerance[worst]:.3g}, below {floor[worst]:.3g} at its coordinate "
            f"{largest[worst]:.6g}): the output's float32 coordinates cannot resolve it, so the error bound may "
            f"not hold there{raised}; move the scene nearer the origin or raise the tolerance")


__all__ = ["scene_tolerances", "tolerances_below_float32", "worst_bound_ratio"]
