"""Benchmark (issue 5): a scene of at least 50 million output triangles tessellated to a PLY
file under a memory cap; prints wall time, peak RSS and the output size.

    python bench/stream_large.py [--copies 80] [--eps 0.0002] [--max-memory 512M]

The scene is COPIES transformed teapots (32 patches each) written to a temporary JSON scene;
the run is the CLI in a child process so that its peak RSS is its own.  A baseline child
(one teapot at a coarse tolerance) gives the fixed cost of imports and the OpenCL runtime.
"""
import argparse
import json
import math
import subprocess
import sys
import tempfile
import time
from pathlib import Path

SCENES = Path(__file__).resolve().parent.parent / "scenes"
CHILD = r"""
import re, sys
from pathlib import Path
from cltess.cli import main
code = main(["tessellate"] + sys.argv[1:])
# VmHWM, not ru_maxrss: Linux carries ru_maxrss over execve from the parent process.
print("PEAK_RSS", int(re.search(r"VmHWM:\s+(\d+) kB", Path("/proc/self/status").read_text()).group(1)) * 1024)
sys.exit(code)
"""


def run_child(*args):
    started = time.perf_counter()
    done = subprocess.run([sys.executable, "-c", CHILD, *map(str, args)], capture_output=True, text=True)
    wall = time.perf_counter() - started
    if done.returncode:
        sys.exit(done.stderr)
    peak = int(done.stdout.split("PEAK_RSS")[-1])
    return wall, peak, done.stdout.split("PEAK_RSS")[0]


def herd(copies: int, folder: Path) -> Path:
    side = math.ceil(math.sqrt(copies))
    objects = []
    for k in range(copies):
        x, y = 8.0 * (k % side), 8.0 * (k // side)
        angle = 0.7 * k
        c, s = math.cos(angle), math.sin(angle)
        objects.append({"file": str(SCENES / "teapot.bez"), "object_id": k,
                        "transform": [[c, -s, 0, x], [s, c, 0, y], [0, 0, 1, 0], [0, 0, 0, 1]]})
    path = folder / "herd.json"
    path.write_text(json.dumps({"objects": objects}))
    return path


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--copies", type=int, default=80)
    parser.add_argument("--eps", default="0.0002")
    parser.add_argument("--max-factor", default="256")
    parser.add_argument("--max-memory", default="512M")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(dir=".") as folder:
        folder = Path(folder)
        scene = herd(args.copies, folder)
        _, baseline, _ = run_child(SCENES / "teapot.bez", "--eps", "0.1", "-q", "-o", folder / "tiny.ply")
        wall, peak, summary = run_child(scene, "--eps", args.eps, "--max-factor", args.max_factor,
                                        "--max-memory", args.max_memory, "-o", folder / "herd.ply")
        size = (folder / "herd.ply").stat().st_size
    print(summary.rstrip())
    print(f"{args.copies} teapots ({32 * args.copies} patches), eps {args.eps}, cap {args.max_memory}: "
          f"wall {wall:.1f} s, peak RSS {peak / 2**20:.0f} MiB (baseline run {baseline / 2**20:.0f} MiB, "
          f"so {(peak - baseline) / 2**20:.0f} MiB above it), PLY {size / 2**30:.2f} GiB")


if __name__ == "__main__":
    main()
