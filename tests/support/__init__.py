"""Shared test helpers: random patches, closed patch grids, triangle meshes, the bound and
watertightness checks."""
from __future__ import annotations

import importlib.util
import os
import sys
from pathlib import Path

import numpy as np
import trimesh

from cltess.reference import surface_points
from cltess.scene import Scene

ROOT = Path(__file__).resolve().parents[2]
SCENES = ROOT / "scenes"
# The data handed to the project (../shared/data beside the checkout); tests that need it skip
# when it is absent.  CLTESS_DATA overrides, as for the benchmarks.
DATA = Path(os.environ.get("CLTESS_DATA", ROOT.parent / "shared" / "data"))


def load_script(path: Path, name: str):
    """A script (bench/, scenes/, docs/: no package) as module ``name``, registered in
    sys.modules first (its dataclasses look their module up there)."""
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def load_make_scenes():
    """scenes/make_scenes.py as a module (it is a script, not part of the package)."""
    return load_script(SCENES / "make_scenes.py", "make_scenes")


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


def bound_ratio(patches: np.ndarray, tess, eps, order: int = 6, chunk: int = 200_000,
                surface=surface_points) -> float:
    """Largest |surface(u,v) - mesh(u,v)| / eps over samples inside every output triangle.

    Both are taken at the same (u, v): barycentric samples of order ``order`` (edges included)
    interpolate the triangle's vertex positions and its vertex (u, v), which is then evaluated
    on the float64 patch.  eps: scalar or per-patch (P,).  ``surface(patches, ids, u, v)``:
    reference.surface_points for Bézier patches, reference.pn_surface_points for PN control
    points.
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
        exact = surface(patches, pid, uv[:, 0], uv[:, 1])
        worst = max(worst, float((np.linalg.norm(exact - mesh, axis=1) / eps[pid]).max()))
    return worst


def weld_exact(positions: np.ndarray, triangles: np.ndarray) -> trimesh.Trimesh:
    """Merge bitwise-equal positions only, drop triangles that collapse, as a trimesh."""
    _, first, remap = np.unique(positions.view(np.dtype((np.void, 12))).ravel(),
                                return_index=True, return_inverse=True)
    faces = remap.ravel()[triangles.astype(np.int64)]
    keep = (faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 2] != faces[:, 0])
    return trimesh.Trimesh(positions[first], faces[keep], process=False)


# --- triangle meshes (PN triangles) --------------------------------------------------------------

def random_pn_triangles(rng: np.random.Generator, count: int, spread: float = 3.0) -> np.ndarray:
    """(count, 12, 4) float32 PN input (PNKind's layout) of unrelated random triangles: unit
    vertex normals near the face normal, edge-end normals mostly the vertex normals, some zero
    (straight edges) and some other unit vectors (averaged sharp edges)."""
    corners = rng.normal(size=(count, 3, 3)) + rng.normal(size=(count, 1, 3)) * spread
    face = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    face /= np.linalg.norm(face, axis=1, keepdims=True)
    normals = face[:, None] + rng.normal(size=(count, 3, 3)) * 0.4
    normals /= np.linalg.norm(normals, axis=2, keepdims=True)
    ends = np.stack([normals, np.roll(normals, -1, axis=1)], axis=2)  # (T, 3, 2, 3)
    pick = rng.random((count, 3))
    ends[pick < 0.1] = 0.0
    other = rng.normal(size=ends.shape)
    other /= np.linalg.norm(other, axis=3, keepdims=True)
    ends[pick > 0.9] = other[pick > 0.9]
    out = np.zeros((count, 12, 4), np.float32)
    out[:, 0:3, :3], out[:, 0:3, 3] = corners, 1.0
    out[:, 3:6, :3] = normals
    out[:, 6:12, :3] = ends.reshape(count, 6, 3)
    return out


def icosphere(subdivisions: int = 2, radius: float = 1.0) -> trimesh.Trimesh:
    return trimesh.creation.icosphere(subdivisions=subdivisions, radius=radius)


def torus(major: float = 2.0, minor: float = 0.7, sections=(24, 12)) -> trimesh.Trimesh:
    return trimesh.creation.torus(major_radius=major, minor_radius=minor, major_sections=sections[0],
                                  minor_sections=sections[1])


def genus2(resolution: int = 2, smoothing: int = 8) -> trimesh.Trimesh:
    """A closed mesh of genus 2: the boundary of a voxel slab 5 x 3 x 1 with two square holes
    (one triangle pair per voxel face, ``resolution`` voxels per unit), Taubin-smoothed."""
    shape = np.array([5, 3, 1]) * resolution
    solid = np.ones(shape, bool)
    for x0 in (1, 3):
        solid[x0 * resolution:(x0 + 1) * resolution, resolution:2 * resolution, :] = False
    padded = np.pad(solid, 1)
    quads = []
    for axis in range(3):
        for side in (0, 1):
            step = np.zeros(3, int)
            step[axis] = 1 if side else -1
            neighbour = np.roll(padded, -step, axis=(0, 1, 2))[1:-1, 1:-1, 1:-1]
            for cell in np.argwhere(solid & ~neighbour):
                a, b = [k for k in range(3) if k != axis]
                origin = cell.copy()
                origin[axis] += side
                da, db = np.eye(3, dtype=int)[a], np.eye(3, dtype=int)[b]
                quad = [origin, origin + da, origin + da + db, origin + db]
                # outward: (da x db) along +axis for side 1 when (a, b, axis) is cyclic
                cyclic = (a, b) in ((1, 2), (2, 0), (0, 1))
                quads.append(quad if cyclic == bool(side) else quad[::-1])
    points = np.array(quads, float).reshape(-1, 3) / resolution
    vertices, index = np.unique(points, axis=0, return_inverse=True)
    quads = index.reshape(-1, 4)
    faces = np.concatenate([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    for _ in range(smoothing):
        for weight in (0.5, -0.53):
            total = np.zeros_like(vertices)
            count = np.zeros(len(vertices))
            np.add.at(total, edges[:, 0], vertices[edges[:, 1]])
            np.add.at(count, edges[:, 0], 1)
            vertices = vertices + weight * (total / count[:, None] - vertices)
    return trimesh.Trimesh(vertices, faces, process=False)


def flat_shaded(mesh: trimesh.Trimesh) -> trimesh.Trimesh:
    """Every face with vertices of its own and its face normal at them: all edges between
    faces of different planes are sharp."""
    faces = np.asarray(mesh.faces)
    vertices = np.asarray(mesh.vertices)[faces].reshape(-1, 3)
    normal = np.cross(vertices[1::3] - vertices[0::3], vertices[2::3] - vertices[0::3])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    return trimesh.Trimesh(vertices, np.arange(len(vertices)).reshape(-1, 3),
                           vertex_normals=np.repeat(normal, 3, axis=0), process=False)


def split_some_vertices(rng: np.random.Generator, mesh: trimesh.Trimesh, fraction: float = 0.3,
                        noise: float = 0.2) -> trimesh.Trimesh:
    """Split a random fraction of the vertices into one per face corner, each with its own
    perturbed normal (sharp edges there); the others keep their smooth normal."""
    from cltess.scene import vertex_normals

    vertices, faces = np.asarray(mesh.vertices), np.asarray(mesh.faces)
    normals = vertex_normals(vertices, faces)
    chosen = rng.random(len(vertices)) < fraction
    new_vertices, new_normals = list(vertices), list(normals)
    faces = faces.copy()
    for f, c in np.argwhere(chosen[faces]):
        v = faces[f, c]
        n = normals[v] + rng.normal(size=3) * noise
        new_vertices.append(vertices[v])
        new_normals.append(n / np.linalg.norm(n))
        faces[f, c] = len(new_vertices) - 1
    return trimesh.Trimesh(np.array(new_vertices), faces, vertex_normals=np.array(new_normals), process=False)


def translated_scene(path, offset: float):
    """A scene file's Bézier patches moved by (offset, offset, offset), and its bounding-box
    diagonal (the same at any offset)."""
    from cltess.formats import load_scene

    base = load_scene(path)
    points = base.patches[..., :3] / base.patches[..., 3:]
    patches = base.patches.copy()
    patches[..., :3] = (points + offset) * patches[..., 3:]
    return (Scene(patches, base.object_ids, name=f"{Path(path).name} + {offset:g}"),
            float(np.linalg.norm(np.ptp(points.reshape(-1, 3), axis=0))))


def assert_same_output(a, b) -> None:
    """Two tessellations' host arrays (cltess.tessellation.HOST_FIELDS) are bitwise equal."""
    from cltess.tessellation import HOST_FIELDS

    for name in HOST_FIELDS:
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
