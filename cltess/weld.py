"""One indexed mesh per object: the tessellation's shared boundary vertices merged into one.

Patches that share a boundary curve sample it bitwise identically (README, "Crack-freeness"),
so welding is exact: vertices merge when their float32 positions are equal (-0.0 = 0.0) and
they belong to the same object.  No tolerance: two points that differ in one bit stay apart,
and the welded mesh's boundary, non-manifold and T-junction counts say whether anything did.

What a welded vertex cannot carry:

* its patch and (u, v): it sits on several patches.  The patch id moves to the triangles
  (``patch_ids`` per triangle); the (u, v) are dropped, or kept per triangle corner as a seam
  (``uv="seam"``: ``corner_uv``, written as OBJ ``vt`` indices and PLY face ``texcoord`` lists,
  the per-wedge texture coordinates MeshLab reads);
* one normal per side of a crease: the welded normal is the normalised mean of the merged
  vertices' normals (the geometry stays exact; only shading softens at creases).

Triangles whose corners weld onto fewer than three distinct vertices (at collapsed edges: the
teapot's lid centre, a sphere's poles) are dropped and counted (``dropped_triangles``).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .checks import exact_weld, t_junctions
from .tessellation import IndexedMesh

__all__ = ["UV_MODES", "WeldedMesh", "weld", "edge_counts"]

#: What happens to the per-patch (u, v) of welded vertices.
UV_MODES = ("drop", "seam")
#: Above this many triangles the T-junction check (about 6 s per million triangles on 2 busy
#: CPU cores) is skipped and the summary has no T-junction count.
T_JUNCTION_CHECK_LIMIT = 1_000_000


@dataclass
class WeldedMesh(IndexedMesh):
    """An indexed triangle mesh, one vertex per distinct (object, position).

    positions (W, 3) float32, normals (W, 3) float32 unit, object_ids (W,) int32;
    triangles (T, 3) uint32 counter-clockwise seen from the normal side; patch_ids (T,) int32,
    the patch each triangle came from; corner_uv (T, 3, 2) float32 or None: each corner's patch
    (u, v) (``uv="seam"``); stats: the tessellation's counts with the welded mesh's own
    (vertices, triangles, dropped_triangles, boundary_edges, nonmanifold_edges,
    misoriented_edges, t_junctions); stage_ms: the tessellation's.
    """

    positions: np.ndarray
    normals: np.ndarray
    object_ids: np.ndarray
    triangles: np.ndarray
    patch_ids: np.ndarray
    corner_uv: np.ndarray | None = None
    stats: dict = field(default_factory=dict)
    stage_ms: dict = field(default_factory=dict)

    def to_trimesh(self):
        """A ``trimesh.Trimesh`` of it (not processed: vertices and faces stay as they are),
        with the vertex normals."""
        from .io.trimesh_formats import to_trimesh

        return to_trimesh(self)


def edge_counts(triangles: np.ndarray) -> dict:
    """Edge statistics of an indexed mesh: ``boundary_edges`` (used by one triangle),
    ``nonmanifold_edges`` (by more than two), ``misoriented_edges`` (by two triangles that run it
    the same way: their orientations disagree).  One sort of the edges' uses, each its undirected
    key times two plus its direction (6-9x the rate of counting undirected and directed edges
    with two ``np.unique`` and an ``np.isin``: bench/RESULTS.md, "Session 12, lead")."""
    faces = np.asarray(triangles, np.int64).reshape(-1, 3)
    if not len(faces):
        return {"boundary_edges": 0, "nonmanifold_edges": 0, "misoriented_edges": 0}
    start, end = faces.reshape(-1), np.roll(faces, -1, axis=1).reshape(-1)
    top = int(faces.max()) + 1
    uses = np.sort((np.minimum(start, end) * top + np.maximum(start, end)) * 2 + (start > end))
    edge = uses >> 1  # (the undirected key; equal keys are side by side)
    firsts = np.flatnonzero(np.r_[True, edge[1:] != edge[:-1]])
    counts = np.diff(np.r_[firsts, len(uses)])
    pairs = firsts[counts == 2]  # an edge of two uses is misoriented when both run the same way
    return {"boundary_edges": int((counts == 1).sum()), "nonmanifold_edges": int((counts > 2).sum()),
            "misoriented_edges": int((uses[pairs] == uses[pairs + 1]).sum())}


def weld(tess, uv: str = "drop", check_t_junctions: bool = True) -> WeldedMesh:
    """Weld a :class:`~cltess.tessellation.Tessellation` exactly (module docstring).

    uv: ``"drop"`` or ``"seam"`` (keep each triangle corner's patch (u, v)).  The T-junction
    count is skipped (absent from the stats) when ``check_t_junctions`` is False or the mesh has
    more than ``T_JUNCTION_CHECK_LIMIT`` triangles.
    """
    if uv not in UV_MODES:
        raise ValueError(f"uv must be one of {', '.join(UV_MODES)}, got {uv!r}")
    positions = np.ascontiguousarray(tess.positions, np.float32) + np.float32(0.0)  # -0.0 -> 0.0
    object_ids = np.asarray(tess.object_ids, np.int32)
    first, remap = exact_weld(positions, object_ids)
    corners = np.asarray(tess.triangles, np.int64).reshape(-1, 3)
    faces = remap[corners]
    keep = (faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 2] != faces[:, 0])

    # Normal per welded vertex: the normalised sum of its copies' normals (the first copy's where
    # they cancel).  np.add.at keeps the copies' order, so the result does not depend on batches.
    normals = np.asarray(tess.normals, np.float64)
    total = np.zeros((len(first), 3))
    np.add.at(total, remap, normals)
    length = np.linalg.norm(total, axis=1, keepdims=True)
    welded_normals = np.where(length > 1e-12, total / np.where(length > 1e-12, length, 1.0), normals[first])

    mesh = WeldedMesh(
        positions=positions[first],
        normals=welded_normals.astype(np.float32),
        object_ids=object_ids[first],
        triangles=faces[keep].astype(np.uint32),
        patch_ids=np.asarray(tess.patch_ids, np.int32)[corners[keep, 0]],
        corner_uv=np.asarray(tess.uv, np.float32)[corners[keep]] if uv == "seam" else None,
        stats={k: v for k, v in tess.stats.items() if k not in ("first_patch", "last_patch")},
        stage_ms=dict(tess.stage_ms),
    )
    mesh.stats.update(patch_vertices=len(positions), vertices=mesh.num_vertices, triangles=mesh.num_triangles,
                      dropped_triangles=int((~keep).sum()))
    mesh.stats.update({f"welded_{name}": count for name, count in edge_counts(mesh.triangles).items()})
    if check_t_junctions and mesh.num_triangles <= T_JUNCTION_CHECK_LIMIT:
        mesh.stats["welded_t_junctions"] = len(t_junctions(mesh.positions, mesh.triangles, mesh.object_ids))
    return mesh
