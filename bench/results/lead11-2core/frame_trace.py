# A host-array frame (tessellate(host=True)) traced: host time before the first kernel is queued,
# the device span, its gaps, host time after the last kernel.  ARGS: scene device
import sys, time, statistics, warnings
warnings.simplefilter("ignore")
sys.path.insert(0, "/work/main/bench")
import frame_loop as fl
import cltess, pyopencl as cl
from cltess.backends.opencl import Tessellator
import cltess.backends.opencl.tessellator as T
scene = fl.suite_scene(sys.argv[1]); t = Tessellator(sys.argv[2])
s = cltess.Session(scene, tessellator=t, pixels=fl.PIXELS)
path = list(fl.orbit(scene.camera, 20))
for c in path: s.tessellate(camera=c, host=True)
captured = []
real_span = T.span_ms
def span(evs):
    captured.extend(evs); return real_span(evs)
T.span_ms = span
rows = []
P = cl.profiling_info
for r in range(10):
    for c in path:
        captured.clear()
        t0 = time.perf_counter_ns()
        fr = s.tessellate(camera=c, host=True)
        t3 = time.perf_counter_ns()
        evs = [(e.get_profiling_info(P.QUEUED), e.get_profiling_info(P.START), e.get_profiling_info(P.END)) for e in captured]
        q0 = min(e[0] for e in evs); s0 = min(e[1] for e in evs); e1 = max(e[2] for e in evs)
        busy = sum(e[2] - e[1] for e in evs)
        rows.append(dict(pre=(q0 - t0) / 1e3, first_start=(s0 - q0) / 1e3, span=(e1 - s0) / 1e3, busy=busy / 1e3,
                         gaps=((e1 - s0) - busy) / 1e3, tail=(t3 - e1) / 1e3, wall=(t3 - t0) / 1e3, n=len(evs)))
for k in rows[0]:
    print(f"{k:12} {statistics.median(r[k] for r in rows):8.1f}")
