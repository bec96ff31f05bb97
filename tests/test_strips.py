"""The strip convention of cltess/strips.py: restart-separated, first triangle's winding kept."""
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from cltess.strips import (STRIP_RESTART, expand_strips, join_strips, split_strips, strip_index_count,
                           strip_triangle_count)


def test_a_strip_alternates_to_keep_the_winding():
    # The quad 0-1-2-3 as the strip 0 1 3 2 (x right, y up: 0 (0,0), 1 (1,0), 2 (1,1), 3 (0,1)).
    triangles = expand_strips(np.array([0, 1, 3, 2], np.uint32))
    assert triangles.tolist() == [[0, 1, 3], [3, 1, 2]]
    xy = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    a, b, c = (xy[triangles[:, k]] for k in range(3))
    cross = (b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0]
    assert (cross > 0).all()  # both counter-clockwise


def test_restart_separates_strips_and_short_strips_are_refused():
    joined = join_strips([[0, 1, 2], [3, 4, 5, 6]])
    assert joined.tolist() == [0, 1, 2, int(STRIP_RESTART), 3, 4, 5, 6]
    assert expand_strips(joined).tolist() == [[0, 1, 2], [3, 4, 5], [5, 4, 6]]
    assert strip_index_count([3, 4]) == len(joined) and strip_triangle_count([3, 4]) == 3
    with pytest.raises(ValueError, match="at least 3"):
        join_strips([[0, 1]])
    assert join_strips([]).size == 0 and expand_strips(join_strips([])).shape == (0, 3)


def test_degenerate_turns_can_be_dropped():
    strip = np.array([0, 1, 2, 2, 3, 4], np.uint32)
    assert len(expand_strips(strip)) == 4
    # The repeated 2 is a "swap": it flips the parity, so the strip goes on with (3 2 4).
    assert expand_strips(strip, drop_degenerate=True).tolist() == [[0, 1, 2], [3, 2, 4]]


@given(st.lists(st.lists(st.integers(0, 1000), min_size=3, max_size=20), max_size=8))
def test_join_split_expand_agree(strips):
    joined = join_strips(strips)
    assert [s.tolist() for s in split_strips(joined)] == strips
    lengths = [len(s) for s in strips]
    assert len(joined) == strip_index_count(lengths)
    assert len(expand_strips(joined)) == strip_triangle_count(lengths)
