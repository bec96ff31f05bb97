"""Thread CPU µs of Session.tessellate(wait=False) with the device idle (queue finished before each
frame; cameras turned away: every patch culled), GPU path (--as-gpu choices); median of frames."""
import sys, time, warnings, statistics
sys.path.insert(0, "/work/wt/host15d/bench"); warnings.simplefilter("ignore")
import numpy as np
import cltess, frame_loop as fl
from cltess.backends.opencl import Tessellator
from cltess.scene import Camera
clock = time.thread_time_ns
t = Tessellator(None, work="point")
t.fused_offsets, t.tiled_offsets, t._cpu = True, True, False
out = []
for key in sys.argv[1:]:
    scene = fl.suite_scene(key)
    s = cltess.Session(scene, tessellator=t, pixels=fl.PIXELS)
    path = list(fl.orbit(scene.camera, 20))
    for c in path: s.tessellate(camera=c).fetch()
    away = [Camera(c.eye, 2 * np.asarray(c.eye) - np.asarray(c.target), c.up, c.fov_y_deg, c.width, c.height, c.near, c.far) for c in path]
    ts = []
    for r in range(40):
        for c in away:
            t.queue.finish()
            st = clock(); f = s.tessellate(camera=c, wait=False); ts.append(clock() - st)
    f.finish()
    out.append(f"{key} p10 {np.percentile(ts, 10)/1e3:.1f} p25 {np.percentile(ts, 25)/1e3:.1f} med {statistics.median(ts)/1e3:.1f}")
print(cltess.__file__.split('/')[2], "; ".join(out))
