"""Cold-cache cost of scenes of new sizes: the runtime choosing the work-group size (argument "runtime": this tree as it is) or every None local size named (argument "fixed": monkeypatched, as programs.py now does on PoCL).  Run from the checkout root with fresh XDG_CACHE_HOME and POCL_CACHE_DIR, CLTESS_DEVICE=pocl|intel."""
import math, os, sys, time, resource
import numpy as np
fixed = sys.argv[1] == "fixed"
from cltess.backends.opencl import programs as P
from cltess.backends.opencl.tessellator import WORK_GROUP
if fixed:
    orig = P.Kernel.launch
    def launch(self, queue, global_size, local_size, args, options=None):
        if local_size is None:
            local_size = (math.gcd(global_size[0], WORK_GROUP),) + (1,) * (len(global_size) - 1)
        return orig(self, queue, global_size, local_size, args, options)
    P.Kernel.launch = launch
from cltess.io import load_scene
from cltess.pipeline import Tessellator
from cltess.scene import Scene
teapot = load_scene("scenes/teapot.bpt")
t = Tessellator()
def cpu(): r = resource.getrusage(resource.RUSAGE_SELF); return r.ru_utime + r.ru_stime
for copies in [1, 2, 3, 5, 8, 13, 21, 34, 55, 89]:
    n = len(teapot.patches) * copies
    scene = Scene(np.concatenate([teapot.patches] * copies), np.zeros(n, np.int32), name="t")
    for rep in range(2):
        c0 = cpu(); w0 = time.perf_counter()
        tess = t.tessellate(scene, eps=0.01)
        print(f"{'fixed' if fixed else 'runtime'} {n:5d} patches rep{rep}: {cpu()-c0:6.2f} CPU-s {time.perf_counter()-w0:6.2f} s  {len(tess.triangles)} tris", flush=True)
