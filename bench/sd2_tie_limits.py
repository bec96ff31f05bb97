"""Issue 13, session 5: what the "Third pass" argument of docs/sd2.md section 5 does and does not
forbid, checked combinatorially on the SD-2 fan (NumPy only, no device).

(A) Native collapse.  The fan with tip c (a = b = n, the paper's strips, no centres) mapped onto the
    lattice of the grid (labels (i_0, i_1, i_2), sum n) by M_c: vertex (i, j) -> corner c index n - i,
    corner c+1 index n - j (clamped onto edge (c, c+1) when i + j < n).  Checked: every fan triangle
    with three distinct labels is a grid triangle, each grid triangle is hit exactly once with the
    same orientation, and every other fan triangle has two equal labels whose pair is a lattice edge
    (so it is degenerate in 3D too: no fins).  Labels only, so this holds for ANY positions of the
    grid's points: fan c reaches every grid configuration without centres, whichever corner ties.
    The same map with partner c+2 (vertex (i, j) -> corner c index n - i, corner c+2 index j) is
    also checked: it needs the other diagonal (today's centres), so it fails here.
(B) Births.  A configuration reached by fan c with its rows and columns on the edges' fractional
    points (location-based, continuous where a factor crosses an odd number) is a product in the
    indices of corners c and c+1: as F -> m+ (odd m) lattice point p of n = m + 2 tends to the
    m-lattice point with indices (p_c', p_{c+1}') (k' the merged index of fractional_odd).  Counted:
    lattice points where the limits for two tips differ.  If any, no single grid configuration is
    such a product for both fans of a wall, so one of them must reach it with the other diagonal
    (the flip that pops near a triple point, docs/sd2.md "Third pass").

(C) Fold-over of the zone's blend w * radial + (1 - w) * C(native label), a = b = n, C the tie
    configuration of a labelled pair (the same for every tip), float64 domain weights: the smallest
    signed area over tips, pairs, real factors F (step --fold-step from 1.05) and w in 0..1.

(D) The plateau of 1, exhaustively (n = 3, F -> 1+).  Every assignment of the fan's 4 interior
    vertices (tip 0, a = b = 3, no centres) to the 10 lattice labels that collapses it onto the grid;
    and, at the base's birth (G -> 1+, the fan with b = 1 has no interior vertex), every assignment
    to the b = 1 fan's 7 vertices that collapses onto that fan.  As F -> 1+ each ring label tends to
    a corner and the grid's centre (1,1,1) to some corner k; a vertex that must go from near one
    corner to near another while F - 1 -> 0 crosses the patch (by about the error at factor 1).
    Printed: for each k, how many wall collapses keep every vertex at its birth corner.

    python bench/sd2_tie_limits.py [--max-n 15] [--max-m 15] [--max-f 15] [--fold-step 0.1]
"""
from __future__ import annotations

import argparse
import itertools

import numpy as np

from cltess.patterns.fractional import locations, odd_segments, to_fixed


def fan_triangles(n: int):
    """The paper's fan (a = b = n) as (i, j) index triples, counter-clockwise as sd2_pattern emits
    them (strip [tip, (1,j), (1,j+1), ..., (n,j), (n,j+1)], odd triangles swapped)."""
    triangles = []
    for j in range(n):
        strip = [(0, 0)] + [v for i in range(1, n + 1) for v in ((i, j), (i, j + 1))]
        for k in range(len(strip) - 2):
            a, b, c = strip[k], strip[k + 1], strip[k + 2]
            triangles.append((b, a, c) if k % 2 else (a, b, c))
    return triangles


def native_label(c: int, n: int, i: int, j: int) -> tuple:
    """Lattice label of fan-c vertex (i, j) under the native map (partner c+1)."""
    idx = [0, 0, 0]
    idx[c] = n - i
    if i + j >= n:
        idx[(c + 1) % 3], idx[(c + 2) % 3] = n - j, i + j - n
    else:
        idx[(c + 1) % 3] = i
    return tuple(idx)


def flipped_label(c: int, n: int, i: int, j: int) -> tuple:
    """Lattice label of fan-c vertex (i, j) with partner c+2 (today's lam = 0 map)."""
    idx = [0, 0, 0]
    idx[c] = n - i
    if j < i:
        idx[(c + 1) % 3], idx[(c + 2) % 3] = i - j, j
    else:
        idx[(c + 2) % 3] = i
    return tuple(idx)


def grid_triangles(n: int) -> set:
    """The lattice's n^2 triangles (up: i2 >= 1, down: i2 >= 2 below), each as a rotation-normalised
    counter-clockwise label triple in (u, v) = (corner 1, corner 2 weights)."""
    out = set()
    for i0 in range(n + 1):
        for i1 in range(n + 1 - i0):
            i2 = n - i0 - i1
            if i2 >= 1:  # up triangle (i0, i1, i2) -> (i0+1, i1, i2-1) -> (i0, i1+1, i2-1)
                out.add(_norm(((i0, i1, i2), (i0 + 1, i1, i2 - 1), (i0, i1 + 1, i2 - 1))))
    # down triangles: (i0, i1+1, i2-1), (i0+1, i1, i2-1), (i0+1, i1+1, i2-2)
    for i0 in range(n + 1):
        for i1 in range(n + 1 - i0):
            i2 = n - i0 - i1
            if i2 >= 2:
                out.add(_norm(((i0 + 1, i1, i2 - 1), (i0 + 1, i1 + 1, i2 - 2), (i0, i1 + 1, i2 - 1))))
    return out


def _xy(label, n):
    """Domain (u, v) = (weight of corner 1, weight of corner 2) of a regular-lattice label."""
    return np.array([label[1], label[2]], float) / n


def _orient(tri, n):
    a, b, c = (_xy(t, n) for t in tri)
    return float((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))


def _norm(tri):
    """The triple rotated to start at its smallest label (orientation kept)."""
    k = tri.index(min(tri))
    return tri[k:] + tri[:k]


def check_collapse(label, c: int, n: int) -> tuple[bool, str]:
    grid = grid_triangles(n)
    hit = {}
    for tri in fan_triangles(n):
        labels = tuple(label(c, n, i, j) for i, j in tri)
        distinct = set(labels)
        if len(distinct) == 3:
            if _orient(labels, n) <= 0:
                return False, f"fan triangle {tri} -> {labels} not counter-clockwise"
            key = _norm(labels)
            if key not in grid:
                return False, f"fan triangle {tri} -> {labels} is no grid triangle"
            hit[key] = hit.get(key, 0) + 1
        elif len(distinct) == 2:
            p, q = sorted(distinct)
            if sum(abs(x - y) for x, y in zip(p, q)) != 2:
                return False, f"fan triangle {tri} collapses onto {p}-{q}, no lattice edge (a 3D fin/chord)"
    if set(hit) != grid or any(v != 1 for v in hit.values()):
        return False, f"grid covered {len(hit)}/{len(grid)} distinct, max multiplicity {max(hit.values())}"
    return True, "ok"


def merged_index(m: int) -> np.ndarray:
    """k' of each point k of an edge of factor m + 1/65536 (n = m + 2): the m-lattice point it tends to."""
    x = locations(int(to_fixed(m)) + 1).astype(np.float64)
    return np.rint(x * m).astype(int)


def birth_mismatches(m: int) -> dict:
    """Lattice points (n = m + 2) whose limits as F -> m+ differ between the product maps of tips."""
    km = merged_index(m)
    n = m + 2
    limits = {}
    for i0 in range(n + 1):
        for i1 in range(n + 1 - i0):
            p = (i0, i1, n - i0 - i1)
            lim = []
            for c in range(3):
                q = [None, None, None]
                q[c], q[(c + 1) % 3] = km[p[c]], km[p[(c + 1) % 3]]
                q[(c + 2) % 3] = m - q[c] - q[(c + 1) % 3]
                lim.append(tuple(q))
            limits[p] = lim
    total = len(limits)
    wall = {c: sum(1 for v in limits.values() if v[c] != v[(c + 1) % 3]) for c in range(3)}
    outside = sum(1 for v in limits.values() if min(min(q) for q in v) < 0)
    return {"points": total, "tips c, c+1 differ": wall, "a limit outside the triangle": outside}


def blend_min_area(factor: float, pair: tuple, c: int, steps: int = 21) -> tuple[float, float]:
    """(smallest signed area, its w) of fan c's zone blend towards the labelled tie configuration
    ``pair`` through the native map, at real factor ``factor`` on all three edges."""
    fixed = int(to_fixed(factor))
    x, n = locations(fixed).astype(np.float64), odd_segments(fixed)
    third = 3 - pair[0] - pair[1]

    def grid_point(label):
        w = np.zeros(3)
        w[pair[0]], w[pair[1]] = x[label[pair[0]]], x[label[pair[1]]]
        w[third] = 1.0 - w[pair[0]] - w[pair[1]]
        return w

    def radial_point(i, j):
        w = np.zeros(3)
        w[c], w[(c + 1) % 3], w[(c + 2) % 3] = 1.0 - x[i], x[i] * (1.0 - x[j]), x[i] * x[j]
        return w

    verts = {(i, j): (radial_point(i, j), grid_point(native_label(c, n, i, j)))
             for i in range(n + 1) for j in range(n + 1)}
    best = (np.inf, 0.0)
    for w in np.linspace(0.0, 1.0, steps):
        for tri in fan_triangles(n):
            p = [w * verts[v][0] + (1.0 - w) * verts[v][1] for v in tri]
            area = (p[1][1] - p[0][1]) * (p[2][2] - p[0][2]) - (p[1][2] - p[0][2]) * (p[2][1] - p[0][1])
            best = min(best, (float(area), float(w)))
    return best


def _collapses(positions: dict, ring: dict, area, allowed_edges, target) -> bool:
    """Whether the fan of a = b = 3 with its interior vertices at `positions` (the rest at `ring`)
    is the triangulation `target` plus triangles with two equal vertices on an allowed edge."""
    hit = {}
    for tri in fan_triangles(3):
        lab = tuple(positions[v] if v in positions else ring[v] for v in tri)
        distinct = set(lab)
        if len(distinct) == 3:
            if area(lab) <= 0 or _norm(lab) not in target:
                return False
            hit[_norm(lab)] = hit.get(_norm(lab), 0) + 1
        elif len(distinct) == 2 and frozenset(distinct) not in allowed_edges:
            return False
    return set(hit) == target and all(v == 1 for v in hit.values())


def plateau_of_one() -> dict:
    """(D): {k: wall collapses of fan tip 0 that keep every interior vertex at its birth corner when
    the grid's centre tends to corner k}, with the counts of wall and birth collapses."""
    inner = [(1, 1), (1, 2), (2, 1), (2, 2)]
    n = 3
    # the wall: the n = 3 lattice (labels), fan vertices outside `inner` on their ring labels
    labels = [(i0, i1, n - i0 - i1) for i0 in range(n + 1) for i1 in range(n + 1 - i0)]
    grid = grid_triangles(n)
    ring_labels = {(i, j): native_label(0, n, i, j) for i in range(n + 1) for j in range(n + 1)}
    lattice_edges = {frozenset((p, q)) for p in labels for q in labels
                     if sum(abs(a - b) for a, b in zip(p, q)) == 2}
    walls = [dict(zip(inner, ch)) for ch in itertools.product(labels, repeat=4)
             if _collapses(dict(zip(inner, ch)), ring_labels, lambda t: _orient(t, n), lattice_edges, grid)]
    # the birth: G = 1+, base points 1, 2 on corners 1, 2; F = 1.5 (X(1) = 1/12) for the areas
    x1, x2 = 1.0 / 12.0, 11.0 / 12.0
    where = {"c0": (0, 0), "r1": (x1, 0), "r2": (x2, 0), "c1": (1, 0), "r1'": (0, x1), "r2'": (0, x2), "c2": (0, 1)}
    corner_of = {"c0": 0, "r1": 0, "r1'": 0, "r2": 1, "c1": 1, "r2'": 2, "c2": 2}
    ring = {(0, j): "c0" for j in range(4)}
    ring.update({(1, 0): "r1", (2, 0): "r2", (3, 0): "c1", (3, 1): "c1", (3, 2): "c2", (3, 3): "c2",
                 (1, 3): "r1'", (2, 3): "r2'"})
    strip = ["c0", "r1", "r1'", "r2", "r2'", "c1", "c2"]
    coarse = [(strip[k + 1], strip[k], strip[k + 2]) if k % 2 else tuple(strip[k:k + 3]) for k in range(5)]

    def area(t):
        (ax, ay), (bx, by), (cx, cy) = (where[v] for v in t)
        return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)

    coarse_edges = {frozenset(e) for t in coarse for e in ((t[0], t[1]), (t[1], t[2]), (t[0], t[2]))}
    births = [dict(zip(inner, ch)) for ch in itertools.product(where, repeat=4)
              if _collapses(dict(zip(inner, ch)), ring, area, coarse_edges, {_norm(t) for t in coarse})]

    def corner(label, k):
        return k if label == (1, 1, 1) else max(range(3), key=lambda q: label[q])

    keep = {k: sum(1 for w in walls if any(all(corner(w[v], k) == corner_of[b[v]] for v in inner) for b in births))
            for k in range(3)}
    return {"wall collapses": len(walls), "birth collapses": len(births),
            "vertex (2,2) at birth": sorted({b[(2, 2)] for b in births}), "kept, by centre corner k": keep}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--max-n", type=int, default=15)
    parser.add_argument("--max-m", type=int, default=15)
    parser.add_argument("--max-f", type=float, default=15.0)
    parser.add_argument("--fold-step", type=float, default=0.1)
    args = parser.parse_args(argv)
    print("(A) fan c onto the grid lattice, labels only (any grid positions)")
    for name, label in (("native, partner c+1", native_label), ("partner c+2, no centres", flipped_label)):
        bad = [(c, n, why) for n in range(1, args.max_n + 1) for c in range(3)
               for ok, why in [check_collapse(label, c, n)] if not ok]
        print(f"  {name}: {3 * args.max_n - len(bad)} of {3 * args.max_n} (c, n) valid collapses"
              + (f"; first failure c={bad[0][0]} n={bad[0][1]}: {bad[0][2]}" if bad else ""))
    print("(B) births at odd m (F -> m+): lattice points of n = m + 2 whose product limits differ")
    for m in range(1, args.max_m + 1, 2):
        print(f"  m = {m}: {birth_mismatches(m)}")
    print("(C) zone blend radial -> C (native map), smallest signed area (negative: fold-over)")
    factors = np.arange(1.05, args.max_f, args.fold_step)
    for pair in ((0, 1), (1, 2), (2, 0)):
        for c in range(3):
            area, w, factor = min(blend_min_area(f, pair, c) + (float(f),) for f in factors)
            print(f"  C = tie of corners {pair}, tip {c}: {area:.3g} (F = {factor:.2f}, w = {w:.2f})")
    print("(D) the plateau of 1, fan tip 0 without centres, n = 3 as F -> 1+ and its birth at G -> 1+")
    print(f"  {plateau_of_one()}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
