"""Issue 15, the CPU line: the whole engine (stages 1-5) on one scene in a loop, for a sampling
profiler, so that each stage's PoCL kernel (its own ``.so`` in ``POCL_CACHE_DIR``) and the
builtins it calls out of line show by symbol.

    POCL_CACHE_DIR=/tmp/pc perf record -k CLOCK_MONOTONIC -e cpu-clock -F 4000 -g -o scene.data -- \\
        python bench/perf_scene.py --device pocl --scene model_zoo --launches 6
    perf report -i scene.data --time START,END --no-children --sort dso,sym --stdio -g none

``--scene``: a suite scene (cltess.bench.suite, at ``--pixels``, default 0.5 px, as frame_loop.py)
or a mesh/patch file (``--eps`` relative to its bounding box's diagonal, default 1e-3; ``.stl``/``.obj`` become PN
triangles).  Tessellates ``--warm`` times untimed, then ``--launches`` times between the marks
``perf_scene: start``/``end`` (``time.monotonic()``, perf's clock with ``-k CLOCK_MONOTONIC``);
prints the process CPU ms per tessellation (min, median), a hash of the output and the
median device ms of each stage (``Tessellation.stage_ms``).
"""
from __future__ import annotations

import argparse
import hashlib
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import cpu_stages  # noqa: E402  (cpu_seconds)
import frame_loop  # noqa: E402  (suite_scene)

from cltess import load_scene  # noqa: E402
from cltess.backends.opencl import Tessellator  # noqa: E402
from cltess.bench.suite import SUITE  # noqa: E402


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--device", help="OpenCL device (substring)")
    parser.add_argument("--scene", default="model_zoo", help="a suite scene or a scene file")
    parser.add_argument("--pixels", type=float, default=0.5)
    parser.add_argument("--eps", type=float, default=1e-3, help="for a file: relative to its size")
    parser.add_argument("--work", default="patch")
    parser.add_argument("--launches", type=int, default=6)
    parser.add_argument("--warm", type=int, default=1)
    args = parser.parse_args(argv)

    tessellator = Tessellator(args.device, work=args.work)
    if args.scene in SUITE:
        scene, options = frame_loop.suite_scene(args.scene), {"pixels": args.pixels}
    else:
        scene = load_scene(Path(args.scene))
        options = {"eps": args.eps * float(scene.diagonal)}
    for _ in range(args.warm):
        tess = tessellator.tessellate(scene, **options)
    cpu, stages = [], []
    print(f"perf_scene: start {time.monotonic():.3f}", file=sys.stderr, flush=True)
    for _ in range(args.launches):
        started = cpu_stages.cpu_seconds()
        tess = tessellator.tessellate(scene, **options)
        cpu.append((cpu_stages.cpu_seconds() - started) * 1e3)
        stages.append(tess.stage_ms)
    print(f"perf_scene: end {time.monotonic():.3f}", file=sys.stderr, flush=True)
    hashed = hashlib.blake2b(digest_size=8)
    for field in ("positions", "normals", "uv", "triangles"):
        hashed.update(np.ascontiguousarray(getattr(tess, field)).tobytes())
    print(f"{args.scene}: {scene.num_patches:,} patches, {len(tess.positions):,} vertices, "
          f"{len(tess.triangles):,} triangles, {args.launches} tessellations: CPU ms min {min(cpu):.0f}, "
          f"median {statistics.median(cpu):.0f}; bits {hashed.hexdigest()}")
    print("  device ms, median: " + ", ".join(f"{k} {statistics.median(t[k] for t in stages):.1f}"
                                              for k in stages[0] if k != "total_wall"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
