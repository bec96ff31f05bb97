"""A float64 experiment (issue 9, session 5; not the engine's bound): how few triangles a bound on
the error's own rational hull would certify on bench/occ_compare.py's 20 random rational patches.

For a triangle T (corners x_i in (u, v), l the affine interpolant of p at them) and a box Q of
the domain, p - l = (X - w l) / w on Q; X (elevated), w l and w (elevated) are (4, 4) Bernstein
nets on Q, so |p - l| <= max_k |E_k| / W_k on Q (the convex hull of a rational patch with weights
W_k > 0, as Lemma 2 in docs/rational-bound.md).  Start with T's bounding box; a box whose bound
is over eps is cut in four and only the quarters meeting T are kept, down to ``--depth`` levels;
T is certified when every kept box is within eps.  For each patch alone the script finds the
uniform m x n grid (2 m n triangles, both diagonals of a cell cut the same way) with the fewest
triangles that is certified, and prints it with the boxes evaluated; ``--ideal`` also prints the
fewest triangles of a grid whose *measured* deviation (occ_compare.measured_deviation) is within
eps.  float64 throughout, no rounding analysis: an estimate of what a float32 kernel of this
bound could reach, not a certificate.

    python bench/error_hull_grid.py --eps 3e-2 [--depth 4] [--patches 2 11 17] [--ideal]
"""
from __future__ import annotations

import argparse
import sys
from math import comb
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from occ_compare import diagonal, measured_deviation, random_rational_patches  # noqa: E402

#: ELEVATION[a, c, i]: the product of a cubic's a-th and a linear's c-th Bernstein coefficient
#: lands on the quartic's i = a + c-th with weight C(3, a) C(1, c) / C(4, i).
ELEVATION = np.zeros((4, 2, 5))
for _a in range(4):
    for _c in range(2):
        ELEVATION[_a, _c, _a + _c] = comb(3, _a) * comb(1, _c) / comb(4, _a + _c)


def restricted(patch: np.ndarray, box) -> np.ndarray:
    """(4, 4, 4) homogeneous net of the patch on box (u0, u1, v0, v1), [v, u, (X, w)]."""
    from cltess.criteria.integral import interval_matrices

    u0, u1, v0, v1 = box
    along_u = interval_matrices(np.array([u0, u1]), 3)[0]
    along_v = interval_matrices(np.array([v0, v1]), 3)[0]
    return np.einsum("bj,ai,jic->bac", along_v, along_u, patch)


def box_bound(patch: np.ndarray, box, corners: np.ndarray, values: np.ndarray) -> float:
    """max_k |E_k| / W_k of p - l on box (l: the affine interpolant of values at corners)."""
    u0, u1, v0, v1 = box
    net = restricted(patch, box)
    x, w = net[..., :3], net[..., 3]
    edges = np.array([corners[1] - corners[0], corners[2] - corners[0]]).T
    linear = np.empty((2, 2, 3))  # l at the box's corners: its exact (1, 1) net on the box
    for d, v in enumerate((v0, v1)):
        for c, u in enumerate((u0, u1)):
            lam = np.linalg.solve(edges, np.array([u, v]) - corners[0])
            linear[d, c] = values[0] + lam[0] * (values[1] - values[0]) + lam[1] * (values[2] - values[0])
    difference = x[:, :, None, None, :] - w[:, :, None, None, None] * linear[None, None]  # [b, a, d, c, xyz]
    error = np.einsum("bdj,aci,badcx->jix", ELEVATION, ELEVATION, difference)
    weights = np.einsum("bdj,aci,ba->ji", ELEVATION, ELEVATION, w)
    return float((np.linalg.norm(error, axis=-1) / weights).max())


def meets(box, corners: np.ndarray) -> bool:
    """Whether the box and the triangle share a point (separating axes: the box's, the edges')."""
    u0, u1, v0, v1 = box
    if corners[:, 0].max() < u0 or corners[:, 0].min() > u1 or corners[:, 1].max() < v0 or corners[:, 1].min() > v1:
        return False
    box_corners = np.array([[u0, v0], [u1, v0], [u0, v1], [u1, v1]])
    for k in range(3):
        a, b, c = corners[k], corners[(k + 1) % 3], corners[(k + 2) % 3]
        normal = np.array([a[1] - b[1], b[0] - a[0]])
        inside, side = normal @ (c - a), (box_corners - a) @ normal
        if (inside > 0 and (side < 0).all()) or (inside < 0 and (side > 0).all()):
            return False
    return True


def certified(patch: np.ndarray, corners: np.ndarray, eps: float, depth: int) -> tuple[bool, int]:
    """(every kept box within eps, boxes evaluated)."""
    from cltess.reference import surface_points

    values = surface_points(patch[None], np.zeros(3, int), corners[:, 0], corners[:, 1])
    stack = [((corners[:, 0].min(), corners[:, 0].max(), corners[:, 1].min(), corners[:, 1].max()), 0)]
    boxes = 0
    while stack:
        box, level = stack.pop()
        boxes += 1
        if box_bound(patch, box, corners, values) <= eps:
            continue
        if level == depth:
            return False, boxes
        u0, u1, v0, v1 = box
        um, vm = (u0 + u1) / 2, (v0 + v1) / 2
        stack += [(q, level + 1) for q in ((u0, um, v0, vm), (um, u1, v0, vm), (u0, um, vm, v1), (um, u1, vm, v1))
                  if meets(q, corners)]
    return True, boxes


def grid_triangles(m: int, n: int):
    for j in range(n):
        for i in range(m):
            c = np.array([[i / m, j / n], [(i + 1) / m, j / n], [(i + 1) / m, (j + 1) / n], [i / m, (j + 1) / n]])
            yield c[[0, 1, 2]]
            yield c[[0, 2, 3]]


def fewest(test, limit: int = 40):
    """(2 m n, m, n, extra) of the grid with the fewest triangles that passes test(m, n) ->
    (ok, extra), searching grids with max(m, n) <= limit."""
    best = None
    for side in range(1, limit + 1):
        for other in range(1, side + 1):
            for m, n in ((other, side), (side, other)):
                if best and 2 * m * n >= best[0]:
                    continue
                ok, extra = test(m, n)
                if ok:
                    best = (2 * m * n, m, n, extra)
        if best and best[0] <= 2 * side:
            break
    return best


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--eps", type=float, default=3e-2, help="of the 20 patches' bounding-box diagonal")
    parser.add_argument("--depth", type=int, default=4)
    parser.add_argument("--patches", type=int, nargs="+", default=list(range(20)))
    parser.add_argument("--ideal", action="store_true")
    args = parser.parse_args(argv)
    from cltess.reference import surface_points

    patches = random_rational_patches()
    eps = args.eps * diagonal(patches)

    def bound_test(patch):
        def test(m, n):
            boxes = 0
            for tri in grid_triangles(m, n):
                ok, k = certified(patch, tri, eps, args.depth)
                boxes += k
                if not ok:
                    return False, boxes
            return True, boxes
        return test

    def measured_test(index):
        def test(m, n):
            tris = np.array(list(grid_triangles(m, n))).reshape(-1, 2)
            uv = tris.astype(float)
            positions = surface_points(patches, np.full(len(uv), index), uv[:, 0], uv[:, 1])
            triangles = np.arange(len(uv)).reshape(-1, 3)
            return measured_deviation(patches[index:index + 1], positions, uv, np.zeros(len(triangles), int),
                                      triangles) <= eps, None
        return test

    print(f"eps {args.eps:g} of the diagonal, depth {args.depth}")
    ideal_header = " measured within eps: triangles (m x n) |" if args.ideal else ""
    print("| patch | certified: triangles (m x n) | boxes evaluated |" + ideal_header)
    print("|---|---|---|" + ("---|" if args.ideal else ""))
    total = ideal_total = 0
    for index in args.patches:
        best = fewest(bound_test(patches[index]))
        total += best[0]
        row = f"| {index} | {best[0]} ({best[1]} x {best[2]}) | {best[3]} |"
        if args.ideal:
            ideal = fewest(measured_test(index))
            ideal_total += ideal[0]
            row += f" {ideal[0]} ({ideal[1]} x {ideal[2]}) |"
        print(row, flush=True)
    print(f"| all | {total} | |" + (f" {ideal_total} |" if args.ideal else ""))


if __name__ == "__main__":
    main()
