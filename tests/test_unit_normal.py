"""Stage 4's normals without a zero dividend (kernels/common.h: ``quotient_by_positive``,
``normal_length``, ``unit_or``) against what they replace, bit for bit, on the device:
``unit_or(n, +z)`` must give ``length(n) > 0 ? n / length(n) : +z`` (kinds/bezier.h's
``surface_normal`` before) for any float3, signed zeros, infinities, NaNs and subnormals included;
``normal_length`` must be ``length`` (on NVIDIA's compiler it is spelled out as that compiler
expands ``length``: there it must also be the spelled-out one, or the speed-up is gone).
Likewise PoCL's builtins as common.h spells them out to have them inline (``dot3f``, ``cross3``,
``length3``, ``store3``, ``store2``; the builtins themselves elsewhere): bit for bit the builtins, and
on PoCL (x86-64) the spelled-out ones."""
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


BUILTINS_KERNEL = """
__kernel void builtins(__global const float4 *a, __global const float4 *b, __global float *spelled,
                       __global float *builtin, __global int *forms)
{
    int id = get_global_id(0);
    float3 x = a[id].xyz, y = b[id].xyz;
    store3(cross3(x, y), 3 * id, spelled);
    spelled[9 * id + 3] = dot3f(x, y);
    spelled[9 * id + 4] = length3(x);
    spelled[9 * id + 5] = 0.0f;
    store2(x.xy, 9 * id / 2 + 3, spelled + (9 * id) % 2);  /* floats 9 id + 6, 9 id + 7 */
    spelled[9 * id + 8] = normal_length(y);
    vstore3(cross(x, y), 3 * id, builtin);
    builtin[9 * id + 3] = dot(x, y);
    builtin[9 * id + 4] = length(x);
    builtin[9 * id + 5] = 0.0f;
    vstore2(x.xy, 9 * id / 2 + 3, builtin + (9 * id) % 2);
    builtin[9 * id + 8] = length(y);
    if (id == 0)
        forms[0] = CLTESS_POCL_FORMS;
}
"""


def test_spelled_builtins_are_the_builtins(tessellator):
    """common.h's dot3f, cross3, length3, store3, store2 (PoCL's builtins spelled out, inline
    there) give the builtins' bits on 20,000 pairs with signed zeros, infinities, NaNs, subnormals
    and values whose squares overflow or underflow (length3's scaled branches)."""
    ctx, queue = tessellator.context, tessellator.queue
    device = ctx.devices[0]
    options = ["-I", str(kernel_dir())] + correctly_rounded_division(device)
    program = cl.Program(ctx, '#include "common.h"\n' + BUILTINS_KERNEL).build(options=options)
    count = 20000
    a, b = vectors(count, seed=16), vectors(count, seed=17)
    rng = np.random.default_rng(18)
    with np.errstate(over="ignore"):  # some overflow to +-inf: wanted too
        a[-2000:, :3] = (rng.standard_normal((2000, 3)) * 2.0 ** rng.integers(-149, 128, (2000, 3))).astype(np.float32)
    mf = cl.mem_flags
    sources = [cl.Buffer(ctx, mf.READ_ONLY | mf.COPY_HOST_PTR, hostbuf=v) for v in (a, b)]
    spelled, builtin, forms = np.empty((count, 9), np.float32), np.empty((count, 9), np.float32), np.zeros(1, np.int32)
    buffers = [cl.Buffer(ctx, mf.WRITE_ONLY, x.nbytes) for x in (spelled, builtin, forms)]
    program.builtins(queue, (count,), None, *sources, *buffers)
    for x, buffer in zip((spelled, builtin, forms), buffers):
        cl.enqueue_copy(queue, x, buffer)
    differ = spelled.view(np.uint32) != builtin.view(np.uint32)
    first = np.nonzero(differ.any(axis=1))[0][:3]
    assert not differ.any(), (f"floats differing by column (cross x3, dot, length, 0, store2 x2, length): "
                              f"{differ.sum(axis=0)}; e.g. a {a[first, :3]}, b {b[first, :3]}: "
                              f"{spelled[first]} against {builtin[first]}")
    lengths = builtin[:, 4]
    assert (lengths[np.isfinite(lengths)] > 0).any()
    if "Portable Computing Language" in device.platform.name and "x86_64" in device.version:
        assert forms[0] == 1  # PoCL on x86-64: the spelled-out forms are what ran
