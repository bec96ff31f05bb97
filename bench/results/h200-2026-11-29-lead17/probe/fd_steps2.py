"""Session 17: the /dev/nvidiactl descriptor a share="gl" session leaves: which part?"""
import gc, os, sys
sys.path.insert(0, "tests")
from support.egl import HeadlessGL
import cltess
from cltess.io import load_scene
from cltess.backends.opencl import Tessellator
from cltess.backends.opencl import share_gl

def count():
    gc.collect(); gl.finish()
    return len(os.listdir("/proc/self/fd"))

gl = HeadlessGL()
scene = load_scene("scenes/tea_table.json")
tess = Tessellator("nvidia")
s = cltess.Session(scene, tessellator=tess, eps=0.02, share="gl"); s.tessellate().gl(); s.close(); del s
def variant(label, run, times=3):
    before = count()
    for _ in range(times):
        run()
    print(f"{label:60s} {count() - before:+d} descriptors over {times} sessions")

def plain_gl():
    with cltess.Session(scene, tessellator=tess, eps=0.02, share="gl") as s:
        s.tessellate().gl()
variant("share=gl, a frame, gl()", plain_gl)
def no_gl_call():
    with cltess.Session(scene, tessellator=tess, eps=0.02, share="gl") as s:
        s.tessellate().finish()
variant("share=gl, a frame, no gl()", no_gl_call)
def no_frame():
    with cltess.Session(scene, tessellator=tess, eps=0.02, share="gl") as s:
        pass
variant("share=gl, no frame (semaphores only)", no_frame)
original = share_gl.GlOutputBuffers._delete_gl
share_gl.GlOutputBuffers._delete_gl = lambda self, name: self._gl_objects.pop(name, None)
variant("share=gl, a frame, gl(), GL objects never deleted", plain_gl)
share_gl.GlOutputBuffers._delete_gl = original
def cuda():
    with cltess.Session(scene, tessellator=tess, eps=0.02, share="cuda") as s:
        s.tessellate().cuda()
variant("share=cuda, a frame, cuda()", cuda)
variant("nothing", lambda: None)
