"""Stage 5 of the quad transition pattern (``grid_cells`` in kernels/patterns/quad_transition.h:
a row's inner cells in one loop, the ring's cells by ``uniform_grid_index`` on a uniform grid)
against its NumPy mirror (cltess/patterns/quad_transition.py ``quad_pattern``) on random factors
with random collapsed edges (a negative factor, as stage 2 marks them): uniform grids, where
every cell on the ring takes the new index path, and transition patterns, whose inner grid
takes the inner-cell loop.  tests/contracts/test_patterns.py checks the same without collapsed
edges; tests/test_triangle_at.py checks small uniform grids under every collapsed mask against
``pattern_triangle_at``."""
import numpy as np

from cltess.patterns import PATTERNS
from support.factors import device_counts_and_indices, offsets


def random_collapsed_factors(rng, count, high=40):
    """(count, 4) factors: half uniform (f0 = f2, f1 = f3), the rest transitions, small ones
    (1-3: the ring's cells meet at the corners) as often as large ones; each edge collapsed
    (negated) with probability 0.3."""
    small = rng.random((count, 4)) < 0.5
    factors = np.where(small, rng.integers(1, 4, (count, 4)), rng.integers(1, high, (count, 4))).astype(np.int32)
    uniform = rng.random(count) < 0.5
    factors[uniform, 2], factors[uniform, 3] = factors[uniform, 0], factors[uniform, 1]
    collapsed = rng.random((count, 4)) < 0.3
    collapsed[collapsed.all(axis=1)] = False  # a patch whose every edge is collapsed is a point
    return np.where(collapsed, -factors, factors).astype(np.int32), uniform


def test_collapsed_grids_equal_the_mirror(tessellator, rng):
    pattern = PATTERNS["quad_transition"]
    factors, uniform = random_collapsed_factors(rng, 800)
    assert uniform.sum() > 300 and (factors < 0).any(axis=1)[uniform].sum() > 100
    layouts, firsts, got = device_counts_and_indices(tessellator, pattern, factors, work="patch")
    index_firsts = offsets([len(t) for _, t in layouts])
    for p, (_, expected) in enumerate(layouts):  # patch by patch, so that a failure names its factors
        assert np.array_equal(got[index_firsts[p]:index_firsts[p + 1]], expected + firsts[p]), factors[p]
