# Run from the branch's worktree with its venv: OCL_ICD_VENDORS=/tmp/empty-icd python bench/results/h100-2026-11-28-gpu15g/oclgrind_projected.py
"""Both Oclgrind passes on scenarios that run kinds/bezier.h's projected both ways (weight exactly 1: the teapot's
uniform grids; not 1: the rational sphere) and its normal fall-back (collapsed edges), through the per-patch,
by-point and prepared-rows kernels, as tests/test_oclgrind.py's test_no_oclgrind_reports checks them."""
import sys, time
from pathlib import Path
sys.path.insert(0, "tests")
from support import oclgrind_passes as passes
names = ["uniform", "uniform_by_points", "uniform_fine_by_prepared_rows", "rational_sphere", "rational_sphere_direct",
         "collapsed_lid", "collapsed_bottom_direct_by_prepared_rows"]
assert all(n in passes.NAMES for n in names)
print("scenarios:", names, flush=True)
out = Path("/tmp/gpu15g-og")
started = {p: passes.start(p, out / p, names) for p in passes.PASSES}
for p, s in started.items():
    t = time.time()
    run = passes.finish(s)
    for n in names:
        problems = [] if n in run.results else ["did not finish"]
        problems += run.reports.get(n, [])
        print(p, n, "OK" if not problems else problems[:3], flush=True)
    print(p, "exit", run.returncode, f"{time.time() - t:.0f} s", flush=True)
