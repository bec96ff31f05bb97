import time, sys, os, resource
T0 = time.perf_counter()
def cpu():
    r = resource.getrusage(resource.RUSAGE_SELF); return r.ru_utime + r.ru_stime
def flt():
    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt
import cltess.cli as cli, cltess.stream, cltess.orient, cltess.io
import cltess.device as device
marks = [("imports", time.perf_counter() - T0, cpu(), flt())]
def wrap(owner, name, label):
    f = getattr(owner, name)
    def g(*a, **k):
        s = time.perf_counter(); c = cpu(); m = flt()
        try: return f(*a, **k)
        finally: marks.append((label, time.perf_counter() - s, cpu() - c, flt() - m))
    setattr(owner, name, g)
from cltess.backends.opencl import tessellator as tm
import cltess.io.scenes as scenes, cltess.orient as orient, cltess.stream as stream
wrap(cli, "_prepare_scene", "prepare_scene")
wrap(scenes, "load_scene", " load_scene")
import cltess.io.bpt as bpt
wrap(bpt, "_fast_bpt", "  _fast_bpt")
wrap(orient, "orient_scene", " orient_scene")
import cltess.crack.adjacency as adj
wrap(adj, "edge_groups", "  edge_groups")
wrap(device, "pick_device", "pick_device")
wrap(tm.Tessellator, "__init__", "Tessellator()")
wrap(tm.Tessellator, "plan", " plan")
wrap(tm.Tessellator, "compose", "  compose")
wrap(stream, "tessellate_to_file", "tessellate_to_file")
code = cli.main(sys.argv[1:])
marks.append(("total", time.perf_counter() - T0, cpu(), flt()))
for m in marks: print(f"{m[0]:22} {m[1]:.3f} cpu {m[2]:.3f} flt {m[3]}")
import glob
hz = os.sysconf("SC_CLK_TCK")
for task in sorted(glob.glob("/proc/self/task/*")):
    try:
        name = open(task + "/comm").read().strip()
        f = open(task + "/stat").read().rsplit(")", 1)[1].split()
        print(f"  thread {name:20} {(int(f[11]) + int(f[12])) / hz:.2f} s cpu")
    except OSError:
        pass
r = resource.getrusage(resource.RUSAGE_SELF)
print(f"  process {r.ru_utime:.2f} user {r.ru_stime:.2f} sys, minflt {r.ru_minflt}")
