"""checks.t_junctions before (the tree at CHECKS_BEFORE, a copy of cltess/checks.py) and now, on
bigguy.bez at eps 0.03% and 0.01% of its diagonal and the tea table at 0.03% (Intel's CPU runtime
tessellates them): the same vertices found, and the time of each (session 12).

    python bench/results/lead12-2core/t_junctions_ab.py CHECKS_BEFORE.py
"""
import sys
import time
import types
import warnings

import numpy as np

warnings.simplefilter("ignore")
from cltess import checks  # noqa: E402
from cltess.io import load_scene  # noqa: E402
from cltess.pipeline import Tessellator  # noqa: E402

before = types.ModuleType("cltess.checks_before")
before.__package__ = "cltess"
exec(compile(open(sys.argv[1]).read(), sys.argv[1], "exec"), before.__dict__)
tessellator = Tessellator()
for name, rel in (("bigguy.bez", 0.0003), ("bigguy.bez", 0.0001), ("tea_table.json", 0.0003)):
    scene = load_scene(f"scenes/{name}")
    tess = tessellator.tessellate(scene, eps=rel * scene.diagonal)
    arrays = (np.array(tess.positions), np.array(tess.triangles), np.array(tess.object_ids))
    found, seconds = {}, {}
    for label, module in (("before", before), ("now", checks)):
        started = time.perf_counter()
        found[label] = module.t_junctions(*arrays)
        seconds[label] = time.perf_counter() - started
    assert np.array_equal(found["before"], found["now"])
    print(f"{name} eps {rel:g} x diagonal: {len(arrays[1]):,} triangles, {len(found['now'])} found; "
          f"before {seconds['before']:.3f} s, now {seconds['now']:.3f} s")
