"""Triangle-strip output on the device, for the patches of a strip pattern (``Pattern.primitive
== "strips"``: SD-2, ESC), beside the triangle list (cltess/strips.py has the one convention: uint32
indices, each strip followed by STRIP_RESTART on the device, the array's last marker dropped).

    stage 3  stages/strip_counts.cl   per-patch strip index counts, the pattern's strip walk in
                                      count mode (docs/sd2.md has the closed forms it equals),
                                      then pyopencl.scan into offsets
    stage 5  stages/strip_indices.cl  the same walk in emit mode, per batch of patches
"""
from __future__ import annotations

import numpy as np
import pyopencl.array as cl_array

from ...strips import STRIP_RESTART


def _global_size(n: int) -> tuple[int]:
    from .tessellator import _global_size as size
    return size(n)


def strip_parts(parts) -> list:
    return [part for part in parts if part.pattern.primitive == "strips"]


def build_strip_programs(tessellator, pattern) -> None:
    """Build a strip pattern's two kernels now, before a plan's buffers exist (Tessellator.compose)."""
    for stage in ("strip_counts", "strip_indices"):
        tessellator.programs.kernel(stage, pattern=pattern)


def strip_offsets(tessellator, factors, parts) -> tuple[cl_array.Array, list]:
    """(offsets (P+1,) uint64 of the strip indices of every patch, 0 for the patches of other
    patterns, the total last; events) from the final factors."""
    queue, programs = tessellator.queue, tessellator.programs
    count = len(factors)
    counts = cl_array.zeros(queue, count, np.uint64)
    offsets = cl_array.zeros(queue, count + 1, np.uint64)
    events = [programs.kernel("strip_counts", pattern=part.pattern)(
        queue, _global_size(part.count), None, factors.data, np.uint32(part.count), np.uint32(part.base),
        counts.data) for part in strip_parts(parts) if part.count]
    events.append(programs.offsets_scan(counts, offsets))
    return offsets, events


def emit_strips(tessellator, plan, first: int, last: int) -> tuple[np.ndarray, list]:
    """(the strip indices of patches first .. last-1, numbering the vertices globally, uint32,
    the last restart marker dropped; events)."""
    queue, programs = tessellator.queue, tessellator.programs
    if (first, last) == (0, plan.num_patches):
        start, stop = 0, plan.num_strip_indices
    else:
        host = plan.strip_offsets.get()
        start, stop = int(host[first]), int(host[last])
    out = cl_array.empty(queue, max(stop - start, 1), np.uint32)
    events = []
    for part in strip_parts(plan.parts):
        lo, hi = max(first, part.base), min(last, part.base + part.count)
        if lo < hi and stop > start:
            events.append(programs.kernel("strip_indices", pattern=part.pattern)(
                queue, _global_size(hi - lo), None, plan.factors.data, plan.vertex_offsets.data,
                plan.strip_offsets.data, np.uint32(lo), np.uint32(hi - lo), np.uint64(start), out.data))
    strips = out.get()[:stop - start]
    if len(strips) and strips[-1] == STRIP_RESTART:
        strips = strips[:-1]
    return strips, events
