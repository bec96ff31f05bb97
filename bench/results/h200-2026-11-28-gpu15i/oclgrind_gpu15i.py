# Run from the branch's worktree with its venv: OCL_ICD_VENDORS=/tmp/empty-icd nice -n 19 python bench/results/h200-2026-11-28-gpu15i/oclgrind_gpu15i.py
"""Both Oclgrind passes on the scenarios that run stage 5 a work-item per triangle (stages/triangles.cl:
pattern_triangles_of, pattern_triangle_pair, a cell's two triangles per work-item, 32-bit numbers within a
work-group): `uniform`, every *_by_points, *_by_prepared_points and *_by_prepared_rows scenario (collapsed
edges, culled patches, PN and ESC patches walked whole, batches, frames), as tests/test_oclgrind.py's
test_no_oclgrind_reports checks them."""
import sys, time
from pathlib import Path
sys.path.insert(0, "tests")
from support import oclgrind_passes as passes
names = [n for n in passes.NAMES if n == "uniform" or "_by_points" in n or "_by_prepared_" in n
         or n == "many_patches_frames_by_points"]
assert all(n in passes.NAMES for n in names)
print("scenarios:", names, flush=True)
out = Path("/tmp/gpu15i-og")
started = {p: passes.start(p, out / p, names) for p in passes.PASSES}
for p, s in started.items():
    t = time.time()
    run = passes.finish(s)
    for n in names:
        problems = [] if n in run.results else ["did not finish"]
        problems += run.reports.get(n, [])
        print(p, n, "OK" if not problems else problems[:3], flush=True)
    print(p, "exit", run.returncode, f"{time.time() - t:.0f} s", flush=True)
