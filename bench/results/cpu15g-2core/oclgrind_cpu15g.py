# Run from the branch's worktree with its venv: OCL_ICD_VENDORS=/tmp/empty-icd nice -n 19 python bench/results/cpu15g-2core/oclgrind_cpu15g.py
"""Both Oclgrind passes on scenarios that run this branch's kernel changes where Oclgrind reaches them
(off PoCL sqrt1f, imin, imax, cross3 are the builtins, so Oclgrind runs the builtin forms): PN
triangles' unit_or_zero and pn_unit_normal (stage 4), the triangle and quad transition patterns'
imin/imax (stages 3, 5), edge_near_fraction, edge_factor and dyadic_factor (stages 1, 4), as
tests/test_oclgrind.py's test_no_oclgrind_reports checks them."""
import sys
from pathlib import Path
sys.path.insert(0, "tests")
from support import oclgrind_passes as passes
names = ["uniform", "one_transition", "two_transitions_adjacent", "collapsed_lid", "saturated",
         "pn_icosphere", "pn_coarse_direct", "pn_semi_uniform_mixed_culled", "semi_uniform_capped_direct",
         "mixed_culled"]
sys.exit(0 if passes.report_scenarios(names, Path("/tmp/cpu15g-og")) else 1)
