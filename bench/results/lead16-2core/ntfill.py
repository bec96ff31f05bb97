"""Session 16: the write rate of plain stores against streaming (non-temporal) stores, per CPU runtime.

    cd /tmp && python /work/main/bench/results/lead16-2core/ntfill.py     (output: ntfill.txt)

Four fills of 512 MiB, six launches each (the GB/s of each, and the best): ``fill`` is
bench/frame_loop.py's FILL_SOURCE (float4 stores; what bench/cpu_stages.py calls the memory-write
rate), ``fill_nt`` the same through ``__builtin_nontemporal_store``, ``fill1`` / ``fill_nt1`` a
float per work-item.  Oclgrind is skipped.
"""
import cltess
import pyopencl as cl, numpy as np, sys, time
src = """
__kernel void fill(__global float4 *out, const float4 value, const ulong count) {
    size_t i = get_global_id(0);
    if (i < count) out[i] = value;
}
__kernel void fill_nt(__global float4 *out, const float4 value, const ulong count) {
    size_t i = get_global_id(0);
    if (i < count) __builtin_nontemporal_store(value, &out[i]);
}
__kernel void fill_nt1(__global float *out, const float value, const ulong count) {
    size_t i = get_global_id(0);
    if (i < count) __builtin_nontemporal_store(value, &out[i]);
}
__kernel void fill1(__global float *out, const float value, const ulong count) {
    size_t i = get_global_id(0);
    if (i < count) out[i] = value;
}
"""
for plat in [p for p in cl.get_platforms() if "grind" not in p.name]:
    dev = plat.get_devices()[0]
    ctx = cl.Context([dev]); q = cl.CommandQueue(ctx, properties=cl.command_queue_properties.PROFILING_ENABLE)
    try:
        prg = cl.Program(ctx, src).build()
    except Exception as e:
        print(plat.name, "build failed", str(e)[:300]); continue
    size = 512 << 20
    buf = cl.Buffer(ctx, cl.mem_flags.READ_WRITE, size)
    for name, n, val in [("fill", size//16, np.zeros(4, np.float32)), ("fill_nt", size//16, np.zeros(4, np.float32)),
                         ("fill1", size//4, np.float32(0)), ("fill_nt1", size//4, np.float32(0))]:
        k = getattr(prg, name); ts = []
        for r in range(6):
            e = k(q, (n,), (256,), buf, val, np.uint64(n)); e.wait()
            ts.append((e.profile.end - e.profile.start) * 1e-9)
        print(plat.name[:20], name, "%.1f GB/s" % (size / min(ts) / 1e9), ["%.1f" % (size/t/1e9) for t in ts])
