import resource, sys, time
import numpy as np
from cltess.backends.opencl.tessellator import Tessellator
from cltess.io import load_scene
from cltess.scene import Scene
teapot = load_scene("scenes/teapot.bpt")
t = Tessellator("pocl", work="patch")
def cpu(): r = resource.getrusage(resource.RUSAGE_SELF); return r.ru_utime + r.ru_stime
res = {True: [], False: []}
for copies, eps in [(250, 0.0005), (10, 0.001)]:
    patches = np.concatenate([teapot.patches] * copies)
    scene = Scene(patches, np.zeros(len(patches), np.int32), name="t")
    for named in (True, False):
        t.programs.names_local_size = named; t.tessellate(scene, eps=eps)  # warm
    for rnd in range(6):
        for named in ((True, False) if rnd % 2 == 0 else (False, True)):
            t.programs.names_local_size = named
            c0, w0 = cpu(), time.perf_counter()
            tess = t.tessellate(scene, eps=eps)
            res[named].append((copies, cpu() - c0, time.perf_counter() - w0, tess.stats.get("stage_ms", {})))
    for named in (True, False):
        rows = [r for r in res[named] if r[0] == copies]
        print(copies, len(tess.triangles), "named" if named else "runtime", "CPU-s min/median %.3f/%.3f" % (min(r[1] for r in rows), np.median([r[1] for r in rows])),
              "wall min/med %.3f/%.3f" % (min(r[2] for r in rows), np.median([r[2] for r in rows])), flush=True)
