"""Issue 13, session 9 (docs/sd2.md section 5, "Ninth pass"): the tie zone with ONE grid
configuration for every fan, no lam, no hint and no centres (the fifth pass's native collapse,
(A)), built on the NumPy mirror as an experiment and measured against main's zone.

The configuration C of a triangle whose three factors are equal (real r, n segments) is the tie
configuration of corners 0 and 1: lattice label (k0, k1, k2) (k0 + k1 + k2 = n) at barycentric
weights ``(X(k0), X(k1), 1 - X(k0) - X(k1))``, X the fractional_odd locations (docs/sd2.md
section 5; the hinted grid's layout with its rows from corner 0).  The grid always takes C.  A fan
with tip c, tip edges F, base G (n_F = a and n_G = b segments), in the zone ``0 <= F - G < 1``:

    vertex (i, j) = w radial(i, j) + (1 - w) C_G(label_c(i', j)),  w = F - G,

radial the paper's fan (section 3), C_G the lattice of the base's factor G, label_c the fan's
native map (vertex (i, j) -> corner c index n - i, corner c+1 index min(n - j, i), corner c+2
index max(i + j - n, 0); bench/sd2_tie_limits.py (A): the fan's triangles fall exactly onto the
grid's, for any positions), n = b, and i' = i where a = b; where a = b + 2 (F has crossed the odd
m = b inside the zone) the merged row index of F = m+ (k' of bench/sd2_tie_limits.merged_index),
so that C_G's target is continuous where F crosses m.  Ring vertices stay on the ring.  Counts are
the plain fan's (no centres).  At F = G every fan and the grid are C: the tie is continuous
whichever corners tie, triple ties included.  Where G crosses the odd m with a = m + 2 the
target jumps for tips whose corner c+2 is 0 or 1 (the fifth pass's (B): the third index is no
product); measured here, not removed.

Variants (``use``): ``main`` (today's mirror), ``one`` (the above), ``hybrid`` (main's layout where
G is an odd whole number, the one configuration from FAR_ODD away, a linear blend between),
``birth`` (the target blended from C on the tie line to the product P, main's lam = 1 target, on the
birth lines: birth_weight), ``product-R`` (towards P within R of an odd G), ``follow`` (session 9, branch
sd2j: main's layout for every record whose largest factor is at most 3, ``birth`` above; PLATEAU_TOP),
``follow-main`` (the same, main's own zone target M in place of the product P above 3:
follow_main_layout).

    python bench/sd2_one_config.py folds [--variants follow --bottom 3]   # fold-over: exhaustive (F, G), 3 tips
    python bench/sd2_one_config.py folds --variants main follow-main --random 1500   # hinted records near 3, 5, 7
    python bench/sd2_one_config.py model [--variants main one birth hybrid]   # model surface
    python bench/sd2_one_config.py orbit --mesh sphere-320 --sweep 20 --steps 10 [sd2_pops options]
                                         [--variants main one] [--top 3]

``orbit`` runs bench/sd2_pops.py's measure (vertices) on the NumPy backend once per variant (records
and surfaces the same; main's row reproduces the OpenCL tables of bench/RESULTS.md), side by side.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "bench"))
sys.path.insert(0, str(REPO / "tests"))

import cltess.patterns.sd2 as sd2  # noqa: E402
from cltess.patterns.fractional import FIXED_ONE, locations, to_fixed  # noqa: E402

MAIN_PATTERN, MAIN_CHORDS = sd2.sd2_pattern, sd2.sd2_chords


def native_label(c: int, n: int, i: int, j: int) -> tuple:
    """Lattice label of fan-c vertex (i, j) under the native map (bench/sd2_tie_limits.py (A))."""
    idx = [0, 0, 0]
    idx[c], idx[(c + 1) % 3], idx[(c + 2) % 3] = n - i, min(n - j, i), max(i + j - n, 0)
    return tuple(idx)


def merged_rows(m: int) -> np.ndarray:
    """k' of each point of an edge with m + 2 segments (its factor past the odd m): the m-lattice
    index its location tends to as the factor falls to m (rint(X(m+) m), one 16.16 unit past m)."""
    x = locations(int(to_fixed(m)) + 1).astype(np.float64)
    return np.rint(x * m).astype(int)


def configuration_point(x: np.ndarray, label) -> np.ndarray:
    """C's barycentric weights of a label: the tie configuration of corners 0 and 1."""
    return np.array([x[label[0]], x[label[1]], 1.0 - x[label[0]] - x[label[1]]])


def zone_weight(f, c: int):
    """w = F - G (factor units) of the fan with tip c, or None outside the zone."""
    big, base = int(f[c]), int(f[(c + 1) % 3])
    return (big - base) / FIXED_ONE if 0 <= big - base < FIXED_ONE else None


def one_config_layout(f) -> tuple[np.ndarray, list]:
    """(uv (V, 2) float64, strips) of the one-configuration tie zone (module docstring)."""
    f = [int(x) for x in f[:4]] + [0] * max(0, 4 - len(f))
    lay = sd2._Layout(f[:3])  # no hint: the ring and the plain shapes
    if lay.shape == "culled":
        return np.zeros((0, 2)), []
    uv = [np.asarray(p, np.float64) for p in sd2._ring_uv(lay.f, lay.n)]
    strips = []
    if lay.shape == "grid":
        lay.tip = 0  # C: rows from corner 0, corner 1's weight at the edges' points
        n, t = lay.n[0], locations(lay.f[0]).astype(np.float64)
        sigma, g = (odd_weight(lay.f[0], PRODUCT_REACH), sd2.sd2_grid_corner(f)) if PRODUCT_REACH > 0 else (0.0, 0)
        for i in range(2, n):
            for j in range(1, i):
                label = (n - i, i - j, j)  # corners 0, 1, 2: rows from corner 0
                point = configuration_point(t, label)
                if sigma > 0:  # near odd factors: towards main's hinted grid (the tie of g, g+1)
                    main = np.zeros(3)
                    main[g], main[(g + 1) % 3] = t[label[g]], t[label[(g + 1) % 3]]
                    main[(g + 2) % 3] = 1 - main[g] - main[(g + 1) % 3]
                    point = sigma * main + (1 - sigma) * point
                uv.append(point[:2])
        for i in range(n):
            strip = []
            for j in range(i + 1, 0, -1):
                strip += [lay.grid(i + 1, j), lay.grid(i, j - 1)]
            strip.append(lay.grid(i + 1, 0))
            strips.append(np.array(strip, np.int64))
    elif lay.shape == "sd2":
        c = lay.tip
        a, b = lay.n[c], lay.n[(c + 1) % 3]
        t, s = locations(lay.f[c]).astype(np.float64), locations(lay.f[(c + 1) % 3]).astype(np.float64)
        w = zone_weight(lay.f, c)
        x_base = s  # C_G: the lattice of the base's factor
        rows = np.arange(a + 1) if a == b else merged_rows(b)
        for i in range(1, a):
            for j in range(1, b):
                radial = np.zeros(3)
                radial[c], radial[(c + 1) % 3], radial[(c + 2) % 3] = 1 - t[i], t[i] * (1 - s[j]), t[i] * s[j]
                point = radial
                if w is not None:
                    target = configuration_point(x_base, native_label(c, b, rows[i], j))
                    if BIRTH_BLEND:  # C on the ties, the product (partner c+1) where rows or columns are born
                        beta = birth_weight(lay.f[c], lay.f[(c + 1) % 3], a, b)
                        product = np.zeros(3)
                        product[c], product[(c + 2) % 3] = 1 - t[i], max(t[i] + s[j] - 1, 0.0)
                        product[(c + 1) % 3] = 1 - product[c] - product[(c + 2) % 3]
                        target = beta * target + (1 - beta) * product
                    elif PRODUCT_REACH > 0:  # near odd G: towards the tie configuration with partner c+1
                        sigma = odd_weight(lay.f[(c + 1) % 3], PRODUCT_REACH)
                        product = np.zeros(3)
                        product[c], product[(c + 2) % 3] = 1 - t[i], max(t[i] + s[j] - 1, 0.0)
                        product[(c + 1) % 3] = 1 - product[c] - product[(c + 2) % 3]
                        target = sigma * product + (1 - sigma) * target
                    point = w * radial + (1 - w) * target
                uv.append(point[:2])
        for j in range(b):
            strip = [lay.sd2(0, 0)]
            for i in range(1, a + 1):
                strip += [lay.sd2(i, j), lay.sd2(i, j + 1)]
            strips.append(np.array(strip, np.int64))
    else:
        return MAIN_PATTERN(f)[0], None  # the transition fallback: unchanged (never from a level function)
    return np.array(uv, np.float64).reshape(-1, 2), strips


def one_config_pattern(f) -> tuple[np.ndarray, np.ndarray]:
    uv, strips = one_config_layout(f)
    if strips is None:
        return MAIN_PATTERN(f)
    triangles = []
    for strip in strips:
        for k in range(len(strip) - 2):
            a, b, c = strip[k], strip[k + 1], strip[k + 2]
            triangles.append((b, a, c) if k % 2 else (a, b, c))
    return uv, np.array(triangles, np.int64).reshape(-1, 3)


#: the hybrid's reach (factor units): main's zone at an odd whole base factor G (births), the one
#: configuration FAR_ODD or more from every odd number, a linear blend between
FAR_ODD = 0.125
#: variant "product": within PRODUCT_REACH of an odd G the zone's target moves from C towards the
#: tie configuration with partner c+1 (main's lam = 1: a product in the fan's own indices,
#: continuous at births for every tip); 0: off
PRODUCT_REACH = 0.0


#: variant "birth": the zone's target C on the tie line F = G and the product (main's lam = 1 target,
#: continuous where rows or columns are born, for every tip) on the birth lines (F at the odd n above,
#: G at the odd n - 2 below), by birth_weight
BIRTH_BLEND = False


#: variant "follow" (session 9, branch sd2j; docs/sd2.md section 5, "Tenth pass"): today's zone (main's
#: layout and chords: hint, lam, centres on the chord) for every record whose largest factor is at most
#: PLATEAU_TOP (the plateau of 1 and every fan with a = 3 tip-edge segments), the birth variant above
#: (C on the tie lines, the fan's own product on its birth lines); the two layouts are never blended
PLATEAU_TOP = 3 * FIXED_ONE


def at_the_plateau_of_1(f) -> bool:
    return max(abs(int(x)) for x in f[:3]) <= PLATEAU_TOP


def follow_pattern(f):
    return MAIN_PATTERN(f) if at_the_plateau_of_1(f) else one_config_pattern(f)


def follow_chords(f):
    return MAIN_CHORDS(f) if at_the_plateau_of_1(f) else no_chords(f)


def birth_weight(big: int, base: int, a: int, b: int) -> float:
    """beta: 1 on the tie line F = G, 0 where F reaches the odd a (rows are born past it) or G the odd
    a - 2 (columns were born there), and 0 where a = b + 2 (between the two births): in the bracket
    (a - 2, a], ``min((G - (a - 2)) / (F - (a - 2)), (a - F) / (a - G))``.  Continuous except at the
    ties at odd whole factors, approached from above."""
    if a != b:
        return 0.0
    if big == base:
        return 1.0
    big, base = big / FIXED_ONE, base / FIXED_ONE
    return min((base - (a - 2)) / (big - (a - 2)), (a - big) / (a - base))


def odd_weight(fixed: int, reach: float | None = None) -> float:
    """sigma: 1 at an odd whole factor, 0 from `reach` (FAR_ODD) on, linear between."""
    reach = FAR_ODD if reach is None else reach
    return float(np.clip(1.0 - sd2.odd_distance(int(fixed)) / FIXED_ONE / reach, 0.0, 1.0))


def follow_main_layout(f) -> tuple[np.ndarray, list, tuple]:
    """(uv, triangles, chords) of the variant "follow-main": main's layout and vertex numbering; above
    PLATEAU_TOP a fan in the zone puts its vertices at ``w radial + (1 - w)(beta C + (1 - beta) M)``, M
    main's target (lam, centres), C the one configuration through the native map, beta = birth_weight
    (1 on the tie line, 0 on the birth lines and where a = b + 2), its centres on their chords at
    (1 - beta) mu; a grid takes C.  At or below PLATEAU_TOP: main's layout bitwise."""
    if at_the_plateau_of_1(f):
        return (*MAIN_PATTERN(f), MAIN_CHORDS(f))
    lay = sd2._Layout(f)
    if lay.shape == "sd2" and zone_weight(lay.f, lay.tip) is not None:
        c = lay.tip
        beta = birth_weight(lay.f[c], lay.f[(c + 1) % 3], lay.n[c], lay.n[(c + 1) % 3])
        if beta > 0:
            return blended_layout(f, 1.0 - beta)
    elif lay.shape == "grid":
        return blended_layout(f, 0.0)
    return (*MAIN_PATTERN(f), MAIN_CHORDS(f))


def hybrid_layout(f) -> tuple[np.ndarray, list, tuple]:
    """(uv, triangles, chords) of the hybrid: main's layout and vertex numbering, every vertex at
    sigma main + (1 - sigma) one-configuration (sigma = odd_weight of the base's factor, the grid's
    factor for a grid), the zone's centres on their chords at sigma mu (the one configuration puts
    them on (i, j+1): the fan's own diagonal, bench/sd2_tie_limits.py (A))."""
    lay = sd2._Layout(f)
    sigma = odd_weight(lay.f[(lay.tip + 1) % 3] if lay.shape == "sd2" else lay.f[0])
    return blended_layout(f, sigma)


def blended_layout(f, sigma: float) -> tuple[np.ndarray, list, tuple]:
    """Main's layout and numbering, every vertex at sigma main + (1 - sigma) one-configuration (pure
    C target: BIRTH_BLEND off), the zone's centres on their chords at sigma mu (the one configuration
    puts them on (i, j+1): the fan's own diagonal, bench/sd2_tie_limits.py (A)); a hinted grid's
    vertices likewise."""
    uv, triangles = MAIN_PATTERN(f)
    chords = MAIN_CHORDS(f)
    lay = sd2._Layout(f)
    if lay.shape == "sd2":
        global BIRTH_BLEND
        saved, BIRTH_BLEND = BIRTH_BLEND, False
        try:
            one_uv, _ = one_config_layout(f)
        finally:
            BIRTH_BLEND = saved
        k = len(one_uv)
        uv = uv.copy()
        uv[:k] = sigma * uv[:k] + (1 - sigma) * one_uv
        if len(chords[0]):
            vertices, start, end, mu = chords
            mu = (sigma * mu.astype(np.float64)).astype(np.float32)
            uv[vertices] = (1 - mu[:, None]) * uv[start] + mu[:, None] * uv[end]
            chords = (vertices, start, end, mu)
    elif lay.shape == "grid" and sd2.sd2_hint(f) is not None:
        n, g, x = lay.n[0], lay.tip, locations(lay.f[0]).astype(np.float64)
        uv = uv.copy()
        for i in range(2, n):
            for j in range(1, i):
                label = [0, 0, 0]
                label[g], label[(g + 1) % 3], label[(g + 2) % 3] = n - i, i - j, j
                uv[lay.grid(i, j)] = sigma * uv[lay.grid(i, j)] + (1 - sigma) * configuration_point(x, label)[:2]
    return uv, triangles, chords


def hybrid_pattern(f):
    uv, triangles, _ = hybrid_layout(f)
    return uv, triangles


def hybrid_chords(f):
    return hybrid_layout(f)[2]


def follow_main_pattern(f):
    uv, triangles, _ = follow_main_layout(f)
    return uv, triangles


def follow_main_chords(f):
    return follow_main_layout(f)[2]


def no_chords(f):
    return np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0, np.float32)


def use(variant: str) -> None:
    """Point the mirror (and the modules that imported its names) at main's pattern or a variant:
    "one", "hybrid" (main near odd base factors, FAR_ODD), "product-R" (the one configuration
    with PRODUCT_REACH = R), "birth" (BIRTH_BLEND), "follow" (main up to PLATEAU_TOP, birth above),
    "follow-main" (follow_main_layout)."""
    import test_sd2_pattern as model
    global PRODUCT_REACH, BIRTH_BLEND
    PRODUCT_REACH = float(variant.split("-")[1]) if variant.startswith("product-") else 0.0
    BIRTH_BLEND = variant in ("birth", "follow")
    variant = "one" if variant.startswith("product-") or variant == "birth" else variant
    pattern, chords = {"main": (MAIN_PATTERN, MAIN_CHORDS), "one": (one_config_pattern, no_chords),
                       "hybrid": (hybrid_pattern, hybrid_chords), "follow": (follow_pattern, follow_chords),
                       "follow-main": (follow_main_pattern, follow_main_chords)}[variant]
    sd2.sd2_pattern, sd2.sd2_chords, model.sd2_pattern = pattern, chords, pattern
    object.__setattr__(sd2.SD2, "layout", pattern)  # a frozen dataclass
    object.__setattr__(sd2.SD2, "chords", chords)


def signed_areas(uv, triangles):
    a, b, c = (uv[triangles[:, k]] for k in range(3))
    return 0.5 * ((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))


def fold_scan(top: float = 11.0, step: int = FIXED_ONE // 32, base_step: int = FIXED_ONE // 32,
              bottom: float = 1.0):
    """Smallest signed area of the variant's zone (the mirror's pattern as `use` set it) over F in
    [bottom, top] (step 16.16 units), G in (F - 1, F] (base_step), the three tips; and the area sum
    (1/2)."""
    worst, where, area_error = np.inf, None, 0.0
    for big in range(int(bottom * FIXED_ONE), int(top * FIXED_ONE) + 1, step):
        for base in range(big, max(big - FIXED_ONE, FIXED_ONE - 1), -base_step):
            for c in range(3):
                f = [0, 0, 0]
                f[c], f[(c + 2) % 3], f[(c + 1) % 3] = big, big, base
                uv, tri = sd2.sd2_pattern(f)
                areas = signed_areas(uv, tri)
                area_error = max(area_error, abs(areas.sum() - 0.5))
                if areas.min() < worst:
                    worst, where = float(areas.min()), (big / FIXED_ONE, base / FIXED_ONE, c)
    return worst, where, area_error


def random_fold_scan(count: int, seed: int = 2):
    """Smallest signed area over `count` random hinted records whose three phi lie within 0.02 (or
    0.002) above 3, 5 or 7 (ties and births at odd factors approached from above), and its phi."""
    import test_sd2_pattern as model
    rng = np.random.default_rng(seed)
    worst, where = np.inf, None
    for _ in range(count):
        phi = rng.choice([3, 5, 7]) + rng.uniform(0, 0.02, 3) * rng.choice([1.0, 0.1])
        smallest = signed_areas(*sd2.sd2_pattern(model.hinted_record([round(x * FIXED_ONE) for x in phi]))).min()
        if smallest < worst:
            worst, where = float(smallest), np.round(phi, 5).tolist()
    return worst, where


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("part", choices=("folds", "model", "orbit"))
    args, rest = parser.parse_known_args(argv)
    if args.part == "folds":
        options = orbit_arguments(rest)
        use(options.variants[-1])  # one by default; --variants follow --bottom 3: its layout above 3
        started = time.process_time()
        if options.random:
            worst, where = random_fold_scan(options.random)
            print(f"smallest signed area {worst:.3g} at phi {where} ({time.process_time() - started:.0f} s CPU)")
            return 0
        worst, where, area_error = fold_scan(bottom=options.bottom)
        print(f"smallest signed area {worst:.3g} at (F, G, tip) = {where}; area sum off 1/2 by {area_error:.2g} "
              f"({time.process_time() - started:.0f} s CPU)")
    elif args.part == "model":
        model_part(orbit_arguments(rest).variants)
    else:
        orbit_part(rest)
    return 0


def births(odd=(3, 5, 7), gaps=(0.2, 0.6), unit=1e-4):
    """Inside the zone the tip edges' F (rows born) or the base's G (columns born) crossing the odd
    n, the other base corner at 0.5 of the gap: the largest jump over the three tips, in units of
    the factor-1 error (tests/test_sd2_pattern.py test_zone_centres_stay_put_... on main)."""
    import test_sd2_pattern as model
    error = model.plateau_error(1)
    for n in odd:
        for tip_edges in (True, False):
            worst = []
            for tip in range(3):
                jumps = []
                for gap in gaps:
                    make = ((lambda s: (n + s, n - gap, n - gap * 0.5)) if tip_edges else
                            (lambda s: (n + gap, n - gap * 0.5, n + s)))

                    def record(s):
                        phi = [0.0, 0.0, 0.0]
                        for k, value in enumerate(make(s)):
                            phi[(tip + k) % 3] = value
                        return model.hinted_record([round(x * FIXED_ONE) for x in phi])
                    jumps.append(model.lifted_distance(record(-unit), record(unit)) / error)
                worst.append(max(jumps))
            print(f"births at {n}, {'F (rows)' if tip_edges else 'G (columns)'} crossing: largest jump by tip "
                  + " / ".join(f"{x:.3f}" for x in worst) + " of the factor-1 error", flush=True)


def model_part(variants):
    import sd2_zone_model as zone
    for variant in variants:
        use(variant)
        print(f"== {variant}", flush=True)
        births()
        zone.triple(factors=(1.05, 2.0, 2.86, 3.05, 5.02), radii=(0.005,))
        zone.passing(factors=(2.0, 2.5, 2.86, 3.0, 3.05, 4.0, 5.0))
        zone.sequential(plateaus=(3,), rates=(0.3, 0.75), delays=(0.0, 0.02), steps=(0.02, 0.01))
        zone.departures(plateaus=(1, 3), rates=(0.25, 0.75))


class NumpyTessellator:
    """bench/sd2_pops.py's plan / emit on the NumPy backend (the mirror's layout, float64 surfaces)."""

    def __init__(self):
        from cltess.backends.numpy import NumpyBackend
        self.backend = NumpyBackend()

    def plan(self, scene, **options):
        from cltess.request import Request
        plan = self.backend.plan(scene, Request.of(**options))
        plan.host_factors = lambda: plan.factors
        return plan

    def emit(self, plan, first, last):
        return self.backend.emit(plan, first, last)


def orbit_arguments(argv):
    parser = argparse.ArgumentParser()
    parser.add_argument("--mesh", default="icosphere")
    parser.add_argument("--level-function", default="depth")
    parser.add_argument("--depth-range", type=float, nargs=2, default=None)
    parser.add_argument("--sweep", type=float, default=20.0)
    parser.add_argument("--steps", type=int, default=10)
    parser.add_argument("--low", type=float, default=1.0)
    parser.add_argument("--high", type=float, default=6.0)
    parser.add_argument("--band", type=float, default=0.25)
    parser.add_argument("--variants", nargs="+", default=["main", "one"])
    parser.add_argument("--bottom", type=float, default=1.0, help="folds: the smallest F scanned")
    parser.add_argument("--random", type=int, default=0, help="folds: random hinted records near 3, 5, 7 instead")
    parser.add_argument("--top", type=int, default=0, help="also print the top patches of the finer steps")
    return parser.parse_args(argv)


def orbit_part(argv):
    import sd2_pops as pops
    args = orbit_arguments(argv)
    scene = pops.mesh(args.mesh)
    print(f"{args.mesh} {args.level_function} {args.low:g}..{args.high:g} range {args.depth_range} "
          f"sweep {args.sweep:g} steps {args.steps} (NumPy backend)")
    for variant in args.variants:
        use(variant)
        started = time.process_time()
        result = pops.measure(NumpyTessellator(), scene, args.sweep, args.steps, args.low, args.high,
                              args.level_function, args.band, "vertices", 0.5, args.depth_range)
        coarse, fine = result[args.steps], result[2 * args.steps]
        print(f"{variant:>5}: worst {coarse['worst']:.5f} / {fine['worst']:.5f} (ratio "
              f"{fine['worst'] / coarse['worst']:.3f}), median {coarse['median']:.5f} / {fine['median']:.5f}, "
              f"jumps {coarse['jumps']} / {fine['jumps']}, triangles {coarse['triangles']} "
              f"({time.process_time() - started:.0f} s CPU)", flush=True)
        print(f"       steps {' '.join(f'{x:.5f}' for x in coarse['step_worst'])}", flush=True)
        print(f"       half  {' '.join(f'{x:.5f}' for x in fine['step_worst'])}", flush=True)
        if args.top:
            top_patches(pops, scene, args, 2 * args.steps)


def top_patches(pops, scene, args, steps):
    """The patches that set the worst of `steps` steps, with both frames' records."""
    tessellator = NumpyTessellator()
    centre, radius, depth_range = pops.setting(scene)
    depth_range = depth_range if args.depth_range is None else args.depth_range
    frames, records = [], []
    for camera in pops.orbit(centre, radius, steps + 1, sweep_deg=args.sweep):
        scene.camera = camera
        plan = tessellator.plan(scene, **pops.frame_options(args.level_function, camera, args.low, args.high,
                                                            args.band, depth_range, 0.5))
        records.append(np.abs(plan.host_factors()))
        frames.append(tessellator.emit(plan, 0, plan.num_patches))

    def state(record):
        lay, c = sd2._Layout(record[:3]), None
        c = lay.tip if lay.shape == "sd2" else None
        w = zone_weight(record, c) if c is not None else None
        return (f"{lay.shape} tip {lay.tip} n {lay.n} factors {np.round(np.array(record[:3]) / FIXED_ONE, 4)}"
                + (f" zone w {w:.4f}" if w is not None else ""))
    worst = []
    for k in range(steps):
        distance, _ = pops.vertex_distance(frames[k], frames[k + 1], records[k], records[k + 1])
        worst += [(float(distance[p]), k, int(p)) for p in np.argsort(distance)[::-1][:args.top]]
    for distance, k, p in sorted(worst, reverse=True)[:args.top]:
        print(f"       step {k} patch {p} moves {distance:.5f}: {state(records[k][p])} -> {state(records[k + 1][p])}",
              flush=True)


if __name__ == "__main__":
    raise SystemExit(main())
