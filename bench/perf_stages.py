"""Issue 15, the CPU line: stage 4 (``vertices``) and stage 5 (``indices``) launched in a loop,
for a sampling profiler (``perf record -e cpu-clock``) to attribute the CPU time instruction by
instruction.

    POCL_CACHE_DIR=/tmp/pc perf record -k CLOCK_MONOTONIC -e cpu-clock -F 4000 -g -o stage4.data -- \\
        python bench/perf_stages.py --device pocl --stage 4 --launches 12 [--local 64] [--kernels DIR] [--define NAME ...]
    perf report -i stage4.data --time START,END --no-children --sort dso,sym --stdio -g none

Uniform level 16 as ``bench/cpu_stages.py`` (``--copies`` teapots of 32 patches, every edge factor
16; or ``--scene``: a suite scene of one kind at ``--pixels``, e.g. the PN triangles of model_zoo), stages 1-3 planned once by the engine; then the named stage's per-patch kernel, built like
cpu_stages.py does (from ``--kernels``, default this tree's kernels/, with ``--define`` NAME or NAME=VALUE
before its headers),
is launched ``--launches`` times, each waited, after ``--warm`` launches that are not timed
(``--local``: with that work-group size; by default none, so the runtime picks: PoCL took 4,000
here, where the engine names 64 on PoCL, programs.py ``names_local_size``).
Prints the launches' process CPU ms (min, median: ``getrusage`` of every thread), the output's
hash (blake2b of the stage's arrays after the last launch: compare two builds' bits), and the
marks ``perf_stages: start``/``end`` with ``time.monotonic()`` (START, END above; perf's clock
when recorded with ``-k CLOCK_MONOTONIC``) so that ``perf report --time`` can cut the build away.  On PoCL set ``POCL_CACHE_DIR`` to a folder of your own so that the
kernel's shared object (``.../vertices.so``) stays there for ``perf report``/``perf annotate``;
the samples in it are the kernel's (``_pocl_kernel_vertices_workgroup``, its work-group function).
"""
from __future__ import annotations

import argparse
import hashlib
import statistics
import sys
import time
from pathlib import Path

import numpy as np
import pyopencl as cl
import pyopencl.array as cl_array

sys.path.insert(0, str(Path(__file__).resolve().parent))
import cpu_stages  # noqa: E402  (build, cpu_seconds)
import frame_loop  # noqa: E402  (teapots, uniform_request)

from cltess.backends.opencl import Tessellator  # noqa: E402
from cltess.backends.opencl.programs import kernel_dir  # noqa: E402
from cltess.tessellation import VERTEX_RECORD  # noqa: E402


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--device", help="OpenCL device (substring)")
    parser.add_argument("--copies", type=int, default=1000, help="teapots (32 patches each)")
    parser.add_argument("--stage", type=int, choices=(4, 5), default=4)
    parser.add_argument("--launches", type=int, default=20)
    parser.add_argument("--warm", type=int, default=2, help="launches before the timed ones")
    parser.add_argument("--kernels", help="a kernels/ folder to build from (default this tree's)")
    parser.add_argument("--define", nargs="*", default=[], help="-D names for the build")
    parser.add_argument("--local", type=int, help="work-group size (default: none, the runtime's choice)")
    parser.add_argument("--scene", help="a suite scene at --pixels (its first kind's patches) instead of the teapots")
    parser.add_argument("--pixels", type=float, default=0.01)
    args = parser.parse_args(argv)

    tessellator = Tessellator(args.device, work="patch")
    context, queue, device = tessellator.context, tessellator.queue, tessellator.device
    if args.scene:
        plan = tessellator.plan(frame_loop.suite_scene(args.scene), pixels=args.pixels)
    else:
        plan = tessellator.plan(frame_loop.teapots(args.copies), **frame_loop.uniform_request(16))
    if len(plan.parts) != 1:
        parser.error(f"{len(plan.parts)} kinds in the scene; this script runs a scene of one")
    part = plan.parts[0]
    patches, vertices = plan.num_patches, plan.num_vertices
    folder = Path(args.kernels) if args.kernels else kernel_dir()
    name = "vertices" if args.stage == 4 else "indices"
    kernel = getattr(cpu_stages.build(context, device, folder, (folder / "stages" / f"{name}.cl").read_text(),
                                      name, part.pattern, args.define, part.kind), name)
    per_patch = (-(-patches // 64) * 64,)
    if args.stage == 4:
        out = [cl_array.empty(queue, (vertices, *shape), dtype) for _, dtype, shape in VERTEX_RECORD]
        arguments = (part.data["controls"].data, plan.factors.data, plan.vertex_offsets.data, plan.objects.data,
                     np.uint32(0), np.uint32(patches), np.uint32(0), np.uint64(0), np.int32(1),
                     np.uint64(vertices), *(a.data for a in out))
    else:
        out = [cl_array.empty(queue, (plan.num_indices,), np.uint32)]
        arguments = (plan.factors.data, plan.vertex_offsets.data, plan.index_offsets.data, np.uint32(0),
                     np.uint32(patches), np.uint64(0), np.uint64(plan.num_indices), out[0].data)
    local = (args.local,) if args.local else None
    for _ in range(args.warm):
        kernel(queue, per_patch, local, *arguments).wait()
    cpu = []
    print(f"perf_stages: start {time.monotonic():.3f}", file=sys.stderr, flush=True)
    for _ in range(args.launches):
        started = cpu_stages.cpu_seconds()
        kernel(queue, per_patch, local, *arguments).wait()
        cpu.append((cpu_stages.cpu_seconds() - started) * 1e3)
    print(f"perf_stages: end {time.monotonic():.3f}", file=sys.stderr, flush=True)
    hashed = hashlib.blake2b(digest_size=8)
    for array in out:
        hashed.update(array.get().tobytes())
    print(f"{device.platform.name.strip()}: stage {args.stage} ({name}), {patches:,} patches, {args.launches} launches: "
          f"CPU ms min {min(cpu):.0f}, median {statistics.median(cpu):.0f}; bits {hashed.hexdigest()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
