"""Stage 4's normals without a zero dividend (kernels/common.h: ``quotient_by_positive``,
``normal_length``, ``unit_or``) against what they replace, bit for bit, on the device:
``unit_or(n, +z)`` must give ``length(n) > 0 ? n / length(n) : +z`` (kinds/bezier.h's
``surface_normal`` before) for any float3, signed zeros, infinities, NaNs and subnormals included;
``normal_length`` must be ``length`` (on NVIDIA's compiler it is spelled out as that compiler
expands ``length``: there it must also be the spelled-out one, or the speed-up is gone)."""
import numpy as np
import pyopencl as cl

from cltess.backends.opencl.programs import correctly_rounded_division, kernel_dir

KERNEL = """
__kernel void normals(__global const float4 *n, __global float *out, __global float *lengths,
                      __global int *spelled)
{
    int id = get_global_id(0);
    float3 v = n[id].xyz;
    float len = length(v);
    vstore3(unit_or(v, (float3)(0.0f, 0.0f, 1.0f)), 2 * id, out);
    vstore3(len > 0.0f ? v / len : (float3)(0.0f, 0.0f, 1.0f), 2 * id + 1, out);
    lengths[2 * id] = normal_length(v);
    lengths[2 * id + 1] = len;
    if (id == 0)
        spelled[0] = CLTESS_SPELLED_LENGTH;
}
"""


def vectors(count: int, seed: int = 15) -> np.ndarray:
    rng = np.random.default_rng(seed)
    n = (rng.standard_normal((count, 4)) * 2.0 ** rng.integers(-30, 30, (count, 4))).astype(np.float32)
    special = np.array([0.0, -0.0, np.inf, -np.inf, np.nan, 1e-40, -1e-40, 3.4e38, -3.4e38, 1.0, -1.0],
                       np.float32)
    quarter = count // 4
    n[:quarter, :3] = rng.choice(special, (quarter, 3))                       # specials everywhere
    mask = rng.random((quarter, 3)) < 0.4                                     # a teapot's: exact zeros
    n[quarter: 2 * quarter, :3] = np.where(mask, np.float32(0.0), n[quarter: 2 * quarter, :3])
    n[2 * quarter: 2 * quarter + 64, :3] = 0.0
    n[2 * quarter + 64: 2 * quarter + 128, :3] = -0.0
    return n


def test_unit_or_is_the_division(tessellator):
    ctx, queue = tessellator.context, tessellator.queue
    device = ctx.devices[0]
    options = ["-I", str(kernel_dir())] + correctly_rounded_division(device)
    program = cl.Program(ctx, '#include "common.h"\n' + KERNEL).build(options=options)
    count = 20000
    n = vectors(count)
    mf = cl.mem_flags
    source = cl.Buffer(ctx, mf.READ_ONLY | mf.COPY_HOST_PTR, hostbuf=n)
    out, lengths, spelled = np.empty((count, 2, 3), np.float32), np.empty((count, 2), np.float32), np.zeros(1, np.int32)
    buffers = [cl.Buffer(ctx, mf.WRITE_ONLY, a.nbytes) for a in (out, lengths, spelled)]
    program.normals(queue, (count,), None, source, *buffers)
    for a, b in zip((out, lengths, spelled), buffers):
        cl.enqueue_copy(queue, a, b)
    assert np.array_equal(out[:, 0].view(np.uint32), out[:, 1].view(np.uint32))
    assert np.array_equal(lengths[:, 0].view(np.uint32), lengths[:, 1].view(np.uint32))
    zeros = (n[:, :3] == 0).any(axis=1) & (lengths[:, 1] > 0)
    assert zeros.sum() > count // 4  # the shortcut's cases were there
    if "NVIDIA" in device.platform.name:
        assert spelled[0] == 1  # cl_nv_pragma_unroll seen: the spelled-out length is what ran
