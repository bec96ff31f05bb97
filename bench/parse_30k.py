"""The cold steps of ``cltess tessellate`` of the 30k-patch teapot scene, each tree in fresh
child processes: the ``.bpt`` text parsed (``bpt._fast_bpt``), and the orientation computed
(``orient_scene`` without the scene cache), by CPU seconds (user + system) and minor page faults.

    python bench/parse_30k.py [--repeat 5] [--baseline SOURCE_TREE] [--folder DIR]

The scene is bench/tessellate_30k.py's (960 teapots, 30,720 patches, 19.6 MB of ``repr``
floats).  Children of the two trees alternate; each prints its numbers and the MD5 of the
parsed patches and of the flips, which must be the same for both trees.
"""
from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent

CHILD = """
import hashlib, os, resource, sys
os.environ["CLTESS_SCENE_CACHE"] = "off"
from cltess.io import bpt
from cltess.orient import orient_scene
from cltess.scene import Scene
import numpy as np

def now():
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime, usage.ru_minflt

data = open(sys.argv[1], "rb").read()
start = now()
patches = bpt._fast_bpt(data)
parsed = now()
scene = Scene(patches, np.zeros(len(patches), np.int32), None, "teapots")
oriented, report = orient_scene(scene)
done = now()
print(parsed[0] - start[0], parsed[1] - start[1], done[0] - parsed[0], done[1] - parsed[1],
      hashlib.md5(patches.tobytes()).hexdigest(), hashlib.md5(oriented.patches.tobytes()).hexdigest())
"""


def child(tree: Path, scene: Path) -> list:
    """One child on ``tree``'s code: PYTHONPATH, and a working folder without a ``cltess``
    (``python -c`` puts the working folder first on sys.path, before PYTHONPATH)."""
    env = dict(os.environ, PYTHONPATH=str(tree))
    out = subprocess.run([sys.executable, "-c", CHILD, str(scene)], env=env, cwd=scene.parent, capture_output=True,
                         text=True, check=True).stdout.split()
    return [float(out[0]), int(out[1]), float(out[2]), int(out[3]), out[4], out[5]]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--baseline", metavar="SOURCE_TREE", help="another checkout, run alternately")
    parser.add_argument("--folder", help="where the scene goes (default: a temporary folder here)")
    args = parser.parse_args()
    sys.path.insert(0, str(HERE))
    from tessellate_30k import write_scene

    trees = {"this tree": HERE.parent}
    if args.baseline:
        trees["baseline"] = Path(args.baseline).resolve()
    with tempfile.TemporaryDirectory(dir=args.folder or ".") as folder:
        scene = Path(folder) / "teapots30k.bpt"
        write_scene(scene)
        print(f"{scene.name}: {scene.stat().st_size / 1e6:.1f} MB; load average {os.getloadavg()}")
        rows = {name: [] for name in trees}
        for _ in range(args.repeat):
            for name, tree in trees.items():
                rows[name].append(child(tree, scene))
        for name, runs in rows.items():
            parse, parse_faults, orient, orient_faults = (sorted(run[k] for run in runs) for k in range(4))
            print(f"  {name:10} parse CPU s median {statistics.median(parse):.3f} [min {parse[0]:.3f}], "
                  f"{statistics.median(parse_faults):.0f} faults; orient CPU s median {statistics.median(orient):.3f} "
                  f"[min {orient[0]:.3f}], {statistics.median(orient_faults):.0f} faults; "
                  f"MD5 patches {runs[0][4][:12]}, oriented {runs[0][5][:12]}")
        digests = {tuple(run[4:]) for runs in rows.values() for run in runs}
        print("patches and flips the same in every run:" if len(digests) == 1 else "DIFFERENT:", digests)
        print(f"load average after {os.getloadavg()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
