"""Stage 5 a work-item per triangle (stages/triangles.cl, issue 15) against the NumPy mirror: on
random quad factors (uniform grids, transitions, collapsed edges, culled patches) the kernel's
indices are cltess.patterns.quad_transition.quad_pattern's, each patch's triangles offset by its
first vertex; for the whole scene and a batch inside it (first_patch > 0; also at an output
offset of one triangle, so not 8-byte aligned: a cell's pair by vstore3), at 1, 3, 16 and 40
triangles per work-item (a work-item's triangles cross patches, and the batch's end falls inside
a work-group).  Random access (pattern_triangle_at) makes the uniform grids' triangles,
pattern_primitives the others'."""
import numpy as np
import pyopencl as cl
import pyopencl.array as cl_array
import pyopencl.cltypes as cltypes
import pytest

from cltess.backends.opencl import tessellator as opencl
from cltess.kinds import BEZIER
from cltess.patterns.quad_transition import quad_pattern


def random_quad_factors(rng, count: int) -> np.ndarray:
    """(count, 4) int32: a third uniform grids (some 1 x n), a third transitions, some culled
    (all 0), and each edge collapsed (negative, as stage 2 marks it) with probability 1/8."""
    factors = rng.integers(1, 20, (count, 4))
    uniform = rng.random(count) < 2 / 3
    factors[uniform, 2], factors[uniform, 3] = factors[uniform, 0], factors[uniform, 1]
    factors[rng.random(count) < 0.1] = 0
    factors[rng.random((count, 4)) < 1 / 8] *= -1
    return factors.astype(np.int32)


def mirror(factors: np.ndarray):
    """(vertex_offsets, index_offsets, triangles) of every patch by the NumPy mirror."""
    patterns = [quad_pattern(tuple(f)) for f in factors]
    vertex_offsets = np.concatenate([[0], np.cumsum([len(uv) for uv, _ in patterns])]).astype(np.uint64)
    index_offsets = np.concatenate([[0], np.cumsum([3 * len(t) for _, t in patterns])]).astype(np.uint64)
    triangles = [t + vertex_offsets[p] for p, (_, t) in enumerate(patterns)]
    return vertex_offsets, index_offsets, np.concatenate(triangles).astype(np.uint32)


@pytest.mark.parametrize("per_item", [1, 3, 16, 40])
def test_triangles_are_the_mirrors(tessellator, rng, per_item):
    by_points = opencl.Tessellator(tessellator.device, work="point")
    by_points.records_per_item = per_item
    factors = random_quad_factors(rng, 600)
    vertex_offsets, index_offsets, expected = mirror(factors)
    queue = by_points.queue
    device = {name: cl_array.to_device(queue, a) for name, a in
              (("factors", factors.view(cltypes.int4).reshape(-1)), ("vertices", vertex_offsets),
               ("indices", index_offsets))}
    # the whole scene; a batch inside it; the same batch in a range one triangle longer at its
    # start, so that the batch's output is not 8-byte aligned (a cell's pair then by vstore3, not
    # as three 8-byte words)
    for first, last, before in ((0, len(factors), 0), (37, 451, 0), (37, 451, 1)):
        start, stop = int(index_offsets[first]), int(index_offsets[last])
        assert start >= 3 * before
        got, events = by_points.stage_indices(device["factors"], device["vertices"], device["indices"],
                                              (start - 3 * before, stop), (first, last), kind=BEZIER, work="point")
        cl.wait_for_events(events)
        got = got.get().reshape(-1)[3 * before:]
        assert np.array_equal(got, expected.reshape(-1)[start:stop]), (first, last, before)
