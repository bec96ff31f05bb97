"""Inclusive thread-CPU µs per overlapped frame by function (wrapped), --as-gpu frames."""
import sys, time, warnings, statistics, collections, importlib
sys.path.insert(0, "/work/wt/host15d/bench"); warnings.simplefilter("ignore")
import pyopencl as cl
import cltess, frame_loop as fl
from cltess.backends.opencl import Tessellator
clock = time.thread_time_ns
T = collections.defaultdict(int)
N = collections.defaultdict(int)
def wrap(owner, name, label=None):
    if isinstance(owner, str):
        owner = importlib.import_module(owner)
    if isinstance(owner, str) or not hasattr(owner, name):
        return
    f = getattr(owner, name)
    label = label or f"{getattr(owner, '__name__', owner)}.{name}"
    if isinstance(f, property):
        g = f.fget
        def get(self):
            s = clock()
            try: return g(self)
            finally: T[label] += clock() - s; N[label] += 1
        setattr(owner, name, property(get)); return
    def call(*a, **k):
        s = clock()
        try: return f(*a, **k)
        finally: T[label] += clock() - s; N[label] += 1
    setattr(owner, name, call)
for spec in sys.argv[2:]:
    mod, _, rest = spec.rpartition(":")
    parts = rest.split(".")
    owner = importlib.import_module(mod)
    for p in parts[:-1]:
        owner = getattr(owner, p)
    wrap(owner, parts[-1], rest)
wrap(cl, "wait_for_events", "WAIT wait_for_events")
wrap(cl.Event, "wait", "WAIT Event.wait")
t = Tessellator(None, work="point")
t.fused_offsets, t.tiled_offsets, t._cpu = True, True, False
scene = fl.suite_scene(sys.argv[1])
s = cltess.Session(scene, tessellator=t, pixels=fl.PIXELS)
path = list(fl.orbit(scene.camera, 20))
for c in path: s.tessellate(camera=c).fetch()
rounds = []
for r in range(6):
    T.clear(); N.clear()
    st = clock()
    frames = [s.tessellate(camera=c, wait=False) for c in path]
    T["WHOLE loop"] += clock() - st
    frames[-1].finish()
    rounds.append({k: v / len(path) / 1e3 for k, v in T.items()} | {"n " + k: v / len(path) for k, v in N.items()})
keys = sorted({k for r in rounds for k in r if not k.startswith("n ")})
for k in keys:
    vals = [r.get(k, 0) for r in rounds]
    print(f"{statistics.median(vals):8.1f} us  (min {min(vals):7.1f})  {k}  x{rounds[-1].get('n '+k, 0):g}")
