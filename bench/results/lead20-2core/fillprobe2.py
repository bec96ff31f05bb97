import sys, time, numpy as np, pyopencl as cl
sys.path.insert(0, "bench")
import frame_loop
from cltess.device import pick_device
dev = pick_device(sys.argv[1]); ctx = cl.Context([dev])
q = cl.CommandQueue(ctx, properties=cl.command_queue_properties.PROFILING_ENABLE)
fill = cl.Program(ctx, frame_loop.FILL_SOURCE).build().fill
nbytes = 565 * 10**6 // 16 * 16; count = nbytes // 16
bufs = [cl.Buffer(ctx, cl.mem_flags.READ_WRITE, nbytes) for _ in range(int(sys.argv[2]))]
def run(b):
    e = fill(q, (-(-count // 256) * 256,), (256,), b, np.zeros(4, np.float32), np.uint64(count)); e.wait()
    return (e.profile.end - e.profile.start) / 1e6
for b in bufs: run(b)
for mode in ("same", "alternate"):
    t = []
    for i in range(12):
        b = bufs[0] if mode == "same" else bufs[i % len(bufs)]
        t.append(run(b))
    print(mode, len(bufs), "buffers: GB/s min-median", round(nbytes / min(t) / 1e6, 1), round(nbytes / sorted(t)[6] / 1e6, 1), [round(x, 1) for x in t])
