"""CPU seconds of a child that imports the CLI's modules: the checkout as measured (no
__pycache__: this shell sets PYTHONDONTWRITEBYTECODE=1) against a copy of the same commit with
its bytecode compiled (git archive HEAD | tar -x -C /tmp/ply15b/cl-copy; python -m compileall
-q /tmp/ply15b/cl-copy/cltess)."""
import os, resource, subprocess, sys, statistics
trees = {"branch tree, no __pycache__ (as measured)": "/work/wt/ply15b", "same code with compiled __pycache__": "/tmp/ply15b/cl-copy"}
res = {k: [] for k in trees}
for i in range(6):
    for name, tree in trees.items():
        env = dict(os.environ, PYTHONPATH=tree)
        b = resource.getrusage(resource.RUSAGE_CHILDREN)
        subprocess.run([sys.executable, "-c", "import cltess.cli, cltess.stream, cltess.orient, cltess.io; assert cltess.__file__.startswith(%r)" % tree], env=env, cwd="/tmp", check=True)
        a = resource.getrusage(resource.RUSAGE_CHILDREN)
        res[name].append(a.ru_utime - b.ru_utime + a.ru_stime - b.ru_stime)
for k, v in res.items(): print(f"{k}: CPU s median {statistics.median(v):.3f} min {min(v):.3f}")
print("load", os.getloadavg())
