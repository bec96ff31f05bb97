"""PN triangles of the scene's meshes (docs/design.md section 3): the host side of
kernels/kinds/pn.h, with the grouping of mesh edges and the sharp-edge policy.

Source (T, 12, 4) float32: positions P1 P2 P3 (w = 1), vertex normals N1 N2 N3, and the normals
each edge's boundary curve uses at its two ends (``pn_edge_normals``: the vertex normals, except
at sharp edges).  Stage 1 writes the control points (T, 16, 4) that stage 4 reads.

Two triangle edges (edge ``e`` of triangle ``t``, from corner ``e`` to ``e+1``, is patch-edge
``3 t + e``) are the same edge when their end points are at bitwise the same float32 positions
(``cltess.scene.weld_positions``), either way round, so meshes split along UV seams still
connect.
"""
from __future__ import annotations

import numpy as np

from ..criteria.filip import pn_factors
from ..crack.adjacency import EdgeGroups, _grouped
from ..patterns import TRI_TRANSITION
from ..scene import weld_positions
from ..surfaces import pn as surface
from ..surfaces.pn import pn_control_points, pn_folded
from .base import FLAG_CULLED, FLAG_FOLDED, KindInput, PatchKind

#: The centre control point b111 (Dyken, Reimers and Seland 2008, section 4): "pn" Vlachos'
#: E + (E - V) / 2 (their eq. 4), "average" the mean E of the six edge control points (eq. 5,
#: slightly flatter); chosen per triangle by the source's row 3 w (1: average).
CENTRE_RULES = ("pn", "average")


def with_centre(source: np.ndarray, centre: str) -> np.ndarray:
    """A copy of PN source rows (T, 12, 4) with the centre rule ``centre`` (CENTRE_RULES)."""
    if centre not in CENTRE_RULES:
        raise ValueError(f"centre must be one of {', '.join(CENTRE_RULES)}, got {centre!r}")
    out = np.array(source, np.float32)
    out[:, 3, 3] = 1.0 if centre == "average" else 0.0
    return out


#: How ``pn_edge_normals`` treats a sharp edge (different normals on its two sides); "crease":
#: ``pn_crease_ends``.
SHARP_EDGE_MODES = ("straight", "average", "keep", "crease")


def mesh_edge_groups(corners: np.ndarray, normals: np.ndarray | None = None) -> tuple[EdgeGroups, np.ndarray]:
    """Group the edges of triangles by welded corner positions.

    corners: (T, 3, 3) corner positions, normals: (T, 3, 3) the corners' normals, both as the
    device sees them (float32).  Patch-edge ``3 t + e`` runs from corner e to corner e+1; it is
    ``flipped`` when it runs from the larger welded vertex number to the smaller.  An edge whose
    two ends weld together is collapsed, and so are all three edges of a folded triangle (two
    corners at one point, cltess.surfaces.pn.pn_folded: it has no output, its other two edges are one
    edge): they are never grouped.  Returns (groups, sharp (3T,) bool):
    sharp where the edge's group holds patch-edges whose normals at the same end differ
    (bitwise), i.e. whose PN boundary curves differ.
    """
    corners = np.asarray(corners, np.float32)
    count = len(corners)
    welded = weld_positions(corners.reshape(-1, 3)).reshape(count, 3).astype(np.int64)
    start, end = welded.reshape(-1), np.roll(welded, -1, axis=1).reshape(-1)
    collapsed = np.repeat((start == end).reshape(count, 3).any(axis=1), 3)
    flipped = start > end
    low, high = np.minimum(start, end), np.maximum(start, end)
    labels = (low * (int(welded.max()) + 1) + high)[~collapsed]
    groups = _grouped(labels, collapsed, flipped, collapsed.copy(), edges_per_patch=3)
    sharp = np.zeros(3 * count, bool)
    if normals is not None:
        normals = np.asarray(normals, np.float32) + np.float32(0.0)
        at_start, at_end = normals.reshape(-1, 3), np.roll(normals, -1, axis=1).reshape(-1, 3)
        # The normals at the low and the high welded end, as raw bits.
        ends = np.where(flipped[:, None], np.hstack([at_end, at_start]), np.hstack([at_start, at_end]))
        bits = np.ascontiguousarray(ends).view(np.uint32)
        first = groups.members[groups.group_start[:-1]][groups.group_of]  # first member per edge
        differs = (bits != bits[first]).any(axis=1)
        sharp_group = np.zeros(groups.num_groups, bool)
        np.logical_or.at(sharp_group, groups.group_of, differs)
        sharp = sharp_group[groups.group_of]
    return groups, sharp


def pn_edge_normals(normals: np.ndarray, groups: EdgeGroups, sharp: np.ndarray, mode: str = "straight") -> np.ndarray:
    """The normals each triangle edge's PN boundary curve uses at its two ends: (T, 3, 2, 3) float32,
    ``[t, e, 0]`` at corner e, ``[t, e, 1]`` at corner e+1.

    Smooth edges use the corners' vertex normals.  Sharp edges (``mesh_edge_groups``), by mode:
    ``"straight"`` zero normals, so the boundary curve is the straight edge on every side
    (watertight, the crease stays a straight line); ``"average"`` at each end the normalised
    mean of the sides' normals there, the same on every side (watertight, a curved crease);
    ``"keep"`` each side's own normals, as plain PN triangles do (the surface may crack there).
    """
    if mode not in SHARP_EDGE_MODES or mode == "crease":
        raise ValueError(f"sharp_edges must be one of {', '.join(SHARP_EDGE_MODES[:3])}, got {mode!r}"
                         + (" (crease ends: pn_crease_ends)" if mode == "crease" else ""))
    normals = np.asarray(normals, np.float32)
    out = np.stack([normals, np.roll(normals, -1, axis=1)], axis=2)  # (T, 3, 2, 3)
    flat = out.reshape(-1, 2, 3)
    if mode == "straight":
        flat[sharp] = 0.0
    elif mode == "average" and sharp.any():
        flipped = groups.flipped
        # Per group, the sum of the normals at its low and its high end (float64), then unit.
        low_high = np.where(flipped[:, None, None], flat[:, ::-1], flat).astype(np.float64)
        total = np.zeros((groups.num_groups, 2, 3))
        np.add.at(total, groups.group_of[sharp], low_high[sharp])
        length = np.linalg.norm(total, axis=2, keepdims=True)
        mean = np.where(length > 0, total / np.where(length > 0, length, 1.0), 0.0).astype(np.float32)
        own = mean[groups.group_of[sharp]]
        flat[sharp] = np.where(flipped[sharp][:, None, None], own[:, ::-1], own)
    return out



def pn_crease_ends(normals: np.ndarray, groups: EdgeGroups, sharp: np.ndarray) -> np.ndarray:
    """``sharp_edges="crease"`` (Dyken, Reimers and Seland 2008, section 4): (T, 3, 2, 4) float32,
    what each edge end's boundary curve uses, in the layout of ``pn_edge_normals`` with a w.

    A smooth end (its two sides' normals bitwise equal) keeps its vertex normal (w = 0), so it
    is bitwise today's PN.  A sharp end of an edge of two triangles, normals n_s and n_t there,
    follows the crease: ``t = normalize(n_s x n_t)`` with w = 1, and its inner control point is
    ``p + ((q - p) . t) / 3 t`` (kernels/kinds/pn.h pn_end_control).  t is made once per edge
    end, from the group's first member's normal crossed with the second's at the same welded
    end, and given to both sides, so the curve is bitwise one.  A sharp end whose normals are
    opposite (no cross product) and the sharp ends of edges of more than two triangles take the
    straight edge (normal 0), as ``"straight"`` does."""
    normals = np.asarray(normals, np.float32)
    own = np.stack([normals, np.roll(normals, -1, axis=1)], axis=2).reshape(-1, 2, 3)  # (3T, 2, 3)
    out = np.zeros((len(own), 2, 4), np.float32)
    out[:, :, :3] = own
    if not sharp.any():
        return out.reshape(-1, 3, 2, 4)
    flipped = groups.flipped
    canonical = np.where(flipped[:, None, None], own[:, ::-1], own)  # (low end, high end)
    sizes = groups.group_sizes[groups.group_of]
    first = groups.members[groups.group_start[:-1]][groups.group_of]
    second = groups.members[np.minimum(groups.group_start[:-1] + 1, groups.group_start[1:] - 1)][groups.group_of]
    n_s, n_t = canonical[first].astype(np.float64), canonical[second].astype(np.float64)
    cross = np.cross(n_s, n_t)
    length = np.linalg.norm(cross, axis=-1, keepdims=True)
    tangent = np.where(length > 0, cross / np.where(length > 0, length, 1.0), 0.0).astype(np.float32)
    differs = (canonical[first].view(np.uint32) != canonical[second].view(np.uint32)).any(axis=-1)  # (3T, 2)
    crease = sharp[:, None] & (sizes == 2)[:, None] & differs & (length[..., 0] > 0)
    straight = sharp[:, None] & differs & ~crease
    ends = np.zeros((len(own), 2, 4), np.float32)
    ends[:, :, :3] = np.where(crease[..., None], tangent, np.where(straight[..., None], 0.0, canonical))
    ends[:, :, 3] = crease
    mine = np.where(flipped[:, None, None], ends[:, ::-1], ends)  # back to (start, end) of each patch-edge
    out[sharp] = mine[sharp]
    return out.reshape(-1, 3, 2, 4)


class PNKind(PatchKind):
    name = "pn"
    domain = "tri"
    edges = 3
    header = "kinds/pn.h"
    pattern = TRI_TRANSITION
    surface = surface

    def count(self, scene):
        return scene.num_triangles

    def prepare(self, scene, sharp_edges="straight"):
        meshes = scene.meshes
        corners = np.concatenate([m.vertices[m.faces] for m in meshes]).astype(np.float32)
        normals = np.concatenate([m.normals[m.faces] for m in meshes]).astype(np.float32)
        groups, sharp = mesh_edge_groups(corners, normals)
        source = np.zeros((len(corners), 12, 4), np.float32)
        source[:, 0:3, :3] = corners
        source[:, 0:3, 3] = 1.0
        source[:, 3:6, :3] = normals
        if sharp_edges == "crease":
            source[:, 6:12] = pn_crease_ends(normals, groups, sharp).reshape(-1, 6, 4)
        else:
            source[:, 6:12, :3] = pn_edge_normals(normals, groups, sharp, sharp_edges).reshape(-1, 6, 3)
        objects = np.concatenate([np.full(m.num_faces, m.object_id, np.int32) for m in meshes])
        stats = {
            "pn_triangles": len(corners),
            "sharp_edges": int(len(np.unique(groups.group_of[sharp]))),
            "degenerate_triangles": sum(m.degenerate_triangles for m in meshes),
            "folded_triangles": int(pn_folded(corners).sum()),
            "repaired_normals": sum(m.repaired_normals for m in meshes),
        }
        return KindInput(source, objects, groups, stats)

    def controls_shape(self, count):
        return (count, 16, 4)

    def reference_factors(self, source, tolerance, max_factor):
        controls = pn_control_points(np.asarray(source, np.float64))
        points = controls[:, :10, :3]
        eps, culled = tolerance.reference(points.min(axis=1), points.max(axis=1))
        factors, _, saturated = pn_factors(controls, eps, culled, max_factor)
        flags = np.where(pn_folded(controls), FLAG_FOLDED, np.where(culled, FLAG_CULLED, saturated.astype(np.int32)))
        return controls, factors, flags.astype(np.int32)


PN = PNKind()
