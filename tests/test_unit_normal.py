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


def run_pair_kernel(tessellator, source: str, name: str, a: np.ndarray, b: np.ndarray, outputs, seed: int) -> None:
    """Build ``source`` after common.h, give a's last 2,000 rows magnitudes 2^-149 .. 2^127 (some
    squares overflow or underflow), run kernel ``name`` on a, b, one work-item a row, and read
    its outputs into the arrays ``outputs``."""
    ctx, queue = tessellator.context, tessellator.queue
    options = ["-I", str(kernel_dir())] + correctly_rounded_division(ctx.devices[0])
    program = cl.Program(ctx, '#include "common.h"\n' + source).build(options=options)
    rng = np.random.default_rng(seed)
    with np.errstate(over="ignore"):  # some overflow to +-inf: wanted too
        a[-2000:, :3] = (rng.standard_normal((2000, 3)) * 2.0 ** rng.integers(-149, 128, (2000, 3))).astype(np.float32)
    mf = cl.mem_flags
    sources = [cl.Buffer(ctx, mf.READ_ONLY | mf.COPY_HOST_PTR, hostbuf=v) for v in (a, b)]
    buffers = [cl.Buffer(ctx, mf.WRITE_ONLY, x.nbytes) for x in outputs]
    getattr(program, name)(queue, (len(a),), None, *sources, *buffers)
    for x, buffer in zip(outputs, buffers):
        cl.enqueue_copy(queue, x, buffer)


def test_spelled_builtins_are_the_builtins(tessellator):
    """common.h's dot3f, cross3, length3, store3, store2 (PoCL's builtins spelled out, inline
    there) give the builtins' bits on 20,000 pairs with signed zeros, infinities, NaNs, subnormals
    and values whose squares overflow or underflow (length3's scaled branches)."""
    count = 20000
    a, b = vectors(count, seed=16), vectors(count, seed=17)
    spelled, builtin, forms = np.empty((count, 9), np.float32), np.empty((count, 9), np.float32), np.zeros(1, np.int32)
    run_pair_kernel(tessellator, BUILTINS_KERNEL, "builtins", a, b, (spelled, builtin, forms), seed=18)
    device = tessellator.context.devices[0]
    differ = spelled.view(np.uint32) != builtin.view(np.uint32)
    first = np.nonzero(differ.any(axis=1))[0][:3]
    assert not differ.any(), (f"floats differing by column (cross x3, dot, length, 0, store2 x2, length): "
                              f"{differ.sum(axis=0)}; e.g. a {a[first, :3]}, b {b[first, :3]}: "
                              f"{spelled[first]} against {builtin[first]}")
    lengths = builtin[:, 4]
    assert (lengths[np.isfinite(lengths)] > 0).any()
    if "Portable Computing Language" in device.platform.name and "x86_64" in device.version:
        assert forms[0] == 1  # PoCL on x86-64: the spelled-out forms are what ran


FORMS_KERNEL = """
__kernel void forms(__global const float4 *a, __global const float4 *b, __global float *spelled,
                    __global float *builtin, __global int *ints)
{
    int id = get_global_id(0);
    float3 x = a[id].xyz, y = b[id].xyz;
    float3 u = unit_or_zero(x);
    float len = sqrt(dot3(x, x));
    float3 v = len > 0.0f ? x / len : (float3)(0.0f);
    spelled[4 * id] = sqrt1f(x.x);
    spelled[4 * id + 1] = u.x;
    spelled[4 * id + 2] = u.y;
    spelled[4 * id + 3] = u.z;
    builtin[4 * id] = sqrt(x.x);
    builtin[4 * id + 1] = v.x;
    builtin[4 * id + 2] = v.y;
    builtin[4 * id + 3] = v.z;
    int i = as_int(a[id].w) >> (id % 31), j = as_int(b[id].w) >> (id % 29);
    ints[4 * id] = imin(i, j);
    ints[4 * id + 1] = min(i, j);
    ints[4 * id + 2] = imax(i, j);
    ints[4 * id + 3] = max(i, j);
}
"""


def test_spelled_sqrt_min_max_are_the_builtins(tessellator):
    """common.h's sqrt1f, imin, imax (PoCL's sqrt(float), min(int), max(int) spelled out, inline
    there: issue 15, branch cpu15g) and unit_or_zero (its root by sqrt1f) give the builtins' bits
    on 20,000 pairs with signed zeros, infinities, NaNs, subnormals and negative roots."""
    count = 20000
    a, b = vectors(count, seed=26), vectors(count, seed=27)
    a[:100, 3] = np.array([0, -1, 1, 2**31 - 1, -2**31], np.int32).view(np.float32)[np.arange(100) % 5]
    spelled, builtin, ints = np.empty((count, 4), np.float32), np.empty((count, 4), np.float32), np.empty((count, 4), np.int32)
    run_pair_kernel(tessellator, FORMS_KERNEL, "forms", a, b, (spelled, builtin, ints), seed=28)
    differ = spelled.view(np.uint32) != builtin.view(np.uint32)
    assert not differ.any(), f"floats differing by column (sqrt, unit_or_zero x3): {differ.sum(axis=0)}"
    assert np.isnan(builtin[:, 0]).any() and (builtin[:, 0] > 0).any()  # negative and positive roots met
    assert (ints[:, 0] == ints[:, 1]).all() and (ints[:, 2] == ints[:, 3]).all()
    assert (ints[:, 0] != ints[:, 2]).any()


LANES_KERNEL = """
__kernel void lanes(__global const float4 *a, __global const float4 *b, __global float *lanes,
                    __global float *builtin, __global int *flags)
{
    int id = get_global_id(0);
#if CLTESS_LANES
    float8 ax, ay, az, bx, by, bz;  /* eight pairs, pair 8 id + k in lane k */
    float x[6][8];
    for (int k = 0; k < 8; ++k) {
        float4 p = a[8 * id + k], q = b[8 * id + k];
        x[0][k] = p.x; x[1][k] = p.y; x[2][k] = p.z; x[3][k] = q.x; x[4][k] = q.y; x[5][k] = q.z;
    }
    ax = vload8(0, x[0]); ay = vload8(0, x[1]); az = vload8(0, x[2]);
    bx = vload8(0, x[3]); by = vload8(0, x[4]); bz = vload8(0, x[5]);
    float8 out[6] = {lanes_cross_term(ay, bz, az, by), lanes_cross_term(az, bx, ax, bz),
                     lanes_cross_term(ax, by, ay, bx), lanes_dot(ax, ay, az, bx, by, bz),
                     lanes_length(ax, ay, az),
                     as_float8(lanes_length_plain(lanes_dot(ax, ay, az, ax, ay, az)))};
    for (int c = 0; c < 6; ++c)
        vstore8(out[c], 0, x[c]);
    for (int k = 0; k < 8; ++k)
        for (int c = 0; c < 6; ++c)
            lanes[6 * (8 * id + k) + c] = x[c][k];
#endif
    for (int k = 0; k < 8; ++k) {
        float3 p = a[8 * id + k].xyz, q = b[8 * id + k].xyz;
        vstore3(cross(p, q), 2 * (8 * id + k), builtin);
        builtin[6 * (8 * id + k) + 3] = dot(p, q);
        builtin[6 * (8 * id + k) + 4] = length(p);
        builtin[6 * (8 * id + k) + 5] = 0.0f;
    }
    if (id == 0)
        flags[0] = CLTESS_LANES;
}
"""


def test_lane_forms_are_the_builtins(tessellator):
    """Stage 4's lanes (kernels/common.h CLTESS_LANES: on by default on PoCL for x86-64 and on
    Intel's CPU runtime) compute cross, dot and length as that runtime's builtins do: bit for bit
    (a NaN's sign aside) on 20,000 pairs with signed zeros, infinities, NaNs, subnormals and
    values whose squares overflow or underflow, length wherever lanes_length_plain says its value
    is the plain one (elsewhere the lanes leave the point to the scalar code).  On PoCL x86-64
    and Intel's CPU runtime the lanes must be on; on other devices, where they are off, the test
    has nothing to compare."""
    count = 20000
    a, b = vectors(count, seed=36), vectors(count, seed=37)
    lanes, builtin, flags = np.zeros((count, 6), np.float32), np.empty((count, 6), np.float32), np.zeros(1, np.int32)
    ctx, queue = tessellator.context, tessellator.queue
    options = ["-I", str(kernel_dir())] + correctly_rounded_division(ctx.devices[0])
    program = cl.Program(ctx, '#include "common.h"\n' + LANES_KERNEL).build(options=options)
    rng = np.random.default_rng(38)
    with np.errstate(over="ignore"):
        a[-2000:, :3] = (rng.standard_normal((2000, 3)) * 2.0 ** rng.integers(-149, 128, (2000, 3))).astype(np.float32)
    mf = cl.mem_flags
    sources = [cl.Buffer(ctx, mf.READ_ONLY | mf.COPY_HOST_PTR, hostbuf=v) for v in (a, b)]
    buffers = [cl.Buffer(ctx, mf.READ_WRITE, x.nbytes) for x in (lanes, builtin, flags)]
    program.lanes(queue, (count // 8,), None, *sources, *buffers)
    for x, buffer in zip((lanes, builtin, flags), buffers):
        cl.enqueue_copy(queue, x, buffer)
    device = ctx.devices[0]
    pocl_x86 = "Portable Computing Language" in device.platform.name and "x86_64" in device.version
    if pocl_x86 or "Intel(R) OpenCL" in device.platform.name and device.type & cl.device_type.CPU:
        assert flags[0] == 1  # the lanes are on where they are the default
    if not flags[0]:
        return
    # A NaN's sign may differ (x86's vector default NaN has it set): a lane that meets a NaN is
    # never plain, so the scalar code makes that point (kinds/bezier.h normal_lanes).
    both_nan = np.isnan(lanes[:, :4]) & np.isnan(builtin[:, :4])
    differ = (lanes[:, :4].view(np.uint32) != builtin[:, :4].view(np.uint32)) & ~both_nan
    assert not differ.any(), f"floats differing by column (cross x3, dot): {differ.sum(axis=0)}"
    plain = lanes[:, 5].view(np.int32) != 0
    assert plain.sum() > count // 2 and (~plain).any() == pocl_x86  # PoCL's length has scaled branches
    length_differs = lanes[plain, 4].view(np.uint32) != builtin[plain, 4].view(np.uint32)
    assert not length_differs.any(), f"{length_differs.sum()} lengths differ"
