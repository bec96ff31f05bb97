"""Shared test helpers: random patches, closed patch grids, the bound and watertightness checks."""
from __future__ import annotations

import numpy as np
import trimesh

from cltess.reference import surface_points
from cltess.scene import Scene


def random_patches(rng: np.random.Generator, count: int, spread: float = 5.0) -> np.ndarray:
    """(count, 4, 4, 4) random rational patches, weights 0.2 to 5, scattered in a box."""
    points = rng.normal(size=(count, 4, 4, 3)) * 0.3 + rng.normal(size=(count, 1, 1, 3)) * spread
    points += np.stack(np.meshgrid(np.arange(4), np.arange(4), [0], indexing="xy"), -1)[:, :, 0] * 0.3
    weights = rng.uniform(0.2, 5.0, size=(count, 4, 4))
    return np.concatenate([points * weights[..., None], weights[..., None]], axis=-1)


def as_float32(patches: np.ndarray) -> np.ndarray:
    """The patches as the device sees them (float32), back in float64 for the reference."""
    return patches.astype(np.float32).astype(np.float64)


def closed_torus_grid(rng: np.random.Generator, patches_u: int, patches_v: int,
                      noise: float = 0.05, radii=(3.0, 1.0), weights=(0.5, 2.0)) -> Scene:
    """A closed C0 surface of patches_u x patches_v bicubic patches with random weights.

    Weights are drawn uniformly from ``weights``.  One periodic control net of (3 patches_u) x (3 patches_v) points on a torus; neighbouring
    patches share their boundary rows of that net exactly (same floats), as a real model does.
    """
    nu, nv = 3 * patches_u, 3 * patches_v
    a = 2 * np.pi * np.arange(nu) / nu
    b = 2 * np.pi * np.arange(nv) / nv
    big, small = radii
    ring = big + small * np.cos(b)[:, None]  # (nv, 1), rows of the net run around the tube
    net = np.stack(np.broadcast_arrays(ring * np.cos(a), ring * np.sin(a), small * np.sin(b)[:, None]), -1)
    net = net + rng.normal(size=net.shape) * noise
    w = rng.uniform(*weights, size=net.shape[:2])
    homogeneous = np.concatenate([net * w[..., None], w[..., None]], -1)
    patches = [homogeneous[np.ix_((3 * q + np.arange(4)) % nv, (3 * p + np.arange(4)) % nu)]
               for q in range(patches_v) for p in range(patches_u)]
    return Scene(np.array(patches), np.zeros(len(patches), np.int32), name="torus-grid")


def bound_ratio(patches: np.ndarray, tess, eps, order: int = 6, chunk: int = 200_000) -> float:
    """Largest |surface(u,v) - mesh(u,v)| / eps over samples inside every output triangle.

    Both are taken at the same (u, v): barycentric samples of order ``order`` (edges included)
    interpolate the triangle's vertex positions and its vertex (u, v), which is then evaluated
    on the float64 patch.  eps: scalar or per-patch (P,).
    """
    ij = [(i, j) for i in range(order + 1) for j in range(order + 1 - i)]
    bary = np.array([(i, j, order - i - j) for i, j in ij], float) / order  # (S, 3)
    tris = tess.triangles.astype(np.int64)
    eps = np.broadcast_to(np.asarray(eps, float), (len(patches),))
    worst = 0.0
    for start in range(0, len(tris), chunk // len(bary) + 1):
        t = tris[start:start + chunk // len(bary) + 1]
        pid = np.repeat(tess.patch_ids[t[:, 0]], len(bary))
        mesh = np.einsum("sk,tkc->tsc", bary, tess.positions[t].astype(float)).reshape(-1, 3)
        uv = np.einsum("sk,tkc->tsc", bary, tess.uv[t].astype(float)).reshape(-1, 2)
        surface = surface_points(patches, pid, uv[:, 0], uv[:, 1])
        worst = max(worst, float((np.linalg.norm(surface - mesh, axis=1) / eps[pid]).max()))
    return worst


def weld_exact(positions: np.ndarray, triangles: np.ndarray) -> trimesh.Trimesh:
    """Merge bitwise-equal positions only, drop triangles that collapse, as a trimesh."""
    _, first, remap = np.unique(positions.view(np.dtype((np.void, 12))).ravel(),
                                return_index=True, return_inverse=True)
    faces = remap.ravel()[triangles.astype(np.int64)]
    keep = (faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 2] != faces[:, 0])
    return trimesh.Trimesh(positions[first], faces[keep], process=False)
