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

from .crack.adjacency import scene_edge_groups
from .kinds.pn import mesh_edge_groups
from .surfaces.bezier import bernstein3
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


def orientation_flips(groups, num_patches: int, edges_per_patch: int, points: np.ndarray,
                      grid: np.ndarray) -> tuple[np.ndarray, Orientation]:
    """(flip (P,) bool, report): which patches to reverse so that every shared edge is run in
    opposite directions and every component has a positive signed volume.  points (3, P, S): S
    samples of each patch (x, y, z rows); grid (T, 3): the triangles over a patch's samples,
    facing as the patch does."""
    sizes = groups.group_sizes
    pair_start = groups.group_start[:-1][sizes == 2]
    a, b = groups.members[pair_start].astype(np.int64), groups.members[pair_start + 1].astype(np.int64)
    p, q = a // edges_per_patch, b // edges_per_patch
    use = p != q
    p, q, differ = p[use], q[use], (groups.flipped[a] == groups.flipped[b])[use]
    flip, component, report = _parity_components(num_patches, p, q, differ)

    volume, size = _signed_volumes(points, grid, component, np.where(flip, -1.0, 1.0), report.components)
    inward = volume < -FLAT * size ** 3  # a flat piece has no outside: left as it is
    flip ^= inward[component]
    report.flipped = int(flip.sum())
    return flip, report


def _parity_components(num_patches: int, p: np.ndarray, q: np.ndarray, differ: np.ndarray):
    """(flip, component, report) of the parity constraints ``flip[q] = flip[p] ^ differ``: each
    component's smallest patch keeps its orientation and components are numbered in order of
    their smallest patch (what a breadth-first walk from patch 0, 1, ... gives).

    Vectorised: each patch is two nodes, "kept" (2 p) and "reversed" (2 p + 1); a constraint
    joins (2 p, 2 q + differ) and (2 p + 1, 2 q + 1 - differ).  The connected components of that
    doubled graph (``_components``, labelled by their smallest node) are the answer: patch p is
    reversed when its "kept" node is not in the component of its seed's "kept" node.  Where a
    patch's two nodes meet (a conflict: a Moebius strip) the breadth-first walk decides
    (``_parity_walk``), which also counts the conflicting edges."""
    differ = differ.astype(np.int64)
    heads = np.concatenate([2 * p, 2 * p + 1])
    tails = np.concatenate([2 * q + differ, 2 * q + 1 - differ])
    label = _components(2 * num_patches, heads, tails)
    kept, reversed_ = label[0::2], label[1::2]
    if (kept == reversed_).any():
        return _parity_walk(num_patches, p, q, differ.astype(bool))
    seed = np.minimum(kept, reversed_)  # 2 s, s the component's smallest patch
    seeds, component = np.unique(seed, return_inverse=True)
    report = Orientation(components=len(seeds))
    return kept != seed, component.ravel().astype(np.int64), report


def _components(count: int, heads: np.ndarray, tails: np.ndarray) -> np.ndarray:
    """(count,) the smallest node of each node's connected component (edges heads[k]-tails[k]):
    roots hooked onto the smaller root across an edge, then paths shortened to their root, until
    no edge joins two roots (Shiloach-Vishkin style, all in NumPy)."""
    label = np.arange(count)
    while True:
        a, b = label[heads], label[tails]
        hooked = label.copy()
        np.minimum.at(hooked, np.maximum(a, b), np.minimum(a, b))
        while True:  # pointer jumping: every node to its root
            jumped = hooked[hooked]
            if np.array_equal(jumped, hooked):
                break
            hooked = jumped
        if np.array_equal(hooked, label):
            return label
        label = hooked


def _parity_walk(num_patches: int, p: np.ndarray, q: np.ndarray, differ: np.ndarray):
    """``_parity_components`` by a breadth-first walk, counting conflicting edges."""
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

    return flip, component, report


def _signed_volumes(points: np.ndarray, grid: np.ndarray, component: np.ndarray, sign: np.ndarray,
                    count: int):
    """((count,) signed volume, (count,) bounding-box diagonal) per component.  The volume: the
    sum over its patches' triangles (a, b, d) (``grid`` over ``points``, each patch's times its
    sign) of det(a - c, b - c, d - c) / 6 = (det(a, b, d) - c . (a x b + b x d + d x a)) / 6, c
    the centroid of the component's triangle corners.  Coordinates are taken about the scene's
    centre first (against cancellation far from the origin).  The sums are taken per patch,
    then per component (bincount)."""
    points = points - points.reshape(3, -1).mean(axis=1)[:, None, None]
    determinant, twice_area, corner_sum = _patch_sums(points, grid)
    determinant, twice_area = determinant * sign, twice_area * sign

    def per_component(values):
        return np.bincount(component, values, minlength=count)

    corners = per_component(np.full(len(component), 3.0 * len(grid)))
    centre = np.stack([per_component(corner_sum[axis]) for axis in range(3)], axis=1)
    centre /= np.maximum(corners, 1)[:, None]
    area = np.stack([per_component(twice_area[axis]) for axis in range(3)], axis=1)
    # bounding boxes of the samples: patches sorted by component, reduced per run
    order = np.argsort(component, kind="stable")
    present, start = np.unique(component[order], return_index=True)
    low, high = np.full((count, 3), np.inf), np.full((count, 3), -np.inf)
    if len(order):
        low[present] = np.minimum.reduceat(points.min(axis=2).T[order], start)
        high[present] = np.maximum.reduceat(points.max(axis=2).T[order], start)
    size = np.linalg.norm(np.where(np.isfinite(high - low), high - low, 0), axis=1)
    return (per_component(determinant) - (centre * area).sum(axis=1)) / 6, size


#: Patches per step of ``_patch_sums``: its (3, n, T) temporaries stay a few MB, in the CPU's
#: cache and in memory the process has (30k patches at once: 24 MB each, bench/RESULTS.md
#: "Issue 15: the 30k-patch PLY cold and warm (session 8)").
VOLUME_PATCHES_PER_STEP = 2048  # 4 or more (_patch_sums)


def _patch_sums(points: np.ndarray, grid: np.ndarray):
    """Per patch: sum of det(a, b, d), (3, P) sum of a x b + b x d + d x a, (3, P) sum of
    a + b + d over its triangles (a, b, d) (``grid`` over ``points``), a few patches at a time.
    The same bits as all at once: each patch's sums are taken in the same order whatever the
    step (no step has one patch unless the scene has, where NumPy would merge axes)."""
    count = points.shape[1]
    determinant, twice_area, corner_sum = np.empty(count), np.empty((3, count)), np.empty((3, count))
    for part in np.array_split(np.arange(count), max(1, -(-count // VOLUME_PATCHES_PER_STEP))):
        part = slice(part[0], part[-1] + 1) if len(part) else slice(0, 0)
        a, b, d = (points[:, part][:, :, grid[:, k]] for k in range(3))  # (3, n, T) each
        b_x_d = _cross(b, d)
        determinant[part] = (a * b_x_d).sum(axis=(0, 2))
        twice_area[:, part] = (_cross(a, b) + b_x_d + _cross(d, a)).sum(axis=2)
        corner_sum[:, part] = (a + b + d).sum(axis=2)
    return determinant, twice_area, corner_sum


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a x b of (3, n) arrays (rows x, y, z), as np.cross computes each component."""
    return np.stack([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def _bezier_samples(patches: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(points (3, P, S), grid (T, 3)): each patch sampled on a VOLUME_SAMPLES^2 grid, two
    triangles per cell, counter-clockwise in (u, v), so facing the t_u x t_v side.  The points
    are one matrix product: B(v_s) B(u_s) per sample s against each patch's 16 control points."""
    n = VOLUME_SAMPLES
    u, v = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n))
    u, v = u.ravel(), v.ravel()
    cells = np.array([(j * n + i, j * n + i + 1, (j + 1) * n + i + 1, (j + 1) * n + i)
                      for j in range(n - 1) for i in range(n - 1)])
    grid = np.concatenate([cells[:, [0, 1, 2]], cells[:, [0, 2, 3]]])
    weights = (bernstein3(v)[:, :, None] * bernstein3(u)[:, None, :]).reshape(len(u), 16)  # [s, 4 j + i]
    controls = np.asarray(patches, np.float64).reshape(len(patches), 16, 4).transpose(2, 0, 1)  # (4, P, 16)
    homogeneous = controls @ weights.T  # (4, P, S)
    return homogeneous[:3] / homogeneous[3:], grid


def orient_scene(scene: Scene) -> tuple[Scene, Orientation]:
    """The scene with its patches reversed where needed (module docstring), and what was done.
    Returns the scene itself when nothing is reversed."""
    report = Orientation()
    patches = scene.patches
    if len(patches):
        flip, part = _bezier_flips(scene)
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
        flip, part = orientation_flips(groups, mesh.num_faces, 3, corners.astype(np.float64).transpose(2, 0, 1),
                                       np.array([[0, 1, 2]]))
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


def _bezier_flips(scene: Scene) -> tuple[np.ndarray, Orientation]:
    """``orientation_flips`` of the scene's Bézier patches; a large scene's are kept in the
    scene cache (``io.scene_cache.derived``: keyed by the patches and the code that decides)."""
    from . import scene as scene_module
    from .crack import adjacency
    from .io.scene_cache import derived
    from .surfaces import bezier

    def make():
        flip, report = orientation_flips(scene_edge_groups(scene), len(scene.patches), 4,
                                         *_bezier_samples(scene.patches))
        return {"flip": flip, "counts": np.array([report.flipped, report.components, report.conflicts])}

    sources = [__file__, adjacency.__file__, bezier.__file__, scene_module.__file__]
    stored = derived(scene, "orientation", sources, make)
    return stored["flip"], Orientation(*(int(count) for count in stored["counts"]))


def _mesh_options(mesh: TriangleMesh) -> dict:
    """Construction options a TriangleMesh keeps (the crease angle, where it has one)."""
    angle = getattr(mesh, "crease_angle", None)
    return {} if angle is None else {"crease_angle": angle}


def _add(report: Orientation, part: Orientation) -> None:
    report.flipped += part.flipped
    report.components += part.components
    report.conflicts += part.conflicts
