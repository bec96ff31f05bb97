"""Stage 3 (stages/counts.cl + pyopencl.scan, Tessellator.stage_counts): known counts, a large scan,
kinds side by side.  Random factors against the mirrors: tests/contracts/test_patterns.py."""
import numpy as np
import pyopencl.array as cl_array

from cltess import reference
from support.factors import random_factors, random_triangle_factors


def device_offsets(tessellator, factors):
    vertex_offsets, index_offsets, _ = tessellator.stage_counts(cl_array.to_device(tessellator.queue, factors))
    return vertex_offsets.get(), index_offsets.get()


def test_uniform_grid_counts(tessellator):
    factors = np.array([[1, 1, 1, 1], [4, 3, 4, 3], [64, 64, 64, 64], [0, 0, 0, 0]], np.int32)
    vertex_offsets, index_offsets = device_offsets(tessellator, factors)
    assert np.diff(vertex_offsets).tolist() == [4, 20, 65 * 65, 0]
    assert np.diff(index_offsets).tolist() == [6, 3 * 24, 3 * 2 * 64 * 64, 0]


def test_scan_of_a_large_batch(tessellator, rng):
    """Enough patches for pyopencl.scan to use several work-groups."""
    factors = rng.integers(1, 8, size=(200_000, 4)).astype(np.int32)
    factors[:, 2:] = factors[:, :2]
    vertex_offsets, index_offsets = device_offsets(tessellator, factors)
    m, n = factors[:, 0].astype(np.int64), factors[:, 1].astype(np.int64)
    assert np.array_equal(np.diff(vertex_offsets), (m + 1) * (n + 1))
    assert np.array_equal(np.diff(index_offsets), 6 * m * n)


def test_uniform_triangle_counts(tessellator):
    from cltess.pipeline import PN

    factors = np.array([[1, 1, 1, 0], [4, 4, 4, 0], [64, 64, 64, 0], [0, 0, 0, 0]], np.int32)
    vertex_offsets, index_offsets, _ = tessellator.stage_counts(cl_array.to_device(tessellator.queue, factors),
                                                                kind=PN)
    assert np.diff(vertex_offsets.get()).tolist() == [3, 15, 65 * 66 // 2, 0]  # (n+1)(n+2)/2
    assert np.diff(index_offsets.get()).tolist() == [3, 3 * 16, 3 * 64 * 64, 0]  # n^2 triangles


def test_counts_of_kinds_side_by_side(tessellator, rng):
    """A scene's (P, 4) factors hold Bézier patches then PN triangles: one scan over both."""
    from cltess.pipeline import BEZIER, PN

    quads, triangles = random_factors(rng, 300), random_triangle_factors(rng, 500)
    factors = np.concatenate([quads, triangles])
    vertex_offsets, index_offsets, _ = tessellator.stage_counts(
        cl_array.to_device(tessellator.queue, factors), kind=[(BEZIER, 0, 300), (PN, 300, 500)])
    counts = [np.concatenate(pair) for pair in zip(reference.counts(quads), reference.counts(triangles, kind="pn"))]
    assert np.array_equal(vertex_offsets.get(), reference.offsets(counts[0]))
    assert np.array_equal(index_offsets.get(), reference.offsets(counts[1]))
