"""Issue 2's first benchmark: many teapot copies at one object-space tolerance.

    python bench/teapots.py [--copies 64] [--eps 0.002] [--repeat 5] [--device NAME] [--json OUT]

Prints the device milliseconds per stage (OpenCL profiling events) and triangles per second,
with forward differencing (FD) on and off, beside a plain NumPy evaluation (cltess.bench.
numpy_evaluate: vectorised einsum over the Bernstein bases, float64) of positions and normals
at exactly the vertices the pipeline produced (its uv and patch ids, so the same factors).
Every figure is the median of ``--repeat`` runs after one warm-up run.
"""
from __future__ import annotations

import argparse
import json
import math
import statistics
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))

from cltess.bench import device_info, machine_info, numpy_evaluate, transform_patches  # noqa: E402
from cltess.io import read_bez  # noqa: E402
from cltess.scene import Scene  # noqa: E402


def teapot_grid(copies: int) -> Scene:
    """``copies`` teapots (scenes/teapot.bez, 32 patches) on a square grid, each turned about
    z by a different angle; object id = copy number."""
    teapot = read_bez(REPO / "scenes" / "teapot.bez").patches
    side = math.ceil(math.sqrt(copies))
    chunks = []
    for k in range(copies):
        angle = 2 * math.pi * k / copies
        c, s = math.cos(angle), math.sin(angle)
        matrix = np.array([[c, -s, 0, 8.0 * (k % side)], [s, c, 0, 8.0 * (k // side)], [0, 0, 1, 0], [0, 0, 0, 1]])
        chunks.append(transform_patches(teapot, matrix))
    ids = np.repeat(np.arange(copies, dtype=np.int32), len(teapot))
    return Scene(np.concatenate(chunks), ids, name=f"{copies} teapots")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--copies", type=int, default=64)
    parser.add_argument("--eps", type=float, default=0.002)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--device")
    parser.add_argument("--json")
    args = parser.parse_args(argv)

    from cltess.pipeline import Tessellator

    scene = teapot_grid(args.copies)
    tessellator = Tessellator(device=args.device)
    record = {"device": device_info(tessellator.device), "machine": machine_info(), "copies": args.copies,
              "patches": scene.num_patches, "eps": args.eps, "repeat": args.repeat, "variants": {}}
    print(f"{scene.name}: {scene.num_patches} patches, eps {args.eps:g}, device "
          f"{record['device']['name']} ({record['device']['platform']}), median of {args.repeat} runs")
    last = None
    for fd in (True, False):
        tessellator.tessellate(scene, eps=args.eps, forward_differencing=fd)  # warm-up (builds kernels)
        runs = []
        for _ in range(args.repeat):
            result = tessellator.tessellate(scene, eps=args.eps, forward_differencing=fd)
            runs.append(result.stage_ms)
        median = {k: statistics.median(r[k] for r in runs) for k in runs[0]}
        device_ms = sum(v for k, v in median.items() if k != "total_wall")
        triangles = result.num_triangles
        name = "FD" if fd else "direct"
        record["variants"][name] = {"stage_ms": median, "device_ms": device_ms, "stats": result.stats}
        stages = "  ".join(f"{k} {v:.3f}" for k, v in median.items() if k != "total_wall")
        print(f"{name:>6}: {stages}  | device {device_ms:.3f} ms, end to end {median['total_wall']:.1f} ms | "
              f"{triangles:,} triangles: {triangles / device_ms / 1e3:.2f} Mtri/s device, "
              f"{triangles / median['total_wall'] / 1e3:.2f} Mtri/s end to end")
        if result.stats.get("saturated"):
            print(f"        ({result.stats['saturated']} patches saturated at max factor 64)")
        last = last or result

    times = []
    for _ in range(args.repeat):
        started = time.perf_counter()
        positions, normals = numpy_evaluate(scene.patches, last.patch_ids, last.uv)
        times.append((time.perf_counter() - started) * 1e3)
    numpy_ms = statistics.median(times)
    gap = float(np.abs(positions - last.positions).max())
    record["numpy_ms"] = numpy_ms
    record["numpy_max_position_gap"] = gap
    direct_ms = record["variants"]["direct"]["stage_ms"]["vertices"]
    print(f" NumPy: positions + normals of the same {last.num_vertices:,} vertices in {numpy_ms:.1f} ms "
          f"({last.num_vertices / numpy_ms / 1e3:.2f} Mvertices/s; {numpy_ms / direct_ms:.0f}x the direct "
          f"vertices stage); max |position - pipeline| = {gap:.2e}")
    if args.json:
        Path(args.json).write_text(json.dumps(record, indent=1, default=float) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
