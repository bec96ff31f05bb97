"""The collapse lemma behind docs/sd2.md section 5 "Fifth pass" (bench/sd2_tie_limits.py): the
paper's fan with tip c collapses onto the grid lattice by its native map (partner c+1) for every n,
labels only (so for any positions of the grid's points); the partner-c+2 map needs the other
diagonal; and at every odd m the product limits of two tips' maps differ (the birth obstruction)."""
import pytest

from support import ROOT, load_script

_bench = load_script(ROOT / "bench" / "sd2_tie_limits.py", "bench_sd2_tie_limits")
birth_mismatches, blend_min_area, check_collapse = _bench.birth_mismatches, _bench.blend_min_area, _bench.check_collapse
flipped_label, native_label, plateau_of_one = _bench.flipped_label, _bench.native_label, _bench.plateau_of_one


@pytest.mark.parametrize("n", range(1, 12))
@pytest.mark.parametrize("c", range(3))
def test_the_fan_collapses_natively_onto_the_grid(c, n):
    ok, why = check_collapse(native_label, c, n)
    assert ok, why


@pytest.mark.parametrize("n", range(2, 8))
def test_the_partner_c2_map_needs_the_other_diagonal(n):
    assert not check_collapse(flipped_label, 0, n)[0]


@pytest.mark.parametrize("m", [1, 3, 5, 7])
def test_product_limits_of_two_tips_differ_at_every_birth(m):
    counts = birth_mismatches(m)["tips c, c+1 differ"]
    assert all(v > 0 for v in counts.values())


@pytest.mark.parametrize("factor", [1.3, 2.0, 2.86, 4.5, 6.2])
@pytest.mark.parametrize("c", range(3))
def test_the_native_blend_towards_one_labelled_configuration_does_not_fold(c, factor):
    area, _ = blend_min_area(factor, (0, 1), c)
    assert area >= -1e-12


def test_near_factor_1_the_plain_fan_needs_the_grid_centre_at_its_corner_c_plus_2():
    result = plateau_of_one()
    assert result["wall collapses"] == 1 and result["vertex (2,2) at birth"] == ["r2'"]
    assert result["kept, by centre corner k"] == {0: 0, 1: 0, 2: 1}
