"""The SD-2 pattern's NumPy mirror (cltess/patterns/sd2.py): exhaustive over whole factor
triples and random fractional ones: no fold-over, areas sum to the domain, the closed-form
counts, the tip where the equal edges meet, strips expanding to exactly the triangle list."""
import itertools

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from cltess.patterns.fractional import FIXED_ONE, odd_segments, to_fixed
from cltess.patterns.sd2 import sd2_counts, sd2_pattern, sd2_shape, sd2_strip_indices
from cltess.strips import STRIP_RESTART, expand_strips


def signed_areas(uv, triangles):
    a, b, c = (uv[triangles[:, k]] for k in range(3))
    return 0.5 * ((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))


def check_pattern(f):
    uv, triangles = sd2_pattern(f)
    vertices, count, strip_indices = sd2_counts(f)
    assert (len(uv), len(triangles)) == (vertices, count), f
    areas = signed_areas(uv.astype(np.float64), triangles)
    assert areas.min() >= -1e-9, (f, areas.min())  # no fold-over (zero-area where points coincide)
    assert abs(areas.sum() - 0.5) < 1e-6, (f, areas.sum())
    assert len(np.unique(triangles)) == vertices  # every vertex used
    strips = sd2_strip_indices(f)
    assert len(strips) == strip_indices and strips[-1] == np.int64(STRIP_RESTART)
    expanded = expand_strips(strips.astype(np.uint32))
    assert np.array_equal(expanded.astype(np.int64), triangles)
    # every edge of the mesh inside the triangle is shared by exactly two triangles, so the
    # winding is consistent: each directed edge appears once
    directed = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    nondegenerate = np.repeat(areas > 1e-12, 1)
    keep = np.tile(nondegenerate, 3)
    assert len(np.unique(directed[keep], axis=0)) == keep.sum(), f


def test_whole_factor_triples_exhaustive():
    for f in itertools.product(range(1, 14), repeat=3):
        check_pattern([x * FIXED_ONE for x in f])


def test_closed_forms():
    for a, b in itertools.product(range(1, 20), repeat=2):
        fa, fb = a * FIXED_ONE, b * FIXED_ONE
        na, nb = odd_segments(fa), odd_segments(fb)
        if a != b:
            assert sd2_counts([fa, fa, fb])[:2] == (na * (nb + 1) + 1, nb * (2 * na - 1))
        else:
            assert sd2_counts([fa, fa, fa])[:2] == ((na + 1) * (na + 2) // 2, na * na)


@settings(max_examples=300, deadline=None)
@given(st.lists(st.floats(1.0, 64.0), min_size=3, max_size=3), st.integers(0, 3))
def test_random_fractional_factors(reals, ties):
    f = list(to_fixed(reals))
    if ties == 1:
        f[1] = f[0]
    elif ties == 2:
        f[2] = f[1] = f[0]
    check_pattern(f)


def test_tip_is_where_the_equal_edges_meet():
    a, b = 5 * FIXED_ONE + 123, 9 * FIXED_ONE
    # edge e runs from corner e to corner e+1: edges 2 and 0 meet at corner 0, 0 and 1 at 1
    assert sd2_shape([a, b, a]) == ("sd2", 0)
    assert sd2_shape([a, a, b]) == ("sd2", 1)
    assert sd2_shape([b, a, a]) == ("sd2", 2)
    assert sd2_shape([a, a, a]) == ("grid", 0)
    assert sd2_shape([a, a + 1, b]) == ("transition", -1)
    uv, triangles = sd2_pattern([a, a, b])
    # the tip (corner 1, uv (0, 1)) is the fan's centre: in b triangles
    tip = np.flatnonzero((np.abs(uv - [0, 1]) < 1e-7).all(axis=1))
    assert len(tip) == 1 and (triangles == tip[0]).any(axis=1).sum() == odd_segments(b)


def test_paper_counts_at_factor_7():
    """SEEDS.md 2.1: at f = 7 the SD-2 pattern has 91 triangles, the uniform grid 49."""
    assert sd2_counts([7 * FIXED_ONE] * 3)[1] == 49
    assert 7 * (2 * 7 - 1) == 91 and sd2_counts([7 * FIXED_ONE, 7 * FIXED_ONE, 7 * FIXED_ONE - 1])[1] == 91
