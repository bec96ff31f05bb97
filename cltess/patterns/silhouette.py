"""Blended evaluation of fractional levels (Dyken, Reimers and Seland, CGF 2008, section 5,
eq. 9-11) on the semi-uniform pattern's layout: the NumPy mirror (float64, slow, plain) of
kernels/stages/silhouette_vertices.cl, whose header comment (and docs/design.md, "Silhouette
refinement") says what surface it is.

A patch with edge levels s_e has the topological level m = ceil(s_max) and the surface that is
piecewise linear over P^m with the vertex values: on the open edge e, S_{s_e}[F] (the edge's
curve interpolated over its level-L intervals, blended between floor(s_e) and ceil(s_e));
inside, (1 - a) G_k + a G_{k+1} with k = floor(s_max), G_L interpolating over P^L the values F
inside and the edges' values on the boundary.  Its record (the semi-uniform pattern's dyadic
factors) may put it on a finer lattice 2^m' with each edge snapped to its own level: each vertex
then takes that surface's value at its point.
"""
from __future__ import annotations

import math

import numpy as np

from .semi_uniform import EDGES, edge_point, record_levels


def _evaluate(kind, controls, lattice, n) -> tuple[np.ndarray, np.ndarray]:
    points = np.asarray(lattice, np.float64).reshape(-1, 2) / n
    return kind.surface.evaluate(controls, points[:, 0], points[:, 1])


def _unit(v):
    return v / max(np.linalg.norm(v), 1e-300)


def edge_sample(kind, controls, e: int, a: int, m: int, level: int):
    """(position, normal) of S_level[F] and S_level[N] at the point a / 2^m of edge e."""
    domain, n = kind.domain, 1 << m
    d = n >> level
    a0, r = a // d * d, a % d
    if r == 0:
        p, nrm = _evaluate(kind, controls, edge_point(domain, e, a, m), n)
        return p[0], nrm[0]
    ends = np.array([edge_point(domain, e, a0, m), edge_point(domain, e, a0 + d, m)])
    p, nrm = _evaluate(kind, controls, ends, n)
    w = r / d
    return (1 - w) * p[0] + w * p[1], (1 - w) * nrm[0] + w * nrm[1]


def cell(domain: str, i: int, j: int, n: int, level: int) -> list[tuple[tuple[int, int], float]]:
    """The level-`level` triangle holding lattice point (i, j) of n: [(lattice corner, weight)],
    zero weights left out (quad cells split along (0,0)-(1,1), triangle cells as P^m)."""
    d = n >> level
    ci, cj, ri, rj = i // d * d, j // d * d, i % d, j % d
    if ri == 0 and rj == 0:
        return [((i, j), 1.0)]
    x, y = ri / d, rj / d
    if domain == "quad":
        if ri >= rj:
            corners = [((ci, cj), 1 - x), ((ci + d, cj), x - y), ((ci + d, cj + d), y)]
        else:
            corners = [((ci, cj), 1 - y), ((ci, cj + d), y - x), ((ci + d, cj + d), x)]
    elif ri + rj <= d:
        corners = [((ci, cj), 1 - x - y), ((ci + d, cj), x), ((ci, cj + d), y)]
    else:
        corners = [((ci + d, cj), 1 - y), ((ci, cj + d), 1 - x), ((ci + d, cj + d), x + y - 1)]
    return [(c, w) for c, w in corners if w != 0]


def lattice_edge(domain: str, i: int, j: int, n: int):
    """(edge, parameter a in 0..n-1) of a boundary lattice point (its start corner included), or None."""
    if domain == "quad":
        tests = [(j == 0 and i < n, 0, i), (i == n and j < n, 1, j), (j == n and i > 0, 2, n - i),
                 (i == 0 and j > 0, 3, n - j)]
    else:
        tests = [(i + j == n and j < n, 0, j), (i == 0 and j > 0, 1, n - j), (j == 0 and i < n, 2, i)]
    return next(((e, a) for hit, e, a in tests if hit), None)


class _Patch:
    def __init__(self, kind, controls, record, levels, blend):
        self.kind, self.controls, self.blend = kind, controls, blend
        self.m_lattice, self.edge_levels = record_levels(record, kind.domain)
        self.n = 1 << self.m_lattice
        self.collapsed = [int(x) < 0 for x in record[:EDGES[kind.domain]]]
        self.s = [float(np.float32(x)) for x in list(levels)[:EDGES[kind.domain]]]
        self.s_max = max(self.s)
        self.m = math.ceil(self.s_max)

    def edge_value(self, e: int, a: int):
        """S_{s_e}[F] at the point a / n of edge e (a = 0: the corner exactly)."""
        if not self.blend or a == 0 or self.collapsed[e]:
            p, nrm = _evaluate(self.kind, self.controls, edge_point(self.kind.domain, e, 0 if self.collapsed[e] else a,
                                                                     self.m_lattice), self.n)
            return p[0], nrm[0]
        return blended(lambda level: edge_sample(self.kind, self.controls, e, a, self.m_lattice, level),
                       self.s[e], self.edge_levels[e])

    def hat(self, i: int, j: int):
        on_edge = lattice_edge(self.kind.domain, i, j, self.n)
        if on_edge is not None:
            return self.edge_value(*on_edge)
        p, nrm = _evaluate(self.kind, self.controls, (i, j), self.n)
        return p[0], nrm[0]

    def coarse(self, i: int, j: int, level: int):
        """G_level at lattice point (i, j)."""
        corners = cell(self.kind.domain, i, j, self.n, level)
        values = [self.hat(*c) for c, _ in corners]
        return sum(w * v[0] for (_, w), v in zip(corners, values)), sum(w * v[1] for (_, w), v in zip(corners, values))

    def value(self, i: int, j: int):
        """The surface's value at a point (i, j) of P^m."""
        if not self.blend or lattice_edge(self.kind.domain, i, j, self.n) is not None:
            return self.hat(i, j)
        return blended(lambda level: self.coarse(i, j, level), self.s_max, self.m)

    def vertex(self, i: int, j: int):
        if not self.blend:
            p, nrm = _evaluate(self.kind, self.controls, (i, j), self.n)
            return p[0], nrm[0]
        corners = cell(self.kind.domain, i, j, self.n, min(self.m, self.m_lattice))
        values = [self.value(*c) for c, _ in corners]
        position = sum(w * v[0] for (_, w), v in zip(corners, values))
        normal = sum(w * v[1] for (_, w), v in zip(corners, values))
        return position, _unit(normal)


def blended(sample, s: float, finest: int):
    """eq. 9 at a point of level `finest` with geometric level s: (position, unit normal)."""
    k = math.floor(s)
    a = s - k
    lo, nlo = sample(min(k, finest))
    if a == 0:
        return lo, _unit(nlo)
    hi, nhi = sample(min(k + 1, finest))
    return (1 - a) * lo + a * hi, _unit((1 - a) * nlo + a * nhi)


def blended_patch(kind, controls, record, levels, blend: bool = True):
    """(positions (V, 3), normals (V, 3), lod (V,)) of one patch, in the semi-uniform pattern's
    vertex layout: record its dyadic factors as stages 3-5 read them (collapsed edges negated),
    levels its edges' s_e (float32 as the device has them), controls what kind.surface.evaluate
    takes.  A culled patch: empty."""
    domain = kind.domain
    m, p_levels = record_levels(record, domain)
    if m < 0:
        return np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0)
    patch = _Patch(kind, controls, record, levels, blend)
    n = 1 << m
    positions, normals, lod = [], [], []
    for e, p in enumerate(p_levels):
        for k in range(1 << p):
            position, normal = patch.edge_value(e, k << (m - p))
            positions.append(position)
            normals.append(_unit(normal))
            lod.append(patch.s[e])
    for j in range(1, n):
        for i in range(1, n if domain == "quad" else n - j):
            position, normal = patch.vertex(i, j)
            positions.append(position)
            normals.append(normal)
            lod.append(patch.s_max)
    return np.array(positions), np.array(normals), np.array(lod)


__all__ = ["edge_sample", "cell", "lattice_edge", "blended", "blended_patch"]
