# Every Oclgrind scenario of tests/support/oclgrind_passes.py, both passes (checks, uninitialised
# values), on the tree as it is: session 11's closing check of the kernels changed since bf961ed.
import sys
from pathlib import Path
sys.path.insert(0, "tests")
from support import oclgrind_passes as passes
sys.exit(0 if passes.report_scenarios(list(passes.NAMES), Path("/tmp/lead11-og")) else 1)
