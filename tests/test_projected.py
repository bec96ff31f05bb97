"""Stage 4's exact shortcut against NumPy's float32 division, bit for bit, on random input:
``projected`` (kernels/kinds/bezier.h: h.xyz / h.w with no division where h.w is exactly 1) must
give the correctly rounded quotient's bits, signed zeros and infinities included, which is what
NumPy's IEEE division gives."""
import numpy as np
import pyopencl as cl

from cltess.backends.opencl.programs import correctly_rounded_division, kernel_dir

KERNEL = """
__kernel void points(__global const float4 *h, __global float *out)
{
    int id = get_global_id(0);
    vstore3(projected(h[id]), id, out);
}
"""


def build(tessellator):
    ctx = tessellator.context
    options = ["-I", str(kernel_dir())] + correctly_rounded_division(ctx.devices[0])
    return cl.Program(ctx, '#include "kinds/bezier.h"\n' + KERNEL).build(options=options), bool(options[2:])


def run(tessellator, kernel_name, inputs, out):
    ctx, queue = tessellator.context, tessellator.queue
    program, _ = build(tessellator)
    mf = cl.mem_flags
    buffers = [cl.Buffer(ctx, mf.READ_ONLY | mf.COPY_HOST_PTR, hostbuf=a) for a in inputs]
    result = cl.Buffer(ctx, mf.WRITE_ONLY, out.nbytes)
    getattr(program, kernel_name)(queue, (len(inputs[0]),), None, *buffers, result)
    cl.enqueue_copy(queue, out, result)
    return out


def test_projected_is_the_division(tessellator):
    rng = np.random.default_rng(9)
    count = 8000
    h = (rng.standard_normal((count, 4)) * 2.0 ** rng.integers(-20, 20, (count, 4))).astype(np.float32)
    h[: count // 2, 3] = 1.0  # the shortcut's half
    special = np.array([0.0, -0.0, np.inf, -np.inf, 1e-40, -1e-40, 3.4e38, -1.0, 1.0], np.float32)
    h[: count // 4, :3] = rng.choice(special, (count // 4, 3))  # signed zeros, infinities, subnormals
    h[count // 2: count // 2 + 100, 3] = np.nextafter(np.float32(1), np.float32(2))  # not 1, only near it
    got = run(tessellator, "points", [h], np.empty((count, 3), np.float32))
    with np.errstate(all="ignore"):
        want = h[:, :3] / h[:, 3:]
    unit = h[:, 3] == 1.0
    assert np.array_equal(got[unit].view(np.uint32), h[unit, :3].view(np.uint32))  # x / 1 is x
    assert np.array_equal(got[unit].view(np.uint32), want[unit].view(np.uint32))
    _, correctly_rounded = build(tessellator)
    normal = ~unit & np.isfinite(want).all(axis=1) & (np.abs(want) > 1e-37).all(axis=1)
    if correctly_rounded:  # elsewhere OpenCL allows 2.5 ulp for a division
        assert np.array_equal(got[normal].view(np.uint32), want[normal].view(np.uint32))
    assert unit.sum() == count // 2 and normal.sum() > count // 4
