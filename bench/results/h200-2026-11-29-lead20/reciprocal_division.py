"""Markstein's quotient (kernels/common.h ``markstein_quotient``) against the correctly rounded
division, bit for bit, over every pair of significands: the check that common.h's
``quotients_by_positive`` relies on.

    python bench/reciprocal_division.py --device nvidia            # all 2^46 pairs (H200: about a minute)
    python bench/reciprocal_division.py --device intel --b-count 64 # the first 64 divisors, every dividend

a and b run over [1, 2): b's 23-bit significand from ``--b-first`` for ``--b-count`` values
(default all 2^23), every a for each.  Both quotients come from the same program, built as the
engine builds its programs (``-cl-fp32-correctly-rounded-divide-sqrt`` where the device has it):
``markstein_quotient(a, b, 1.0f / b)`` and ``a / b``.  Prints the pairs checked, the number that
differ and the first of them; exits 1 if any differ.  Why [1, 2) is enough: common.h, above
``markstein_quotient``.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
import pyopencl as cl

from cltess.backends.opencl.programs import correctly_rounded_division, kernel_dir
from cltess.device import pick_device

SIGNIFICANDS = 1 << 23
A_PER_ITEM = 1 << 12


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--device", default=None, help="a device name's part (default: cltess's default device)")
    parser.add_argument("--b-first", type=int, default=0)
    parser.add_argument("--b-count", type=int, default=SIGNIFICANDS)
    parser.add_argument("--b-per-launch", type=int, default=1 << 14)
    args = parser.parse_args(argv)
    device = pick_device(args.device)
    context = cl.Context([device])
    queue = cl.CommandQueue(context)
    source = (Path(__file__).parent / "kernels" / "reciprocal_division.cl").read_text()
    options = ["-I", str(kernel_dir())] + correctly_rounded_division(device)
    program = cl.Program(context, source).build(options=options)
    check = program.markstein_against_division
    max_examples = 16
    mismatches = np.zeros(2, np.uint32)
    examples = np.zeros((max_examples, 2), np.uint32)
    flags = cl.mem_flags
    mismatches_buffer = cl.Buffer(context, flags.READ_WRITE | flags.COPY_HOST_PTR, hostbuf=mismatches)
    examples_buffer = cl.Buffer(context, flags.READ_WRITE | flags.COPY_HOST_PTR, hostbuf=examples)
    last = min(args.b_first + args.b_count, SIGNIFICANDS)
    print(f"{device.name.strip()} ({device.platform.name.strip()}), options {' '.join(options[2:]) or '-'}")
    start = time.perf_counter()
    for b_first in range(args.b_first, last, args.b_per_launch):
        b_count = min(args.b_per_launch, last - b_first)
        check(queue, (SIGNIFICANDS // A_PER_ITEM, b_count), None, np.uint32(0), np.uint32(A_PER_ITEM),
              np.uint32(b_first), mismatches_buffer, examples_buffer, np.uint32(max_examples))
    cl.enqueue_copy(queue, mismatches, mismatches_buffer)
    cl.enqueue_copy(queue, examples, examples_buffer)
    seconds = time.perf_counter() - start
    pairs = (last - args.b_first) * SIGNIFICANDS
    print(f"pairs checked: {pairs:,} (b significands {args.b_first:,} .. {last - 1:,}, every a), "
          f"{seconds:.1f} s; differing: {int(mismatches[0]):,}")
    for a_bits, b_bits in examples[: min(int(mismatches[1]), max_examples)]:
        a, b = np.array([a_bits, b_bits], np.uint32).view(np.float32)
        print(f"  a = {float(a)!r} ({a_bits:#010x}), b = {float(b)!r} ({b_bits:#010x})")
    return 1 if mismatches[0] else 0


if __name__ == "__main__":
    sys.exit(main())
