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
from .fractional import FIXED_ONE, locations, odd_segments
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


#: The hint a level function leaves in a patch's fourth factor slot (docs/sd2.md section 5):
#: ``(phi_m << HINT_SHIFT) | m``, m the corner of the smallest per-vertex factor phi_m (16.16,
#: the edge factors being the larger of their ends' phi); 0: no hint.  kernels/patterns/sd2.h.
HINT_SHIFT = 2



def sd2_hint(f) -> tuple[int, int] | None:
    """(m, phi_m) of a patch's hint slot f[3], or None (no hint, or not a corner)."""
    if len(f) < 4 or int(f[3]) == 0:
        return None
    h = abs(int(f[3]))  # stage 2 stores an unused slot negated (kernels/common.h patch_factors)
    m = h & ((1 << HINT_SHIFT) - 1)
    return (m, h >> HINT_SHIFT) if m < 3 else None


def sd2_morph(f, c: int) -> tuple[bool, np.float32, np.float32]:
    """(in the tie zone, w, lam) of the fan with tip c (docs/sd2.md section 5).  w: the radial
    pattern's weight, ``(F - G) / 1.0`` (F the tip edges' factor, G the base's): 0 at a tie, the
    zone is w < 1.  lam: the weight of the tie configuration with partner c+1 against partner
    c+2, ``min(e2 / e1, 1)``, e_k = F - phi_k the distance of base corner k from tying with the
    tip: 1 at e1 = 0, 0 at e2 = 0, continuous elsewhere, and 1 when the base corners tie with each
    other (e1 = e2: a plateau left by the tip starts from the tie configuration with partner c+1,
    which at an odd whole factor is the plateau's grid); then sharpened about 1/2 near a triple
    tie at an odd whole factor of 3 or more (_sharpen to width _switch_width; docs/sd2.md
    section 5, "Seventh pass"), where a blend of the two configurations slides each vertex by up to
    n lattice cells while the configurations themselves are nearly the same lattice.  Outside the
    zone, or without a usable hint: (False, 1, 1)."""
    one = np.float32(1.0)
    hint = sd2_hint(f)
    big, base = int(f[c]), int(f[(c + 1) % 3])
    if hint is None or hint[0] == c or hint[1] > base or big < base or big - base >= FIXED_ONE:
        return False, one, one
    m, phi_m = hint
    e_m, e_other = big - phi_m, big - base
    e1, e2 = (e_m, e_other) if m == (c + 1) % 3 else (e_other, e_m)
    w = np.float32(e_other) * np.float32(1.0 / FIXED_ONE)
    lam = min(np.float32(np.float32(e2) / np.float32(e1)), np.float32(1.0)) if e1 > 0 else np.float32(1.0)
    return True, w, _sharpen(lam, _switch_width(big, phi_m))


def odd_distance(x: int) -> int:
    """The distance (16.16) of a fixed-point factor from the nearest odd whole number (where
    fractional_odd places its points at k / n and every tie configuration is the regular lattice).
    Device: sd2.h sd2_odd_distance, the same integer operations."""
    r = abs(int(x) - FIXED_ONE) % (2 * FIXED_ONE)
    return min(r, 2 * FIXED_ONE - r)


#: How close (factor units) to a triple tie at an odd whole number the zone switches between its
#: two tie configurations instead of blending them (docs/sd2.md section 5, "Seventh pass"): the
#: switch's width kappa grows as rho / SWITCH_REACH.  Device: sd2.h SD2_SWITCH_REACH.
SWITCH_REACH = 0.125


def _switch_width(big: int, phi_m: int) -> np.float32:
    """kappa, the width in lam over which the zone moves from one tie configuration to the other
    (docs/sd2.md section 5, "Seventh pass"): ``min(1, max(rho / SWITCH_REACH, sigma_m / rho))``,
    rho = F - phi_m the distance from the triple tie, sigma_m the distance of phi_m from the nearest
    odd whole number.  Small only near a triple tie at an odd whole number (rho and sigma_m both
    small), where the two tie configurations are within O(rho + sigma_m) of the same lattice as
    surfaces while any blend of them stands off both by about the error; 1 (lam itself) elsewhere,
    near isolated triple ties off the odd numbers included, and below phi_m = 2, where the
    plateau of 1's blends already move in proportion (their centres on the chord, sixth pass) and a
    steeper lam would only move them faster (kappa is 1 near phi_m = 2 either way).  Device: sd2.h sd2_switch_width, the
    same operations."""
    rho = int(big) - int(phi_m)
    if rho <= 0 or phi_m < 2 * FIXED_ONE:
        return np.float32(1.0)
    apart = np.float32(np.float32(odd_distance(phi_m)) / np.float32(rho))
    from_tie = np.float32(np.float32(np.float32(rho) * np.float32(1.0 / FIXED_ONE)) / np.float32(SWITCH_REACH))
    return min(np.float32(1.0), max(from_tie, apart))


def _sharpen(lam: np.float32, kappa: np.float32) -> np.float32:
    """lam steepened about 1/2 to width kappa: ``clamp(1/2 + (lam - 1/2) / kappa, 0, 1)``
    (kappa = 1: lam itself, bitwise; kappa = 0: the step, 1 from lam = 1/2 on).  0 and 1 are kept, so the
    ties (lam 1 at e1 = 0, 0 at e2 = 0) and the plateau's lam = 1 are unchanged.  Device: sd2.h
    sd2_sharpen, the same operations."""
    half, zero, one = np.float32(0.5), np.float32(0.0), np.float32(1.0)
    if kappa >= one:
        return lam
    d = np.float32(lam - half)
    if kappa <= zero:
        return one if d >= zero else zero
    return min(max(np.float32(half + np.float32(d / kappa)), zero), one)


def _fan_z(t: np.float32, s: np.float32, w: np.float32, lam: np.float32) -> np.float32:
    """Corner c+2's weight of the zone's fan vertex at row location t and base location s:
    ``w t s + (1 - w) (lam max(t + s - 1, 0) + (1 - lam) min(s, t))``: the radial pattern's t s
    pulled towards the tie configurations with partner c+1 (lines of constant corner c+1 weight
    through the base points) and c+2 (constant c+2 weight), its Frechet bounds; nondecreasing in
    s, so rows stay ordered (device: sd2_fan_z, the same operations)."""
    f32, one, zero = np.float32, np.float32(1.0), np.float32(0.0)
    radial = f32(t * s)
    towards_1 = max(f32(f32(t + s) - one), zero)
    towards_2 = min(s, t)
    tie = f32(f32(lam * towards_1) + f32(f32(one - lam) * towards_2))
    return f32(f32(w * radial) + f32(f32(one - w) * tie))


def _centre_mu(w: np.float32, lam: np.float32) -> np.float32:
    """How far a zone quad's centre has slid from its corner (i, j+1) towards (i, j):
    ``(1 - w)(1 - lam)`` (docs/sd2.md section 5): 0 at the zone's outer edge (w = 1, the radial
    pattern's diagonal) and wherever the tie partner is c+1 (lam = 1), 1 at a tie with c+2 (the
    other diagonal).  The centre is a vertex of its row on both sides (the quad below fans from
    it, the triangle above is split at it), placed in space on the chord between its row
    neighbours (sd2_chords), so it may sit on (i, j+1) itself.  Device: sd2.h sd2_centre_mu."""
    one = np.float32(1.0)
    return np.float32(np.float32(one - w) * np.float32(one - lam))


def _row_point(c: int, t: np.float32, z: np.float32) -> np.ndarray:
    """Barycentric point on the row at location t from corner c with corner c+2 weight z."""
    weights = np.zeros(3, np.float32)
    weights[c] = np.float32(1.0) - t
    weights[(c + 1) % 3] = np.float32(t - z)
    weights[(c + 2) % 3] = z
    return weights


def sd2_grid_corner(f) -> int:
    """The corner the grid's rows start from: with a hint, m + 1 (the tied pair is m+1, m+2 and
    the grid is their tie configuration), else 0."""
    hint = sd2_hint(f)
    return (hint[0] + 1) % 3 if hint is not None else 0


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
        self.zone, self.w, self.lam = False, np.float32(1.0), np.float32(1.0)
        if self.shape == "grid":
            self.tip = sd2_grid_corner(f)
        elif self.shape == "sd2":
            self.zone, self.w, self.lam = sd2_morph(f, self.tip)

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

    def centre(self, i, j):
        """The zone's centre vertex of the quad between rows i, i+1 and radial lines j, j+1."""
        a, b = self.n[self.tip], self.n[(self.tip + 1) % 3]
        return self.ring_size + (a - 1) * (b - 1) + (i - 1) * b + j

    def grid(self, i, j):
        n, g = self.n[0], self.tip
        if i == 0:
            return self.ring(g, 0)
        if j == 0:
            return self.ring(g, i)
        if i == n:
            return self.ring(g + 1, j)
        if j == i:
            return self.ring(g + 2, n - i)
        return self.ring_size + (i - 2) * (i - 1) // 2 + (j - 1)


def _zone(lay: "_Layout") -> tuple[list, np.float32]:
    """(z, mu) of a fan in the tie zone: z[i][j] corner c+2's weight of vertex (i, j) (_fan_z),
    mu the centres' slide (_centre_mu)."""
    c = lay.tip
    a, b = lay.n[c], lay.n[(c + 1) % 3]
    t, s = locations(lay.f[c]), locations(lay.f[(c + 1) % 3])
    z = [[_fan_z(t[i], s[j], lay.w, lay.lam) for j in range(b + 1)] for i in range(a + 1)]
    return z, _centre_mu(lay.w, lay.lam)


def _zone_strips(lay: "_Layout") -> list[np.ndarray]:
    """The tie zone's strips (docs/sd2.md section 5).  Centre C(i, j) of the quad between rows i,
    i+1 and radial lines j, j+1 lies on row i between A = (i, j) and E = (i, j+1), and is a
    vertex of both sides of that row: the tip's triangle (i = 1) or the quad above has its lower
    edge A E split at it, and the quad fans from it to B = (i+1, j), D = (i+1, j+1) and the
    lower row's own centre C' = C(i+1, j) on B D (none on the base).  Per radial pair:
    ``[A1, C1, tip, E1]``, then per quad ``[A, B, C, C', D]`` and ``[C, D, E]``, or
    ``[A, B, C, D, E]`` on the base's row."""
    c = lay.tip
    a, b = lay.n[c], lay.n[(c + 1) % 3]
    strips = []
    for j in range(b):
        strips.append([lay.sd2(1, j), lay.centre(1, j), lay.sd2(0, 0), lay.sd2(1, j + 1)])
        for i in range(1, a):
            A, B, D, E = lay.sd2(i, j), lay.sd2(i + 1, j), lay.sd2(i + 1, j + 1), lay.sd2(i, j + 1)
            C = lay.centre(i, j)
            if i + 1 < a:
                strips += [[A, B, C, lay.centre(i + 1, j), D], [C, D, E]]
            else:
                strips.append([A, B, C, D, E])
    return [np.array(strip, np.int64) for strip in strips]


def sd2_chords(f) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The vertices that stage 4 places on a chord of the mesh rather than on the surface
    (kernels/patterns/sd2.h pattern_chord_point; kernels/stages/rows.h chord_position): the tie
    zone's centres.  (vertices (K,), start (K,), end (K,) local numbers, mu (K,) float32): vertex k
    goes to ``P[start] + mu (P[end] - P[start])``, P the other vertices' positions, start its row's
    vertex (i, j+1) and end (i, j).  A centre on the surface stood off its row's chord by up to the
    row's chord error, a fin that moved the mesh by most of the error at low factors whenever lam
    moved (docs/sd2.md section 5); on the chord it only moves its quad's fan between the quad's two
    diagonals.  Empty outside the zone."""
    lay = _Layout(f)
    if lay.shape != "sd2" or not lay.zone:
        return np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0, np.float32)
    a, b = lay.n[lay.tip], lay.n[(lay.tip + 1) % 3]
    pairs = [(i, j) for i in range(1, a) for j in range(b)]
    return (np.array([lay.centre(i, j) for i, j in pairs], np.int64),
            np.array([lay.sd2(i, j + 1) for i, j in pairs], np.int64),
            np.array([lay.sd2(i, j) for i, j in pairs], np.int64),
            np.full(len(pairs), _centre_mu(lay.w, lay.lam), np.float32))


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
        if not lay.zone:
            uv += [_point(c, t[i], s[j])[:2] for i in range(1, a) for j in range(1, b)]
            for j in range(b):
                strip = [lay.sd2(0, 0)]
                for i in range(1, a + 1):
                    strip += [lay.sd2(i, j), lay.sd2(i, j + 1)]
                strips.append(np.array(strip, np.int64))
        else:
            # the tie zone: vertices pulled towards the tie configuration, and each quad's centre
            # on its upper row, slid from corner (i, j+1) (the radial pattern's diagonal) towards
            # (i, j) (the other diagonal, partner c+2) by mu = (1 - w)(1 - lam)
            z, mu = _zone(lay)
            keep = np.float32(1.0) - mu
            uv += [_row_point(c, t[i], z[i][j])[:2] for i in range(1, a) for j in range(1, b)]
            uv += [_row_point(c, t[i], np.float32(np.float32(keep * z[i][j + 1]) + np.float32(mu * z[i][j])))[:2]
                   for i in range(1, a) for j in range(b)]
            strips += _zone_strips(lay)
    elif lay.shape == "grid":
        n = lay.n[0]
        t = locations(lay.f[0])
        if sd2_hint(f) is None:
            uv += [_point(0, t[i], np.float32(j) / np.float32(i))[:2] for i in range(2, n) for j in range(1, i)]
        else:  # the tie configuration: corner g+1's weight at the edges' points (docs/sd2.md 5)
            uv += [_row_point(lay.tip, t[i], np.float32(t[i] - t[i - j]))[:2] for i in range(2, n) for j in range(1, i)]
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
        if lay.zone:
            return a * (b + 1) + 1 + (a - 1) * b, b * (4 * a - 3), b * (10 * a - 9)
        return a * (b + 1) + 1, b * (2 * a - 1), b * (2 * a + 2)
    if lay.shape == "grid":
        n = lay.n[0]
        return (n + 1) * (n + 2) // 2, n * n, n * n + 3 * n
    uv, triangles = tri_pattern(lay.n)
    return len(uv), len(triangles), 4 * len(triangles)


SD2 = Pattern("sd2", "tri", 3, "patterns/sd2.h", sd2_pattern, primitive="strips", fixed_point=True,
              chords=sd2_chords)
