# Run from the branch's worktree with its venv: OCL_ICD_VENDORS=/tmp/empty-icd nice -n 19 python bench/results/cpu15f-2core/oclgrind_cpu15f.py
"""Both Oclgrind passes on scenarios that run this branch's kernel changes where Oclgrind reaches them:
put_vertex's stores and surface_normal's cross/dot (common.h: the builtins themselves off PoCL, so
Oclgrind runs the builtin forms), stage 5's grid_cell(s) now always inline (the uniform grid, transitions,
collapsed edges, batches), as tests/test_oclgrind.py's test_no_oclgrind_reports checks them.  (The
spelled-out forms are PoCL's only: Oclgrind cannot run them; tests/test_unit_normal.py checks them on PoCL.)"""
import sys
from pathlib import Path
sys.path.insert(0, "tests")
from support import oclgrind_passes as passes
names = ["uniform", "uniform_fine", "one_transition", "two_transitions_adjacent", "collapsed_lid",
         "collapsed_bottom_direct", "rational_sphere", "many_patches_batched", "mixed_culled"]
sys.exit(0 if passes.report_scenarios(names, Path("/tmp/cpu15f-og")) else 1)
