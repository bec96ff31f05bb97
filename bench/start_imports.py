"""The CLI's start: CPU seconds of a fresh child that imports the ``cltess tessellate`` path's
modules, this tree against another, each as this shell runs it and with compiled bytecode.

    python bench/start_imports.py --baseline SOURCE_TREE [--repeat 9]

"source": the tree as it is (this shell sets PYTHONDONTWRITEBYTECODE=1 and a checkout has no
``__pycache__``, so every start compiles cltess's sources); "bytecode": a copy of the tree's
``cltess`` package with ``python -m compileall`` run on it (what a ``pip install`` gives a user).
The children run outside any checkout (``python -c`` puts the working folder first on
sys.path) with PYTHONPATH set to the tree; each child checks where cltess came from.  Runs
alternate between the four variants; CPU seconds are user + system of the child (getrusage),
which the other processes of a loaded machine disturb less than the wall clock.
"""
from __future__ import annotations

import argparse
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

TREE = Path(__file__).resolve().parent.parent
#: What ``cltess tessellate`` imports before it reads the scene (bench/tessellate_30k.py's peer).
IMPORTS = "import cltess.cli, cltess.stream, cltess.orient, cltess.io"


def child_cpu(tree: Path, folder: Path, extra: str = "") -> tuple[float, str]:
    """CPU seconds of one child importing IMPORTS from ``tree``, and what ``extra`` printed."""
    check = f"assert cltess.__file__.startswith({str(tree)!r}), cltess.__file__"
    env = dict(os.environ, PYTHONPATH=str(tree))
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    done = subprocess.run([sys.executable, "-c", f"{IMPORTS}\n{check}\n{extra}"], env=env, cwd=folder,
                          capture_output=True, text=True, check=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime, done.stdout.strip()


def compiled_copy(tree: Path, into: Path) -> Path:
    """A copy of ``tree``'s cltess package with its bytecode compiled."""
    shutil.copytree(tree / "cltess", into / "cltess", ignore=shutil.ignore_patterns("__pycache__"))
    subprocess.run([sys.executable, "-m", "compileall", "-q", str(into / "cltess")], check=True)
    return into


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", required=True, metavar="SOURCE_TREE")
    parser.add_argument("--repeat", type=int, default=9)
    args = parser.parse_args()
    baseline = Path(args.baseline).resolve()
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        variants = {"this tree, source": TREE, "baseline, source": baseline,
                    "this tree, bytecode": compiled_copy(TREE, folder / "tree"),
                    "baseline, bytecode": compiled_copy(baseline, folder / "baseline")}
        count = "import sys; print(len(sys.modules), sum(n.startswith('pygments') for n in sys.modules))"
        for name, tree in variants.items():  # one untimed start each (the file cache), and the module counts
            print(f"{name}: {tree}; modules, of them pygments: {child_cpu(tree, folder, count)[1]}")
        cpu: dict = {name: [] for name in variants}
        loads = []
        for _ in range(args.repeat):
            for name, tree in variants.items():
                loads.append(os.getloadavg()[0])
                cpu[name].append(child_cpu(tree, folder)[0])
        print(f"CPU seconds (user + system) of a child running {IMPORTS!r}, median [min] of {args.repeat}, "
              f"load {min(loads):.1f}-{max(loads):.1f}:")
        for name, values in cpu.items():
            print(f"  {name:22}: {statistics.median(values):.3f} [{min(values):.3f}]")
    return 0


if __name__ == "__main__":
    sys.exit(main())
