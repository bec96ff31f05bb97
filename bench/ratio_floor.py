"""Where the slack of the rational bound is at coarse eps (issue 9: measured ratio floor).

On bench/occ_compare.py's 20 random rational patches (weights 0.2 to 5) the worst measured
|p - l| / eps is 0.18 at eps = 3e-2 of the diagonal.  This splits the gap, for the patches that
set the worst ratio, into its three possible sources:

1. the constants: the hull bounds M_ab (docs/rational-bound.md, Lemma 2) against the true
   sup |p_ab| over the patch (dense float64 sampling, 201 x 201);
2. rounding: the factors against the unrounded 1/du, 1/dv;
3. the form of the bound: on a uniform grid at the patch's factors (two triangles per cell),
   the measured error of the worst cell against Lemma 1 evaluated with that cell's own true
   sup of |p_uu|, |p_uv|, |p_vv| (25 x 25 samples per cell), i.e. the best any bound built from
   sups of second derivatives over a triangle's box can do.

    python bench/ratio_floor.py [--device pocl]
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from occ_compare import diagonal, random_rational_patches  # noqa: E402


def second_derivatives(patch, u, v):
    """(p_uu, p_uv, p_vv) of p = X / w at (u, v), float64, by the quotient rule."""
    def basis(t, order):
        s = 1 - t
        return [np.stack([s ** 3, 3 * t * s * s, 3 * t * t * s, t ** 3], -1),
                np.stack([-3 * s * s, 3 * s * s - 6 * t * s, 6 * t * s - 3 * t * t, 3 * t * t], -1),
                np.stack([6 * s, -12 * s + 6 * t, 6 * s - 12 * t, 6 * t], -1)][order]

    def at(du, dv):
        return np.einsum("nj,ni,jic->nc", basis(v, dv), basis(u, du), patch)

    s, s_u, s_v = at(0, 0), at(1, 0), at(0, 1)
    w, p = s[:, 3:], s[:, :3] / s[:, 3:]
    p_u, p_v = (s_u[:, :3] - s_u[:, 3:] * p) / w, (s_v[:, :3] - s_v[:, 3:] * p) / w
    s_uu, s_uv, s_vv = at(2, 0), at(1, 1), at(0, 2)
    return ((s_uu[:, :3] - s_uu[:, 3:] * p - 2 * s_u[:, 3:] * p_u) / w,
            (s_uv[:, :3] - s_uv[:, 3:] * p - s_u[:, 3:] * p_v - s_v[:, 3:] * p_u) / w,
            (s_vv[:, :3] - s_vv[:, 3:] * p - 2 * s_v[:, 3:] * p_v) / w)


def true_sups(patch, u, v) -> np.ndarray:
    return np.array([np.linalg.norm(d, axis=1).max() for d in second_derivatives(patch, u, v)])


def worst_cell(patch, m: int, n: int, eps: float):
    """(measured worst |p - l| / eps over a uniform m x n grid of two-triangle cells, that cell's
    local Lemma 1 / eps, the cell (i, j))."""
    from cltess.surfaces.bezier import surface_points

    one = patch[None]
    s = np.linspace(0, 1, 13)
    a, b = (x.ravel() for x in np.meshgrid(s, s))
    keep = a + b <= 1 + 1e-12
    lam = np.stack([1 - a[keep] - b[keep], a[keep], b[keep]], 1)
    g = np.linspace(0, 1, 25)
    best = (-1.0, 0.0, None)
    for j in range(n):
        for i in range(m):
            corners = np.array([[i / m, j / n], [(i + 1) / m, j / n], [(i + 1) / m, (j + 1) / n], [i / m, (j + 1) / n]])
            points = surface_points(one, np.zeros(4, int), corners[:, 0], corners[:, 1])
            error = 0.0
            for tri in ([0, 1, 2], [0, 2, 3]):
                uv, linear = lam @ corners[tri], lam @ points[tri]
                exact = surface_points(one, np.zeros(len(uv), int), uv[:, 0], uv[:, 1])
                error = max(error, float(np.linalg.norm(exact - linear, axis=1).max()))
            if error / eps > best[0]:
                uu, vv = (x.ravel() for x in np.meshgrid(corners[0, 0] + g / m, corners[0, 1] + g / n))
                m_uu, m_uv, m_vv = true_sups(patch, uu, vv)
                local = (m_uu / m ** 2 + 2 * m_uv / (m * n) + m_vv / n ** 2) / 8
                best = (error / eps, local / eps, (i, j))
    return best


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--device", default=None)
    parser.add_argument("--relative-eps", type=float, nargs="+", default=[3e-2, 1e-2])
    parser.add_argument("--patches", type=int, default=4, help="how many of the worst patches to analyse")
    args = parser.parse_args(argv)

    from cltess.criteria.zheng_sederberg import second_derivative_hull, zs_inverse_steps
    from cltess.pipeline import Tessellator
    from cltess.scene import Scene
    from cltess.surfaces.bezier import surface_points

    patches = random_rational_patches()
    size = diagonal(patches)
    tessellator = Tessellator(args.device)
    order = 6
    ij = [(i, j) for i in range(order + 1) for j in range(order + 1 - i)]
    bary = np.array([(i, j, order - i - j) for i, j in ij], float) / order
    grid = np.linspace(0, 1, 201)
    u, v = (x.ravel() for x in np.meshgrid(grid, grid))
    print("| eps / diag | patch | measured ratio | 1/du, 1/dv | factors | hull M / true sup (uu, uv, vv) | "
          "worst cell: measured / its own Lemma 1 (in eps) |")
    print("|---|---|---|---|---|---|---|")
    for relative in args.relative_eps:
        eps = relative * size
        tess = tessellator.tessellate(Scene(patches, np.zeros(len(patches), np.int32)), eps=eps, max_factor=4096)
        triangles = tess.triangles
        points = np.einsum("sk,tkc->tsc", bary, tess.positions[triangles].astype(float)).reshape(-1, 3)
        params = np.einsum("sk,tkc->tsc", bary, tess.uv[triangles].astype(float)).reshape(-1, 2)
        ids = np.repeat(tess.patch_ids[triangles[:, 0]], len(bary))
        error = np.linalg.norm(surface_points(patches, ids, params[:, 0], params[:, 1]) - points, axis=1) / eps
        per_patch = np.zeros(len(patches))
        np.maximum.at(per_patch, ids, error)
        for p in np.argsort(-per_patch)[:args.patches]:
            hull = np.linalg.norm(second_derivative_hull(patches[p]), axis=-1).max(axis=0)
            sups = true_sups(patches[p], u, v)
            inverse = zs_inverse_steps(patches[p], eps)
            m, n = int(tess.factors[p, 0]), int(tess.factors[p, 1])
            measured, local, cell = worst_cell(patches[p], m, n, eps)
            print(f"| {relative:g} | {p} | {per_patch[p]:.3f} | {inverse[0]:.2f}, {inverse[1]:.2f} | {m} x {n} | "
                  f"{', '.join(f'{x:.2f}' for x in hull / sups)} | {measured:.3f} / {local:.3f} at cell {cell} |",
                  flush=True)


if __name__ == "__main__":
    main()
