"""The SD-2 pattern (Amresh and Fünfzig, "Semi-uniform, 2-different tessellation of triangular
parametric surfaces", section 3.3; docs/sd2.md): the NumPy mirror of kernels/patterns/sd2.h,
and its registry entry.

Factors are real, as 16.16 fixed-point integers (cltess.patterns.fractional), an edge of
factor r has ``odd_segments(r)`` segments placed by fractional_odd (symmetric, continuous).  A
triangle's three factors decide its shape:

* two equal, the third different (**SD-2**): the *tip* is the corner where the two equal edges
  meet, the *base* the edge opposite.  Parallel lines to the base at the tip edges' points
  ``t_i`` (``i = 0 .. a``, a the tip edges' segments) cross radial lines from the tip to the
  base points ``s_j`` (``j = 0 .. b``): vertex (i, j) = tip + t_i (base(s_j) - tip).  Counts
  ``V = a (b + 1) + 1``, ``T = b (2a - 1)``; one triangle strip per pair of radial lines
  (the paper's Fig. 4 strips): ``[tip, (1,j), (1,j+1), (2,j), (2,j+1), ..., (a,j), (a,j+1)]``.
* all three equal (**grid**; the SD-2 pattern would have about twice the triangles): rows
  parallel to edge 1 at corner 0's edge points, row i with i + 1 points at i equal steps (the
  last row: edge 1's own points), ``V = (n+1)(n+2)/2``, ``T = n^2``, one strip per band between
  rows, walked from edge 2's side.
* all three different (**fallback**): the transition pattern (cltess/patterns/tri_transition.py)
  on the segment counts, its ring at the fractional points; one strip per triangle.

Vertex layout (patterns/layout.h): the ring (edge e's points k = 0 .. n_e - 1, counter-clockwise
from corner 0), then the interior rows.  Triangles are counter-clockwise in (u, v) and are
exactly the expanded strips (cltess.strips.expand_strips), whose indices carry one restart
marker after each strip.
"""
from __future__ import annotations

import numpy as np

from ..strips import STRIP_RESTART
from .base import Pattern
from .fractional import locations, odd_segments
from .tri_transition import tri_pattern

EYE = np.eye(3, dtype=np.float32)


def sd2_shape(f) -> tuple[str, int]:
    """("sd2", tip corner) | ("grid", 0) | ("transition", -1) | ("culled", -1) of fixed factors f."""
    f = [int(x) for x in f[:3]]
    if min(f) <= 0:
        return "culled", -1
    if f[0] == f[1] == f[2]:
        return "grid", 0
    # edges c-1 and c meet at corner c (edge e runs from corner e to corner e+1)
    for c in range(3):
        if f[(c + 2) % 3] == f[c]:
            return "sd2", c
    return "transition", -1


def _point(c: int, t: np.float32, s: np.float32) -> np.ndarray:
    """Barycentric (u, v, w) float32 of tip (corner c) + t (base(s) - tip), base(s) = corner c+1
    to corner c+2 at s (the device's operation order: sd2_point)."""
    one = np.float32(1.0)
    weights = np.zeros(3, np.float32)
    weights[c] = one - t
    weights[(c + 1) % 3] = t * (one - s)
    weights[(c + 2) % 3] = t * s
    return weights


def _ring_uv(f, segments) -> list:
    """(u, v) of the ring points, as kernels/common.h tri_edge_point places them."""
    uv = []
    for e in range(3):
        x = locations(f[e])
        for k in range(segments[e]):
            t = x[k]
            s = np.float32(1.0) - t
            uv.append([(s, t), (np.float32(0.0), s), (t, np.float32(0.0))][e])
    return uv


class _Layout:
    """Local vertex numbers of one patch: the ring, then interior rows."""

    def __init__(self, f):
        self.f = [int(x) for x in f[:3]]
        self.n = [odd_segments(x) for x in self.f]
        self.ring_size = sum(self.n)
        self.base = [0, self.n[0], self.n[0] + self.n[1]]
        self.shape, self.tip = sd2_shape(self.f)

    def ring(self, e, k):
        return (self.base[e % 3] + k) % self.ring_size

    def sd2(self, i, j):
        c, a, b = self.tip, self.n[self.tip], self.n[(self.tip + 1) % 3]
        if i == 0:
            return self.ring(c, 0)
        if j == 0:
            return self.ring(c, i)
        if i == a:
            return self.ring(c + 1, j)
        if j == b:
            return self.ring(c + 2, a - i)
        return self.ring_size + (i - 1) * (b - 1) + (j - 1)

    def grid(self, i, j):
        n = self.n[0]
        if i == 0:
            return self.ring(0, 0)
        if j == 0:
            return self.ring(0, i)
        if i == n:
            return self.ring(1, j)
        if j == i:
            return self.ring(2, n - i)
        return self.ring_size + (i - 2) * (i - 1) // 2 + (j - 1)


def sd2_layout(f) -> tuple[np.ndarray, list[np.ndarray]]:
    """(uv (V, 2) float32, strips: list of (L,) int64 local index arrays) of fixed factors f."""
    lay = _Layout(f)
    if lay.shape == "culled":
        return np.zeros((0, 2), np.float32), []
    uv = _ring_uv(lay.f, lay.n)
    strips = []
    if lay.shape == "sd2":
        c = lay.tip
        a, b = lay.n[c], lay.n[(c + 1) % 3]
        t, s = locations(lay.f[c]), locations(lay.f[(c + 1) % 3])
        uv += [_point(c, t[i], s[j])[:2] for i in range(1, a) for j in range(1, b)]
        for j in range(b):
            strip = [lay.sd2(0, 0)]
            for i in range(1, a + 1):
                strip += [lay.sd2(i, j), lay.sd2(i, j + 1)]
            strips.append(np.array(strip, np.int64))
    elif lay.shape == "grid":
        n = lay.n[0]
        t = locations(lay.f[0])
        uv += [_point(0, t[i], np.float32(j) / np.float32(i))[:2] for i in range(2, n) for j in range(1, i)]
        for i in range(n):
            strip = []
            for j in range(i + 1, 0, -1):
                strip += [lay.grid(i + 1, j), lay.grid(i, j - 1)]
            strip.append(lay.grid(i + 1, 0))
            strips.append(np.array(strip, np.int64))
    else:
        grid_uv, triangles = tri_pattern(lay.n)
        uv += [p.astype(np.float32) for p in grid_uv[lay.ring_size:]]
        strips = [np.array(tri, np.int64) for tri in triangles]
    return np.array(uv, np.float32).reshape(-1, 2), strips


def sd2_strip_indices(f) -> np.ndarray:
    """The strips of one patch as the device emits them (local numbers): each strip followed by
    one restart marker (so patches concatenate; the host drops the last marker)."""
    _, strips = sd2_layout(f)
    parts = [np.append(s, np.int64(STRIP_RESTART)) for s in strips]
    return np.concatenate(parts).astype(np.int64) if parts else np.zeros(0, np.int64)


def sd2_pattern(f) -> tuple[np.ndarray, np.ndarray]:
    """The pattern's layout for the registry: (uv (V, 2) float64, triangles (T, 3) int64), the
    triangles being the strips expanded (winding rule of cltess.strips)."""
    uv, strips = sd2_layout(f)
    triangles = []
    for strip in strips:
        for i in range(len(strip) - 2):
            a, b, c = strip[i], strip[i + 1], strip[i + 2]
            triangles.append((b, a, c) if i % 2 else (a, b, c))
    return uv.astype(np.float64), np.array(triangles, np.int64).reshape(-1, 3)


def sd2_counts(f) -> tuple[int, int, int]:
    """Closed-form (vertices, triangles, strip indices) of fixed factors f (docs/sd2.md)."""
    lay = _Layout(f)
    if lay.shape == "culled":
        return 0, 0, 0
    if lay.shape == "sd2":
        a, b = lay.n[lay.tip], lay.n[(lay.tip + 1) % 3]
        return a * (b + 1) + 1, b * (2 * a - 1), b * (2 * a + 2)
    if lay.shape == "grid":
        n = lay.n[0]
        return (n + 1) * (n + 2) // 2, n * n, n * n + 3 * n
    uv, triangles = tri_pattern(lay.n)
    return len(uv), len(triangles), 4 * len(triangles)


SD2 = Pattern("sd2", "tri", 3, "patterns/sd2.h", sd2_pattern, primitive="strips", fixed_point=True)
