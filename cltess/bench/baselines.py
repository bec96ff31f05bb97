"""The baselines the suite compares against: a plain, fully vectorised NumPy evaluation at the
pipeline's vertices (the reference's math, cltess.surfaces, batched), and the memory-write
bandwidth."""
from __future__ import annotations

import math
import time

import numpy as np

from ..surfaces import bezier, pn


def _evaluate_chunk(grid, u, v):
    """Homogeneous B, B_u, B_v (n, 4) of patches ``grid`` (n, 4, 4, 4) [n, j, i, c], one (u, v)
    each: the reference's Bernstein bases (cltess.surfaces.bezier), contracted u first."""
    bu, du = bezier.bernstein3(u), bezier.bernstein3_derivative(u)
    bv, dv = bezier.bernstein3(v), bezier.bernstein3_derivative(v)
    rows = np.einsum("ni,njic->njc", bu, grid)  # collapse u: (n, 4 v-points, 4)
    rows_u = np.einsum("ni,njic->njc", du, grid)
    return (np.einsum("nj,njc->nc", bv, rows), np.einsum("nj,njc->nc", bv, rows_u),
            np.einsum("nj,njc->nc", dv, rows))


def _normals(b, b_u, b_v):
    """Positions, unnormalised normals and where they are usable: the reference's rule."""
    n = bezier.tangent_cross(b, b_u, b_v)
    return b[:, :3] / b[:, 3:], n, bezier.normal_ok(n, b, b_u, b_v)


def numpy_evaluate(patches: np.ndarray, patch_ids: np.ndarray, uv: np.ndarray,
                   dtype=np.float64, chunk: int = 1 << 16):
    """Positions and unit normals (V, 3) of rational bicubic ``patches`` (P, 4, 4, 4)
    [p, j, i, (wx, wy, wz, w)] at vertex ``n``'s patch ``patch_ids[n]`` and ``uv[n]``.

    The baseline: plain NumPy, vectorised over vertices in chunks of ``chunk``, einsum over
    the Bernstein bases (u first, then v), in ``dtype``.  float64 by default: in float32 the
    normals next to a collapsed edge (a sphere's pole) come out wrong for a few vertices in
    a thousand, and float64 costs only about 30% more.  Where ``t_u x t_v``
    (nearly) vanishes, at a collapsed edge, the normal is the reference's
    (``cltess.surfaces.bezier.evaluate``: the limit from inside the patch).
    """
    grid_all = np.ascontiguousarray(patches, dtype=dtype)
    count = len(patch_ids)
    positions = np.empty((count, 3), dtype)
    normals = np.empty((count, 3), dtype)
    for start in range(0, count, chunk):
        stop = min(start + chunk, count)
        grid = grid_all[patch_ids[start:stop]]
        u = uv[start:stop, 0].astype(dtype)
        v = uv[start:stop, 1].astype(dtype)
        b, b_u, b_v = _evaluate_chunk(grid, u, v)
        p, n, ok = _normals(b, b_u, b_v)
        bad = np.flatnonzero(~ok)
        if len(bad):  # collapsed edges: the reference's rule (surfaces.bezier.evaluate), vectorised
            limit = bezier.limit_normal(grid[bad], u[bad], v[bad], b[bad], b_u[bad], b_v[bad])
            stronger = (limit * limit).sum(1) > (n[bad] * n[bad]).sum(1)
            shift = dtype(bezier.NORMAL_SHIFT)
            us, vs = u[bad] + shift * (dtype(0.5) - u[bad]), v[bad] + shift * (dtype(0.5) - v[bad])
            _, inside, _ = _normals(*_evaluate_chunk(grid[bad], us, vs))
            n[bad] = np.where(stronger[:, None], limit, inside)
        length = np.sqrt((n * n).sum(1, keepdims=True))
        positions[start:stop] = p
        normals[start:stop] = n / np.where(length > 0, length, 1)
    return positions, normals


def pn_controls(vertices: np.ndarray, normals: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """PN control points (T, 16, 4) of a smooth mesh (every edge curve from its corners' vertex
    normals): the reference's ``cltess.surfaces.pn.pn_control_points``."""
    corners, corner_normals = vertices[faces], normals[faces]  # (T, 3, 3)
    source = np.zeros((len(faces), 12, 4))
    source[:, 0:3, :3], source[:, 0:3, 3] = corners, 1.0
    source[:, 3:6, :3] = corner_normals
    source[:, 6:12, :3] = np.stack([corner_normals, np.roll(corner_normals, -1, axis=1)], axis=2).reshape(-1, 6, 3)
    return pn.pn_control_points(source)


def pn_numpy_evaluate(vertices, normals, faces, patch_ids, uv, chunk: int = 1 << 16):
    """The PN baseline: positions and unit normals (V, 3) of the PN triangles of a mesh at
    vertex ``n``'s triangle ``patch_ids[n]`` and barycentric ``uv[n]`` (weights u, v, 1-u-v of
    corners 1, 2, 3); control points from :func:`pn_controls`, then einsum of the gathered
    controls with the cubic (and quadratic, for the normal field) Bernstein-triangle bases."""
    controls = pn_controls(np.asarray(vertices, float), np.asarray(normals, float), np.asarray(faces))
    b, nc = controls[:, :10, :3], controls[:, 10:, :3]
    count = len(patch_ids)
    positions, out_normals = np.empty((count, 3)), np.empty((count, 3))
    for start in range(0, count, chunk):
        stop = min(start + chunk, count)
        ids = patch_ids[start:stop]
        u, v = uv[start:stop, 0].astype(float), uv[start:stop, 1].astype(float)
        w = 1 - u - v
        cubic = np.stack([u ** 3, v ** 3, w ** 3, 3 * u * u * v, 3 * u * v * v, 3 * v * v * w,
                          3 * v * w * w, 3 * u * w * w, 3 * u * u * w, 6 * u * v * w], axis=-1)
        quadratic = np.stack([u * u, v * v, w * w, 2 * u * v, 2 * v * w, 2 * u * w], axis=-1)
        positions[start:stop] = np.einsum("nk,nkc->nc", cubic, b[ids])
        n = np.einsum("nk,nkc->nc", quadratic, nc[ids])
        out_normals[start:stop] = n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
    return positions, out_normals


def write_bandwidth(nbytes: int = 512 << 20, repeat: int = 5) -> float:
    """Bytes per second written by a single ``numpy`` fill of ``nbytes`` (best of ``repeat``,
    pages touched first)."""
    buffer = np.empty(nbytes, np.uint8)
    buffer.fill(0)
    best = math.inf
    for k in range(repeat):
        started = time.perf_counter()
        buffer.fill(k + 1)
        best = min(best, time.perf_counter() - started)
    return nbytes / best
