"""Semi-uniform adaptive patch tessellation (Dyken, Reimers and Seland, CGF 2009, section 3):
NumPy mirror of kernels/patterns/semi_uniform.h, and the registry entries QUAD_SEMI_UNIFORM and
TRI_SEMI_UNIFORM (family "semi_uniform": ``Request(pattern="semi_uniform")``).

A patch at level ``m`` is the uniform dyadic pattern ``P^m`` (a 2^m x 2^m grid split along
the diagonals (i, j)-(i+1, j+1) for a quad, 4^m triangles for a triangle).  Edge e carries its
own level ``p_e <= m`` (the level of the edge shared with the neighbour): the snap function phi
of the paper's eq. 1 moves the boundary points of P^m that are not p_e-dyadic to the nearest
p_e-dyadic point, and the triangles that collapse are dropped.  No crack can form, since both
patches at an edge sample it at exactly its 2^p_e + 1 dyadic points.

Everything here is exact: points are integers (i, j) on the 2^m lattice, uv = (i, j) / 2^m.

Conventions (those of cltess/reference.py, quad_pattern and tri_pattern, so that an edge shared
with a transition pattern is sampled at the same points):

* quad, uv in [0, 1]^2, edges counter-clockwise: 0: v = 0, 1: u = 1, 2: v = 1, 3: u = 0; point k
  of edge e at edge parameter t = k / f_e: (t, 0), (1, t), (1 - t, 1), (0, 1 - t).
* tri, (u, v) the barycentric weights of corners P1, P2 (w = 1 - u - v); edge e runs from corner
  e to corner e+1: (1 - t, t), (0, 1 - t), (t, 0).
* Vertex layout: the ring first, edge by edge, ``f_e = 2^p_e`` points each (the edge's start
  corner and its interior p_e-dyadic points), then the interior lattice points row by row
  (rows j = 1.., points i = 1..), as the uniform transition patterns lay them out.  With all
  p_e = m the pattern equals the transition pattern of factors 2^m, vertex for vertex, and has
  its triangles (in another order).
* Triangle order (:func:`emit_order`): P^m's interior triangles first (never moved nor dropped
  by the snap, so at the same places for every patch of a level: the level's template), then
  the band along the boundary, each in the uniform pattern's order.

Record (the int4 the device reads): the dyadic edge factors ``f_e = 2^p_e`` (0: culled), so that
the ring is ``f_e`` points per edge as for every pattern, the crack-free max over an edge group
keeps them dyadic, and ``2^m = max_e f_e``.  Stage 1 makes it from the kind's factors
(common.h ``dyadic_factors``, the patterns being ``dyadic``); :func:`dyadic_factors` is its
mirror: ``p_e = min(ceil(log2 f_e), M)``, ``m = max_e p_e``.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from .base import Pattern

#: The default maximum level M (issue 11: --max-level); 2^6 = the default maximum factor.
DEFAULT_MAX_LEVEL = 6
EDGES = {"quad": 4, "tri": 3}


# --- levels -----------------------------------------------------------------------------------

def ceil_log2(f) -> np.ndarray:
    """Exact ``ceil(log2 f)`` of integers f >= 1 (no floating-point log): the number of p >= 1
    with 2^(p-1) < f."""
    f = np.asarray(f, np.int64)
    if (f < 1).any():
        raise ValueError("ceil_log2 needs f >= 1")
    return sum((f > (1 << p)).astype(np.int64) for p in range(63))


def edge_levels(factors, max_level: int = DEFAULT_MAX_LEVEL) -> tuple[np.ndarray, np.ndarray]:
    """Edge levels ``p_e = min(ceil(log2 f_e), M)`` of integer factors (P, E) (the crack-free
    factors: every edge keeps at least its factor, so the error bound holds below the cap), and
    patch levels ``m = max_e p_e = min(max_e ceil(log2 f_e), M)`` (P,).  A factor 0 (culled)
    gives level -1."""
    factors = np.asarray(factors, np.int64)
    levels = np.full(factors.shape, -1, np.int64)
    alive = factors > 0
    levels[alive] = np.minimum(ceil_log2(factors[alive]), max_level)
    return levels, levels.max(axis=-1, initial=-1)


def dyadic_factors(factors, max_level: int = DEFAULT_MAX_LEVEL) -> np.ndarray:
    """The pattern's record: ``2^p_e`` for each factor (:func:`edge_levels`), 0 where culled;
    int32 of the input's shape (PN factors (f0, f1, f2, 0) keep their 0)."""
    levels, _ = edge_levels(factors, max_level)
    return np.where(levels >= 0, np.left_shift(1, np.maximum(levels, 0)), 0).astype(np.int32)


def level_histogram(records) -> list[int]:
    """Patches per level m = log2 max_e f_e of records of dyadic factors (P, 4), culled ones
    left out: [patches at level 0, level 1, ...] up to the highest level present."""
    records = np.abs(np.asarray(records, np.int64).reshape(-1, 4))  # collapsed edges are stored negated
    sizes = records[records[:, 0] > 0].max(axis=1)
    return np.bincount(ceil_log2(sizes)).tolist() if len(sizes) else []


def record_levels(record, domain: str) -> tuple[int, list[int]]:
    """(m, [p_e]) of one record of dyadic factors (a collapsed edge's negated, as stage 2
    stores it); m = -1 when culled."""
    f = [abs(int(x)) for x in record[:EDGES[domain]]]
    if min(f) <= 0:
        return -1, []
    levels = [x.bit_length() - 1 for x in f]
    if any(1 << p != x for p, x in zip(levels, f)):
        raise ValueError(f"not a dyadic record: {f}")
    return max(levels), levels


# --- the snap function (eq. 1) ------------------------------------------------------------------

def snap(a, m: int, p: int) -> np.ndarray:
    """sigma_p of eq. 1 on the edge parameter t = a / 2^m (a integer, 0..2^m), as a lattice index:
    the nearest p-dyadic point, ties towards 0 when t < 1/2 and towards 1 otherwise.

    Applied to the edge parameter alone (the other barycentric coordinate is 1 - t), as the
    paper's Listing 1 does.  That fixes the paper's tie at p = 0: applied to both coordinates
    of the midpoint (1/2, 1/2), eq. 1 gives (1, 1), not a barycentric point; here the midpoint
    goes to the edge's end (t = 1).  For p >= 1, sigma_p(1 - t) = 1 - sigma_p(t), so the two
    patches sharing an edge, which walk it in opposite directions, snap alike; at p = 0 the
    edge keeps only its corners whichever way the tie goes.
    """
    a = np.asarray(a, np.int64)
    n, d = 1 << m, 1 << (m - p)   # t = a / n; p-dyadic points are the multiples of d
    # 2^p t - 1/2 = (2a - d) / (2d): ceil for t < 1/2, floor of (2a + d) / (2d) otherwise
    return np.where(2 * a < n, -((d - 2 * a) // (2 * d)), (2 * a + d) // (2 * d)) * d


def edge_point(domain: str, e: int, a, m: int) -> np.ndarray:
    """Lattice points (..., 2) of edge e at edge parameters a / 2^m."""
    a, n = np.asarray(a, np.int64), 1 << m
    zero, full = np.zeros_like(a), np.full_like(a, n)
    if domain == "quad":
        i, j = [(a, zero), (full, a), (n - a, full), (zero, n - a)][e]
    else:
        i, j = [(n - a, a), (zero, n - a), (a, zero)][e]
    return np.stack([i, j], axis=-1)


def edge_parameter(domain: str, e: int, points, m: int) -> tuple[np.ndarray, np.ndarray]:
    """(on edge e (...,) bool, edge parameter a (...,)) of lattice points (..., 2)."""
    points, n = np.asarray(points, np.int64), 1 << m
    i, j = points[..., 0], points[..., 1]
    if domain == "quad":
        return [(j == 0, i), (i == n, j), (j == n, n - i), (i == 0, n - j)][e]
    return [(i + j == n, j), (i == 0, n - j), (j == 0, i)][e]


def phi(domain: str, points, m: int, levels) -> np.ndarray:
    """The snap function phi (section 3) on lattice points (..., 2): interior points kept, a
    point of edge e moved to sigma_{p_e} of its edge parameter.  Corners lie on two edges and
    are kept by both (sigma_p(0) = 0, sigma_p(1) = 1)."""
    points = np.asarray(points, np.int64)
    out = points.copy()
    for e, p in enumerate(levels):
        on, a = edge_parameter(domain, e, points, m)
        out[on] = edge_point(domain, e, snap(a[on], m, p), m)
    return out


# --- the pattern ------------------------------------------------------------------------------

@lru_cache(maxsize=None)
def uniform_triangles(domain: str, m: int) -> np.ndarray:
    """The triangles of P^m as lattice points (T, 3, 2), counter-clockwise, in the order of the
    uniform transition patterns (reference.quad_pattern, reference.tri_pattern); read-only."""
    n, tris = 1 << m, []
    for j in range(n):
        for i in range(n if domain == "quad" else n - j):
            if domain == "quad":
                tris.append([(i, j), (i + 1, j), (i + 1, j + 1)])
                tris.append([(i, j), (i + 1, j + 1), (i, j + 1)])
            else:
                tris.append([(i + 1, j), (i, j + 1), (i, j)])
                if i + j < n - 1:
                    tris.append([(i + 1, j), (i + 1, j + 1), (i, j + 1)])
    tris = np.array(tris, np.int64).reshape(-1, 3, 2)
    tris.flags.writeable = False
    return tris


def inside(domain: str, points, m: int) -> np.ndarray:
    """Which lattice points (..., 2) lie strictly inside the domain (phi keeps them, and no
    collapsed edge reaches them)."""
    points, n = np.asarray(points, np.int64), 1 << m
    i, j = points[..., 0], points[..., 1]
    return (i > 0) & (j > 0) & ((i < n) & (j < n) if domain == "quad" else (i + j < n))


@lru_cache(maxsize=None)
def interior_mask(domain: str, m: int) -> np.ndarray:
    """Which triangles of P^m (uniform_triangles) are interior: all three corners inside, so
    the snap neither moves nor drops them; the others form the band along the boundary."""
    mask = inside(domain, uniform_triangles(domain, m), m).all(axis=1)
    mask.flags.writeable = False
    return mask


@lru_cache(maxsize=None)
def emit_order(domain: str, m: int) -> np.ndarray:
    """P^m's triangles in the order the pattern emits them (kernels/patterns/semi_uniform.h
    pattern_primitives): the interior triangles, then the band's, each in uniform_triangles'
    order.  The interior ones then sit at fixed places whatever the edge levels, so that
    stage 5 by level writes each from the level's template (interior_template)."""
    mask = interior_mask(domain, m)
    tris = uniform_triangles(domain, m)
    ordered = np.concatenate([tris[mask], tris[~mask]])
    ordered.flags.writeable = False
    return ordered


def interior_vertex(domain: str, points, m: int) -> np.ndarray:
    """Local number less the ring's size of interior lattice points (..., 2): rows j = 1..,
    points i = 1.. (kernels/patterns/semi_uniform.h su_interior_vertex)."""
    points, n = np.asarray(points, np.int64), 1 << m
    i, j = points[..., 0], points[..., 1]
    return (j - 1) * (n - 1) + (i - 1) if domain == "quad" else (j - 1) * (2 * n - 2 - j) // 2 + (i - 1)


@lru_cache(maxsize=None)
def point_template(domain: str, m: int) -> np.ndarray:
    """Level m's vertex template (stages/level_vertices.cl): the lattice points (i, j) of P^m
    row by row, (S, 2) int32; the snap and the layout are applied per patch on the device."""
    n = 1 << m
    points = [(i, j) for j in range(n + 1) for i in range(n + 1 if domain == "quad" else n + 1 - j)]
    out = np.array(points, np.int32)
    out.flags.writeable = False
    return out


@lru_cache(maxsize=None)
def interior_template(domain: str, m: int) -> np.ndarray:
    """Level m's triangle template (stages/level_indices.cl level_interior): P^m's interior
    triangles as local vertex numbers less the ring's size, (T, 3) uint32, in emit order; the
    same for every patch of the level."""
    tris = uniform_triangles(domain, m)[interior_mask(domain, m)]
    out = interior_vertex(domain, tris, m).astype(np.uint32).reshape(-1, 3)
    out.flags.writeable = False
    return out


def lattice_layout(domain: str, m: int, levels) -> tuple[np.ndarray, np.ndarray]:
    """The pattern P^m_{p_0 p_1 ...}: (points (V, 2) int64 on the 2^m lattice, triangles (T, 3)
    int64 local indices, counter-clockwise, in emit_order), degenerate triangles dropped.  Layout
    in the module docstring."""
    levels = [int(p) for p in levels]
    if len(levels) != EDGES[domain] or not all(0 <= p <= m for p in levels):
        raise ValueError(f"{domain} levels {levels} must be {EDGES[domain]} values in 0..m = {m}")
    n = 1 << m
    ring = [edge_point(domain, e, np.arange(1 << p) << (m - p), m) for e, p in enumerate(levels)]
    rows = [(i, j) for j in range(1, n) for i in range(1, n if domain == "quad" else n - j)]
    points = np.concatenate(ring + [np.array(rows, np.int64).reshape(-1, 2)])
    number = np.full((n + 1, n + 1), -1, np.int64)  # lattice point -> vertex
    number[points[:, 0], points[:, 1]] = np.arange(len(points))
    snapped = phi(domain, emit_order(domain, m), m, levels)
    triangles = number[snapped[..., 0], snapped[..., 1]]
    assert (triangles >= 0).all(), "phi left the vertex set"
    a, b, c = triangles.T
    return points, triangles[(a != b) & (b != c) & (c != a)]


def _dropped(m: int, levels) -> int:
    """Boundary points of P^m snapped away: 2^m - 2^p_e per edge."""
    return sum((1 << m) - (1 << p) for p in levels)


def vertex_count(domain: str, m: int, levels) -> int:
    """Closed form (SEEDS.md 1.3): (2^m + 1)^2 (quad) or (2^m + 1)(2^m + 2) / 2 (tri) points of
    P^m, less those snapped away."""
    n = 1 << m
    return ((n + 1) ** 2 if domain == "quad" else (n + 1) * (n + 2) // 2) - _dropped(m, levels)


def triangle_count(domain: str, m: int, levels) -> int:
    """Closed form: 2 * 4^m (quad) or 4^m (tri) triangles of P^m, less one per snapped point
    (each is an edge collapse along the boundary)."""
    return (2 if domain == "quad" else 1) * 4 ** m - _dropped(m, levels)


def pattern(domain: str, record) -> tuple[np.ndarray, np.ndarray]:
    """The layout of one record of dyadic factors (the Pattern protocol's ``layout``): (uv (V, 2)
    float64, triangles (T, 3) int64), as reference.quad_pattern / tri_pattern return them.
    Culled (a factor 0): none."""
    m, levels = record_levels(record, domain)
    if m < 0:
        return np.zeros((0, 2)), np.zeros((0, 3), np.int64)
    points, triangles = lattice_layout(domain, m, levels)
    return points / float(1 << m), triangles[~on_collapsed_edges(triangles, record, domain)]


def on_collapsed_edges(triangles: np.ndarray, record, domain: str) -> np.ndarray:
    """Which triangles have a side on a collapsed edge (a negative factor: its points coincide,
    kernels/common.h patch_factors), so are left out: two of their corners among the ring points
    of that edge, its two corners included (kernels/patterns/semi_uniform.h su_put)."""
    f = [int(x) for x in record[:EDGES[domain]]]
    sizes = [abs(x) for x in f]
    ring, start = sum(sizes), np.cumsum([0] + sizes[:-1])
    out = np.zeros(len(triangles), bool)
    for e, factor in enumerate(f):
        if factor < 0:
            on_edge = (triangles < ring) & ((triangles - start[e]) % ring <= sizes[e])
            out |= on_edge.sum(axis=1) >= 2
    return out


def quad_pattern(record) -> tuple[np.ndarray, np.ndarray]:
    return pattern("quad", record)


def tri_pattern(record) -> tuple[np.ndarray, np.ndarray]:
    return pattern("tri", record)


QUAD_SEMI_UNIFORM = Pattern("quad_semi_uniform", "quad", 4, "patterns/quad_semi_uniform.h", quad_pattern,
                            family="semi_uniform", dyadic=True)
TRI_SEMI_UNIFORM = Pattern("tri_semi_uniform", "tri", 3, "patterns/tri_semi_uniform.h", tri_pattern,
                           family="semi_uniform", dyadic=True)


def counts(records, domain: str) -> tuple[np.ndarray, np.ndarray]:
    """(vertex counts (P,), index counts (P,)) of records (P, 4), from the closed forms: the
    stage-3 mirror (reference.counts for the transition patterns)."""
    out = np.zeros((2, len(records)), np.int64)
    for r, record in enumerate(records):
        m, levels = record_levels(record, domain)
        if m >= 0:
            triangles = (len(pattern(domain, record)[1]) if min(record[:EDGES[domain]]) < 0  # collapsed edges
                         else triangle_count(domain, m, levels))
            out[:, r] = vertex_count(domain, m, levels), 3 * triangles
    return out[0], out[1]


__all__ = ["DEFAULT_MAX_LEVEL", "EDGES", "ceil_log2", "edge_levels", "dyadic_factors", "level_histogram", "record_levels", "snap",
           "edge_point", "edge_parameter", "phi", "uniform_triangles", "inside", "interior_mask", "emit_order",
           "interior_vertex", "point_template", "interior_template", "lattice_layout", "vertex_count",
           "triangle_count", "pattern", "on_collapsed_edges", "quad_pattern", "tri_pattern", "counts", "QUAD_SEMI_UNIFORM", "TRI_SEMI_UNIFORM"]
