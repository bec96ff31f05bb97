"""Issue 15, the CPU line: do subnormal operands cost extra on this CPU's OpenCL runtimes?

    python bench/subnormal_cost.py [--device pocl] [--rounds 5]

x86 cores may take a microcode assist on a float operation with a subnormal operand or result
(unless the runtime flushes them, which stage 4 may not: the bits), as NVIDIA's division takes its
slow path on a zero dividend (bench/RESULTS.md, "Issue 15: stage 4 under Nsight Compute on the
H200").  Each kernel runs a dependent chain of 4,096 operations per work-item (65,536 work-items)
on a value that stays subnormal (1e-40) or normal (1e-30): ``x * one``, ``x / one``, ``x + zero``,
``sqrt(x)`` squared (a subnormal operand of the root, a subnormal product), and ``(x * c) * 1e10``
with c = 1e-10 on x = 1e-30 (a subnormal product of normal operands; the "normal" column starts
at 1e-20); and the same chains on x = 0 (a zero dividend: NVIDIA's division takes its slow path
there).  ``one``, ``zero`` and ``c`` come from a buffer, so that the compiler cannot fold them.  Reported: process CPU ms per kernel and
value, the minimum over ``--rounds`` interleaved rounds (both values launched in each), and the
ratio subnormal / normal.
"""
from __future__ import annotations

import argparse
import sys

import numpy as np
import pyopencl as cl

from cltess.backends.opencl import Tessellator

SOURCE = """
__kernel void chain(__global float *out, __global const float *k, float start, int op)
{
    float x = start + 0.0f * (float)get_global_id(0), c = k[op];
    for (int n = 0; n < 4096; ++n) {
        if (op == 0) x = x * c;
        else if (op == 1) x = x / c;
        else if (op == 2) x = x + c;
        else if (op == 3) { float r = sqrt(x); x = r * r; }
        else x = (x * c) * 1.0e10f;
    }
    out[get_global_id(0)] = x;
}
"""
OPS = ("x * one", "x / one", "x + zero", "sqrt(x) * sqrt(x)", "(x * 1e-10) * 1e10")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--device")
    parser.add_argument("--rounds", type=int, default=5)
    args = parser.parse_args(argv)
    sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parent))
    from cpu_stages import cpu_seconds

    tessellator = Tessellator(args.device)
    context, queue = tessellator.context, tessellator.queue
    program = cl.Program(context, SOURCE).build()
    count = 65536
    out = cl.Buffer(context, cl.mem_flags.READ_WRITE, 4 * count)
    constants = np.array([1.0, 1.0, 0.0, 0.0, 1.0e-10], np.float32)
    k = cl.Buffer(context, cl.mem_flags.READ_ONLY | cl.mem_flags.COPY_HOST_PTR, hostbuf=constants)
    starts = {"subnormal": np.float32(1e-40), "normal": np.float32(1e-30), "zero": np.float32(0.0)}
    best, final = {}, {}
    for _ in range(args.rounds):
        for op in range(len(OPS)):
            for label, start in starts.items():
                begun = cpu_seconds()
                start = start * np.float32(1e10) if op == 4 else start  # op 4: the product is what is subnormal
                program.chain(queue, (count,), None, out, k, start, np.int32(op)).wait()
                ms = (cpu_seconds() - begun) * 1e3
                result = np.empty(1, np.float32)
                cl.enqueue_copy(queue, result, out)
                final[op, label] = float(result[0])  # where the chain ended: still (sub)normal?
                best[op, label] = min(best.get((op, label), ms), ms)
    print(f"{tessellator.device.platform.name.strip()}: CPU ms for {count} x 4096 dependent operations")
    print("| operation | normal x (1e-30; op 5: 1e-20) | subnormal x (1e-40; op 5: 1e-30) | ratio | x = 0 | ratio | "
          "x at the end (normal, subnormal) |")
    print("|---|---|---|---|---|---|---|")
    for op, name in enumerate(OPS):
        normal, subnormal = best[op, "normal"], best[op, "subnormal"]
        zero = best[op, "zero"]
        print(f"| {name} | {normal:.0f} | {subnormal:.0f} | {subnormal / normal:.2f} | {zero:.0f} | {zero / normal:.2f} | "
              f"{final[op, 'normal']:.3g}, {final[op, 'subnormal']:.3g} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
