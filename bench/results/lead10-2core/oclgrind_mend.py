import sys
from pathlib import Path
sys.path.insert(0, "tests")
from support import oclgrind_passes as passes
names = ["uniform", "uniform_fine", "one_transition", "two_transitions_adjacent", "collapsed_lid",
         "collapsed_bottom_direct", "rational_sphere", "many_patches_batched", "mixed_culled",
         "uniform_by_points", "uniform_fine_by_prepared_rows", "pn_icosphere_by_prepared_rows"]
names = [n for n in names if n in passes.NAMES] + [n for n in passes.NAMES if n.startswith("pn_")][:3]
sys.exit(0 if passes.report_scenarios(sorted(set(names)), Path("/tmp/lead-og")) else 1)
