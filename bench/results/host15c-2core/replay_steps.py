import sys, time, warnings, statistics, collections
sys.path.insert(0, "/work/wt/host15c/bench"); warnings.simplefilter("ignore")
import numpy as np, pyopencl as cl
import cltess, frame_loop as fl
from cltess.backends.opencl import Tessellator
from cltess.backends.opencl import recorded as R
from cltess.backends.opencl.tessellator import Plan, PendingEmit
from cltess.scene import Camera
import cltess.session as S
clock = time.thread_time_ns
steps = collections.defaultdict(list)
def replay(self, tessellator, data, request, started, scratch, output):
    t0 = clock()
    recorded, queue = self.plan, tessellator.queue
    tolerance_args = request.tolerance_for(data.scene).kernel_args()
    t1 = clock(); steps["kernel_args"].append(t1 - t0)
    events = {"factors": [launch.again(queue, R.with_tolerance(launch.args, tolerance_args)) for launch in self.launches["factors"]]}
    t2 = clock(); steps["stage 1 launch"].append(t2 - t1)
    for stage in R.PLANNED_STAGES[1:]:
        events[stage] = [launch.again(queue) for launch in self.launches[stage]]
    t3 = clock(); steps["stages 2-3 launches"].append(t3 - t2)
    totals, _ = tessellator._read_back_arrays(scratch, recorded.num_patches, flags=False)
    copy = cl.enqueue_copy(queue, totals, self.summary.data, is_blocking=False)
    t4 = clock(); steps["summary copy"].append(t4 - t3)
    plan = Plan(recorded.name, recorded.num_patches, recorded.parts, recorded.objects, recorded.factors,
                recorded.vertex_offsets, recorded.index_offsets, None, None, dict(self.stats), events, started,
                request, _pending=(totals, None, [copy]))
    t5 = clock(); steps["Plan()"].append(t5 - t4)
    arrays = output.take(*output.capacity)
    t6 = clock(); steps["take"].append(t6 - t5)
    emitted = dict(events)
    for stage in R.EMITTED_STAGES:
        emitted[stage] = [launch.again(queue) for launch in self.launches[stage]]
    t7 = clock(); steps["stages 4-5 launches"].append(t7 - t6)
    queue.flush()
    t8 = clock(); steps["flush"].append(t8 - t7)
    p = PendingEmit(tessellator, plan, 0, recorded.num_patches, 0, arrays, emitted, output, None, self.forward_differencing)
    steps["PendingEmit()"].append(clock() - t8)
    return p
R.RecordedFrame.replay = replay
orig_rf = S.Session.request_for
def rf(self, *a, **k):
    st = clock(); r = orig_rf(self, *a, **k); steps["request_for"].append(clock() - st); return r
S.Session.request_for = rf
from cltess.backends.opencl.tessellator import PendingEmit as PE
orig_res = PE.result
def res(self, *a, **k):
    st = clock(); r = orig_res(self, *a, **k); steps["result()"].append(clock() - st); return r
PE.result = res
t = Tessellator(None, work="point")
t.fused_offsets, t.tiled_offsets, t._cpu = True, True, False
key = sys.argv[1]
scene = fl.suite_scene(key)
s = cltess.Session(scene, tessellator=t, pixels=fl.PIXELS)
path = list(fl.orbit(scene.camera, 20))
for c in path: s.tessellate(camera=c).fetch()
away = [Camera(c.eye, 2 * np.asarray(c.eye) - np.asarray(c.target), c.up, c.fov_y_deg, c.width, c.height, c.near, c.far) for c in path]
steps.clear()
for r in range(10):
    for c in away:
        t.queue.finish()
        st = clock(); f = s.tessellate(camera=c, wait=False); steps["whole tessellate"].append(clock() - st)
f.finish()
for k, v in steps.items():
    print(f"{statistics.median(v)/1e3:8.1f} us  {k}")
