"""The quad transition pattern (CudaTess section 3; docs/design.md section 5): the NumPy mirror
of kernels/patterns/quad_transition.h, and its registry entry."""
from __future__ import annotations

import numpy as np

from .base import Pattern


def quad_pattern(f: tuple[int, int, int, int]) -> tuple[np.ndarray, np.ndarray]:
    """The tessellation pattern of a quad patch with edge factors f (CudaTess Fig. 3).

    Vertex layout, boundary first: the ring of ``R = f0+f1+f2+f3`` boundary points walking
    counter-clockwise from (0, 0) (edge e, point k at ``t = k / f_e``), then the inner grid
    ``(i / A, j / B)`` for ``j = 1..B-1``, ``i = 1..A-1`` row by row.

    Uniform (f0 = f2 and f1 = f3): the regular A x B grid, A = f0, B = f1.  Otherwise the core
    factors are ``A = max(min(f0, f2), 2)``, ``B = max(min(f1, f3), 2)``; the inner grid's cells
    are split regularly and each edge's strip between boundary and inner grid is stitched
    Bresenham-style, advancing the side whose next segment midpoint comes first.

    A negative factor -f_e is a collapsed edge (stage 2, ``kernels/common.h`` patch_factors): its
    points coincide, and the triangles with a side on it are left out.

    Returns (uv (V, 2) float64, triangles (T, 3) int64 local indices, counter-clockwise in uv).
    Culled patches (factors 0) have no vertices and no triangles.
    """
    collapsed = [int(x) < 0 for x in f]
    f = [abs(int(x)) for x in f]
    if min(f) <= 0:
        return np.zeros((0, 2)), np.zeros((0, 3), np.int64)
    uniform = f[0] == f[2] and f[1] == f[3]
    a = f[0] if uniform else max(min(f[0], f[2]), 2)
    b = f[1] if uniform else max(min(f[1], f[3]), 2)
    ring_size = sum(f)
    base = np.cumsum([0] + f)

    def ring(e, k):
        return (base[e] + k) % ring_size

    def inner(i, j):
        return ring_size + (j - 1) * (a - 1) + (i - 1)

    uv = []
    for e in range(4):
        for k in range(f[e]):
            t = k / f[e]
            uv.append([(t, 0.0), (1.0, t), (1.0 - t, 1.0), (0.0, 1.0 - t)][e])
    uv += [(i / a, j / b) for j in range(1, b) for i in range(1, a)]

    def grid(i, j):
        if j == 0:
            return ring(0, i)
        if i == a:
            return ring(1, j)
        if j == b:
            return ring(2, a - i)
        if i == 0:
            return ring(3, b - j)
        return inner(i, j)

    tris = []

    def cells(i0, i1, j0, j1, collapsed):
        for j in range(j0, j1):
            for i in range(i0, i1):
                if not ((j == 0 and collapsed[0]) or (i + 1 == a and collapsed[1])):
                    tris.append((grid(i, j), grid(i + 1, j), grid(i + 1, j + 1)))
                if not ((j + 1 == b and collapsed[2]) or (i == 0 and collapsed[3])):
                    tris.append((grid(i, j), grid(i + 1, j + 1), grid(i, j + 1)))

    if uniform:
        cells(0, a, 0, b, collapsed)
    else:
        cells(1, a - 1, 1, b - 1, [False] * 4)
        inner_edge = [lambda k: inner(1 + k, 1), lambda k: inner(a - 1, 1 + k),
                      lambda k: inner(a - 1 - k, b - 1), lambda k: inner(1, b - 1 - k)]
        for e in range(4):
            outer_n, core = f[e], (a if e % 2 == 0 else b)
            inner_n = core - 2
            o = k = 0
            while o < outer_n or k < inner_n:
                if k == inner_n or (o < outer_n and (2 * o + 1) * core <= (2 * k + 3) * outer_n):
                    if not collapsed[e]:
                        tris.append((ring(e, o), ring(e, o + 1), inner_edge[e](k)))
                    o += 1
                else:
                    tris.append((ring(e, o), inner_edge[e](k + 1), inner_edge[e](k)))
                    k += 1
    return np.array(uv, float).reshape(-1, 2), np.array(tris, np.int64).reshape(-1, 3)


QUAD_TRANSITION = Pattern("quad_transition", "quad", 4, "patterns/quad_transition.h", quad_pattern, family="transition")
