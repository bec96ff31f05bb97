# Stream (tessellate_to_file of the 30k scene, in one process, warm kernels): the read-back enqueued
# behind its batch ("early") against when the host asks for it ("late"), alternating.  cd /tmp/t30d first.
import time, sys, resource, statistics
import cltess.stream as stream
from cltess.io import load_scene
from cltess.orient import orient_scene
from cltess.backends.opencl import Tessellator
import cltess.backends.opencl.tessellator as tm
scene = load_scene("scene.bpt"); scene, _ = orient_scene(scene)
t = Tessellator()
keep = tm.PendingEmit.start_read_back
res = {"early": [], "late": []}
for r in range(12):
    for v in (("early", "late") if r % 2 == 0 else ("late", "early")):  # the order swapped each round
        tm.PendingEmit.start_read_back = keep if v == "early" else (lambda self: None)
        s = time.perf_counter(); c0 = resource.getrusage(resource.RUSAGE_SELF)
        stream.tessellate_to_file(t, scene, "out-x.ply", eps=0.0085)
        c1 = resource.getrusage(resource.RUSAGE_SELF)
        res[v].append((time.perf_counter() - s, c1.ru_utime-c0.ru_utime+c1.ru_stime-c0.ru_stime))
for v, xs in res.items():
    print(v, "wall median", round(statistics.median(x[0] for x in xs), 3), "min", round(min(x[0] for x in xs), 3), "cpu median", round(statistics.median(x[1] for x in xs), 3))
