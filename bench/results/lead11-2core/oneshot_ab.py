# One-shot Tessellator.tessellate calls (host arrays): the read-back enqueued behind the stages
# ("early", emit's start_read_back) against when the result asks for it ("late"), alternating.
import sys, time, statistics, warnings
warnings.simplefilter("ignore")
sys.path.insert(0, "/work/main/bench")
import frame_loop as fl
from cltess.backends.opencl import Tessellator
import cltess.backends.opencl.tessellator as T
scene = fl.suite_scene(sys.argv[1]); t = Tessellator(sys.argv[2])
keep = T.PendingEmit.start_read_back
cam = scene.camera
for _ in range(5): t.tessellate(scene, pixels=0.5)
res = {"late": [], "early": []}
for r in range(40):
    for name in (list(res) if r % 2 == 0 else list(res)[::-1]):  # the order swapped each round
        T.PendingEmit.start_read_back = keep if name == "early" else (lambda self: None)
        a = time.perf_counter_ns(); tess = t.tessellate(scene, pixels=0.5); b = time.perf_counter_ns()
        res[name].append((b - a) / 1e3)
for k, v in res.items(): print(sys.argv[1], sys.argv[2], k, "call us median", round(statistics.median(v), 1))
