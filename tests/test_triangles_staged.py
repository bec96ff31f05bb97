"""Stage 5 a work-item per triangle, in runs with staged stores (stages/triangles.cl, issue 15): on random
quad factors (uniform grids, transitions, collapsed edges, culled patches) the kernel's indices are
the NumPy mirror's (cltess.patterns.quad_transition.quad_pattern, each patch's triangles offset by
its first vertex), in batches (first_patch > 0) and at several triangles per work-item (runs of 1, 3 and 16; 40 is
three steps, the last one partial), so that runs and steps end inside a patch, past the batch's end
and on the whole-patch emissions; and the kernel's work-group size is the host's."""
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


def test_triangle_group_is_the_hosts(tessellator):
    constants = np.zeros(2, np.uint32)  # TRIANGLE_GROUP, TRIANGLE_RUN
    buffer = cl.Buffer(tessellator.context, cl.mem_flags.READ_WRITE, constants.nbytes)
    tessellator.programs.kernel("triangles", "triangle_constants", pattern=BEZIER.pattern)(
        tessellator.queue, (1,), None, buffer)
    cl.enqueue_copy(tessellator.queue, constants, buffer)
    assert constants[0] == opencl.WORK_GROUP and constants[1] >= 1


@pytest.mark.parametrize("per_item", [1, 3, 16, 40])
def test_staged_triangles_are_the_mirrors(tessellator, rng, per_item):
    by_points = opencl.Tessellator(tessellator.device, work="point")
    by_points.records_per_item = per_item
    factors = random_quad_factors(rng, 600)
    vertex_offsets, index_offsets, expected = mirror(factors)
    queue = by_points.queue
    device = {name: cl_array.to_device(queue, a) for name, a in
              (("factors", factors.view(cltypes.int4).reshape(-1)), ("vertices", vertex_offsets),
               ("indices", index_offsets))}
    for first, last in ((0, len(factors)), (37, 451)):  # the whole scene; a batch inside it
        start, stop = int(index_offsets[first]), int(index_offsets[last])
        got, events = by_points.stage_indices(device["factors"], device["vertices"], device["indices"],
                                              (start, stop), (first, last), kind=BEZIER, work="point")
        cl.wait_for_events(events)
        assert np.array_equal(got.get().reshape(-1), expected.reshape(-1)[start:stop]), (first, last)
