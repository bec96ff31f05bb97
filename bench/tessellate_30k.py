"""Issue 15's end-to-end target: ``cltess tessellate`` of a 30k-patch teapot scene to a PLY.

    python bench/tessellate_30k.py [--device NAME] [--eps 0.0085] [--repeat 3]

The scene: 960 teapots (scenes/teapot.bez, 30,720 patches) on a grid, each turned about z
(the placement of bench/stream_large.py), written as one ``.bpt`` file (19.6 MB of ``repr``
floats).  At eps 0.0085 the per-patch PLY (``--no-weld``) is 550 MB: 8.6 M vertices, 16.1 M
triangles.  Each run is the CLI in a child process, wall clock from start to exit (Python start,
imports, OpenCL start, parsing, orientation, stages, the file written and fsync'd):

* "cold": an empty scene cache (``CLTESS_SCENE_CACHE`` at a fresh folder): the text is parsed;
* "warm": the same cache again: the patches come from the binary cache;
* each with the default ``--orient`` and with ``--no-orient``.

Then the same steps timed one by one in this process (warm kernels), to show where the time
goes.
"""
from __future__ import annotations

import argparse
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

SCENES = Path(__file__).resolve().parent.parent / "scenes"


def write_scene(path: Path, copies: int = 960) -> None:
    from cltess.io import load_scene
    from cltess.io.bpt import write_bpt

    teapot = np.asarray(load_scene(SCENES / "teapot.bez").patches, np.float64)
    side = math.ceil(math.sqrt(copies))
    parts = []
    for k in range(copies):
        c, s = math.cos(0.7 * k), math.sin(0.7 * k)
        matrix = np.array([[c, -s, 0, 8.0 * (k % side)], [s, c, 0, 8.0 * (k // side)], [0, 0, 1, 0], [0, 0, 0, 1]])
        parts.append(teapot @ matrix.T)
    write_bpt(path, np.concatenate(parts))


def run_cli(args: list[str], env: dict) -> float:
    started = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "cltess", "tessellate", *args], env=env, capture_output=True,
                          text=True)
    wall = time.perf_counter() - started
    if done.returncode:
        sys.exit(done.stderr)
    return wall


def steps(scene_path: Path, out: Path, eps: float, device: str | None) -> dict:
    """The CLI's steps one by one (after a warm-up run of the same), seconds."""
    from cltess.backends.opencl import Tessellator
    from cltess.io import load_scene
    from cltess.orient import orient_scene
    from cltess.stream import tessellate_to_file

    tessellator = Tessellator(device)
    times = {}
    started = time.perf_counter()
    scene = load_scene(scene_path)
    times["load (parse or cache)"] = time.perf_counter() - started
    started = time.perf_counter()
    oriented, _ = orient_scene(scene)
    times["orient"] = time.perf_counter() - started
    started = time.perf_counter()
    result = tessellate_to_file(tessellator, oriented, out, eps=eps)
    times["tessellate + write PLY"] = time.perf_counter() - started
    times["of which device stages"] = sum(v for k, v in result.stage_ms.items() if k != "total_wall") / 1e3
    times["file MB"] = out.stat().st_size / 1e6
    return times


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--device")
    parser.add_argument("--eps", type=float, default=0.0085)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--folder", help="where the scene and the PLY go (default: a temporary folder here)")
    parser.add_argument("--baseline", metavar="SOURCE_TREE",
                        help="also run the CLI of another checkout (PYTHONPATH=SOURCE_TREE), its runs "
                             "interleaved with these, e.g. the main branch before issue 15")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(dir=args.folder or ".") as folder:
        folder = Path(folder)
        scene = folder / "teapots30k.bpt"
        write_scene(scene)
        out = folder / "out.ply"
        base = ["--eps", str(args.eps), "--no-weld", "-q", "-o", str(out)] + (["--device", args.device] if args.device else [])
        print(f"{scene.name}: {scene.stat().st_size / 1e6:.1f} MB; load average {os.getloadavg()}")
        rows = {}
        for orient in ("--orient", "--no-orient"):
            for state in ("cold", "warm"):
                walls, baseline = [], []
                for _ in range(args.repeat):
                    cache = folder / f"cache-{orient}-{len(walls)}"  # cold: a fresh cache each run
                    env = dict(os.environ, CLTESS_SCENE_CACHE=str(cache if state == "cold" else folder / "cache"))
                    if state == "warm" and not walls:
                        run_cli([str(scene), orient, *base], env)  # fills the warm cache
                    walls.append(run_cli([str(scene), orient, *base], env))
                    if args.baseline and state == "cold":  # the baseline has no cache: cold only
                        baseline.append(run_cli([str(scene), orient, *base],
                                                dict(env, PYTHONPATH=str(Path(args.baseline).resolve()))))
                rows[(orient, state)] = walls
                if baseline:
                    rows[(orient, "baseline")] = baseline
        size = out.stat().st_size
        print(f"PLY {size / 1e6:.0f} MB, eps {args.eps}; wall seconds, median [min-max] of {args.repeat}:")
        for (orient, state), walls in rows.items():
            print(f"  {orient:12} {state:5}: {statistics.median(walls):.2f} [{min(walls):.2f}-{max(walls):.2f}]")
        os.environ["CLTESS_SCENE_CACHE"] = str(folder / "cache")
        steps(scene, out, args.eps, args.device)  # warm-up
        for name, value in steps(scene, out, args.eps, args.device).items():
            print(f"  step: {name}: {value:.2f}")
        print(f"load average after {os.getloadavg()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
