"""Fractional point placement (D3D11 fractional_odd; docs/sd2.md section 1): the NumPy mirror
cltess/patterns/fractional.py and kernels/common.h fractional_location / boundary_point.

What must hold (issue 13): an edge's points are the same walked from either end (bitwise, on
the device, in 3D), move continuously as the factor changes (across whole numbers too), and
always include the ends."""
import numpy as np
import pyopencl as cl
from hypothesis import given, settings
from hypothesis import strategies as st

from cltess.backends.opencl.programs import correctly_rounded_division, kernel_dir
from cltess.patterns.fractional import FIXED_ONE, locations, odd_segments, split_point, to_fixed

ALL_FIXED = np.arange(FIXED_ONE, 64 * FIXED_ONE + 1, 97)  # every 97th 16.16 factor in [1, 64]
#: the 16.16 factors within 2 units of the last place of every whole number in [1, 64]
NEAR_WHOLE = np.array([w * FIXED_ONE + d for w in range(1, 65) for d in range(-2, 3)
                       if FIXED_ONE <= w * FIXED_ONE + d <= 64 * FIXED_ONE])


def test_segments_are_the_odd_ceiling():
    for fixed in ALL_FIXED:
        r = fixed / FIXED_ONE
        n = odd_segments(fixed)
        assert n % 2 == 1 and n >= r and n - 2 < r, (r, n)


def test_ends_included_monotone_and_mirrored():
    for fixed in ALL_FIXED[::5]:
        x = locations(fixed)
        assert x[0] == 0.0 and x[-1] == 1.0
        assert (np.diff(x) >= 0).all(), x
        # mirrored: point k from the start is 1 - point n-k (both placed from their nearer end)
        assert np.abs(x - (1 - x[::-1])).max() < 1e-6


def test_odd_whole_factors_are_uniform_and_even_ones_lie_between():
    for r in range(1, 64, 2):
        assert np.allclose(locations(r * FIXED_ONE), np.arange(r + 1) / r, atol=1e-6)
    # r = 2 is halfway from 1 segment (0, 1) with the pair split at 0 to 3 segments
    assert np.allclose(locations(2 * FIXED_ONE), [0, 1 / 6, 5 / 6, 1], atol=1e-6)


def test_continuous_across_whole_numbers():
    """A point set moves by O(delta) when the factor moves by delta; where the segment count
    changes (past an odd whole factor) the new points come out of an old one."""
    for r in range(1, 64):
        below, above = locations(r * FIXED_ONE), locations(r * FIXED_ONE + 1)
        # compare as sets: every point of each within 1e-3 of a point of the other
        gap = np.abs(below[:, None] - above[None, :])
        assert gap.min(axis=1).max() < 1e-3 and gap.min(axis=0).max() < 1e-3, r


@settings(max_examples=200, deadline=None)
@given(st.floats(1.0, 63.9), st.floats(1e-4, 1e-2))
def test_lipschitz_in_the_factor(r, delta):
    a, b = locations(to_fixed(r)), locations(to_fixed(r + delta))
    gap = np.abs(a[:, None] - b[None, :])
    # points move at most ~ delta / r^0 per unit factor: far below the smallest segment change
    assert max(gap.min(axis=1).max(), gap.min(axis=0).max()) <= 2.0 * delta + 2e-5, (r, delta)


def test_split_point_is_inside_the_half():
    for fixed in ALL_FIXED:
        n = odd_segments(fixed)
        if n != fixed / FIXED_ONE:  # an odd whole factor has no split
            assert split_point(fixed) < (n + 1) // 2


KERNEL = """
__kernel void placement(__global const int *fixed, __global const float4 *curve, int count, int max_points,
                        __global float *location, __global float4 *forward, __global float4 *backward)
{
    int id = get_global_id(0);
    if (id >= count) return;
    int n = odd_segments(fixed[id]);
    float4 c[4], r[4];
    for (int i = 0; i < 4; ++i) { c[i] = curve[4 * id + i]; r[i] = curve[4 * id + 3 - i]; }
    for (int k = 0; k <= n; ++k) {
        edge_param t = {k, n, fixed[id]};
        edge_param back = {n - k, n, fixed[id]};
        location[id * max_points + k] = edge_location(t);
        forward[id * max_points + k] = boundary_point(c, t);
        backward[id * max_points + k] = boundary_point(r, back);
    }
}
"""


def test_device_matches_the_mirror_and_is_bitwise_symmetric(tessellator, rng):
    # every 776th 16.16 factor, those next to whole numbers and random ones: the mirror's Python loop
    # over all of ALL_FIXED took 28 CPU-seconds, the suite's longest test
    fixed = np.concatenate([ALL_FIXED[::8], NEAR_WHOLE, rng.integers(FIXED_ONE, 64 * FIXED_ONE, 300)]).astype(np.int32)
    count, width = len(fixed), 66
    curves = rng.normal(size=(count, 4, 4)).astype(np.float32) * 10
    ctx, queue = tessellator.context, tessellator.queue
    program = cl.Program(ctx, '#include "common.h"\n' + KERNEL).build(
        options=["-I", str(kernel_dir())] + correctly_rounded_division(ctx.devices[0]))
    mf = cl.mem_flags
    bufs = [cl.Buffer(ctx, mf.READ_ONLY | mf.COPY_HOST_PTR, hostbuf=a) for a in (fixed, curves)]
    location = np.zeros((count, width), np.float32)
    forward = np.zeros((count, width, 4), np.float32)
    backward = np.zeros_like(forward)
    outs = [cl.Buffer(ctx, mf.WRITE_ONLY, a.nbytes) for a in (location, forward, backward)]
    program.placement(queue, (count,), None, *bufs, np.int32(count), np.int32(width), *outs)
    for host, buf in zip((location, forward, backward), outs):
        cl.enqueue_copy(queue, host, buf)
    for i, f in enumerate(fixed):
        n = odd_segments(int(f))
        assert np.allclose(location[i, :n + 1], locations(int(f)), atol=2e-7), f
        assert location[i, 0] == 0.0 and location[i, n] == 1.0
        # bitwise: the neighbour walking the edge the other way gets the same points
        assert np.array_equal(forward[i, :n + 1].view(np.uint32), backward[i, :n + 1].view(np.uint32)), f
        assert np.array_equal(forward[i, 0], curves[i, 0]) and np.array_equal(forward[i, n], curves[i, 3])
