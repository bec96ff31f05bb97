"""The triangle transition pattern (CudaTess section 4; docs/design.md section 5): the NumPy
mirror of kernels/patterns/tri_transition.h, and its registry entry."""
from __future__ import annotations

import numpy as np

from .base import Pattern


def tri_pattern(f) -> tuple[np.ndarray, np.ndarray]:
    """The tessellation pattern of a triangle patch with edge factors f (CudaTess Fig. 5).

    Core factor ``N = max(f0, f1, f2)``.  Vertex layout, boundary first: the ring of
    ``R = f0+f1+f2`` points counter-clockwise from P1 (edge e, point k at ``t = k / f_e``), then
    the factor-N grid's interior points ``(i / N, j / N)``, rows ``j = 1..N-2``, ``i = 1..N-1-j``
    (u, v: the barycentric coordinates of P1, P2).

    Triangles: the regular factor-N grid, less the band along each edge whose factor is below N
    (a transition edge: at most two); each band is stitched Bresenham-style between the edge's
    f_e segments and the grid row one step inside it, whose point m stands at (m + 1/2) / N
    along the edge, advancing the side whose next segment midpoint comes first.  Where two
    transition bands meet, each row stops at the crossing point of the two rows.  Every triangle
    keeps the Filip bound: in coordinates along two edge directions scaled by their factors, its
    smallest enclosing circle has radius^2 <= 1/2, as the core's grid triangles do (tests).

    Returns (uv (V, 2) float64, triangles (T, 3) int64 local, counter-clockwise in uv).  Culled
    (factor 0) triangles have none.  Factors (1, 1, 1) give the one triangle (0, 1, 2).
    """
    f = [int(x) for x in f[:3]]
    if min(f) <= 0:
        return np.zeros((0, 2)), np.zeros((0, 3), np.int64)
    n = max(f)
    ring_size = sum(f)
    base = [0, f[0], f[0] + f[1]]
    t = [int(fe < n) for fe in f]

    def ring(e, k):
        return (base[e] + k) % ring_size

    def grid(i, j):
        k = n - i - j
        if i == n:
            return 0
        if j == n:
            return base[1]
        if k == n:
            return base[2]
        if k == 0:
            return ring(0, j)
        if i == 0:
            return ring(1, k)
        if j == 0:
            return ring(2, i)
        return ring_size + (j - 1) * (2 * n - 2 - j) // 2 + (i - 1)

    def row(e, m):
        c = [0, 0, 0]
        c[e], c[(e + 1) % 3], c[(e + 2) % 3] = n - 1 - m, m, 1
        return grid(c[0], c[1])

    uv = []
    for e in range(3):
        for k in range(f[e]):
            s, r = k / f[e], (f[e] - k) / f[e]
            uv.append([(r, s), (0.0, r), (s, 0.0)][e])
    uv += [(i / n, j / n) for j in range(1, n - 1) for i in range(1, n - j)]

    tris = []
    m = n - sum(t)
    for j in range(m):
        for i in range(m - j):
            a, b = t[1] + i, t[2] + j
            tris.append((grid(a + 1, b), grid(a, b + 1), grid(a, b)))
            if i + j < m - 1:
                tris.append((grid(a + 1, b), grid(a + 1, b + 1), grid(a, b + 1)))
    for e in range(3):
        if not t[e]:
            continue
        fe, o = f[e], 0
        k, k_end = t[(e + 2) % 3], n - 1 - t[(e + 1) % 3]
        while o < fe or k < k_end:
            if k == k_end or (o < fe and (2 * o + 1) * n <= 2 * (k + 1) * fe):
                tris.append((ring(e, o), ring(e, o + 1), row(e, k)))
                o += 1
            else:
                tris.append((ring(e, o), row(e, k + 1), row(e, k)))
                k += 1
    return np.array(uv, float).reshape(-1, 2), np.array(tris, np.int64).reshape(-1, 3)



TRI_TRANSITION = Pattern("tri_transition", "tri", 3, "patterns/tri_transition.h", tri_pattern, family="transition")
