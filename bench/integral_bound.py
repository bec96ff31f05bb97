"""How far the integral form of the interpolation remainder could take the rational bound
(issue 9: the measured ratio floor at coarse eps).  An experiment, not the engine's bound.

For linear interpolation on a triangle with corners x_i, barycentric coordinates l_i(x) and
h_i = x_i - x (docs/rational-bound.md, Lemma 1's proof):

    p(x) - sum_i l_i p(x_i) = -sum_i l_i int_0^1 (1 - t) D^2 p(x + t h_i)[h_i, h_i] dt.

With a piecewise-constant majorant of |p_uu|, |p_uv|, |p_vv| over an S x S grid of subpatches
(the hull bound of docs/rational-bound.md, Lemma 2, applied to each subpatch's (9, 9) nets,
from de Casteljau subdivision of N_ab and w^3) and upper sums (the triangle cut into K^2
sub-triangles P, [0, 1] into T intervals; on P x [t0, t1] each factor at its max: l_i at P's
corners, |h_iu|, |h_iv| at P's corners, the majorant over the subpatches meeting the box of the
six points (1 - t) q + t x_i), the sum is a rigorous upper bound of |p - l| on each sub-triangle
(up to float64 rounding).  The (1 - t) weight discounts a curvature spike at a corner x_i.

A cell passes cheaply where Lemma 1 with the majorant over the subpatches it meets (its own
local sups) is already <= eps; only the others take the upper sums.

For each of bench/occ_compare.py's 20 random rational patches and each eps this searches the
(m, n) grids with m <= today's factors (fewest m n whose bound over all cells, both diagonals of
each cell, is <= eps) and measures the error of that uniform grid (two triangles per cell,
float64, 28 samples per triangle).  It covers the uniform core grid of an isolated patch, NOT the
transition triangles of the engine's pattern or crack-free raised edge factors: that is what
stands between this and a bound the engine can use (docs/rational-bound.md).

    python bench/integral_bound.py [--subpatches 64] [--k 6] [--t 8] [--patches 0-19]
"""
from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from occ_compare import diagonal, random_rational_patches  # noqa: E402

from cltess.criteria.integral import numerator_nets  # noqa: E402  (the engine's since issue 9, session 3)
from cltess.criteria.zheng_sederberg import zs_constant_steps, zs_constants  # noqa: E402
from cltess.surfaces.bezier import surface_points  # noqa: E402


def halve(nets: np.ndarray, axis: int) -> np.ndarray:
    """de Casteljau at 1/2 along ``axis`` of every net: the pieces' nets, stacked on a new
    leading axis of twice the length of the old one (left, right interleaved in order)."""
    c = np.moveaxis(nets, axis, -1)
    left, right = [c[..., 0]], [c[..., -1]]
    while c.shape[-1] > 1:
        c = (c[..., :-1] + c[..., 1:]) / 2
        left.append(c[..., 0])
        right.append(c[..., -1])
    left, right = np.stack(left, -1), np.stack(right[::-1], -1)
    pieces = np.stack([left, right], axis=1)  # (n, 2, ..., degree + 1)
    pieces = pieces.reshape((-1,) + pieces.shape[2:])
    return np.moveaxis(pieces, -1, axis)


def subpatch_majorants(patch: np.ndarray, levels: int) -> np.ndarray:
    """(3, S, S) [which, v piece, u piece], S = 2^levels: max_k |N_ab,k| / W_k of each subpatch's
    nets (Lemma 2 on the subpatch: |p_ab| <= that on it)."""
    numerators, cube = numerator_nets(patch)
    nets = np.concatenate([numerators.reshape(10, 10, 9), cube[..., None]], axis=-1)[None, None]
    # nets: (S_v, S_u, 10 [j], 10 [i], 10 components)
    for _ in range(levels):
        s_v, s_u = nets.shape[:2]
        flat = nets.reshape((s_v * s_u,) + nets.shape[2:])
        flat = halve(flat, 2)  # along i (u): (2 s_v s_u, ...)
        flat = flat.reshape(s_v, s_u, 2, *flat.shape[1:])
        nets = flat.reshape(s_v, 2 * s_u, *flat.shape[3:])
        flat = np.moveaxis(nets, 0, 1).reshape((2 * s_u * s_v,) + nets.shape[2:])
        flat = halve(flat, 1)  # along j (v)
        flat = flat.reshape(2 * s_u, s_v, 2, *flat.shape[1:]).reshape(2 * s_u, 2 * s_v, *flat.shape[1:])
        nets = np.moveaxis(flat, 0, 1)
    weights = nets[..., 9]
    assert (weights > 0).all()
    values = np.linalg.norm(nets[..., :9].reshape(nets.shape[:4] + (3, 3)), axis=-1) / weights[..., None]
    return values.max(axis=(2, 3)).transpose(2, 0, 1)  # (3, S_v, S_u)


class RangeMax:
    """2-D sparse table: the max of a (3, S, S) array over index rectangles in O(1)."""

    def __init__(self, values: np.ndarray):
        self.size = values.shape[-1]
        self.levels = int(math.log2(self.size)) + 1
        self.table = {}
        rows = [values]
        for ky in range(1, self.levels):
            prev, half = rows[-1], 1 << (ky - 1)
            rows.append(np.maximum(prev[:, :-half], prev[:, half:]))
        for ky, row in enumerate(rows):
            cols = [row]
            for kx in range(1, self.levels):
                prev, half = cols[-1], 1 << (kx - 1)
                cols.append(np.maximum(prev[:, :, :-half], prev[:, :, half:]))
            for kx, col in enumerate(cols):
                self.table[ky, kx] = col

    def query(self, u_lo, u_hi, v_lo, v_hi) -> np.ndarray:
        """(3, Q): max over the subpatches meeting each box [u_lo, u_hi] x [v_lo, v_hi]."""
        s = self.size
        i0 = np.clip(np.floor(u_lo * s), 0, s - 1).astype(np.int64)
        i1 = np.clip(np.floor(u_hi * s), 0, s - 1).astype(np.int64)
        j0 = np.clip(np.floor(v_lo * s), 0, s - 1).astype(np.int64)
        j1 = np.clip(np.floor(v_hi * s), 0, s - 1).astype(np.int64)
        kx = np.floor(np.log2(i1 - i0 + 1)).astype(np.int64)
        ky = np.floor(np.log2(j1 - j0 + 1)).astype(np.int64)
        out = np.zeros((3, len(i0)))
        for key in set(zip(ky.tolist(), kx.tolist())):
            sel = (ky == key[0]) & (kx == key[1])
            t = self.table[key]
            a0, a1, b0, b1 = i0[sel], i1[sel] - (1 << key[1]) + 1, j0[sel], j1[sel] - (1 << key[0]) + 1
            out[:, sel] = np.maximum(np.maximum(t[:, b0, a0], t[:, b0, a1]), np.maximum(t[:, b1, a0], t[:, b1, a1]))
        return out


def sub_triangles(k: int) -> np.ndarray:
    """(k^2, 3, 3): barycentric corners of the k^2 sub-triangles of a triangle."""
    out = []
    for i in range(k):
        for j in range(k - i):
            a = np.array([[i, j, k - i - j], [i + 1, j, k - i - j - 1], [i, j + 1, k - i - j - 1]], float)
            out.append(a / k)
            if i + j < k - 1:
                b = np.array([[i + 1, j, k - i - j - 1], [i, j + 1, k - i - j - 1], [i + 1, j + 1, k - i - j - 2]], float)
                out.append(b / k)
    return np.array(out)


def triangle_bounds(corners: np.ndarray, table: RangeMax, k: int, t_count: int) -> np.ndarray:
    """(N,) upper bounds of sup |p - l| on N triangles corners (N, 3, 2) in (u, v)."""
    subs = sub_triangles(k)  # (Q, 3 corners, 3 bary)
    q = np.einsum("qab,nbc->nqac", subs, corners)  # (N, Q, 3 corners of P, 2)
    t_edges = np.linspace(0.0, 1.0, t_count + 1)
    weight = [(t1 - t0) - (t1 * t1 - t0 * t0) / 2 for t0, t1 in zip(t_edges[:-1], t_edges[1:])]  # int (1 - t)
    total = np.zeros(q.shape[:2])
    for i in range(3):
        lam = subs[:, :, i].max(axis=1)  # (Q,) max of l_i over P's corners
        x_i = corners[:, None, None, i, :]  # (N, 1, 1, 2)
        h = np.abs(x_i - q).max(axis=2)  # (N, Q, 2)
        quad_u, quad_v = h[..., 0] ** 2, h[..., 1] ** 2
        cross = 2 * h[..., 0] * h[..., 1]
        for t0, t1, wt in zip(t_edges[:-1], t_edges[1:], weight):
            pts = np.concatenate([(1 - t0) * q + t0 * x_i, (1 - t1) * q + t1 * x_i], axis=2)  # (N, Q, 6, 2)
            # widened by 1e-12 so that rounding of the corners cannot drop a subpatch the box meets
            lo, hi = pts.min(axis=2).reshape(-1, 2) - 1e-12, pts.max(axis=2).reshape(-1, 2) + 1e-12
            m = table.query(lo[:, 0], hi[:, 0], lo[:, 1], hi[:, 1]).reshape((3,) + q.shape[:2])
            total += lam * wt * (m[0] * quad_u + m[1] * cross + m[2] * quad_v)
    return total.max(axis=1)


def grid_triangles(m: int, n: int) -> np.ndarray:
    """(4 m n, 3, 2): both diagonals' two triangles of every cell of the uniform m x n grid."""
    i, j = np.meshgrid(np.arange(m), np.arange(n), indexing="ij")
    u0, v0 = (i / m).ravel(), (j / n).ravel()
    u1, v1 = ((i + 1) / m).ravel(), ((j + 1) / n).ravel()
    a, b, c, d = (np.stack(p, -1) for p in ((u0, v0), (u1, v0), (u1, v1), (u0, v1)))
    return np.concatenate([np.stack(t, 1) for t in ((a, b, c), (a, c, d), (a, b, d), (b, c, d))])


def grid_bound(m: int, n: int, table: RangeMax, k: int, t_count: int, eps: float) -> float:
    """Upper bound of sup |p - l| over every triangle of the m x n grid (either diagonal), or
    early-exit with a value > eps."""
    tri = grid_triangles(m, n)
    lo, hi = tri.min(axis=1) - 1e-12, tri.max(axis=1) + 1e-12
    local = table.query(lo[:, 0], hi[:, 0], lo[:, 1], hi[:, 1])
    du, dv = 1.0 / m, 1.0 / n
    lemma1 = (local[0] * du * du + 2 * local[1] * du * dv + local[2] * dv * dv) / 8  # local Lemma 1
    hard = lemma1 > eps
    worst = float(lemma1[~hard].max()) if (~hard).any() else 0.0
    if hard.any():
        for start in range(0, int(hard.sum()), 64):
            b = triangle_bounds(tri[hard][start:start + 64], table, k, t_count)
            worst = max(worst, float(b.max()))
            if worst > eps:
                return worst
    return worst


def measured(patch: np.ndarray, m: int, n: int) -> float:
    """Worst |p - l| over the uniform m x n grid, one diagonal (a, b, c), (a, c, d), float64."""
    tri = grid_triangles(m, n)[:2 * m * n]
    order = 6
    bary = np.array([(a, b, order - a - b) for a in range(order + 1) for b in range(order + 1 - a)], float) / order
    worst = 0.0
    for start in range(0, len(tri), 4000):
        t = tri[start:start + 4000]
        uv_c = t.reshape(-1, 2)
        corners = surface_points(patch[None], np.zeros(len(uv_c), int), uv_c[:, 0], uv_c[:, 1]).reshape(len(t), 3, 3)
        uv = np.einsum("sk,tkc->tsc", bary, t).reshape(-1, 2)
        exact = surface_points(patch[None], np.zeros(len(uv), int), uv[:, 0], uv[:, 1]).reshape(len(t), -1, 3)
        lin = np.einsum("sk,tkc->tsc", bary, corners)
        worst = max(worst, float(np.linalg.norm(exact - lin, axis=-1).max()))
    return worst


def search(table: RangeMax, m0: int, n0: int, k: int, t_count: int, eps: float):
    """Fewest-triangle (m, n) <= (m0, n0) whose grid bound is <= eps: for each m, the smallest n
    by bisection (the bound is checked at the n returned, so monotonicity is not assumed)."""
    best = (m0, n0)
    for m in range(1, m0 + 1):
        if m * 1 >= best[0] * best[1]:
            break
        lo, hi = 1, min(n0, (best[0] * best[1] - 1) // m)
        if hi < 1 or grid_bound(m, hi, table, k, t_count, eps) > eps:
            continue
        while lo < hi:
            mid = (lo + hi) // 2
            if grid_bound(m, mid, table, k, t_count, eps) <= eps:
                hi = mid
            else:
                lo = mid + 1
        if grid_bound(m, hi, table, k, t_count, eps) <= eps and m * hi < best[0] * best[1]:
            best = (m, hi)
    return best


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--subpatches-log2", type=int, default=6, help="S = 2^this subpatches per side")
    parser.add_argument("--k", type=int, default=6, help="sub-triangles per side of a triangle")
    parser.add_argument("--t", type=int, default=8, help="intervals of t")
    parser.add_argument("--eps", type=float, nargs="+", default=[3e-2, 1e-2, 3e-3, 1e-3])
    parser.add_argument("--patches", default="0-19")
    args = parser.parse_args(argv)
    patches = random_rational_patches()
    size = diagonal(patches)
    first, last = (int(x) for x in args.patches.split("-"))
    rows = {}
    for index in range(first, last + 1):
        patch = patches[index]
        start = time.perf_counter()
        table = RangeMax(subpatch_majorants(patch, args.subpatches_log2))
        prep = time.perf_counter() - start
        constants = zs_constants(patch)
        for rel in args.eps:
            eps = rel * size
            inv = zs_constant_steps(constants, eps)
            m0, n0 = (max(1, math.ceil(x)) for x in inv)
            start = time.perf_counter()
            m, n = search(table, m0, n0, args.k, args.t, eps)
            took = time.perf_counter() - start
            before, after = measured(patch, m0, n0) / eps, measured(patch, m, n) / eps
            rows.setdefault(rel, []).append((index, m0, n0, before, m, n, after, prep + took))
            print(f"patch {index:2d} eps {rel:g}: today {m0} x {n0} ratio {before:.3f} -> integral {m} x {n} "
                  f"ratio {after:.3f} ({prep + took:.1f} s)", flush=True)
    print("\n| eps / diag | cells today | cells integral | worst ratio today | worst ratio integral | s per patch |")
    print("|---|---|---|---|---|---|")
    for rel, r in rows.items():
        print(f"| {rel:g} | {sum(x[1] * x[2] for x in r):,} | {sum(x[4] * x[5] for x in r):,} | "
              f"{max(x[3] for x in r):.3f} | {max(x[6] for x in r):.3f} | {np.mean([x[7] for x in r]):.1f} |")


if __name__ == "__main__":
    main()
