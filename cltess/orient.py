"""Scene preparation on the host: patches turned to face one way across shared edges, and
outwards.

Two patches that share an edge are consistently oriented when they run it in opposite
directions (``adjacency.EdgeGroups.flipped`` differs).  Each shared pair of patch-edges is
therefore a parity constraint between its two patches, ``s_p xor s_q = (flipped_a ==
flipped_b)`` with ``s`` = "reverse this patch"; a breadth-first walk over each connected
component solves them (a conflict, as on a Möbius strip, is counted and left).  Then each
component faces outwards: its signed volume ``sum (a - c) . ((b - c) x (d - c)) / 6`` over a
coarse sampling of its surface (c: the samples' centroid) must be positive (summed per
component with bincount, so a soup of many pieces costs no more than one).  For a closed
component this is its enclosed volume, whatever c; for an open one (a cup, a spoon) it says
whether the surface faces away from its centre on the whole; a flat one (volume near 0) is
left facing as it does.

Reversing a patch (``formats``: "Mirroring transforms keep surfaces facing outwards"): a Bézier
patch reverses u (``patches[p, :, ::-1]``), which negates ``t_u x t_v``; a mesh triangle
reverses its winding.  Meshes whose file gives normals are left as they are (the normals say
which side is out).  Non-manifold groups (more than two patch-edges) constrain nothing.
"""
from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import numpy as np

from .crack.adjacency import edge_groups
from .kinds.pn import mesh_edge_groups
from .surfaces.bezier import surface_points
from .scene import Scene, TriangleMesh

__all__ = ["Orientation", "orient_scene", "orientation_flips"]

#: Samples per parameter direction of each Bézier patch for the signed volume.
VOLUME_SAMPLES = 5
#: A component whose |signed volume| is below FLAT * (its bounding-box diagonal)^3 is flat (a
#: table top, a planar mesh): it has no outside, so its orientation is left as it is.
FLAT = 1e-9


@dataclass
class Orientation:
    """What ``orient_scene`` did: ``flipped`` patches reversed, in ``components`` connected
    components; ``conflicts`` shared edges that no orientation makes consistent (non-orientable
    surfaces)."""

    flipped: int = 0
    components: int = 0
    conflicts: int = 0

    def stats(self) -> dict:
        return {"flipped_patches": self.flipped, "orientation_conflicts": self.conflicts}


def orientation_flips(groups, num_patches: int, edges_per_patch: int, triangles: np.ndarray,
                      patch_of: np.ndarray) -> tuple[np.ndarray, Orientation]:
    """(flip (P,) bool, report): which patches to reverse so that every shared edge is run in
    opposite directions and every component has a positive signed volume.  triangles (n, 3, 3):
    a sampling of the patches, facing as they do; patch_of (n,): the patch of each."""
    sizes = groups.group_sizes
    pair_start = groups.group_start[:-1][sizes == 2]
    a, b = groups.members[pair_start].astype(np.int64), groups.members[pair_start + 1].astype(np.int64)
    p, q = a // edges_per_patch, b // edges_per_patch
    use = p != q
    p, q, differ = p[use], q[use], (groups.flipped[a] == groups.flipped[b])[use]
    # adjacency lists (CSR) of the constraint graph, both ways
    heads = np.concatenate([p, q])
    tails = np.concatenate([q, p])
    parity = np.concatenate([differ, differ])
    order = np.argsort(heads, kind="stable")
    start = np.searchsorted(heads[order], np.arange(num_patches + 1))
    tails, parity = tails[order].tolist(), parity[order].tolist()
    start = start.tolist()

    flip = np.zeros(num_patches, bool)
    component = np.full(num_patches, -1, np.int64)
    report = Orientation()
    conflicts = 0
    for seed in range(num_patches):
        if component[seed] >= 0:
            continue
        component[seed] = report.components
        queue = deque([seed])
        while queue:
            here = queue.popleft()
            for k in range(start[here], start[here + 1]):
                there, want = tails[k], flip[here] ^ parity[k]
                if component[there] < 0:
                    component[there], flip[there] = report.components, want
                    queue.append(there)
                elif flip[there] != want:
                    conflicts += 1
        report.components += 1
    report.conflicts = conflicts // 2  # each conflicting edge is seen from both sides

    volume, size = _signed_volumes(triangles, component[patch_of], np.where(flip[patch_of], -1.0, 1.0),
                                   report.components)
    inward = volume < -FLAT * size ** 3  # a flat piece has no outside: left as it is
    flip ^= inward[component]
    report.flipped = int(flip.sum())
    return flip, report


def _signed_volumes(triangles: np.ndarray, component: np.ndarray, sign: np.ndarray, count: int):
    """((count,) signed volume, (count,) bounding-box diagonal) per component.  The volume: the
    sum over its triangles (a, b, d), each times sign, of det(a - c, b - c, d - c) / 6 =
    (det(a, b, d) - c . (a x b + b x d + d x a)) / 6, c the centroid of the component's
    corners.  Coordinates are taken about the scene's centre first (against cancellation far
    from the origin)."""
    points = triangles - triangles.reshape(-1, 3).mean(axis=0)
    a, b, d = points[:, 0], points[:, 1], points[:, 2]
    determinant = np.einsum("ij,ij->i", a, np.cross(b, d)) * sign
    twice_area = (np.cross(a, b) + np.cross(b, d) + np.cross(d, a)) * sign[:, None]

    def per_component(values):
        return np.bincount(component, values, minlength=count)

    corners = per_component(np.full(len(points), 3.0))
    centre = np.stack([per_component(points[..., axis].sum(axis=1)) for axis in range(3)], axis=1)
    centre /= np.maximum(corners, 1)[:, None]
    area = np.stack([per_component(twice_area[:, axis]) for axis in range(3)], axis=1)
    low, high = np.full((count, 3), np.inf), np.full((count, 3), -np.inf)
    np.minimum.at(low, component, points.min(axis=1))
    np.maximum.at(high, component, points.max(axis=1))
    size = np.linalg.norm(np.where(np.isfinite(high - low), high - low, 0), axis=1)
    return (per_component(determinant) - (centre * area).sum(axis=1)) / 6, size


def _bezier_samples(patches: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(triangles, patch_of): each patch sampled on a VOLUME_SAMPLES^2 grid, two triangles per
    cell, counter-clockwise in (u, v), so facing the t_u x t_v side."""
    n = VOLUME_SAMPLES
    u, v = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n))
    u, v = u.ravel(), v.ravel()
    cells = np.array([(j * n + i, j * n + i + 1, (j + 1) * n + i + 1, (j + 1) * n + i)
                      for j in range(n - 1) for i in range(n - 1)])
    grid = np.concatenate([cells[:, [0, 1, 2]], cells[:, [0, 2, 3]]])
    count = len(patches)
    points = surface_points(patches, np.repeat(np.arange(count), len(u)), np.tile(u, count), np.tile(v, count))
    triangles = points.reshape(count, len(u), 3)[:, grid]
    return triangles.reshape(-1, 3, 3), np.repeat(np.arange(count), len(grid))


def orient_scene(scene: Scene) -> tuple[Scene, Orientation]:
    """The scene with its patches reversed where needed (module docstring), and what was done.
    Returns the scene itself when nothing is reversed."""
    report = Orientation()
    patches = scene.patches
    if len(patches):
        groups = edge_groups(patches)
        flip, part = orientation_flips(groups, len(patches), 4, *_bezier_samples(patches))
        _add(report, part)
        if flip.any():
            patches = patches.copy()
            patches[flip] = patches[flip][:, :, ::-1]
    meshes = []
    for mesh in scene.meshes:
        if mesh.normals_from_file:
            meshes.append(mesh)
            continue
        corners = mesh.vertices[mesh.faces].astype(np.float32)
        groups, _ = mesh_edge_groups(corners)
        flip, part = orientation_flips(groups, mesh.num_faces, 3, corners.astype(np.float64),
                                       np.arange(mesh.num_faces))
        _add(report, part)
        if flip.any():
            faces = mesh.faces.copy()
            faces[flip] = faces[flip][:, ::-1]
            mesh = TriangleMesh(mesh.vertices, faces, None, mesh.object_id, mesh.name,
                                **_mesh_options(mesh))
        meshes.append(mesh)
    if not report.flipped:
        return scene, report
    return Scene(patches, scene.object_ids, scene.camera, scene.name, meshes), report


def _mesh_options(mesh: TriangleMesh) -> dict:
    """Construction options a TriangleMesh keeps (the crease angle, where it has one)."""
    angle = getattr(mesh, "crease_angle", None)
    return {} if angle is None else {"crease_angle": angle}


def _add(report: Orientation, part: Orientation) -> None:
    report.flipped += part.flipped
    report.components += part.components
    report.conflicts += part.conflicts
