"""Level functions for the SD-2 pattern (Amresh and Fünfzig, sections 3.1-3.2; docs/sd2.md
section 2): a value per welded mesh vertex, and each edge's real factor from its two ends'
values, so every triangle has at most two different factors.  Host preparation and the NumPy
mirror of kernels/criteria/level.h (the device runs it: cltess/backends/opencl/level_functions.py).

* ``depth``: d(v) = distance of v to the camera's eye plane; edge factor g(min(d_s, d_e)) with
  g1 (linear) or g2 (quadratic) mapping the depth range [near, far] (this frame's, unless
  given) onto [high, low].  With d0 <= d1 <= d2 at a triangle's corners its factors are
  g(d0), g(d0), g(d1): the equal pair meets at the nearest corner, the tip.
* ``silhouette``: the vertex's value is the cosine c(v) = n . (eye - v) / |eye - v|, front-facing
  when >= 0; an edge whose ends differ is crossed and gets ``high`` (the paper's b), the others
  the ramp ``psi(min(|c_s|, |c_e|))`` from ``high`` at 0 down to ``low`` (a) at the band width
  (``silhouette_band``; 0: ``low``, the paper's classes): continuous in the view, and still 0 or
  2 crossed edges per triangle meeting at the odd corner, so at most two different factors.
* ``bound``: h(v) = the largest error-bound factor (stage 1's, rounded up to an odd whole
  number, which fractional_odd spaces evenly) of the edges at v; the edge takes max(h(s), h(e)),
  at least its own bound, so the error bound still holds; the equal pair meets at the corner
  with the largest h.
"""
from __future__ import annotations

import numpy as np

from .patterns.fractional import FIXED_ONE
from .scene import Camera, weld_positions

#: kernels/criteria/level.h LEVEL_*: the level functions by name.
LEVEL_FUNCTIONS = {"depth": 1, "silhouette": 2, "bound": 3}
#: kernels/criteria/level.h LEVEL_MAP_*: g1 and g2 of section 3.2.
DEPTH_MAPS = {"linear": 0, "quadratic": 1}
#: Default (low, high) factors: the paper's silhouette refinement uses b = 7 (Tables 1-2).
DEFAULT_LEVEL_FACTORS = (1.0, 7.0)
#: Default width (in cosine) of the silhouette's ramp from high to low (docs/sd2.md section 2):
#: about the turn of the normal across one edge of a coarse mesh (sphere-320: 0.30 rad, the
#: median), so the ramp spans about one ring of triangles; 0 gives the paper's classes (and pops).
DEFAULT_SILHOUETTE_BAND = 0.25


def welded_corners(scene) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(corners (T, 3) int32 welded vertex ids of every PN triangle in scene order, positions
    (W, 3) float32, normals (W, 3) float32): one vertex per bitwise float32 position (the PN
    adjacency's welding), with one canonical unit normal, the mean of the normals there, so both
    sides of a split-normal edge classify it alike."""
    meshes = scene.meshes
    corners = np.concatenate([m.vertices[m.faces] for m in meshes]).astype(np.float32).reshape(-1, 3)
    normals = np.concatenate([m.normals[m.faces] for m in meshes]).astype(np.float64).reshape(-1, 3)
    welded = weld_positions(corners)
    count = int(welded.max()) + 1
    positions = np.zeros((count, 3), np.float32)
    positions[welded] = corners + np.float32(0.0)
    total = np.zeros((count, 3))
    np.add.at(total, welded, normals)
    length = np.linalg.norm(total, axis=1, keepdims=True)
    unit = np.where(length > 0, total / np.where(length > 0, length, 1.0), 0.0).astype(np.float32)
    return welded.reshape(-1, 3).astype(np.int32), positions, unit


def camera_frame(camera: Camera) -> tuple[np.ndarray, np.ndarray]:
    """(eye, unit forward) float32 of a camera."""
    eye = np.asarray(camera.eye, np.float64)
    forward = np.asarray(camera.target, np.float64) - eye
    norm = np.linalg.norm(forward)
    if not np.isfinite(norm) or norm == 0:
        raise ValueError("the camera's eye and target must differ")
    return eye.astype(np.float32), (forward / norm).astype(np.float32)


# --- the NumPy mirror of kernels/criteria/level.h ------------------------------------------------

def vertex_levels(function: str, positions, normals, camera: Camera) -> np.ndarray:
    """(W,) float32 values of the welded vertices: depth, or the silhouette's cosine
    n . (eye - v) / |eye - v| (its sign the paper's class: >= 0 front)."""
    eye, forward = camera_frame(camera)
    positions = np.asarray(positions, np.float32)
    if function == "depth":
        return ((positions - eye) * forward).sum(axis=1, dtype=np.float32)
    view = eye - positions
    length = np.sqrt((view * view).sum(axis=1, dtype=np.float32))
    facing = (np.asarray(normals, np.float32) * view).sum(axis=1, dtype=np.float32)
    return np.where(length > 0, facing / np.where(length > 0, length, 1), 0).astype(np.float32)


def silhouette_ramp(x, band: float, low: float, high: float) -> np.ndarray:
    """psi: the silhouette's factor at cosine distance x from it, high at 0 falling linearly to low
    at the band (float32, the device's operations); band 0: low everywhere (the paper's classes)."""
    x = np.asarray(x, np.float32)
    f32 = np.float32
    if band <= 0:
        return np.full(x.shape, f32(low))
    ramp = f32(high) - f32(f32(high) - f32(low)) * (x / f32(band))
    return np.where(x < f32(band), ramp, f32(low)).astype(np.float32)


def depth_factor(d, depth_map: str, near: float, far: float, low: float, high: float) -> np.ndarray:
    """g1 / g2: depth in [near, far] onto [high, low], clamped outside (float64)."""
    d = np.asarray(d, np.float64)
    x = np.clip((d - near) / (far - near), 0.0, 1.0) if far > near else np.zeros_like(d)
    y = 1.0 - x
    return low + (high - low) * y * y if depth_map == "quadratic" else high * y + low * x


def vertex_bounds(corners, factors) -> np.ndarray:
    """(W,) int: per welded vertex, the largest odd-rounded stage-1 factor of its triangles'
    edges at it (factor 0: culled, left out)."""
    corners = np.asarray(corners, np.int64)
    factors = np.asarray(factors, np.int64)[:, :3]
    bounds = np.zeros(int(corners.max()) + 1, np.int64)
    live = factors[:, 0] > 0
    odd = factors | 1
    for e in range(3):
        np.maximum.at(bounds, corners[live, e], odd[live, e])
        np.maximum.at(bounds, corners[live, (e + 1) % 3], odd[live, e])
    return bounds


def _fixed(r) -> np.ndarray:
    """kernels/criteria/level.h fixed_factor of float32 factors r: 16.16, at least 1.0."""
    scaled = np.asarray(r, np.float32) * np.float32(FIXED_ONE)
    return np.maximum(np.rint(scaled), FIXED_ONE).astype(np.int64)


def level_factors(function: str, corners, values, depth_map: str = "linear", near: float = 0.0,
                  far: float = 1.0, low: float = 1.0, high: float = 7.0, band: float = 0.0) -> np.ndarray:
    """(T, 3) fixed-point edge factors (edge e from corner e to e+1) from the corners' values
    (levels, or ``vertex_bounds`` for "bound"); float64, so equal to the device's within a
    float32 rounding of the depth map.  ``band``: the silhouette's ramp width (cosine)."""
    corners = np.asarray(corners, np.int64)
    values = np.asarray(values, np.float64)
    a, b = values[corners], values[np.roll(corners, -1, axis=1)]
    if function == "depth":
        g = lambda d: np.maximum(np.rint(depth_factor(d, depth_map, near, far, low, high) * FIXED_ONE), FIXED_ONE)
        return np.maximum(g(a), g(b)).astype(np.int64)
    if function == "silhouette":
        crossed = (a >= 0) != (b >= 0)
        plain = silhouette_ramp(np.minimum(np.abs(a), np.abs(b)), band, low, high)
        return _fixed(np.where(crossed, np.float32(high), plain))
    return (np.maximum(a, b) * FIXED_ONE).astype(np.int64)


def level_hints(function: str, corners, values, depth_map: str = "linear", near: float = 0.0,
                far: float = 1.0, low: float = 1.0, high: float = 7.0, band: float = 0.0) -> np.ndarray:
    """(T,) the SD-2 pattern's hint per triangle (kernels/criteria/level.h level_hint,
    cltess/patterns/sd2.py sd2_hint): ``(phi_m << 2) | m``, m the first corner of the smallest
    per-corner factor phi, every edge's factor being the larger of its ends' phi (depth: g of its
    depth; bound: its bound; silhouette: high at the triangle's odd corner, else the ramp of its
    own |cosine|)."""
    from .patterns.sd2 import HINT_SHIFT
    corners = np.asarray(corners, np.int64)
    values = np.asarray(values, np.float64)[corners]
    if function == "depth":
        phi = np.maximum(np.rint(depth_factor(values, depth_map, near, far, low, high) * FIXED_ONE), FIXED_ONE)
    elif function == "bound":
        phi = values * FIXED_ONE
    else:
        front = values >= 0
        odd = (front != np.roll(front, -1, axis=1)) & (front != np.roll(front, -2, axis=1))
        phi = _fixed(np.where(odd, np.float32(high), silhouette_ramp(np.abs(values), band, low, high)))
    phi = phi.astype(np.int64)
    m = np.argmin(phi, axis=1)
    smallest = phi[np.arange(len(phi)), m]
    return np.where((smallest > 0) & (smallest < 1 << 29), (smallest << HINT_SHIFT) | m, 0)


def reference_level_factors(scene, request, stage1: np.ndarray) -> tuple[np.ndarray, dict]:
    """The NumPy backend's level-function stage: (T, 4) fixed-point factors of the scene's PN
    triangles from their stage-1 factors ``stage1`` (T, 4) (culled and folded: 0 stays 0), as
    cltess/backends/opencl/level_functions.py computes them; and the stats it reports."""
    function = request.sd2_level_function
    corners, positions, normals = welded_corners(scene)
    low, high = (float(x) for x in request.level_factors)
    stats = {"level_function": function}
    near, far = 0.0, 0.0
    if function == "bound":
        values = vertex_bounds(corners, stage1)
    else:
        values = vertex_levels(function, positions, normals, request.camera or scene.camera)
        if function == "depth":
            near, far = request.depth_range if request.depth_range is not None else \
                (float(values.min()), float(values.max()))
            stats["depth_range"] = (near, far)
    band = request.silhouette_band
    fixed = level_factors(function, corners, values, request.depth_map, near, far, low, high, band)
    out = np.zeros((len(corners), 4), np.int64)
    live = np.asarray(stage1)[:, 0] > 0
    out[live, :3] = fixed[live]
    out[live, 3] = level_hints(function, corners, values, request.depth_map, near, far, low, high, band)[live]
    return out.astype(np.int32), stats
