"""The result of a tessellation run: arrays in, arrays out (shapes in the field docs)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

#: The vertex record: (field, dtype, per-vertex shape), in the order of the kernels' output
#: (kernels/common.h vertex_out), the Tessellation fields and the writers' columns.
VERTEX_RECORD = (
    ("positions", np.float32, (3,)),
    ("normals", np.float32, (3,)),
    ("uv", np.float32, (2,)),
    ("patch_ids", np.int32, ()),
    ("object_ids", np.int32, ()),
)
#: Bytes of one vertex and of one index in the output.
BYTES_PER_VERTEX = sum(np.dtype(dtype).itemsize * int(np.prod(shape)) for _, dtype, shape in VERTEX_RECORD)
BYTES_PER_INDEX = 4


class IndexedMesh:
    """What every mesh of cltess answers: its vertex and triangle counts (``positions`` (V, 3),
    ``triangles`` (T, 3))."""

    @property
    def num_vertices(self) -> int:
        return len(self.positions)

    @property
    def num_triangles(self) -> int:
        return len(self.triangles)


@dataclass
class Tessellation(IndexedMesh):
    """A triangle mesh sampled from a scene's patches, with its per-patch bookkeeping.

    positions:  (V, 3) float32
    normals:    (V, 3) float32, unit length
    uv:         (V, 2) float32, the patch parameters of each vertex (PN triangles: the
                barycentric weights of the face's first two corners)
    patch_ids:  (V,) int32, the patch each vertex belongs to: the scene's Bézier patches
                first, then its meshes' faces (``cltess.scene``; a mesh file: the face index)
    object_ids: (V,) int32, the object of that patch
    triangles:  (T, 3) uint32, counter-clockwise seen from the normal side
    factors:    (P, 4) int32, the final (crack-free) edge factors; 0 = culled (PN triangles:
                (f0, f1, f2, 0))
    stage_ms:   device milliseconds per stage, from OpenCL profiling events
    stats:      counts for the summary: patches, culled, saturated, shared/boundary edges...
    strips:     (S,) uint32 triangle strips of the strip patterns' patches (SD-2), restart-
                separated (cltess.strips), or None; they expand to those patches' triangles
    real_factors: (P, 4) float32 real edge factors where a pattern is fractional (SD-2; there
                ``factors`` are each edge's segments, the odd ceiling), else None
    """

    positions: np.ndarray
    normals: np.ndarray
    uv: np.ndarray
    patch_ids: np.ndarray
    object_ids: np.ndarray
    triangles: np.ndarray
    factors: np.ndarray
    stage_ms: dict = field(default_factory=dict)
    stats: dict = field(default_factory=dict)
    strips: np.ndarray | None = None
    real_factors: np.ndarray | None = None

    def welded(self, uv: str = "drop", check_t_junctions: bool = True):
        """One indexed mesh per object, shared boundary vertices merged exactly
        (:func:`cltess.weld.weld`; ``uv="seam"`` keeps the per-patch (u, v) per triangle corner)."""
        from .weld import weld

        return weld(self, uv=uv, check_t_junctions=check_t_junctions)

    def to_trimesh(self, weld: bool = True):
        """A ``trimesh.Trimesh``: welded (watertight where the surface is closed) by default, else
        the per-patch vertices as they are."""
        from .io.trimesh_formats import to_trimesh

        return to_trimesh(self.welded(check_t_junctions=False) if weld else self)
