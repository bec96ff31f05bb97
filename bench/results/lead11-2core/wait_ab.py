import sys, time, statistics, warnings
warnings.simplefilter("ignore")
sys.path.insert(0, "/work/main/bench")
import frame_loop as fl
import cltess, pyopencl as cl
from cltess.backends.opencl import Tessellator
import cltess.backends.opencl.events as E, cltess.backends.opencl.tessellator as T, cltess.backends.opencl.output as O, cltess.backends.opencl.plan as P
new = E.wait_ms
def old(events):
    s = time.perf_counter(); cl.wait_for_events(events); return (time.perf_counter() - s) * 1e3
def use(f):
    for m in (T, O, P):
        if hasattr(m, "wait_ms"): m.wait_ms = f
scene = fl.suite_scene(sys.argv[1]); t = Tessellator(sys.argv[2])
s = cltess.Session(scene, tessellator=t, pixels=fl.PIXELS)
path = list(fl.orbit(scene.camera, 20))
for c in path: s.tessellate(camera=c).fetch()
res = {"old": [], "new": []}
for r in range(30):
    for name, f in (("old", old), ("new", new)):
        use(f)
        for c in path:
            a = time.perf_counter_ns(); fr = s.tessellate(camera=c); fr.fetch(); b = time.perf_counter_ns()
            res[name].append((b - a) / 1e3 / fl.device_ms(fr) / 1e3)
for k, v in res.items(): print(k, "wall/device median", round(statistics.median(v), 3), "mean", round(statistics.mean(v), 3))
