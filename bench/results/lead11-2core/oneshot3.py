# One-shot calls on a GPU: no early read-back, the current rule, and copies into pageable memory
# forced early; the order rotated each round.  ARGS: scene device
import sys, time, statistics, warnings
warnings.simplefilter("ignore")
sys.path.insert(0, "bench")
import frame_loop as fl
from cltess.backends.opencl import Tessellator
import cltess.backends.opencl.tessellator as T
scene = fl.suite_scene(sys.argv[1]); t = Tessellator(sys.argv[2])
keep = T.PendingEmit.start_read_back
def forced(self):
    if self.plan.settled:
        self.plan.enqueue_host_factors()
        b, a = self.buffers, self.arrays
        b._started = (b.generation, a.num_vertices, a.num_triangles, b._enqueue_copies(a.num_vertices, a.num_triangles))
variants = {"none": lambda self: None, "current": keep}
if not t.device.type & 2:  # (not a CPU device: its copies, forced early too)
    variants["forced-pageable"] = forced
for _ in range(5): t.tessellate(scene, pixels=0.5)
res = {k: [] for k in variants}
names = list(variants)
for r in range(30):
    order = names[r % len(names):] + names[:r % len(names)]
    for name in order:
        T.PendingEmit.start_read_back = variants[name]
        a = time.perf_counter_ns(); tess = t.tessellate(scene, pixels=0.5); b = time.perf_counter_ns()
        res[name].append((b - a) / 1e3)
        del tess
for k, v in res.items(): print(sys.argv[1], sys.argv[2], k, "call us median", round(statistics.median(v), 1))
