import sys, time, numpy as np, pyopencl as cl
sys.path.insert(0, "bench")
import frame_loop
from cltess.device import pick_device
dev = pick_device(sys.argv[1]); ctx = cl.Context([dev])
q = cl.CommandQueue(ctx, properties=cl.command_queue_properties.PROFILING_ENABLE)
fill = cl.Program(ctx, frame_loop.FILL_SOURCE).build().fill
nbytes = 565 * 10**6 // 16 * 16; count = nbytes // 16
buf = cl.Buffer(ctx, cl.mem_flags.READ_WRITE, nbytes)
out = []
for i in range(int(sys.argv[2])):
    e = fill(q, (-(-count // 256) * 256,), (256,), buf, np.zeros(4, np.float32), np.uint64(count))
    e.wait()
    ms = (e.profile.end - e.profile.start) / 1e6
    out.append(ms)
    print(f"{time.strftime('%H:%M:%S')} {i:3d} {ms:6.1f} ms {nbytes/ms/1e6:5.1f} GB/s", flush=True)
    time.sleep(float(sys.argv[3]) if len(sys.argv) > 3 else 0)
print("min", min(out), "median", sorted(out)[len(out)//2])
