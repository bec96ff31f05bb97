"""Patch-edge adjacency and the crack policy "max" (docs/design.md section 4): Bézier patches by
shared boundary control points, PN triangles by shared welded vertex positions (the grouping of
mesh edges is cltess.kinds.pn.mesh_edge_groups).

Two Bézier patch edges are the same edge when their four homogeneous boundary control points
(``cltess.scene.boundary_curves``, edge ``e`` of patch ``p`` is patch-edge ``4 p + e``) are
exactly equal, in the same or the reversed order.  Exact float equality is what makes shared
boundary vertices bitwise identical; -0.0 and 0.0 count as equal.  A collapsed edge (its four
control points at one Cartesian position, e.g. the teapot lid's centre or a sphere's pole) is
never grouped.  Edges shared by more than two patches, or a patch glued to itself, are scene
facts counted in the stats, not errors.

Two triangle edges (edge ``e`` of triangle ``t``, from corner ``e`` to ``e+1``, is patch-edge
``3 t + e``) are the same edge when their end points are at bitwise the same float32 positions
(``cltess.scene.weld_positions``), either way round, so meshes split along UV seams still
connect.  Their PN boundary curves then agree exactly when the normals at the two ends do too;
where they differ the edge is *sharp* and ``cltess.kinds.pn.pn_edge_normals`` decides the curve both sides use.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..scene import boundary_curves

#: A patch-edge is collapsed when its four Cartesian control points lie within this much of
#: their magnitude of each other: float64 roundings, far below float32's 6e-8.
COLLAPSED_RELATIVE = 1e-13

__all__ = ["EdgeGroups", "edge_groups", "scene_edge_groups", "merge_edge_groups", "crack_free_factors"]


@dataclass
class EdgeGroups:
    """Patch-edges grouped into shared edges (P patches of E edges each, G groups).

    group_of:    (EP,) int32, the group of patch-edge ``E p + e`` (E = 4 for Bézier patches,
                 3 for triangles).
    group_start: (G+1,) int32 and members: (EP,) int32, CSR: the patch-edges of group g are
                 ``members[group_start[g]:group_start[g+1]]`` (ascending).  Every patch-edge
                 is in exactly one group, so ``members`` is a permutation of ``0..EP-1``.
                 Groups are numbered in order of their first patch-edge.
    flipped:     (EP,) bool, True where the patch-edge runs against its group's canonical
                 direction (Bézier: the lexicographically smaller of its two point orders;
                 triangles: from the smaller welded vertex number to the larger).
    shared:      groups of exactly two patch-edges.
    boundary:    singleton groups that are not collapsed (open boundary).
    collapsed:   collapsed patch-edges (each a singleton group).
    nonmanifold: groups of more than two patch-edges.
    self_glued:  groups holding two edges of the same patch.
    reversed_pairs: shared pairs whose two curves run in the same direction (inconsistent
                 patch orientation; consistently oriented neighbours run opposite ways).
    collapsed_edges: (EP,) bool or None: the collapsed Bézier patch-edges (a sphere's pole, the
                 teapot lid's centre), whose final factors stage 2 stores negated: all their
                 points are their first corner, and no triangle joins two of them.
    """

    group_of: np.ndarray
    group_start: np.ndarray
    members: np.ndarray
    flipped: np.ndarray
    shared: int
    boundary: int
    collapsed: int
    nonmanifold: int
    self_glued: int
    reversed_pairs: int
    collapsed_edges: np.ndarray | None = None

    @property
    def num_groups(self) -> int:
        return len(self.group_start) - 1

    @property
    def group_sizes(self) -> np.ndarray:
        """(G,) int32 number of patch-edges per group."""
        return np.diff(self.group_start).astype(np.int32)

    def stats(self) -> dict:
        """The counts, for a tessellation summary."""
        return {
            "shared": self.shared,
            "boundary": self.boundary,
            "collapsed": self.collapsed,
            "nonmanifold": self.nonmanifold,
            "self_glued": self.self_glued,
            "reversed_pairs": self.reversed_pairs,
        }

    def describe(self) -> str:
        """One-line human summary."""
        text = (
            f"{len(self.group_of)} patch-edges in {self.num_groups} groups: {self.shared} shared, "
            f"{self.boundary} boundary, {self.collapsed} collapsed"
        )
        for count, what in (
            (self.nonmanifold, "non-manifold (>2 patches)"),
            (self.self_glued, "self-glued"),
            (self.reversed_pairs, "same-direction pairs (inconsistent orientation)"),
        ):
            text += f", {count} {what}"
        return text


def edge_groups(patches: np.ndarray) -> EdgeGroups:
    """Group equal patch edges.  patches: (P, 4, 4, 4) homogeneous control points."""
    patches = np.asarray(patches, dtype=np.float64)
    if patches.ndim != 4 or patches.shape[1:] != (4, 4, 4):
        raise ValueError(f"patches must have shape (P, 4, 4, 4), got {patches.shape}")
    num_edges = 4 * len(patches)
    curves = boundary_curves(patches).reshape(num_edges, 4, 4) + 0.0  # + 0.0: -0.0 -> 0.0

    # Collapsed: all four Cartesian points one point (homogeneous weights may still differ),
    # to within a few float64 roundings of their size (a pole moved far from the origin).
    cartesian = curves[:, :, :3] / curves[:, :, 3:]
    spread = np.abs(cartesian[:, 1:] - cartesian[:, :1]).max(axis=(1, 2))
    collapsed = spread <= COLLAPSED_RELATIVE * np.abs(cartesian).max(axis=(1, 2))

    # Canonical order: the lexicographically smaller of the forward and reversed sequences.
    forward = curves.reshape(num_edges, 16)
    backward = curves[:, ::-1].reshape(num_edges, 16)
    differ = forward != backward
    first_diff = np.argmax(differ, axis=1)
    rows = np.arange(num_edges)
    palindrome = ~differ.any(axis=1)  # reads the same both ways: direction undefined
    flipped = ~palindrome & (backward[rows, first_diff] < forward[rows, first_diff])
    canonical = np.ascontiguousarray(np.where(flipped[:, None], backward, forward))

    # Group equal canonical rows: hash to 64 bits, group by hash, verify bit equality.
    # Collapsed edges get groups of their own (never grouped).
    open_edges = np.flatnonzero(~collapsed)
    bits = canonical[open_edges].view(np.uint64)  # (n, 16): equal floats <=> equal bits
    _, first_open, inverse = np.unique(_hash_rows(bits), return_index=True, return_inverse=True)
    inverse = inverse.ravel()
    # a hash collision: sort the bytes (one gather: bits[first_open][inverse] took 5x the CPU here)
    if not np.array_equal(bits, bits[first_open[inverse]]):
        keys = np.ascontiguousarray(bits).view(np.dtype((np.void, 16 * 8))).ravel()
        _, inverse = np.unique(keys, return_inverse=True)
    groups = _grouped(inverse.ravel(), collapsed, flipped, palindrome, edges_per_patch=4)
    groups.collapsed_edges = collapsed
    return groups


def scene_edge_groups(scene) -> EdgeGroups:
    """``edge_groups(scene.patches)``, computed once per scene (``Scene.prepared``): orientation
    (cltess/orient.py) and the pipeline's Bézier input share it; a large scene's are kept in
    the scene cache (``io.scene_cache.derived``: keyed by the patches and this code)."""
    def make():
        from ..io.scene_cache import derived

        stored = derived(scene, "edge-groups", [__file__, boundary_curves.__code__.co_filename],
                         lambda: {field.name: np.asarray(getattr(groups, field.name)) for groups in
                                  [edge_groups(scene.patches)] for field in dataclasses.fields(EdgeGroups)})
        return EdgeGroups(**{field.name: stored[field.name] if stored[field.name].ndim else int(stored[field.name])
                             for field in dataclasses.fields(EdgeGroups)})

    return scene.prepared("bezier edge groups", make)


def _grouped(labels: np.ndarray, collapsed: np.ndarray, flipped: np.ndarray, palindrome: np.ndarray,
             edges_per_patch: int) -> EdgeGroups:
    """EdgeGroups from a group label per open (not collapsed) patch-edge, in order."""
    num_edges = len(collapsed)
    open_edges = np.flatnonzero(~collapsed)
    closed_edges = np.flatnonzero(collapsed)
    _, first_open, inverse = np.unique(labels, return_index=True, return_inverse=True)
    raw = np.empty(num_edges, np.int64)
    raw[open_edges] = inverse.ravel()
    raw[closed_edges] = len(first_open) + np.arange(len(closed_edges))
    first = np.concatenate([open_edges[first_open], closed_edges])  # first patch-edge per raw group
    # Renumber groups by their first patch-edge.
    rank = np.empty(len(first), np.int64)
    rank[np.argsort(first)] = np.arange(len(first))
    group_of = rank[raw]

    members = np.argsort(group_of, kind="stable")
    sizes = np.bincount(group_of, minlength=len(first))
    group_start = np.concatenate([[0], np.cumsum(sizes)])

    # Stats.  Members of a group are ascending, so two edges of one patch sit side by side.
    same_group = group_of[members[1:]] == group_of[members[:-1]]
    same_patch = members[1:] // edges_per_patch == members[:-1] // edges_per_patch
    self_glued = len(np.unique(group_of[members[1:]][same_group & same_patch]))
    pair_starts = group_start[:-1][sizes == 2]
    a, b = members[pair_starts], members[pair_starts + 1]
    reversed_pairs = int((~palindrome[a] & ~palindrome[b] & (flipped[a] == flipped[b])).sum())
    group_collapsed = collapsed[members[group_start[:-1]]]

    int32 = lambda x: np.ascontiguousarray(x, dtype=np.int32)  # noqa: E731
    return EdgeGroups(
        group_of=int32(group_of),
        group_start=int32(group_start),
        members=int32(members),
        flipped=flipped,
        shared=int((sizes == 2).sum()),
        boundary=int(((sizes == 1) & ~group_collapsed).sum()),
        collapsed=int(collapsed.sum()),
        nonmanifold=int((sizes > 2).sum()),
        self_glued=int(self_glued),
        reversed_pairs=reversed_pairs,
    )


def merge_edge_groups(parts, num_patches: int, slots: int = 4) -> EdgeGroups:
    """The edge groups of several patch kinds as groups over one (P, slots) factor array.

    parts: (groups, edges per patch, base) per kind: its patch-edge ``E p + e`` becomes entry
    ``slots (base + p) + e``.  Entries a kind leaves unused become collapsed singletons (their
    factor stays 0).  Kinds never share edges.  The counts are the sums of the parts'.
    """
    total = slots * num_patches
    if len(parts) == 1 and parts[0][1] == slots and parts[0][2] == 0 and len(parts[0][0].group_of) == total:
        return parts[0][0]
    labels = np.full(total, -1, np.int64)
    flipped = np.zeros(total, bool)
    collapsed_edges = np.zeros(total, bool)
    offset = 0
    for groups, edges, base in parts:
        count = len(groups.group_of) // edges
        entries = (slots * (base + np.arange(count))[:, None] + np.arange(edges)).reshape(-1)
        labels[entries] = groups.group_of + offset
        flipped[entries] = groups.flipped
        if groups.collapsed_edges is not None:
            collapsed_edges[entries] = groups.collapsed_edges
        offset += groups.num_groups
    unused = labels < 0
    merged = _grouped(labels[~unused], unused, flipped, unused, slots)
    counts = {name: sum(getattr(groups, name) for groups, _, _ in parts)
              for name in ("shared", "boundary", "collapsed", "nonmanifold", "self_glued", "reversed_pairs")}
    return dataclasses.replace(merged, collapsed_edges=collapsed_edges, **counts)


def _hash_rows(bits: np.ndarray) -> np.ndarray:
    """(n, k) uint64 -> (n,) uint64, an FNV-style mix of each row (collisions are checked)."""
    h = np.full(len(bits), 0xCBF29CE484222325, np.uint64)
    prime = np.uint64(0x100000001B3)
    for k in range(bits.shape[1]):
        h ^= bits[:, k]
        h *= prime
        h ^= h >> np.uint64(29)
    return h


def crack_free_factors(factors: np.ndarray, group_of: np.ndarray, group_start: np.ndarray,
                       members: np.ndarray, collapsed_edges: np.ndarray | None = None) -> np.ndarray:
    """The crack policy "max" (NumPy mirror of kernels/crack/max.h and stages/crack_free.cl):
    each patch edge takes the max factor over all patch edges of its group; culled stay 0;
    ``collapsed_edges`` (EdgeGroups.collapsed_edges) are stored negated.

    factors: (P, 4); group_of: (4P,); group_start: (G+1,); members: (4P,).  Returns (P, 4).
    """
    flat = factors.reshape(-1)
    out = np.zeros_like(flat)
    for edge, group in enumerate(group_of):
        if flat[edge] == 0:
            continue
        out[edge] = max(flat[members[k]] for k in range(group_start[group], group_start[group + 1]))
        if collapsed_edges is not None and collapsed_edges[edge]:
            out[edge] = -out[edge]
    return out.reshape(factors.shape)
