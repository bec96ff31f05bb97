"""Checks of tessellation output.

t_junctions: output vertices that lie in the interior of another triangle's edge of the same
object, after exact welding (issue 11).  A hanging node whose neighbour's edge runs straight
through it; the weld-and-is_watertight check only sees it as an unmatched edge, this names it.

Exact, no tolerance.  Positions are float32; a vertex v lies strictly inside the edge (a, b)
when d2 = v - a is t * d1, d1 = b - a, for some 0 < t < 1:

* d1, d2 are formed in float64; the difference of two float32 numbers is exact there unless
  their exponents lie more than 29 apart, and Knuth's TwoSum error term tells which (those rare
  candidates go through Python's exact Fractions instead);
* collinearity d1 x d2 = 0 compares the products of each component pair exactly: Dekker's
  TwoProduct (Veltkamp split) gives x * y = p + e with p = fl(x * y), both floats, exactly (no
  overflow or underflow is possible for products of float32 differences in float64), and
  x * y = z * w exactly iff their (p, e) pairs are equal;
* betweenness: 0 < d2_k / d1_k < 1 along an axis k with d1_k != 0, by exact comparisons.

Candidate pairs come from a uniform grid (a sort-based join, vectorised): cells of the median
edge extent, the vertices sorted by cell, every edge cut into pieces no longer than a cell whose
(slightly padded) boxes look up the cells they cover; then the vertex must lie in the edge's
box, and the exact test decides.  About 8 s for a million triangles on one busy CPU core.
"""
from __future__ import annotations

from fractions import Fraction

import numpy as np

_SPLIT = 134217729.0  # 2^27 + 1, Veltkamp's splitter for float64


def exact_weld(positions: np.ndarray, object_ids: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(first (W,) the first output vertex of each welded vertex, remap (V,) output vertex ->
    welded vertex): vertices merge when their positions are bitwise equal and their objects are
    the same (-0.0 and 0.0 stay apart, as in tests/support.weld_exact)."""
    positions = np.ascontiguousarray(positions, np.float32)
    keys = np.empty((len(positions), 4), np.int32)
    keys[:, :3] = positions.view(np.int32)
    keys[:, 3] = 0 if object_ids is None else np.asarray(object_ids, np.int32)
    _, first, remap = np.unique(keys.view(np.dtype((np.void, 16))).ravel(), return_index=True, return_inverse=True)
    return first, remap.ravel()


def _two_sum(x, y):
    """s = fl(x + y) and its exact error e (Knuth): x + y = s + e."""
    s = x + y
    bv = s - x
    av = s - bv
    return s, (x - av) + (y - bv)


def _split(x):
    c = _SPLIT * x
    hi = c - (c - x)
    return hi, x - hi


def _two_product(x, y):
    """p = fl(x * y) and its exact error e (Dekker): x * y = p + e."""
    p = x * y
    xh, xl = _split(x)
    yh, yl = _split(y)
    return p, ((xh * yh - p) + xh * yl + xl * yh) + xl * yl


def _strictly_inside_fast(d1, d2):
    """Exact test on float64 differences that are themselves exact (see the module docstring)."""
    collinear = np.ones(len(d1), bool)
    for i, j in ((1, 2), (2, 0), (0, 1)):
        p1, e1 = _two_product(d1[:, i], d2[:, j])
        p2, e2 = _two_product(d1[:, j], d2[:, i])
        collinear &= (p1 == p2) & (e1 == e2)
    k = np.argmax(np.abs(d1), axis=1)
    along, length = np.take_along_axis(d2, k[:, None], 1)[:, 0], np.take_along_axis(d1, k[:, None], 1)[:, 0]
    return collinear & (along * np.sign(length) > 0) & (np.abs(along) < np.abs(length))


def _strictly_inside_exact(v, a, b) -> bool:
    v, a, b = ([Fraction(float(x)) for x in p] for p in (v, a, b))
    d1 = [q - p for p, q in zip(a, b)]
    d2 = [q - p for p, q in zip(a, v)]
    if any(d1[i] * d2[j] != d1[j] * d2[i] for i, j in ((1, 2), (2, 0), (0, 1))):
        return False
    k = max(range(3), key=lambda i: abs(d1[i]))
    return 0 < d2[k] / d1[k] < 1


def strictly_inside(v: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(N,) bool: float32 point v[n] lies strictly between a[n] and b[n] (a != b) on their
    segment, exactly."""
    v, a, b = (np.asarray(x, np.float32).astype(np.float64) for x in (v, a, b))
    d1, e1 = _two_sum(b, -a)
    d2, e2 = _two_sum(v, -a)
    inexact = ((e1 != 0) | (e2 != 0)).any(axis=1)
    out = _strictly_inside_fast(d1, d2)
    for n in np.flatnonzero(inexact):
        out[n] = _strictly_inside_exact(v[n], a[n], b[n])
    return out


def _edge_pieces(a, b, h):
    """(edge (N,), lo (N, 3), hi (N, 3)): each edge a-b cut into pieces of extent <= h, the
    boxes of the pieces padded against the rounding of their computed ends."""
    extent = np.abs(b - a).max(axis=1)
    pieces = np.maximum(np.ceil(extent / h), 1).astype(np.int64)
    edge = np.repeat(np.arange(len(a)), pieces)
    long = np.flatnonzero(pieces[edge] > 1)  # most edges are one piece: their own box
    p0, p1 = a[edge], b[edge]
    step = (np.arange(len(edge)) - np.repeat(np.cumsum(pieces) - pieces, pieces))[long]
    count, e = pieces[edge[long]], edge[long]
    p0[long] = a[e] + (step / count)[:, None] * (b[e] - a[e])
    p1[long] = a[e] + ((step + 1) / count)[:, None] * (b[e] - a[e])
    pad = 1e-6 * h + 1e-12 * np.maximum(np.abs(p0), np.abs(p1))
    return edge, np.minimum(p0, p1) - pad, np.maximum(p0, p1) + pad


def _candidates(points, objects, edges, chunk):
    """Chunks of candidate pairs (vertex (N,), edge (N,)) of the same object, the vertex in the
    edge's closed box and not one of its ends.  A uniform grid of the median edge extent: the
    vertices sorted by cell; every edge cut into pieces no longer than a cell, and each cell
    that a piece's box covers (at most 2 per axis, 3 where the padding crosses a cell wall)
    looked up in the sorted vertices."""
    a, b = points[edges[:, 0]], points[edges[:, 1]]
    h = float(np.median(np.abs(b - a).max(axis=1)))
    origin = points.min(axis=0)
    edge, lo, hi = _edge_pieces(a, b, h)
    first = np.floor((lo - origin) / h).astype(np.int64)
    span = np.floor((hi - origin) / h).astype(np.int64) - first + 1
    vertex_cells = np.floor((points - origin) / h).astype(np.int64)
    size = np.maximum(vertex_cells.max(axis=0), (first + span).max(axis=0)) + 2
    if int(objects.max() + 1) * int(size[0]) * int(size[1]) * int(size[2]) >= 2 ** 62:
        raise ValueError("scene too large for the cell grid")

    def key(obj, c):
        return ((obj * size[0] + c[:, 0] + 1) * size[1] + c[:, 1] + 1) * size[2] + c[:, 2] + 1

    vertex_keys = key(objects, vertex_cells)
    by_cell = np.argsort(vertex_keys).astype(np.int32)
    # the occupied cells, each with its run of vertices in by_cell
    cells, cell_start, cell_count = np.unique(vertex_keys[by_cell], return_index=True, return_counts=True)
    edge_objects = objects[edges[:, 0]]
    box_lo, box_hi = np.minimum(a, b).astype(np.float32), np.maximum(a, b).astype(np.float32)
    points32 = points.astype(np.float32)  # exact: the points are float32 values
    ends = edges.astype(np.int32)
    step = max(1, chunk // 4)
    reaches = [[span[:, axis] > k for k in range(int(span[:, axis].max()))] for axis in range(3)]
    for offset in np.ndindex(*span.max(axis=0)):
        covers = np.flatnonzero(reaches[0][offset[0]] & reaches[1][offset[1]] & reaches[2][offset[2]])
        for part in range(0, len(covers), step):  # about `chunk` pairs at once
            take = covers[part:part + step]
            e = edge[take]
            keys = key(edge_objects[e], first[take] + np.array(offset))
            at = np.minimum(np.searchsorted(cells, keys), len(cells) - 1)
            occupied = cells[at] == keys
            start = cell_start[at]
            n = np.where(occupied, cell_count[at], 0)
            e = np.repeat(e, n).astype(np.int32)
            at = np.arange(len(e)) - np.repeat(np.cumsum(n) - n, n)
            vertex = by_cell[np.repeat(start, n) + at]
            keep = (ends[e, 0] != vertex) & (ends[e, 1] != vertex)
            vertex, e = vertex[keep], e[keep]
            v = points32[vertex]
            keep = ((v >= box_lo[e]) & (v <= box_hi[e])).all(axis=1)
            yield vertex[keep], e[keep]


def t_junctions(positions: np.ndarray, triangles: np.ndarray, object_ids: np.ndarray | None = None,
                chunk: int = 4_000_000) -> np.ndarray:
    """Output vertices (sorted indices into positions) of triangles that lie strictly inside an
    edge of a triangle of the same object that does not have them as a vertex, after exact
    welding (:func:`exact_weld`).  Triangles that the weld collapses are dropped.  Every output
    vertex welded to such a point is reported.  positions (V, 3) float32, triangles (T, 3),
    object_ids (V,) per vertex (Tessellation.object_ids) or None (one object).  chunk: candidate
    pairs handled at once (memory)."""
    positions = np.asarray(positions, np.float32)
    first, remap = exact_weld(positions, object_ids)
    points = positions[first].astype(np.float64)
    objects = np.zeros(len(first), np.int64) if object_ids is None else np.asarray(object_ids, np.int64)[first]
    faces = remap[np.asarray(triangles, np.int64).reshape(-1, 3)]
    faces = faces[(faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 2] != faces[:, 0])]
    if not len(faces):
        return np.zeros(0, np.int64)
    # the edges, once each, and the triangles at each (CSR)
    sides = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    keys, side_edge = np.unique(sides[:, 0] * len(points) + sides[:, 1], return_inverse=True)
    edges = np.stack([keys // len(points), keys % len(points)], axis=1)
    side_order = np.argsort(side_edge.ravel(), kind="stable")
    side_start = np.searchsorted(side_edge.ravel()[side_order], np.arange(len(edges) + 1))
    found = np.zeros(len(points), bool)
    for vertex, edge in _candidates(points, objects, edges, chunk):
        hit = strictly_inside(points[vertex], points[edges[edge, 0]], points[edges[edge, 1]])
        for v, e in zip(vertex[hit], edge[hit]):  # on another triangle's edge, not a degenerate own one
            triangles_at = side_order[side_start[e]:side_start[e + 1]] % len(faces)
            found[v] |= bool((faces[triangles_at] != v).all(axis=1).any())
    used = np.zeros(len(points), bool)
    used[faces.ravel()] = True
    return np.flatnonzero((found & used)[remap])
