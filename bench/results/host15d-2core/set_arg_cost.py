# One-off micro-benchmark (session 8, host15d): what setting one kernel argument and enqueueing cost the host
# on this VM, by pyopencl entry point.  python set_arg_cost.py [pocl]  (Intel CPU runtime by default)
import sys, time, warnings, statistics
sys.path.insert(0, "/work/wt/host15d/bench"); warnings.simplefilter("ignore")
import numpy as np, pyopencl._cl as _cl
import cltess, frame_loop as fl
from cltess.backends.opencl import Tessellator
from cltess.backends.opencl.recorded import with_tolerance
t = Tessellator(sys.argv[1] if len(sys.argv) > 1 else None, work="point")
t.fused_offsets, t.tiled_offsets, t._cpu = True, True, False
scene = fl.suite_scene("tea_table")
s = cltess.Session(scene, tessellator=t, pixels=fl.PIXELS)
path = list(fl.orbit(scene.camera, 20))
for c in path: s.tessellate(camera=c).fetch()
rec = s._recorded
q = t.queue
L1 = rec.launches["factors"][0]; L4 = rec.launches["vertices"][0]
targs = s.request_for(path[3]).tolerance_for(scene).kernel_args()
clock = time.thread_time_ns
def med(f, n=50, reps=9):
    ts = []
    for i in range(reps):
        q.finish()
        st = clock()
        for _ in range(n): f()
        ts.append((clock() - st) / n)
    q.finish()
    return min(ts) / 1e3, statistics.median(ts) / 1e3
args1 = with_tolerance(L1.args, targs)
k1 = L1.kernel
view = targs[1]
E = lambda L: _cl.enqueue_nd_range_kernel(q, L.kernel.kernel, L.global_size, L.local_size, None, None, False, False)
for name, f in [
 ("set_arg(view) alone", lambda: k1.kernel.set_arg(5, view)),
 ("set_arg(np.float32) alone", lambda: k1.kernel.set_arg(4, np.float32(0))),
 ("enqueue alone stage4", lambda: E(L4)),
 ("enqueue alone stage1", lambda: E(L1)),
 ("set_arg(view)+enqueue", lambda: (k1.kernel.set_arg(5, view), E(L1))),
 ("full typed invoker", lambda: k1.kernel(q, L1.global_size, L1.local_size, *args1)),
 ("set_args typed (no enqueue)", lambda: k1.kernel.set_args(*args1)),
 ("Kernel.__call__ stage4 kept", lambda: L4.again(q)),
 ("flush", lambda: q.flush()),
]:
    print(f"{name:32s} min {med(f)[0]:6.1f}  median {med(f)[1]:6.1f}")
print("---")
for name, f in [
 ("_set_arg_buf_multi(view)", lambda: k1.kernel._set_arg_buf_multi((5, view))),
 ("_set_arg_buf_pack_multi(f32)", lambda: k1.kernel._set_arg_buf_pack_multi((4, b'f', np.float32(0)))),
 ("_set_arg_multi(buffer)", lambda: k1.kernel._set_arg_multi((0, args1[0]))),
 ("_set_arg_buf_multi(view)+enqueue", lambda: (k1.kernel._set_arg_buf_multi((5, view)), E(L1))),
]:
    print(f"{name:32s} min {med(f)[0]:6.1f}  median {med(f)[1]:6.1f}")
print([type(a).__name__ for a in args1])
