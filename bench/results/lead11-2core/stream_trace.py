# The stream batch by batch: enqueues and waits (host clock) against the events (the device clock).  cd /tmp/t30d first.
import time, sys
import pyopencl as cl
import cltess.stream as stream
from cltess.io import load_scene
from cltess.orient import orient_scene
from cltess.backends.opencl import Tessellator
import cltess.backends.opencl.events as ev
import cltess.backends.opencl.tessellator as tm, cltess.backends.opencl.output as om
scene = load_scene("scene.bpt"); scene, _ = orient_scene(scene)
t = Tessellator()
log = []
ow = ev.wait_ms
def wait_ms(events):
    s = time.perf_counter(); r = ow(events); e = time.perf_counter()
    log.append(("wait", s, e, [(ev.command_type, ev.profile.queued, ev.profile.start, ev.profile.end) for ev in events])); log[-1][3].append(("host", int(s*1e9), int(s*1e9), int(e*1e9)))
    return r
tm.wait_ms = wait_ms; om.wait_ms = wait_ms
orig = t.emit_async
def emit_async(*a, **k):
    s = time.perf_counter(); job = orig(*a, **k); log.append(("enq", s, time.perf_counter(), [])); return job
t.emit_async = emit_async
for r in range(2):
    log.clear()
    res = stream.tessellate_to_file(t, scene, "out-x.ply", eps=0.0085)
t0 = log[0][1]
for kind, s, e, evs in log[:40]:
    print(kind, f"{(s-t0)*1e3:8.2f} {(e-t0)*1e3:8.2f} dur {(e-s)*1e3:6.2f}", [(c, round(q/1e6-t0*1e3,2), round(st/1e6-t0*1e3,2), round(en/1e6-t0*1e3, 2)) for c, q, st, en in evs])
