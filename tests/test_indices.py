"""The patterns' own properties (cltess.patterns: valid triangulations, the Filip bound on every
triangle).  The kernels against these mirrors: tests/contracts/test_patterns.py."""
import itertools

import numpy as np
from hypothesis import given, settings, strategies as st

from cltess import reference


def assert_pattern_is_a_valid_triangulation(f):
    """Counter-clockwise, covering the unit square exactly once, boundary = the ring."""
    uv, tris = reference.quad_pattern(f)
    a, b, c = uv[tris[:, 0]], uv[tris[:, 1]], uv[tris[:, 2]]
    area = ((b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0]) / 2
    assert (area > 0).all(), "degenerate or flipped triangle"
    assert abs(area.sum() - 1) < 1e-12
    directed = np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]])
    edges = set(map(tuple, directed))
    assert len(edges) == len(directed)
    boundary = {e for e in edges if e[::-1] not in edges}
    ring = sum(f)
    assert boundary == {(k, (k + 1) % ring) for k in range(ring)}


def test_every_small_factor_combination_gives_a_valid_pattern():
    for f in itertools.product([1, 2, 3, 4, 7], repeat=4):
        assert_pattern_is_a_valid_triangulation(f)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.integers(1, 64), min_size=4, max_size=4))
def test_random_factor_patterns_are_valid(f):
    assert_pattern_is_a_valid_triangulation(f)


# --- PN triangles: reference.tri_pattern, kernels pn_indices ---------------------------------

EDGE_DIRECTIONS_UV = np.array([[-1.0, 1.0], [0.0, -1.0], [1.0, 0.0]])  # d_e in (u, v)


def filip_radius2(f, uv, tris):
    """Per triangle, the smallest over the three pairs of edge directions (d_a, d_b) of the
    squared radius of its smallest enclosing circle in coordinates (alpha f_a, beta f_b), where
    x = alpha d_a + beta d_b.  <= 1/2 means the Filip bound holds on it: per direction e the
    factors guarantee (D_ee + D_e*) / f_e^2 <= 4 eps, so |surface - triangle| <= 2 eps r^2
    (Taylor at each point; docs/design.md section 3).  The core's grid triangles have exactly 1/2."""
    p = uv[tris] - uv[tris][:, :1]  # (T, 3, 2)
    best = np.full(len(tris), np.inf)
    for a, b in ((0, 1), (1, 2), (2, 0)):
        basis = np.stack([EDGE_DIRECTIONS_UV[a] / f[a], EDGE_DIRECTIONS_UV[b] / f[b]], axis=1)
        q = p @ np.linalg.inv(basis).T  # (T, 3, 2) scaled coordinates
        sides = np.stack([((q[:, (k + 1) % 3] - q[:, (k + 2) % 3]) ** 2).sum(-1) for k in range(3)], 1)
        longest = sides.max(1)
        obtuse = longest >= sides.sum(1) - longest
        cross = np.abs((q[:, 1, 0] - q[:, 0, 0]) * (q[:, 2, 1] - q[:, 0, 1])
                       - (q[:, 1, 1] - q[:, 0, 1]) * (q[:, 2, 0] - q[:, 0, 0]))
        circum = sides.prod(1) / (4 * cross ** 2)  # (abc / 4 area)^2, area = cross / 2
        best = np.minimum(best, np.where(obtuse, longest / 4, circum))
    return best


def assert_triangle_pattern_is_valid(f):
    """Counter-clockwise, covering the domain triangle exactly once, boundary = the ring, every
    vertex used, counts as stated, and the Filip bound kept on every triangle."""
    uv, tris = reference.tri_pattern(f)
    n = max(f[:3])
    assert len(uv) == sum(f[:3]) + (n - 1) * (n - 2) // 2
    a, b, c = uv[tris[:, 0]], uv[tris[:, 1]], uv[tris[:, 2]]
    area = ((b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0]) / 2
    assert (area > 0).all(), "degenerate or flipped triangle"
    assert abs(area.sum() - 0.5) < 1e-12
    directed = np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]])
    edges = set(map(tuple, directed))
    assert len(edges) == len(directed)
    boundary = {e for e in edges if e[::-1] not in edges}
    ring = sum(f[:3])
    assert boundary == {(k, (k + 1) % ring) for k in range(ring)}
    assert np.array_equal(np.unique(tris), np.arange(len(uv)))
    assert filip_radius2(f, uv, tris).max() <= 0.5 + 1e-9


def test_every_small_triangle_factor_combination_gives_a_valid_pattern():
    for f in itertools.product([1, 2, 3, 4, 5, 8], repeat=3):
        assert_triangle_pattern_is_valid(f)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.integers(1, 64), min_size=3, max_size=3), st.integers(0, 2), st.booleans())
def test_random_triangle_factor_patterns_are_valid(f, top, two):
    """Random factors, biased to the patterns that occur: after stage 2 at least one edge of a
    triangle often has the core factor, with one or two edges below it."""
    f = list(f)
    f[top] = max(f)
    if two:
        f[(top + 1) % 3] = f[top]
    assert_triangle_pattern_is_valid(f)


def test_factors_one_give_the_coarse_triangle():
    uv, tris = reference.tri_pattern((1, 1, 1))
    assert uv.tolist() == [[1, 0], [0, 1], [0, 0]] and tris.tolist() == [[0, 1, 2]]


def test_the_filip_check_rejects_a_stretched_triangle():
    """The check itself: a triangle reaching two core steps from the edge fails it."""
    uv = np.array([[0.0, 0.0], [0.5, 0.0], [0.25, 0.5]])
    assert filip_radius2((4, 4, 4), uv, np.array([[0, 1, 2]]))[0] > 0.5
    assert filip_radius2((4, 4, 4), uv / 2, np.array([[0, 1, 2]]))[0] <= 0.5
