# Run from the branch's worktree with its venv: OCL_ICD_VENDORS=/tmp/empty-icd nice -n 19 python bench/results/h200-2026-11-28-gpu15i/oclgrind_gpu15i.py
"""Both Oclgrind passes on the scenarios that run stage 5 a work-item per triangle (stages/triangles.cl:
pattern_triangles_of, pattern_triangle_pair, a cell's two triangles per work-item, 32-bit numbers within a
work-group): `uniform`, every *_by_points, *_by_prepared_points and *_by_prepared_rows scenario (collapsed
edges, culled patches, PN and ESC patches walked whole, batches, frames), as tests/test_oclgrind.py's
test_no_oclgrind_reports checks them."""
import sys
from pathlib import Path
sys.path.insert(0, "tests")
from support import oclgrind_passes as passes
names = [n for n in passes.NAMES if n == "uniform" or "_by_points" in n or "_by_prepared_" in n
         or n == "many_patches_frames_by_points"]
sys.exit(0 if passes.report_scenarios(names, Path("/tmp/gpu15i-og")) else 1)  # (the loop it ran: support.oclgrind_passes.report_scenarios)
