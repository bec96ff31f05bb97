"""Stage 5 (kernels/indices.cl, Tessellator.stage_indices) against reference.quad_pattern."""
import itertools

import numpy as np
import pyopencl.array as cl_array
from hypothesis import given, settings, strategies as st

from cltess import reference
from test_counts import random_factors


def device_triangles(tessellator, factors):
    final = cl_array.to_device(tessellator.queue, factors)
    vertex_offsets, index_offsets, _ = tessellator.stage_counts(final)
    total = int(index_offsets[len(factors)].get())
    triangles, _ = tessellator.stage_indices(final, vertex_offsets, index_offsets, (0, total), (0, len(factors)))
    return triangles.get(), vertex_offsets.get()


def test_indices_match_reference_on_random_factors(tessellator, rng):
    factors = random_factors(rng, 800)
    got, vertex_offsets = device_triangles(tessellator, factors)
    expected = [reference.quad_pattern(f)[1] + vertex_offsets[p] for p, f in enumerate(factors)]
    assert np.array_equal(got, np.concatenate(expected))
    assert got.max() < vertex_offsets[-1]  # every index in range


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
