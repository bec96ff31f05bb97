"""The error-hull kernel against float64 measurement on many random triangles (issue 9, session 6):
how many it certifies at a tolerance just above each triangle's measured error, and whether any
certified one is over its bound (error / bound must stay <= 1).

Random patches (tests/support.random_patches) with weights all equal, up to 25x and up to 100x
apart; triangles of 0.003 to 1 of the domain; each triangle its own patch, with tolerance 1.05x,
1.5x or 3x its error measured at barycentric points of order 20 (float64, the exact surface at the
float32 corners).

    python bench/error_hull_soundness.py [--count 400] [--seed 7]
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--count", type=int, default=400, help="triangles per weight spread")
    parser.add_argument("--seed", type=int, default=7)
    args = parser.parse_args(argv)
    from cltess.backends.opencl.error_hull import error_hull_ratios
    from cltess.criteria import error_hull
    from cltess.pipeline import Tessellator
    from cltess.reference import surface_points
    from support import random_patches
    from test_bound_integral import dense_errors

    tessellator = Tessellator()
    print(f"device: {tessellator.device.name.strip()}\n")
    print("| weights up to | certified | worst error / bound of the certified | infinite |")
    print("|---|---|---|---|")
    rng = np.random.default_rng(args.seed)
    n = args.count
    for spread in (1.0, 25.0, 100.0):
        patches = random_patches(rng, n)
        w = np.exp(rng.uniform(0, np.log(spread), (n, 4, 4)))
        patches = np.concatenate([patches[..., :3] / patches[..., 3:] * w[..., None], w[..., None]], axis=-1)
        size = rng.choice([0.003, 0.03, 0.3, 1.0], (n, 1, 1))
        corners = (rng.uniform(0, 1, (n, 3, 2)) * size + rng.uniform(0, 1, (n, 1, 2)) * (1 - size)).astype(np.float32)
        uv, ids, tris = corners.reshape(-1, 2), np.repeat(np.arange(n), 3), np.arange(3 * n).reshape(-1, 3)
        positions = surface_points(patches, ids, uv[:, 0].astype(float), uv[:, 1].astype(float))
        error = dense_errors(patches, positions, uv, ids, tris, order=20)
        tolerance = (error * rng.choice([1.05, 1.5, 3.0], n)).astype(np.float32) + np.float32(1e-12)
        nets, radii = error_hull.centred_nets(patches)
        ratios, _ = error_hull_ratios(tessellator, nets, radii, np.ones(n, np.int32), uv, ids, tris, tolerance)
        ok = ratios <= 1
        worst = (error[ok] / (ratios[ok] * tolerance[ok])).max() if ok.any() else 0.0
        print(f"| {spread:g}x | {ok.sum()} of {n} | {worst:.3f} | {np.isinf(ratios).sum()} |", flush=True)


if __name__ == "__main__":
    main()
