"""Scene preparation on the host: patches turned to face one way across shared edges, and
outwards.

Two patches that share an edge are consistently oriented when they run it in opposite
directions (``adjacency.EdgeGroups.flipped`` differs).  Each shared pair of patch-edges is
therefore a parity constraint between its two patches, ``s_p xor s_q = (flipped_a ==
flipped_b)`` with ``s`` = "reverse this patch"; a breadth-first walk over each connected
component solves them (a conflict, as on a Möbius strip, is counted and left).  Then each
component faces outwards: its signed volume ``sum (a - c) . ((b - c) x (d - c)) / 6`` over a
coarse sampling of its surface (c: the samples' centroid) must be positive.  For a closed
component this is its enclosed volume, whatever c; for an open one (a cup, a spoon) it says
whether the surface faces away from its centre on the whole.

Reversing a patch (``formats``: "Mirroring transforms keep surfaces facing outwards"): a Bézier
patch reverses u (``patches[p, :, ::-1]``), which negates ``t_u x t_v``; a mesh triangle
reverses its winding.  Meshes whose file gives normals are left as they are (the normals say
which side is out).  Non-manifold groups (more than two patch-edges) constrain nothing.
"""
from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import numpy as np

from .adjacency import edge_groups, mesh_edge_groups
from .reference import surface_points
from .scene import Scene, TriangleMesh

__all__ = ["Orientation", "orient_scene", "orientation_flips"]

#: Samples per parameter direction of each Bézier patch for the signed volume.
VOLUME_SAMPLES = 5


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


def orientation_flips(groups, num_patches: int, edges_per_patch: int, signed_volume) -> tuple[np.ndarray, Orientation]:
    """(flip (P,) bool, report): which patches to reverse so that every shared edge is run in
    opposite directions and every component has a positive ``signed_volume(patch_ids, flips)``
    (the summed signed volume of those patches, each reversed where flips says so)."""
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

    for c in range(report.components):
        members = np.flatnonzero(component == c)
        if signed_volume(members, flip[members]) < 0:
            flip[members] ^= True
    report.flipped = int(flip.sum())
    return flip, report


def _tetra_volume(triangles: np.ndarray) -> float:
    """sum (a - c) . ((b - c) x (d - c)) / 6 over (n, 3, 3) triangles, c their centroid."""
    if not len(triangles):
        return 0.0
    centred = triangles - triangles.reshape(-1, 3).mean(axis=0)
    return float(np.einsum("ij,ij->i", centred[:, 0], np.cross(centred[:, 1], centred[:, 2])).sum() / 6)


def _bezier_volume(patches: np.ndarray):
    """signed_volume for Bézier patches: each sampled on a VOLUME_SAMPLES^2 grid, two triangles
    per cell, counter-clockwise in (u, v) (t_u x t_v side out)."""
    n = VOLUME_SAMPLES
    u, v = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n))
    u, v = u.ravel(), v.ravel()
    cells = np.array([(j * n + i, j * n + i + 1, (j + 1) * n + i + 1, (j + 1) * n + i)
                      for j in range(n - 1) for i in range(n - 1)])
    grid = np.concatenate([cells[:, [0, 1, 2]], cells[:, [0, 2, 3]]])

    def volume(members, flips):
        ids = np.repeat(members, len(u))
        points = surface_points(patches, ids, np.tile(u, len(members)), np.tile(v, len(members)))
        points = points.reshape(len(members), len(u), 3)
        triangles = points[:, grid]  # (m, 2 (n-1)^2, 3, 3)
        triangles[flips] = triangles[flips][:, :, ::-1]
        return _tetra_volume(triangles.reshape(-1, 3, 3))

    return volume


def _mesh_volume(corners: np.ndarray):
    def volume(members, flips):
        triangles = corners[members].copy()
        triangles[flips] = triangles[flips][:, ::-1]
        return _tetra_volume(triangles)

    return volume


def orient_scene(scene: Scene) -> tuple[Scene, Orientation]:
    """The scene with its patches reversed where needed (module docstring), and what was done.
    Returns the scene itself when nothing is reversed."""
    report = Orientation()
    patches = scene.patches
    if len(patches):
        groups = edge_groups(patches)
        flip, part = orientation_flips(groups, len(patches), 4, _bezier_volume(patches))
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
        flip, part = orientation_flips(groups, mesh.num_faces, 3, _mesh_volume(corners.astype(np.float64)))
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
