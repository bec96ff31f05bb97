"""The SD-2 tie zone on a model surface (issue 13; docs/sd2.md section 5, "Sixth pass"): records
lifted onto (u, v, h(u, v)) as tests/test_sd2_pattern.py lifts them (the zone's centres on their
rows' chords where the tree's mirror has sd2_chords), distances in units of the lifted error at
factor 1 (the grid of 1 against the grid of 41).  NumPy only.

    python bench/sd2_zone_model.py                  # both parts; about 10 min on the shared VM
    PYTHONPATH=/tmp/base python bench/sd2_zone_model.py   # another tree's mirror and helpers

departures: leaving the plateau of n (all phi = n) with the tip rising by d and its c+2 at q of
  that rate (lam = 1 - q): the move in the first 1/64 of a factor unit, and the fastest move per
  factor unit over d in [0, 1) (uniform refinement from 1: 0.96 errors per unit).
sequential: leaving the plateau of 3 or 5 with c+2 following after a delay (the generic way: one corner
  after the other): the worst move at two step sizes (seventh pass).
triple: a loop of radius r factor units around a triple tie at factor n (phi_k = n + r cos(theta
  + 2 pi k / 3), 72 angles): its diameter (the largest distance between two of its meshes, each
  against every sixth other).  A pop at the triple point: the diameter does not shrink with r.
  Also in units of the mesh's own error at n (the hinted grid at n against the grid of 41), the
  residual that docs/sd2.md section 5, "Decision", states; ``--factors`` chooses the n.
passing: a path passing within about 0.01 of a triple tie at n (sphere-320 depth's worst patches
  pass one at 2.86): the worst step at 0.02 / 0.01 factor units, for two orders of the corners
  (eighth pass).
"""
from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import numpy as np

TREE = Path(os.environ.get("PYTHONPATH", "").split(os.pathsep)[0] or Path(__file__).resolve().parents[1])
sys.path.insert(0, str(TREE / "tests"))
sys.path.insert(0, str(TREE))

import test_sd2_pattern as model  # noqa: E402
from cltess.patterns.fractional import FIXED_ONE  # noqa: E402


def record(phi) -> list:
    return model.hinted_record([round(x * FIXED_ONE) for x in phi])


def departures(plateaus=(1, 3, 7), rates=(0.25, 0.5, 0.75), step=1 / 64):
    for n in plateaus:
        error = model.plateau_error(n)
        for q in rates:
            at = lambda d: record([n + d, n, n + q * d])  # tip corner 0, its c+2 = corner 2
            first = model.lifted_distance(record([n] * 3), at(step)) / error
            fastest = max(model.lifted_distance(at(d), at(d + step)) for d in np.arange(0.0, 0.95, 0.05)) / step / error
            print(f"plateau {n}, c+2 at {q} of the tip's rate: first 1/64 unit {first:.3f} of its error, "
                  f"fastest {fastest:.2f} errors per unit", flush=True)


def triple(factors=(1.05, 1.2, 1.5, 2.0, 3.05), radii=(0.02, 0.005)):
    error = model.plateau_error(1)
    for n in factors:
        own_error = model.plateau_error(n)
        diameters = [model.triple_tie_loop_diameter(n, r, angles=72, stride=6) / error for r in radii]
        print(f"triple tie at {n}: loop diameter " + ", ".join(f"r = {r}: {d:.3f}" for r, d in zip(radii, diameters))
              + " of the factor-1 error; " + ", ".join(f"{d * error / own_error:.3f}" for d in diameters)
              + f" of the error at {n}", flush=True)


def sequential(plateaus=(3, 5), rates=(0.3, 0.75), delays=(0.0, 0.005, 0.02), steps=(0.02, 0.01)):
    """Leaving the plateau of n with the tip rising by d and its c+2 following at q of that rate
    after a delay d0 (d0 = 0: both at once; the generic way, one corner after the other, passes
    the plateau's corner at rho = d0): the worst move over d in [0, 0.2) at each step size."""
    for n in plateaus:
        error = model.plateau_error(n)
        for q in rates:
            for d0 in delays:
                at = lambda d: record([n + d, n, n + q * max(d - d0, 0.0)])
                worst = [max(model.lifted_distance(at(d), at(d + h)) for d in np.arange(0.0, 0.2, h)) / error
                         for h in steps]
                print(f"plateau {n}, c+2 at {q} after {d0}: worst step " +
                      " / ".join(f"{x:.3f}" for x in worst) + f" of its error at steps {steps}", flush=True)


def passing(factors=(2.0, 2.5, 2.86, 3.0, 3.05, 4.0, 5.0, 6.3), steps=(0.02, 0.01)):
    """Three phi converging to within about 0.01 of n at x = 0.1 and parting again (x in [0, 0.2]):
    the tip moves, and lam goes from one tie configuration to the other near the point."""
    error = model.plateau_error(1)
    for n in factors:
        for order in ((0, 1, 2), (2, 1, 0)):
            def at(x):
                path = [n + 0.1 - x, n - 0.01 + 0.15 * (0.1 - x), n - 0.04 + 0.5 * x]
                return record([path[order[k]] for k in range(3)])
            worst = [max(model.lifted_distance(at(x), at(y)) for x, y in zip(xs[:-1], xs[1:])) / error
                     for xs in (np.arange(0.0, 0.2 + 1e-9, h) for h in steps)]
            print(f"passing a triple tie at {n}, corners {order}: worst step " + " / ".join(f"{x:.3f}" for x in worst)
                  + f" of the factor-1 error at steps {steps}", flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("part", nargs="?", choices=("departures", "triple", "sequential", "passing", "both"), default="both")
    parser.add_argument("--factors", type=float, nargs="*", help="triple: the factors n of the triple ties")
    args = parser.parse_args()
    print(f"tree {TREE}")
    if args.part in ("departures", "both"):
        departures()
    if args.part in ("triple", "both"):
        triple(*([args.factors] if args.factors else []))
    if args.part == "sequential":
        sequential()
    if args.part == "passing":
        passing()


if __name__ == "__main__":
    main()
