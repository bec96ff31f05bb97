"""Session 17: which step of a share="gl" session leaves a /dev/nvidiactl descriptor open?"""
import gc, os, sys
sys.path.insert(0, "tests")
from support.egl import HeadlessGL
import cltess
from cltess.io import load_scene
from cltess.backends.opencl import Tessellator

def fds():
    out = {}
    for fd in os.listdir("/proc/self/fd"):
        try: out[fd] = os.readlink(f"/proc/self/fd/{fd}")
        except OSError: pass
    return out

gl = HeadlessGL()
scene = load_scene("scenes/tea_table.json")
tess = Tessellator("nvidia")
last = fds()
def step(label):
    global last
    gc.collect(); gl.finish()
    now = fds()
    print(f"{label:40s} {len(now):4d}  +{sorted(set(now.items()) - set(last.items()))}  -{sorted(set(last.items()) - set(now.items()))}")
    last = now
for k in range(3):
    s = cltess.Session(scene, tessellator=tess, eps=0.02, share="gl"); step(f"{k} session made")
    f = s.tessellate(); step(f"{k} frame")
    f.gl(); step(f"{k} gl()")
    f2 = s.tessellate(); f2.gl(); step(f"{k} second frame, gl()")
    s.close(); step(f"{k} closed")
    del s, f, f2; step(f"{k} dropped")
for k in range(3):
    s = cltess.Session(scene, tessellator=tess, eps=0.02, share="cuda"); s.tessellate().cuda(); s.close(); del s; step(f"{k} cuda session")
