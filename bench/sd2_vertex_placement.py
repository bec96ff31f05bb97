"""An experiment, not the pattern (issue 13; docs/sd2.md section 5, "Eighth pass"): the tie zone's
fan vertices placed in space rather than on the surface, as the sixth pass placed the centres on
their rows' chords, on the model surface of tests/test_sd2_pattern.py.  NumPy only.

    python bench/sd2_vertex_placement.py [domain,chord,polyline]     # about 5 min on the shared VM

domain    today's mirror: vertex (i, j) on the surface at corner c+2 weight
          z = w t s + (1 - w) (lam z1 + (1 - lam) z2) along its row (z1, z2 the two tie
          configurations' weights, sd2.py _fan_z)
chord     P(z2) + lam (P(z1) - P(z2)): the vertex on the chord, in space, between its two tie
          configurations' points (P the surface at row i's point of that weight)
polyline  on row i's polyline through the surface points at every z1 and z2 of the row, at z

Printed, in units of the factor-1 error (loops, the passing path) or the plateau's error (the
departures): loops of radius 0.005 around a triple tie (worst step between 36 neighbouring
angles, and the total), a path passing a triple tie at 2.86 (worst step at 0.02 / 0.01 units),
leaving the plateaus of 3 and 5 one corner after the other (worst step at 0.02 / 0.01 units), and
the mesh's distance from the surface (against the grid of 41) near a triple tie, in units of the
factor-3 error.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

TREE = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(TREE / "tests"))
sys.path.insert(0, str(TREE))

import test_sd2_pattern as model  # noqa: E402
from cltess.patterns import sd2  # noqa: E402
from cltess.patterns.base import place_chords  # noqa: E402
from cltess.patterns.fractional import FIXED_ONE, locations  # noqa: E402

PLACEMENT = "domain"


def surface(uv) -> np.ndarray:
    uv = np.asarray(uv, np.float64).reshape(-1, 2)
    u, v = uv[:, 0], uv[:, 1]
    w = 1 - u - v
    return np.column_stack([u, v, u * u + 2 * v * v + 3 * w * w + u * v])  # model.lifted's surface


def lifted(record):
    """model.lifted with the zone's interior fan vertices moved by PLACEMENT."""
    uv, triangles = sd2.sd2_pattern(record)
    points = surface(uv)
    lay = sd2._Layout(record)
    if PLACEMENT != "domain" and lay.shape == "sd2" and lay.zone:
        f32, one, c = np.float32, np.float32(1.0), lay.tip
        a, b = lay.n[c], lay.n[(c + 1) % 3]
        t, s = locations(lay.f[c]), locations(lay.f[(c + 1) % 3])
        row = lambda i, z: surface(sd2._row_point(c, t[i], f32(z))[:2])[0]
        for i in range(1, a):
            z1 = [f32(lay.w * f32(t[i] * s[j]) + (one - lay.w) * max(f32(t[i] + s[j]) - one, 0)) for j in range(b + 1)]
            z2 = [f32(lay.w * f32(t[i] * s[j]) + (one - lay.w) * min(s[j], t[i])) for j in range(b + 1)]
            stops = np.unique(np.array(z1 + z2, np.float64))
            for j in range(1, b):
                if PLACEMENT == "chord":
                    points[lay.sd2(i, j)] = row(i, z2[j]) + float(lay.lam) * (row(i, z1[j]) - row(i, z2[j]))
                    continue
                z = float(sd2._fan_z(t[i], s[j], lay.w, lay.lam))
                q = int(np.searchsorted(stops, z))
                if 0 < q < len(stops) and stops[q] != z:
                    x = (z - stops[q - 1]) / (stops[q] - stops[q - 1])
                    points[lay.sd2(i, j)] = row(i, stops[q - 1]) + x * (row(i, stops[q]) - row(i, stops[q - 1]))
    points = place_chords(points, sd2.sd2_chords(record))
    return points, points[triangles]


model.lifted = lifted  # lifted_distance and plateau_error use it


def record(phi) -> list:
    return model.hinted_record([round(x * FIXED_ONE) for x in phi])


def worst_step(at, xs) -> float:
    return max(model.lifted_distance(at(x), at(y)) for x, y in zip(xs[:-1], xs[1:]))


def main(placements):
    global PLACEMENT
    for PLACEMENT in placements:
        error1, lines = model.plateau_error(1), []
        for n in (2.0, 2.86, 3.05, 5.02):
            at = lambda theta: record([n + 0.005 * np.cos(theta + 2 * np.pi * k / 3) for k in range(3)])
            thetas = np.linspace(0, 2 * np.pi, 37)
            steps = [model.lifted_distance(at(x), at(y)) for x, y in zip(thetas[:-1], thetas[1:])]
            lines.append(f"loop at {n}: worst {max(steps) / error1:.3f}, total {sum(steps) / error1:.3f}")
        passing = lambda x: record([2.96 - x, 2.85 + 0.15 * (0.1 - x), 2.82 + 0.5 * x])
        lines.append("passing 2.86: " + " / ".join(f"{worst_step(passing, np.arange(0, 0.2 + 1e-9, h)) / error1:.3f}"
                                                  for h in (0.02, 0.01)))
        for n in (3, 5):
            for q, d0 in ((0.3, 0.005), (0.75, 0.005), (0.75, 0.02), (0.45, 0.0)):
                at = lambda d: record([n + d, n, n + q * max(d - d0, 0.0)])
                lines.append(f"plateau {n}, c+2 at {q} after {d0}: " + " / ".join(
                    f"{worst_step(at, np.arange(0.0, 0.2 + 1e-9, h)) / model.plateau_error(n):.3f}" for h in (0.02, 0.01)))
        fine_points, _ = lifted(model.hinted_record([41 * FIXED_ONE] * 3))
        for phi in ([3.4, 3.3, 3.1], [2.9, 2.86, 2.87]):
            _, triangles = lifted(record(phi))
            off = model.point_triangle_distances(fine_points, triangles).max() / model.plateau_error(3)
            lines.append(f"distance from the surface at {phi}: {off:.3f}")
        print(PLACEMENT, *lines, sep="\n  ", flush=True)


if __name__ == "__main__":
    main(sys.argv[1].split(",") if len(sys.argv) > 1 else ["domain", "chord", "polyline"])
