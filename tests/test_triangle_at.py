"""Random access to a regular patch's triangles (``pattern_triangle_at`` in
kernels/patterns/quad_transition.h, used by stage 5 a work-item per triangle,
stages/triangles.cl) against the pattern's own emission (``pattern_primitives``, grid_cells):
every uniform A x B grid up to 7 x 7 under every one of the 16 collapsed-edge masks,
exhaustively, triangle by triangle; and no random access for a non-uniform patch."""
import itertools

import numpy as np
import pyopencl as cl

from cltess.backends.opencl.programs import correctly_rounded_division, kernel_dir

KERNEL = """
__kernel void both(__global const int4 *factors, __global const int *masks, int width,
                   __global uint *emitted, __global uint *counts, __global uint *random, __global int *offered)
{
    int id = get_global_id(0);
    int4 f = factors[id];
    uint n = pattern_primitives(f, masks[id], emitted + 3 * width * id, 0);
    counts[id] = n;
    uint3 triangle;
    offered[id] = pattern_triangle_at(f, masks[id], 0, &triangle);
    for (uint t = 0; t < n && offered[id]; ++t) {
        pattern_triangle_at(f, masks[id], t, &triangle);
        vstore3(triangle, width * id + t, random);
    }
}
"""


def run_both(tessellator, factors, masks, width):
    ctx, queue = tessellator.context, tessellator.queue
    program = cl.Program(ctx, '#include "common.h"\n#include "patterns/quad_transition.h"\n' + KERNEL).build(
        options=["-I", str(kernel_dir())] + correctly_rounded_division(ctx.devices[0]))
    mf = cl.mem_flags
    inputs = [cl.Buffer(ctx, mf.READ_ONLY | mf.COPY_HOST_PTR, hostbuf=a) for a in (factors, masks)]
    count = len(factors)
    emitted = np.full((count, width, 3), 0xFFFFFFFF, np.uint32)
    random = emitted.copy()
    counts, offered = np.zeros(count, np.uint32), np.zeros(count, np.int32)
    outs = [cl.Buffer(ctx, mf.READ_WRITE | mf.COPY_HOST_PTR, hostbuf=a) for a in (emitted, counts, random, offered)]
    program.both(queue, (count,), None, *inputs, np.int32(width), *outs)
    for host, buf in zip((emitted, counts, random, offered), outs):
        cl.enqueue_copy(queue, host, buf)
    return emitted, counts, random, offered


def test_every_collapsed_mask_of_every_small_grid(tessellator):
    cases = [(a, b, mask) for a, b in itertools.product(range(1, 8), repeat=2) for mask in range(16)]
    factors = np.array([(a, b, a, b) for a, b, _ in cases], np.int32)
    masks = np.array([mask for *_, mask in cases], np.int32)
    emitted, counts, random, offered = run_both(tessellator, factors, masks, width=2 * 7 * 7)
    assert offered.all()
    for case, n, emit, rand in zip(cases, counts, emitted, random):
        a, b, mask = case
        # grid_cells leaves out a triangle with a side on a collapsed edge: a row or column's worth
        assert n <= 2 * a * b and (mask or n == 2 * a * b), case
        assert np.array_equal(rand[:n], emit[:n]), case
    assert counts.min() == 0 and (counts > 0).sum() > len(cases) // 2  # degenerate grids too


def test_no_random_access_without_uniform_factors(tessellator):
    factors = np.array([(3, 2, 4, 2), (3, 2, 3, 5), (2, 2, 2, 3)], np.int32)
    _, counts, _, offered = run_both(tessellator, factors, np.zeros(3, np.int32), width=64)
    assert not offered.any() and (counts > 0).all()
