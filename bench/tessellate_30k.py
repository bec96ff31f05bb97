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

Beside them, in the same loop: the *peers*, a child that writes the PLY's number of bytes from
one NumPy array (``tofile``, fsync, rename onto the last file: the disk's rate as this file
system gives it) and a child that only starts Python and imports the CLI's modules.  The
machine is shared, so every row gives the median and the minimum of ``--repeat`` runs, and the
CPU seconds (user + system, all threads) of the same children, which other processes disturb
less than the wall clock.

Then the same steps timed one by one in this process (warm kernels), to show where the time
goes.

The children run with compiled bytecode, as a user's install has it (``pip`` compiles it; an
editable install writes it on first import): ``PYTHONDONTWRITEBYTECODE`` is dropped from their
environment and each tree's bytecode goes to its own ``PYTHONPYCACHEPREFIX`` folder, filled by an
untimed first run.  ``--source`` keeps this shell's setting instead (a checkout started with
``PYTHONDONTWRITEBYTECODE=1`` compiles cltess's sources at every start: 0.05-0.1 s more).

Each tree writes its own PLY (``out.ply``, ``out-baseline.ply``): a buffered writer that
replaces a file the other tree wrote through the page cache reuses the 556 MB of pages that
file's removal has just freed, which on this VM (free page reporting: freed memory goes back to
the host about two seconds later, and is faulted in again at ~1.5 ms per MB) made the baseline
look up to 2x faster than a run on its own.  ``--spacing S`` waits S seconds before every run,
so that no run starts on memory the previous one freed (a user's single run); the default 0
is runs back to back.  The two PLYs' MD5 are compared at the end (bitwise the same output).
"""
from __future__ import annotations

import argparse
import hashlib
import math
import os
import resource
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


CPU_SECONDS: list = []  # (user + system) CPU seconds of each child run, in run order
LOADS: list = []  # the 1-minute load average as each child run started


#: The tree whose code "this tree"'s children run (PYTHONPATH), and the folder they all run in:
#: not a checkout, since ``python -m`` and ``-c`` put the working folder first on sys.path,
#: before PYTHONPATH (run from a checkout, the baseline's children ran that checkout's code).
TREE = Path(__file__).resolve().parent.parent
CHILD_FOLDER = [None]


def python_path(tree) -> str:
    """PYTHONPATH for a child running ``tree``'s cltess: the tree, then this environment's entries
    that hold no cltess of their own (e.g. the GPU machine's folder of installed wheels)."""
    kept = [entry for entry in os.environ.get("PYTHONPATH", "").split(os.pathsep)
            if entry and not (Path(entry) / "cltess").is_dir()]
    return os.pathsep.join([str(Path(tree).resolve()), *kept])


def run_child(command: list[str], env: dict) -> float:
    """Wall seconds of a child process; its CPU seconds (user + system, all its threads) are
    appended to CPU_SECONDS."""
    LOADS.append(os.getloadavg()[0])
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    started = time.perf_counter()
    done = subprocess.run(command, env=env, capture_output=True, text=True, cwd=CHILD_FOLDER[0])
    wall = time.perf_counter() - started
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    CPU_SECONDS.append(after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)
    if done.returncode:
        sys.exit(done.stderr)
    return wall


SPACING = [0.0]  # seconds to wait before each child (--spacing)


def run_cli(args: list[str], env: dict) -> float:
    time.sleep(SPACING[0])
    return run_child([sys.executable, "-m", "cltess", "tessellate", *args], env)


def md5(path: Path) -> str:
    digest = hashlib.md5()
    with open(path, "rb") as handle:
        for block in iter(lambda: handle.read(1 << 24), b""):
            digest.update(block)
    return digest.hexdigest()


#: The peer of the PLY write: the same number of bytes from one NumPy array, ``tofile`` into
#: a file beside the PLY, fsync'd and renamed onto the last one (what atomic_write does), in
#: a child process (Python start and NumPy import included, as for the CLI).
PEER = """
import os, sys, numpy as np
data = np.ones(int(sys.argv[1]), np.uint8)
with open(sys.argv[2] + ".tmp", "wb") as f:
    data.tofile(f)
    f.flush()
    os.fsync(f.fileno())
os.replace(sys.argv[2] + ".tmp", sys.argv[2])
"""


def run_peer(size: int, path: Path, env: dict) -> float:
    time.sleep(SPACING[0])
    return run_child([sys.executable, "-c", PEER, str(size), str(path)], env)


def run_imports(env: dict) -> float:
    """Python start and the imports of the CLI's tessellate path, in a child."""
    return run_child([sys.executable, "-c", "import cltess.cli, cltess.stream, cltess.orient, cltess.io"], env)


def steps(scene_path: Path, out: Path, eps: float, device: str | None) -> dict:
    """The CLI's steps one by one in this process (run after a warm-up of the same), seconds:
    each step's calls wrapped in a wall clock (``_timed``)."""
    import cltess.io.ply as ply
    from cltess.backends.opencl import Tessellator
    from cltess.backends.opencl import tessellator as module
    from cltess.io import load_scene
    from cltess.orient import orient_scene
    from cltess.stream import tessellate_to_file

    tessellator = Tessellator(device)
    times: dict = {}
    wrapped = [(module.Tessellator, "plan", "plan: host adjacency, uploads, stages 1-3, totals"),
               (module.PendingEmit, "result", "wait for stages 4-5"),
               (ply.PlyWriter, "write_vertices", "PLY vertex records + writes"),
               (ply.PlyWriter, "write_faces", "PLY face records + writes"),
               (os, "fsync", "fsync"), (os, "replace", "rename onto the old file")]
    originals = [(owner, name, getattr(owner, name)) for owner, name, _ in wrapped]
    for owner, name, label in wrapped:
        setattr(owner, name, _timed(getattr(owner, name), label, times))
    try:
        started = time.perf_counter()
        scene = load_scene(scene_path)
        times["load (parse or cache)"] = time.perf_counter() - started
        started = time.perf_counter()
        oriented, _ = orient_scene(scene)
        times["orient (edge groups, shared with plan)"] = time.perf_counter() - started
        started = time.perf_counter()
        result = tessellate_to_file(tessellator, oriented, out, eps=eps)
        times["tessellate + write PLY, in all"] = time.perf_counter() - started
    finally:
        for owner, name, original in originals:
            setattr(owner, name, original)
    times["device stages (profiling spans)"] = sum(v for k, v in result.stage_ms.items() if k != "total_wall") / 1e3
    times["file MB"] = out.stat().st_size / 1e6
    return times


def _timed(function, label: str, times: dict):
    def timed(*args, **kwargs):
        started = time.perf_counter()
        try:
            return function(*args, **kwargs)
        finally:
            times[label] = times.get(label, 0.0) + time.perf_counter() - started
    return timed


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--device")
    parser.add_argument("--eps", type=float, default=0.0085)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--folder", help="where the scene and the PLY go (default: a temporary folder here)")
    parser.add_argument("--baseline", metavar="SOURCE_TREE",
                        help="also run the CLI of another checkout (PYTHONPATH=SOURCE_TREE), its runs "
                             "interleaved with these, e.g. the main branch before issue 15")
    parser.add_argument("--spacing", type=float, default=0.0, metavar="S",
                        help="seconds to wait before every child run (memory freed by the last run is "
                             "then no longer reused: a single run's conditions); default 0")
    parser.add_argument("--states", default="cold,warm", help="which of cold,warm to run (default both)")
    parser.add_argument("--source", action="store_true",
                        help="run the children as this shell sets PYTHONDONTWRITEBYTECODE (default: with "
                             "compiled bytecode, as an installed cltess)")
    args = parser.parse_args()
    SPACING[0] = args.spacing
    with tempfile.TemporaryDirectory(dir=args.folder or ".") as folder:
        folder = Path(folder)
        CHILD_FOLDER[0] = folder
        scene = folder / "teapots30k.bpt"
        write_scene(scene)
        out, base_out = folder / "out.ply", folder / "out-baseline.ply"
        common = ["--eps", str(args.eps), "--no-weld", "-q"] + (["--device", args.device] if args.device else [])
        base = common + ["-o", str(out)]
        baseline_args = common + ["-o", str(base_out)]
        print(f"{scene.name}: {scene.stat().st_size / 1e6:.1f} MB; load average {os.getloadavg()}; "
              f"spacing {args.spacing:g} s; {'sources compiled at each start' if args.source else 'compiled bytecode'}")
        rows, cpu, loads = {}, {}, {}
        peer = folder / "peer.bin"
        shell = dict(os.environ)
        if not args.source:  # compiled bytecode per tree, compiled by an untimed run of each
            shell.pop("PYTHONDONTWRITEBYTECODE", None)
            for tree, name in ((TREE, "tree"), (args.baseline, "baseline")):
                if tree:
                    env = dict(shell, PYTHONPATH=python_path(tree), CLTESS_SCENE_CACHE="off",
                               PYTHONPYCACHEPREFIX=str(folder / f"pycache-{name}"))
                    run_cli([str(scene), *common, "-o", str(folder / "compile.ply")], env)
        for orient in ("--orient", "--no-orient"):
            for state in [state for state in ("cold", "warm") if state in args.states.split(",")]:
                walls, baseline, peers, imports = [], [], [], []
                for _ in range(args.repeat):
                    cache = folder / f"cache-{orient}-{len(walls)}"  # cold: a fresh cache each run
                    env = dict(shell, PYTHONPATH=python_path(TREE), PYTHONPYCACHEPREFIX=str(folder / "pycache-tree"),
                               CLTESS_SCENE_CACHE=str(cache if state == "cold" else folder / "cache"))
                    if state == "warm" and not walls:
                        run_cli([str(scene), orient, *base], env)  # fills the warm cache
                    walls.append(run_cli([str(scene), orient, *base], env))
                    cpu.setdefault((orient, state), []).append(CPU_SECONDS[-1])
                    loads.setdefault((orient, state), []).append(LOADS[-1])
                    if args.baseline:  # its own caches: a fresh one (cold), its warm one (warm)
                        base_cache = folder / (f"cache-baseline-{orient}-{len(walls)}" if state == "cold"
                                               else "cache-baseline")
                        base_env = dict(env, PYTHONPATH=python_path(args.baseline),
                                        PYTHONPYCACHEPREFIX=str(folder / "pycache-baseline"),
                                        CLTESS_SCENE_CACHE=str(base_cache))
                        if state == "warm" and not baseline:
                            run_cli([str(scene), orient, *baseline_args], base_env)  # fills its warm cache
                        baseline.append(run_cli([str(scene), orient, *baseline_args], base_env))
                        cpu.setdefault((orient, f"{state}, baseline"), []).append(CPU_SECONDS[-1])
                        loads.setdefault((orient, f"{state}, baseline"), []).append(LOADS[-1])
                    if orient == "--orient" and state == "warm":  # the peers, in the same loop
                        peers.append(run_peer(out.stat().st_size, peer, env))
                        cpu.setdefault(("peer", "write"), []).append(CPU_SECONDS[-1])
                        loads.setdefault(("peer", "write"), []).append(LOADS[-1])
                        imports.append(run_imports(env))
                        cpu.setdefault(("peer", "imports"), []).append(CPU_SECONDS[-1])
                        loads.setdefault(("peer", "imports"), []).append(LOADS[-1])
                rows[(orient, state)] = walls
                if baseline:
                    rows[(orient, f"{state}, baseline")] = baseline
                if peers:
                    rows[("peer", "write")] = peers
                    rows[("peer", "imports")] = imports
        size = out.stat().st_size
        if args.baseline:
            same = md5(out) == md5(base_out)
            print(f"PLY MD5 {md5(out)}; the baseline's {'the same' if same else 'DIFFERENT: ' + md5(base_out)}")
        print(f"PLY {size / 1e6:.0f} MB, eps {args.eps}; wall seconds, median [min-max] of {args.repeat}; "
              f"CPU seconds (user + system) of the same runs, median [min]:")
        for (orient, state), walls in rows.items():
            spent = cpu[(orient, state)]
            label = {"write": "tofile + fsync + rename of the PLY's bytes", "imports": "python + the CLI's imports"}.get(
                state, state) if orient == "peer" else state
            load = loads[(orient, state)]
            print(f"  {orient:12} {label:44}: {statistics.median(walls):.2f} [{min(walls):.2f}-{max(walls):.2f}]"
                  f"   CPU {statistics.median(spent):.2f} [{min(spent):.2f}]   load {min(load):.1f}-{max(load):.1f}")
        os.environ["CLTESS_SCENE_CACHE"] = str(folder / "cache")
        SPACING[0] = 0.0
        steps(scene, out, args.eps, args.device)  # warm-up
        for name, value in steps(scene, out, args.eps, args.device).items():
            print(f"  step: {name}: {value:.2f}")
        print(f"load average after {os.getloadavg()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
