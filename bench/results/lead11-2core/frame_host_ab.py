# A Session frame with host arrays: the read-back enqueued with the stages ("early",
# as tessellate(host=True)) against tessellate() then fetch() ("late"), alternating.  ARGS: scene device
import sys, time, statistics, warnings
warnings.simplefilter("ignore")
sys.path.insert(0, "/work/main/bench")
import frame_loop as fl
import cltess
from cltess.backends.opencl import Tessellator
scene = fl.suite_scene(sys.argv[1]); t = Tessellator(sys.argv[2])
s = cltess.Session(scene, tessellator=t, pixels=fl.PIXELS)
path = list(fl.orbit(scene.camera, 20))
for c in path: s.tessellate(camera=c).fetch()
res = {"late": [], "early": []}
for r in range(30):
    for name in (list(res) if r % 2 == 0 else list(res)[::-1]):  # the order swapped each round
        for c in path:
            a = time.perf_counter_ns()
            if name == "late":
                fr = s.tessellate(camera=c); fr.fetch()
            else:
                fr = s.tessellate(camera=c, host=True)
            b = time.perf_counter_ns()
            res[name].append((b - a) / 1e3 / fl.device_ms(fr) / 1e3)
for k, v in res.items(): print(sys.argv[1], sys.argv[2], k, "wall/device median", round(statistics.median(v), 3), "mean", round(statistics.mean(v), 3))
