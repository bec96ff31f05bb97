# Run from the branch's worktree with its venv: OCL_ICD_VENDORS=/tmp/empty-icd python bench/results/h100-2026-11-28-gpu15f/oclgrind_triangles.py
"""Both Oclgrind passes on the scenarios that run stages/triangles.cl (POINTS, PREPARED_POINTS, PREPARED_ROWS)
and the plain uniform one, as tests/test_oclgrind.py's test_no_oclgrind_reports checks them."""
import sys, time
from pathlib import Path
sys.path.insert(0, "tests")
import oclgrind_scenarios as scenarios
from support import oclgrind_passes as passes
names = ["uniform", *scenarios.POINTS]
names = list(dict.fromkeys(n for n in names if n in passes.NAMES))
print("scenarios:", names, flush=True)
out = Path("/tmp/gpu15f-og")
started = {p: passes.start(p, out / p, names) for p in passes.PASSES}
for p, s in started.items():
    t = time.time()
    run = passes.finish(s)
    for n in names:
        problems = [] if n in run.results else ["did not finish"]
        problems += run.reports.get(n, [])
        print(p, n, "OK" if not problems else problems[:3], flush=True)
    print(p, "exit", run.returncode, f"{time.time() - t:.0f} s", flush=True)
