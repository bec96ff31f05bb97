"""Issue 15 under Nsight Compute: the stage 4-5 kernels of uniform level 16, replayed through CUDA.

    python bench/ncu_stage45.py --device nvidia [--work rows-prep] [--repeat 20] [--json out.json]
        [--kernels prepare_patches prepared_rows triangles] [--no-replay] [--ptx DIR]
    ncu --clock-control none -k regex:'^(prepared_rows|triangles)$' --set full -o stage45 \\
        python3 bench/ncu_stage45.py --device nvidia --repeat 1

Nsight Compute profiles CUDA launches; whether it sees kernels that NVIDIA's OpenCL driver
launches is not known here (bench/RESULTS.md, "Issue 15: stage 4 under Nsight Compute on the
H200").  So this script launches the engine's own kernels again through CUDA (CuPy), on the
engine's own inputs:

1. a cltess ``Session`` of uniform level 16 (``frame_loop.teapots(--copies)``, every edge factor
   16), ``Tessellator(work=--work)``; a first frame builds and uploads, a second frame runs with
   ``programs.Kernel.launch`` wrapped, recording each launch of the ``--kernels`` (its PTX: the
   program's binary on NVIDIA, its global and local sizes, its arguments);
2. after that frame each buffer argument is read back to the host;
3. each recorded launch is made again through CuPy: the program's PTX with its ``%envregN``
   (the OpenCL global offset registers; the engine launches with no offset) read as 0 and its
   ``.metadata_section`` dropped, loaded with ``cupy.RawModule``, the buffers copied in, the
   kernel's output buffers (``OUTPUTS``) poisoned with 0xFF bytes first; the output is compared
   bytewise with the OpenCL frame's over the bytes the frame wrote ("same bits");
4. the replay is timed with CUDA events (median of ``--repeat`` after one warm-up) beside the
   same kernel's OpenCL profiling-event time in ``--repeat`` frames, and the compiled
   function's registers, local (spill) bytes and static shared bytes are printed.

Under ``ncu`` (give it ``--clock-control none``: the lent machines' advice), the replayed launches
are what it profiles, and the OpenCL frames' launches too if it can see them (its
``==PROF==`` lines, interleaved with this script's "replay" lines, say which).  ``--no-replay``
stops after step 1 (the cheap check whether ncu sees OpenCL at all).  A table last.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import re
import statistics
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent

#: output (written) buffer arguments of each kernel, by position in its parameter list
OUTPUTS = {"prepared_rows": range(10, 15), "prepared_points": range(10, 15), "vertex_points": range(11, 16),
           "prepare_patches": (5,), "triangles": (8,)}
#: bytes per vertex of the five vertex outputs (positions, normals, uv, patch ids, object ids)
VERTEX_BYTES = (12, 12, 8, 4, 4)


def cuda_ptx(ptx: str) -> str:
    """NVIDIA OpenCL PTX as the CUDA driver takes it: %envregN (OpenCL's global work offset and
    its like; the engine launches with none) read as 0, the OpenCL metadata section dropped."""
    ptx = ptx.rstrip("\0")
    ptx = re.sub(r"mov\.b32\s+(%r\d+),\s*%envreg\d+;", r"mov.b32 \1, 0;", ptx)
    return re.sub(r"\.metadata_section\s*\{.*\Z", "", ptx, flags=re.S)


def written_bytes(name: str, position: int, args: tuple, record: dict) -> int | None:
    """How many leading bytes of an output buffer the frame wrote (None: the whole buffer)."""
    outputs = list(OUTPUTS[name])
    if name in ("prepared_rows", "prepared_points", "vertex_points"):
        return record["vertices"] * VERTEX_BYTES[outputs.index(position)]
    if name == "triangles":
        return record["triangles"] * 12
    if name == "prepare_patches":
        return int(args[3]) * record["kind_patch_size"]
    return None


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--device", default="nvidia")
    parser.add_argument("--copies", type=int, default=1000)
    parser.add_argument("--level", type=int, default=16)
    parser.add_argument("--work", default="rows-prep")
    parser.add_argument("--kernels", nargs="+", default=["prepare_patches", "prepared_rows", "triangles"])
    parser.add_argument("--repeat", type=int, default=20)
    parser.add_argument("--no-replay", action="store_true")
    parser.add_argument("--ptx", help="write each replayed kernel's PTX (as loaded) here")
    parser.add_argument("--json")
    args = parser.parse_args(argv)

    import numpy as np
    import pyopencl as cl

    sys.path.insert(0, str(HERE))
    import frame_loop

    import cltess
    from cltess.backends.opencl import Tessellator
    from cltess.backends.opencl import programs as programs_module

    tessellator = Tessellator(args.device, work=args.work)
    queue, device = tessellator.queue, tessellator.device
    scene = frame_loop.teapots(args.copies)
    session = cltess.Session(scene, tessellator=tessellator, **frame_loop.uniform_request(args.level))
    first = session.tessellate().fetch()
    digest = hashlib.blake2b(digest_size=8)
    for field in ("positions", "normals", "uv", "patch_ids", "object_ids", "triangles"):
        digest.update(np.ascontiguousarray(getattr(first, field)).tobytes())
    record = {"device": f"{device.name} ({device.platform.name}, driver {device.driver_version})",
              "work": args.work, "level": args.level, "copies": args.copies, "digest": digest.hexdigest(),
              "vertices": int(first.num_vertices), "triangles": int(first.num_triangles),
              "kind_patch_size": max(tessellator._kind_patch_sizes.values(), default=0)}
    del first
    print(f"frame: {record['vertices']} vertices, {record['triangles']} triangles, digest {record['digest']}",
          flush=True)

    launches = []
    original = programs_module.Kernel.launch

    def recording(self, queue_, global_size, local_size, kernel_args, options=None):
        event = original(self, queue_, global_size, local_size, kernel_args, options)
        name = self.kernel.function_name
        if name in args.kernels:
            launches.append((self, name, tuple(global_size), tuple(local_size) if local_size else None,
                             tuple(kernel_args), event))
        return event

    programs_module.Kernel.launch = recording
    try:
        frame = session.tessellate()
        queue.finish()
    finally:
        programs_module.Kernel.launch = original
    print(f"recorded: {[(name, g, l) for _, name, g, l, _, _ in launches]}", flush=True)
    opencl_ms = {name: [] for name in args.kernels}
    for _, name, _, _, _, event in launches:
        opencl_ms[name].append((event.profile.end - event.profile.start) * 1e-6)
    # more frames: the kernels' OpenCL event times (median)
    for _ in range(args.repeat - 1):
        events = []
        programs_module.Kernel.launch = lambda self, q, g, l, a, o=None: _kept(original, events, self, q, g, l, a, o)
        try:
            session.tessellate()
            queue.finish()
        finally:
            programs_module.Kernel.launch = original
        for name, event in events:
            if name in opencl_ms:
                opencl_ms[name].append((event.profile.end - event.profile.start) * 1e-6)
    record["opencl_ms"] = {k: statistics.median(v) for k, v in opencl_ms.items() if v}
    print(f"OpenCL event ms (median of {args.repeat} frames): {record['opencl_ms']}", flush=True)
    if args.no_replay:
        print(json.dumps(record))
        return 0

    # the recorded launches' buffers, as the frame left them
    host = {}
    for _, name, _, _, kernel_args, _ in launches:
        for a in kernel_args:
            if isinstance(a, cl.MemoryObjectHolder) and a.int_ptr not in host:
                data = np.empty(a.size, np.uint8)
                cl.enqueue_copy(queue, data, a)
                host[a.int_ptr] = data
    queue.finish()

    import cupy as cp

    record["kernels"] = []
    modules = {}
    for kernel, name, global_size, local_size, kernel_args, _ in launches:
        program = kernel.kernel.program
        key = program.int_ptr
        if key not in modules:
            ptx = cuda_ptx(program.get_info(cl.program_info.BINARIES)[0].decode())
            path = Path(args.ptx or "/tmp") / f"ncu_stage45-{name}-{key}.ptx"
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(ptx)
            modules[key] = cp.RawModule(path=str(path))
        function = modules[key].get_function(name)
        local = local_size or programs_module.named_local_size(global_size)
        grid = tuple(g // l for g, l in zip(global_size, local))
        outputs = OUTPUTS.get(name, ())
        device_args, checks = [], []
        for position, a in enumerate(kernel_args):
            if isinstance(a, cl.MemoryObjectHolder):
                data = host[a.int_ptr]
                buffer = cp.asarray(data)
                if position in outputs:
                    buffer.fill(0xFF)
                    checks.append((position, buffer, data, written_bytes(name, position, kernel_args, record)))
                device_args.append(buffer)
            elif isinstance(a, np.generic):
                device_args.append(a)
            else:
                raise TypeError(f"{name} argument {position}: {type(a).__name__}")
        launch = lambda: function(grid, local, tuple(device_args))  # noqa: E731
        print(f"replay {name}: grid {grid}, block {local}", flush=True)
        launch()
        cp.cuda.Device().synchronize()
        same = []
        for position, buffer, data, size in checks:
            size = data.size if size is None else size
            got = cp.asnumpy(buffer[:size])
            same.append(bool(np.array_equal(got, data[:size])))
        start, stop = cp.cuda.Event(), cp.cuda.Event()
        spans = []
        for _ in range(args.repeat):
            start.record()
            launch()
            stop.record()
            stop.synchronize()
            spans.append(cp.cuda.get_elapsed_time(start, stop))
        attributes = {k: getattr(function, k, None) for k in ("num_regs", "local_size_bytes", "shared_size_bytes")}
        row = {"kernel": name, "grid": grid, "block": local, "same_bits": all(same) and bool(same),
               "replay_ms": statistics.median(spans), "opencl_ms": record["opencl_ms"].get(name),
               "registers": attributes.get("num_regs"), "local_bytes": attributes.get("local_size_bytes"),
               "shared_bytes": attributes.get("shared_size_bytes")}
        record["kernels"].append(row)
        print(f"  {row}", flush=True)
        del device_args, checks

    lines = [record["device"], f"uniform level {args.level}, {args.copies} teapots, work={args.work}: "
             f"{record['vertices']} vertices, {record['triangles']} triangles", "",
             "| kernel | grid x block | OpenCL ms | CUDA replay ms | registers | local bytes | static shared | same bits |",
             "|---|---|---|---|---|---|---|---|"]
    for row in record["kernels"]:
        lines.append(f"| {row['kernel']} | {row['grid'][0]} x {row['block'][0]} | {row['opencl_ms']:.3f} | "
                     f"{row['replay_ms']:.3f} | {row['registers']} | {row['local_bytes']} | {row['shared_bytes']} | "
                     f"{'yes' if row['same_bits'] else 'NO'} |")
    print("\n".join(lines))
    if args.json:
        Path(args.json).write_text(json.dumps(record, indent=1, default=str) + "\n")
    return 0


def _kept(original, events, self, queue, global_size, local_size, kernel_args, options=None):
    """Kernel.launch, each launch's (kernel name, event) kept: their profiling spans are read after the frame."""
    event = original(self, queue, global_size, local_size, kernel_args, options)
    events.append((self.kernel.function_name, event))
    return event


if __name__ == "__main__":
    sys.exit(main())
