# Run from the branch's worktree with its venv: OCL_ICD_VENDORS=/tmp/empty-icd nice -n 19 python bench/results/h200-2026-11-28-gpu15h/oclgrind_gpu15h.py
"""Both Oclgrind passes on the scenarios that run this branch's kernel changes: unit_or (kinds/bezier.h's
surface_normal, every Bezier path: the uniform grids, the rational sphere, a collapsed edge's fall-back) and
prepared_rows' group staging in local memory (all five *_by_prepared_rows scenarios: culled patches, PN,
batches), as tests/test_oclgrind.py's test_no_oclgrind_reports checks them."""
import sys
from pathlib import Path
sys.path.insert(0, "tests")
from support import oclgrind_passes as passes
names = ["uniform", "uniform_by_points", "rational_sphere", "collapsed_lid", "uniform_fine_by_prepared_rows",
         "pn_icosphere_by_prepared_rows", "mixed_culled_by_prepared_rows", "collapsed_bottom_direct_by_prepared_rows",
         "many_patches_batched_by_prepared_rows"]
sys.exit(0 if passes.report_scenarios(names, Path("/tmp/gpu15h-og")) else 1)  # (the loop it ran: support.oclgrind_passes.report_scenarios)
