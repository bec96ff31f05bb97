"""Compare the CPU OpenCL runtimes cltess can use (issue 8): start-up, the benchmark suite, size.

    python bench/runtimes.py [--devices intel pocl] [--rounds 2] [--repeat 3] [--scenes all]
                             [--out bench/results/runtimes]

For every device name (as for ``--device``), interleaved over ``--rounds`` rounds:
- *cold start*: ``cltess tessellate scenes/teapot.bez --eps 0.002`` in a fresh process with
  every cache empty (``XDG_CACHE_HOME`` and ``CLTESS_CACHE_DIR`` in a new folder: pyopencl's
  binary cache, PoCL's kernel cache, cltess's probe verdicts), wall time of the whole command;
- *warm start*: the same command again with those caches kept;
- ``cltess bench SCENES --repeat N --no-baseline --json``: the paper's tables on that device.
Then the installed size of each runtime's files. Prints a Markdown summary (median end to end
and summed device stage times per scene, per device) and leaves the JSON files in ``--out``.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from importlib import metadata
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
TEAPOT = ["tessellate", str(REPO / "scenes" / "teapot.bez"), "--eps", "0.002", "-q"]


def cltess(args, env, check=True) -> float:
    """Runs ``python -m cltess ARGS``; returns its wall time in seconds."""
    start = time.perf_counter()
    result = subprocess.run([sys.executable, "-m", "cltess", *args], env=env, capture_output=True, text=True)
    elapsed = time.perf_counter() - start
    if check and result.returncode != 0:
        raise SystemExit(f"cltess {' '.join(args)} failed ({result.returncode}):\n{result.stderr}")
    return elapsed


def start_times(device: str, output: Path) -> tuple[float, float]:
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, XDG_CACHE_HOME=cache, CLTESS_CACHE_DIR=str(Path(cache) / "cltess"),
                   POCL_CACHE_DIR=str(Path(cache) / "pocl"))
        args = [*TEAPOT, "--device", device, "-o", str(output)]
        return cltess(args, env), cltess(args, env)


def distribution_size(name: str) -> int:
    try:
        files = metadata.distribution(name).files or ()
    except metadata.PackageNotFoundError:
        return 0
    return sum(Path(file.locate()).stat().st_size for file in files if Path(file.locate()).is_file())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--devices", nargs="+", default=["intel", "pocl"])
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--scenes", nargs="+", default=["all"])
    parser.add_argument("--out", type=Path, default=REPO / "bench" / "results" / "runtimes")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)

    starts = {device: [] for device in args.devices}
    records = {device: [] for device in args.devices}
    for round_ in range(args.rounds):
        for device in args.devices:
            starts[device].append(start_times(device, args.out / "teapot.ply"))
            path = args.out / f"bench-{device}-{round_}.json"
            cltess(["bench", *args.scenes, "--device", device, "--repeat", str(args.repeat),
                    "--no-baseline", "-q", "--json", str(path)], dict(os.environ))
            records[device].append(json.loads(path.read_text()))
            print(f"round {round_ + 1}/{args.rounds}: {device} done", file=sys.stderr)
    (args.out / "teapot.ply").unlink(missing_ok=True)

    print("| device | cold start (s) | warm start (s) |\n|---|---|---|")
    for device in args.devices:
        cold = statistics.median(c for c, _ in starts[device])
        warm = statistics.median(w for _, w in starts[device])
        print(f"| {device} | {cold:.2f} | {warm:.2f} |")

    print("\nmedian over rounds of each round's median; ms")
    print("| scene | triangles | " + " | ".join(f"{d} e2e | {d} device" for d in args.devices) + " |")
    print("|---|---|" + "---|---|" * len(args.devices))
    first = records[args.devices[0]][0]
    for index, row in enumerate(first["scenes"]):
        cells = []
        for device in args.devices:
            rows = [record["scenes"][index] for record in records[device]]
            cells.append(f"{statistics.median(r['fd']['total_wall']['median'] for r in rows):.1f}")
            cells.append(f"{statistics.median(r['fd']['device_total']['median'] for r in rows):.1f}")
        print(f"| {row['title']} | {int(row['stats']['triangles']):,} | " + " | ".join(cells) + " |")

    print("\n| distribution | installed size (MB) |\n|---|---|")
    for name in ("intel-opencl-rt", "intel-cmplr-lib-rt", "tbb", "pocl-binary-distribution"):
        print(f"| {name} | {distribution_size(name) / 1e6:.0f} |")


if __name__ == "__main__":
    main()
