"""Silhouetteness (Dyken, Reimers and Seland, "Real-time GPU silhouette refinement using adaptively
blended Bezier patches", CGF 2008, section 3): the NumPy reference of kernels/criteria/silhouette.h
and the host preparation of its per-edge data (docs/design.md, "Silhouette refinement").

For a shared edge with midpoint ``v`` and the facet normals ``n_s``, ``n_t`` of its two faces, seen
from the eye ``x`` (eq. 1, 2)::

    d = (v - x) / |v - x|,   f = (d . n_s) (d . n_t)
    alpha = 1            if f <= 0          (a silhouette: the eye sees one face front, one back)
            1 - f / beta if 0 < f <= beta
            0            if f > beta

``beta = sin(phi) cos(phi) sin(theta) + sin^2(phi) cos(theta)`` with ``theta`` the angle between
the two facet normals: the transition region is a wedge of angle ``phi`` about the two faces'
planes (the paper's Fig. 3); ``phi=None`` gives the paper's constant 1/4.  Where
``theta + phi >= pi`` the wedge formula gives beta <= 0; it is raised to ``MIN_BETA`` (a nearly
binary test).  ``alpha`` is continuous in ``x`` (a clamped ratio of continuous functions) except
at ``x = v`` itself, where ``d`` is taken as 0, so ``f = 0`` and alpha = 1.

One value per edge group (cltess.crack.adjacency.EdgeGroups), so both sides read the same bits.
The rule per group (``RULE_*``):

* two patch-edges: the pair test above (``RULE_PAIR``);
* one patch-edge, not collapsed (an open boundary), or more than two (non-manifold): always a
  silhouette, alpha = 1 (``RULE_ALWAYS``: an open boundary is an outline from every side, and a
  non-manifold edge has no single pair of faces to test);
* a collapsed patch-edge, or a factor slot the kind does not use: never, alpha = 0
  (``RULE_NEVER``).

Facet normals: PN triangles use their flat triangle's normal.  Bezier patches use the control
net's corner quads (the paper's section 3 test needs normals that differ across an edge; G1
neighbours share their surface normals along it, so f = (d . n)^2 >= 0 would find nothing): patch
edge e's normal is the normalised sum of the normals of the corner quads at its two ends (each
quad's normal from its diagonals, (P11 - P00) x (P01' - P10'), oriented as dS/du x dS/dv).  The
midpoint of a PN edge is the straight edge's ``(v_i + v_j) / 2`` (the paper's ``v_ij``); of a
Bezier edge, its boundary curve at t = 1/2.

The eye is in scene coordinates, which are every object's model space: cltess applies object
transforms when it loads a scene (cltess.io.json_scene; TriangleMesh.transformed).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..kinds.base import FACTOR_SLOTS

#: The group rules (kernels/criteria/silhouette.h SILHOUETTE_RULE_*).
RULE_PAIR, RULE_ALWAYS, RULE_NEVER = 0, 1, 2
#: The paper's heuristic constant beta (section 3).
PAPER_BETA = 0.25
#: The smallest beta: where the wedge formula gives beta <= 0 (theta + phi >= pi).
MIN_BETA = 1.0e-6


def wedge_beta(theta, phi_deg: float | None) -> np.ndarray:
    """beta of the wedge of angle phi (degrees) about two faces whose normals are theta (radians)
    apart: sin(phi) cos(phi) sin(theta) + sin^2(phi) cos(theta), at least MIN_BETA; phi None:
    the paper's constant 1/4."""
    theta = np.asarray(theta, np.float64)
    if phi_deg is None:
        return np.full(theta.shape, PAPER_BETA)
    phi = math.radians(phi_deg)
    beta = math.sin(phi) * math.cos(phi) * np.sin(theta) + math.sin(phi) ** 2 * np.cos(theta)
    return np.maximum(beta, MIN_BETA)


def check_phi(phi_deg) -> None:
    if phi_deg is not None and not (isinstance(phi_deg, (int, float)) and 0 < phi_deg < 90):
        raise ValueError(f"phi (the silhouette wedge angle) must be in (0, 90) degrees, got {phi_deg!r}")


@dataclass
class EdgeSilhouetteData:
    """Per edge group g (G groups, those of the scene's (P, FACTOR_SLOTS) factor array):
    midpoints (G, 3) float64, normals (G, 2, 3) float64 (n_s, n_t: the facet normals of the
    group's first two patch-edges), beta (G,) float64, rule (G,) int32 (RULE_*)."""

    midpoints: np.ndarray
    normals: np.ndarray
    beta: np.ndarray
    rule: np.ndarray

    @property
    def num_groups(self) -> int:
        return len(self.rule)

    def device_arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(midpoints (G, 4) float32 with beta in w, normals (G, 2, 4) float32, rule (G,) int32):
        what kernels/stages/silhouette_alpha.cl reads."""
        mids = np.zeros((self.num_groups, 4), np.float32)
        mids[:, :3], mids[:, 3] = self.midpoints, self.beta
        normals = np.zeros((self.num_groups, 2, 4), np.float32)
        normals[..., :3] = self.normals
        return mids, normals, self.rule.astype(np.int32)


def _unit(a: np.ndarray) -> np.ndarray:
    length = np.linalg.norm(a, axis=-1, keepdims=True)
    return np.where(length > 0, a / np.where(length > 0, length, 1.0), 0.0)


def pn_edge_geometry(corners: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(midpoints (T, 3, 3), facet normals (T, 3, 3)) of triangle edges (edge e: corner e to
    e+1), from the float32 corners (T, 3, 3) the device sees."""
    corners = np.asarray(corners, np.float32).astype(np.float64)
    mids = (corners + np.roll(corners, -1, axis=1)) / 2
    facet = _unit(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]))
    return mids, np.repeat(facet[:, None], 3, axis=1)


def bezier_edge_geometry(source: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(midpoints (P, 4, 3), facet normals (P, 4, 3)) of Bezier patch edges (cltess.scene's edge
    table) from the device's float32 homogeneous control points (P, 16, 4): the boundary curve at
    t = 1/2, and the normalised sum of the corner-quad normals at the edge's two ends."""
    patches = np.asarray(source, np.float32).astype(np.float64).reshape(-1, 4, 4, 4)
    with np.errstate(divide="ignore", invalid="ignore"):
        points = patches[..., :3] / patches[..., 3:]
    # corner quad normals at (u, v) = (0,0), (1,0), (1,1), (0,1): the ends of edges 0..3 in turn
    def quad(j0, i0, dj, di):
        p00, p11 = points[:, j0, i0], points[:, j0 + dj, i0 + di]
        p10, p01 = points[:, j0, i0 + di], points[:, j0 + dj, i0]   # one step along u, along v
        n = np.cross(p11 - p00, p01 - p10)
        return n * np.sign(di * dj)  # a quad walked against u or v turns its normal over
    corners = [quad(0, 0, 1, 1), quad(0, 3, 1, -1), quad(3, 3, -1, -1), quad(3, 0, -1, 1)]
    normals = np.stack([_unit(_unit(corners[e]) + _unit(corners[(e + 1) % 4])) for e in range(4)], axis=1)
    from ..scene import boundary_curves
    curves = boundary_curves(patches)  # (P, 4, 4, 4) homogeneous
    half = (curves[:, :, 0] + 3 * curves[:, :, 1] + 3 * curves[:, :, 2] + curves[:, :, 3]) / 8
    with np.errstate(divide="ignore", invalid="ignore"):
        mids = half[..., :3] / half[..., 3:]
    return mids, normals


def edge_silhouette_data(parts, groups, num_patches: int, phi_deg: float | None = None) -> EdgeSilhouetteData:
    """The per-group data of a scene: parts (kind, source (n, ...) float32 as uploaded, base)
    per kind present; groups: the merged EdgeGroups over the (num_patches, FACTOR_SLOTS) factor
    array (cltess.crack.adjacency.merge_edge_groups)."""
    check_phi(phi_deg)
    slots = FACTOR_SLOTS * num_patches
    mids = np.zeros((slots, 3))
    facets = np.zeros((slots, 3))
    used = np.zeros(slots, bool)
    for kind, source, base in parts:
        count = len(source)
        if kind.domain == "tri":
            m, n = pn_edge_geometry(np.asarray(source)[:, 0:3, :3])
        else:
            m, n = bezier_edge_geometry(source)
        entries = (FACTOR_SLOTS * (base + np.arange(count))[:, None] + np.arange(kind.edges)).reshape(-1)
        mids[entries], facets[entries], used[entries] = m.reshape(-1, 3), n.reshape(-1, 3), True
    collapsed = np.zeros(slots, bool) if groups.collapsed_edges is None else np.asarray(groups.collapsed_edges, bool)
    sizes = groups.group_sizes
    first = groups.members[groups.group_start[:-1]]
    second = groups.members[np.minimum(groups.group_start[:-1] + 1, groups.group_start[1:] - 1)]
    rule = np.where(sizes == 2, RULE_PAIR, RULE_ALWAYS).astype(np.int32)
    rule[(sizes == 1) & (collapsed[first] | ~used[first])] = RULE_NEVER
    normals = np.stack([facets[first], facets[second]], axis=1)
    cosine = np.clip((normals[:, 0] * normals[:, 1]).sum(-1), -1.0, 1.0)
    beta = wedge_beta(np.arccos(cosine), phi_deg)
    return EdgeSilhouetteData(np.nan_to_num(mids[first]), normals, beta, rule)


def silhouetteness(data: EdgeSilhouetteData, eye) -> np.ndarray:
    """alpha (G,) float64 per group for the eye (3,) (module docstring, eq. 1-2)."""
    d = data.midpoints - np.asarray(eye, np.float64)
    d = _unit(d)
    f = (d * data.normals[:, 0]).sum(-1) * (d * data.normals[:, 1]).sum(-1)
    alpha = np.where(f <= 0, 1.0, np.where(f <= data.beta, 1.0 - f / data.beta, 0.0))
    return np.where(data.rule == RULE_ALWAYS, 1.0, np.where(data.rule == RULE_NEVER, 0.0, alpha))


def silhouette_f(data: EdgeSilhouetteData, eye) -> np.ndarray:
    """f of eq. 1 per group (the pair test's value, before the clamp of eq. 2)."""
    d = _unit(data.midpoints - np.asarray(eye, np.float64))
    return (d * data.normals[:, 0]).sum(-1) * (d * data.normals[:, 1]).sum(-1)


# --- fractional edge levels (section 5) --------------------------------------------------------

def edge_levels(alpha, groups, bound, max_level: int, edges_of, use_bound: bool = False,
                snap: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """NumPy mirror of kernels/stages/silhouette_levels.cl and the crack-free pass after it:
    (levels (P, 4) float32, records (P, 4) int32).

    alpha (G,) per group (float32, as the device has it); groups: the scene's merged EdgeGroups;
    bound (P, 4): the crack-free dyadic records of the error bound (0: no output, negative: a
    collapsed edge); edges_of (P,): each patch's edge count.  Edge level ``s_e = M alpha_e``
    (float32), with ``use_bound`` the larger of it and the bound's level ``log2 |bound_e|``, at
    most M; the patch level ``m = ceil(max_e s_e)``; the record ``2^m`` on each edge, then with
    ``snap`` the largest over each edge group (an edge at the larger level of its patches; the
    semi-uniform pattern snaps the others), a collapsed edge's negated."""
    from ..crack.adjacency import crack_free_factors

    alpha = np.asarray(alpha, np.float32)
    bound = np.asarray(bound, np.int64).reshape(-1, FACTOR_SLOTS)
    count = len(bound)
    levels = np.zeros((count, FACTOR_SLOTS), np.float32)
    records = np.zeros((count, FACTOR_SLOTS), np.int32)
    top = np.float32(max_level)
    for p in range(count):
        edges = int(edges_of[p])
        if bound[p, 0] == 0:
            continue
        for e in range(edges):
            s = np.float32(top * alpha[groups.group_of[FACTOR_SLOTS * p + e]])
            if use_bound:
                s = max(s, np.float32(int(abs(bound[p, e])).bit_length() - 1))
            levels[p, e] = min(s, top)
        records[p, :edges] = 1 << int(math.ceil(float(levels[p].max())))
    if snap:
        records = crack_free_factors(records, groups.group_of, groups.group_start, groups.members,
                                     groups.collapsed_edges)
    else:
        records = np.where(bound < 0, -records, records).astype(np.int32)
    return levels, records


__all__ = ["RULE_PAIR", "RULE_ALWAYS", "RULE_NEVER", "PAPER_BETA", "MIN_BETA", "wedge_beta", "check_phi",
           "EdgeSilhouetteData", "pn_edge_geometry", "bezier_edge_geometry", "edge_silhouette_data",
           "silhouetteness", "silhouette_f", "edge_levels"]
