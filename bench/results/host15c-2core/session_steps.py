import sys, time, warnings, statistics, collections
sys.path.insert(0, "/work/wt/host15c/bench"); warnings.simplefilter("ignore")
import numpy as np
import cltess, frame_loop as fl
import cltess.session as S
from cltess.backends.opencl import Tessellator
from cltess.scene import Camera
clock = time.thread_time_ns
T = collections.defaultdict(list)
def tessellate(self, camera=None, wait=True, **request_overrides):
    t0 = clock()
    started = time.perf_counter()
    request = self.request_for(camera, **request_overrides)
    if request.bound != "hull":
        raise ValueError()
    tessellator = self.tessellator
    composed = None if request_overrides else (tessellator.work, tessellator.fused_offsets, tessellator.tiled_offsets, tessellator.one_scan)
    if composed is None or composed != self._composed:
        tessellator.compose(self.scene, request)
        self._composed = composed
    key = request.sharp_edges
    if key not in self._scene_data:
        self._scene_data[key] = tessellator.scene_data(self.scene, key)
        self._scratch[key] = {}
    t1 = clock(); T["request, compose check"].append(t1 - t0)
    for age, plan in enumerate(reversed(self._plans)):
        if age == 1 or plan.totals_ready():
            plan.settle()
        if plan.settled:
            self.output.reserve(plan.num_vertices, plan.num_indices // 3)
    t2 = clock(); T["settle loop"].append(t2 - t1)
    programs, data, scratch = tessellator.programs, self._scene_data[key], self._scratch[key]
    recorded = self._recorded
    programs.keep_arguments = True
    try:
        k = self._frame_key()
        t3 = clock(); T["frame key"].append(t3 - t2)
        if not request_overrides and recorded is not None and recorded.key == k:
            pending = recorded.replay(tessellator, data, request, started, scratch, self.output)
        else:
            raise RuntimeError("not replayed")
        t4 = clock(); T["replay"].append(t4 - t3)
    finally:
        programs.keep_arguments = False
        programs.recording = None
    self._plans = [*self._plans[-1:], pending.plan]
    self.frames += 1
    t5 = clock()
    r = pending.result(on_device=True, wait=wait)
    T["result"].append(clock() - t5)
    return r
t = Tessellator(None, work="point")
t.fused_offsets, t.tiled_offsets, t._cpu = True, True, False
scene = fl.suite_scene(sys.argv[1])
s = cltess.Session(scene, tessellator=t, pixels=fl.PIXELS)
path = list(fl.orbit(scene.camera, 20))
for c in path: s.tessellate(camera=c).fetch()
S.Session.tessellate = tessellate
away = [Camera(c.eye, 2 * np.asarray(c.eye) - np.asarray(c.target), c.up, c.fov_y_deg, c.width, c.height, c.near, c.far) for c in path]
T.clear()
for r in range(10):
    for c in away:
        t.queue.finish()
        st = clock(); f = s.tessellate(camera=c, wait=False); T["whole"].append(clock() - st)
for k, v in T.items():
    print(f"{statistics.median(v)/1e3:8.1f} us  {k}")
