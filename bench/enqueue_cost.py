"""What one enqueue costs the host on an OpenCL device, without cltess around it (issue 15: a
frame's host time): a kernel launch with typed arguments, non-blocking reads of 8 bytes and 4 KB
into pageable and page-locked memory, through ``pyopencl.enqueue_copy`` and its C entry point,
a buffer-to-buffer copy, a marker.  Median of 500 calls each, µs.

    python bench/enqueue_cost.py [--device NAME]
"""
import argparse
import statistics
import time

import numpy as np

import cltess  # noqa: F401  (registers the pip-installed CPU runtimes)
import pyopencl as cl
import pyopencl._cl as _cl
from cltess.device import pick_device


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--device", default=None, help="OpenCL device (substring; default as cltess picks)")
    parser.add_argument("--calls", type=int, default=500)
    args = parser.parse_args()
    device = pick_device(args.device)
    context = cl.Context([device])
    queue = cl.CommandQueue(context, properties=cl.command_queue_properties.PROFILING_ENABLE)
    flags = cl.mem_flags
    source, target = (cl.Buffer(context, flags.READ_WRITE, 1 << 20) for _ in range(2))
    locked = cl.Buffer(context, flags.READ_WRITE | flags.ALLOC_HOST_PTR, 1 << 20)
    pinned, _ = cl.enqueue_map_buffer(queue, locked, cl.map_flags.READ | cl.map_flags.WRITE, 0, (1 << 17,),
                                      np.uint64, is_blocking=True)
    pageable = np.empty(1 << 17, np.uint64)
    program = cl.Program(context, "__kernel void nop(__global ulong *a, uint n)"
                                  "{ if (get_global_id(0) < n) a[get_global_id(0)] += 1; }").build()
    kernel = cl.Kernel(program, "nop")
    kernel.set_arg_types([None, np.uint32])
    print(f"{device.name.strip()} ({device.platform.name.strip()}): host µs per call, median of {args.calls}")
    cases = {
        "kernel launch (typed arguments), one work-group": lambda: kernel(queue, (64,), None, source, 10),
        "enqueue_copy of 8 B into pageable memory, non-blocking":
            lambda: cl.enqueue_copy(queue, pageable[:1], source, src_offset=8, is_blocking=False),
        "enqueue_copy of 8 B into page-locked memory, non-blocking":
            lambda: cl.enqueue_copy(queue, pinned[:1], source, src_offset=8, is_blocking=False),
        "_enqueue_read_buffer of 8 B into pageable memory": lambda: _cl._enqueue_read_buffer(
            queue, source, pageable[:1], 8, None, False),
        "_enqueue_read_buffer of 8 B into page-locked memory": lambda: _cl._enqueue_read_buffer(
            queue, source, pinned[:1], 8, None, False),
        "_enqueue_read_buffer of 4 KB into pageable memory": lambda: _cl._enqueue_read_buffer(
            queue, source, pageable[:512], 0, None, False),
        "_enqueue_read_buffer of 4 KB into page-locked memory": lambda: _cl._enqueue_read_buffer(
            queue, source, pinned[:512], 0, None, False),
        "buffer-to-buffer copy of 8 B": lambda: _cl._enqueue_copy_buffer(queue, source, target, 8, 8, 0, None),
        "marker": lambda: cl.enqueue_marker(queue),
    }
    for name, call in cases.items():
        times = []
        for _ in range(args.calls):
            started = time.perf_counter_ns()
            call()
            times.append(time.perf_counter_ns() - started)
        queue.finish()
        print(f"  {name:58s} {statistics.median(times) / 1e3:7.1f}")


if __name__ == "__main__":
    main()
