"""The tie zone with one grid configuration for every fan (bench/sd2_one_config.py; docs/sd2.md
section 5, "Ninth pass"), a NumPy experiment not built into the pattern: no fold-over over the
zone's (F, G) by hypothesis, every fan reaching the grid's configuration at a tie whichever corners
tie, a path past an isolated triple tie moving the mesh in proportion, and the birth obstruction
(the fifth pass's (B)) as measured: the base's factor crossing an odd number inside the zone
jumps for the tips whose corner c+2 is one of the configuration's pair."""
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from cltess.patterns.fractional import FIXED_ONE, odd_segments
from support import ROOT, load_script
from test_sd2_pattern import hinted_record, lifted_distance, plateau_error, same_surface, signed_areas

one_config = load_script(ROOT / "bench" / "sd2_one_config.py", "bench_sd2_one_config")


def fan(c: int, big: int, base: int) -> list:
    f = [0, 0, 0]
    f[c], f[(c + 2) % 3], f[(c + 1) % 3] = big, big, base
    return f


@settings(max_examples=300, deadline=None)
@given(st.integers(FIXED_ONE + 1, 13 * FIXED_ONE), st.integers(1, FIXED_ONE - 1), st.integers(0, 2))
def test_the_one_configuration_zone_does_not_fold(big, gap, c):
    f = fan(c, big, max(big - gap, FIXED_ONE))  # a fan (F > G) in the zone
    uv, triangles = one_config.one_config_pattern(f)
    areas = signed_areas(uv, triangles)
    # zero-area triangles where the configuration collapses points: float32 edge locations give
    # them areas of a few 1e-9 either side (as tests/test_sd2_pattern.py's tie zone, tolerance 1e-7)
    assert areas.min() >= -1e-7, (f, areas.min())
    assert abs(areas.sum() - 0.5) < 1e-7, f  # float32 edge locations
    a, b = odd_segments(f[c]), odd_segments(f[(c + 1) % 3])
    assert len(uv) == len(np.unique(triangles)) == a * (b + 1) + 1 and len(triangles) == b * (2 * a - 1), f


def test_every_fan_reaches_the_grid_configuration_at_a_tie():
    one_config.use("one")
    try:
        for h in (1.7, 2.0, 2.86, 4.4, 6.3, 8.9):
            grid = [round(h * FIXED_ONE)] * 3
            for c in range(3):
                assert same_surface(fan(c, grid[0] + 1, grid[0]), grid) < 1e-4, (h, c)
    finally:
        one_config.use("main")


def passing_worst(step: float) -> float:
    """A path passing within about 0.01 of a triple tie at 2.86 (sphere-320 depth's worst patches;
    bench/sd2_zone_model.py passing): the worst step, in factor-1 errors."""
    def at(x):
        return hinted_record([round(v * FIXED_ONE) for v in (2.96 - x, 2.85 + 0.15 * (0.1 - x), 2.82 + 0.5 * x)])
    xs = np.arange(0.0, 0.2 + 1e-9, step)
    return max(lifted_distance(at(x), at(y)) for x, y in zip(xs[:-1], xs[1:])) / plateau_error(1)


def test_passing_an_isolated_triple_tie_moves_in_proportion_with_one_configuration():
    one_config.use("one")
    try:
        coarse, fine = passing_worst(0.02), passing_worst(0.01)
    finally:
        one_config.use("main")
    assert coarse < 0.03 and fine < 0.7 * coarse, (coarse, fine)  # main: 0.226 / 0.225


def test_the_base_crossing_an_odd_number_in_the_zone_jumps_for_two_tips():
    """G crossing 3 with F = 3.4 (w about 0.4): tip 0 (its corners c, c+1 the configuration's pair)
    is continuous, tips 1 and 2 jump by about the factor-3 error (main's zone: continuous)."""
    one_config.use("one")
    try:
        jumps = []
        for c in range(3):
            def record(s):
                phi = [0.0, 0.0, 0.0]
                phi[c], phi[(c + 1) % 3], phi[(c + 2) % 3] = 3.4, 2.7, 3.0 + s
                return hinted_record([round(x * FIXED_ONE) for x in phi])
            jumps.append(lifted_distance(record(-1e-4), record(1e-4)) / plateau_error(3))
    finally:
        one_config.use("main")
    assert jumps[0] < 0.01 and min(jumps[1:]) > 0.3, jumps


# ---- the "follow" variant (session 9, branch sd2j; docs/sd2.md section 5, "Tenth pass"): main's layout
# for every record whose largest factor is at most 3, the birth variant (C on the ties, the fan's own
# product on its birth lines) above, never blended


@settings(max_examples=60, deadline=None)
@given(st.integers(3 * FIXED_ONE + 1, 9 * FIXED_ONE), st.integers(1, FIXED_ONE - 1), st.integers(0, 2))
def test_the_follow_zone_above_3_does_not_fold(big, gap, c):
    one_config.use("follow")
    try:
        uv, triangles = one_config.follow_pattern(fan(c, big, big - gap))
    finally:
        one_config.use("main")
    areas = signed_areas(uv, triangles)
    assert areas.min() >= -1e-7 and abs(areas.sum() - 0.5) < 1e-7, (big, gap, c, areas.min())


def crossing_jump(phi_at, error) -> list:
    """The jump, by tip, as phi_at(s) crosses s = 0 (one 1e-4 either side), in units of `error`."""
    jumps = []
    for c in range(3):
        def record(s):
            phi = [0.0, 0.0, 0.0]
            for k, value in enumerate(phi_at(s)):
                phi[(c + k) % 3] = value
            return hinted_record([round(x * FIXED_ONE) for x in phi])
        jumps.append(lifted_distance(record(-1e-4), record(1e-4)) / error)
    return jumps


def test_follow_is_continuous_at_births_above_3_and_jumps_where_it_leaves_main_with_lam_below_1():
    """Above 3 the births are continuous for every tip (`one`: tips 1 and 2 jump); the tip edges
    crossing 3 switch from main's zone to the birth variant's: continuous where main's lam is 1 (the
    larger base corner is c+1, target P on both sides), a jump where it is not (main's lam blend
    against P; measured 0.086-0.166 of the factor-1 error)."""
    one_config.use("follow")
    try:
        births = crossing_jump(lambda s: (5.4, 4.7, 5.0 + s), plateau_error(5))  # G crossing 5, F = 5.4
        lam_one = crossing_jump(lambda s: (3.0 + s, 2.7, 2.4), plateau_error(1))  # F crossing 3, c+1 larger
        lam_below = crossing_jump(lambda s: (3.0 + s, 2.4, 2.7), plateau_error(1))  # c+2 larger: lam 4/7
    finally:
        one_config.use("main")
    assert max(births) < 0.01 and max(lam_one) < 0.01, (births, lam_one)
    assert min(lam_below) > 0.05, lam_below


def test_follow_main_has_no_seam_at_3_but_folds_where_it_blends_two_diagonals():
    """The variant "follow-main" (main's own target M in place of P above 3): F crossing 3 with lam
    below 1 is continuous (M on both sides), but the blend of C (the fan's own diagonal) with M (the
    other diagonal, through main's centres) folds: phi (3.016, 3.020, 3.0007), tip 1, beta 0.8, lam
    0.21, found among 1,500 random records near odd factors (main's smallest there -9.9e-9)."""
    one_config.use("follow-main")
    try:
        seam = crossing_jump(lambda s: (3.0 + s, 2.4, 2.7), plateau_error(1))
        record = hinted_record([round(x * FIXED_ONE) for x in (3.0159631, 3.01995121, 3.00074566)])
        folded = signed_areas(*one_config.follow_main_pattern(record)).min()
        main = signed_areas(*one_config.MAIN_PATTERN(record)).min()
    finally:
        one_config.use("main")
    assert max(seam) < 0.01, seam
    assert folded < -1e-6 and main > -1e-7, (folded, main)
