"""Stage 4 by level, beside the patch-parallel stage 4 (Dyken, Reimers and Seland 2009, section
4.2; docs/design.md section 5): the patches of a pattern with a template (the semi-uniform ones)
are partitioned by their level m on the device, one stream compaction per level (the paper's
CUDA remark; pyopencl.algorithm.copy_if's scan, ``level_scan``), whose counts are the histogram
of levels (the only read-back), and each level's queue is evaluated by one launch of
``stages/level_vertices.cl`` over (queue slot, template point of P^m), the paper's instanced
draw of the level's template.  Other patterns keep the patch-parallel stage 4; stage 5 is the
patch-parallel one for all.

The vertices are those of ``Tessellator.emit`` without forward differencing, bit for bit and in
the same places, so the output is the same mesh (tests/test_semi_uniform_levels.py)."""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import pyopencl.array as cl_array
from pyopencl.scan import GenericScanKernel

from ...kinds import KINDS
from ...tessellation import Tessellation
from .tessellator import WORK_GROUP, Plan, Tessellator, _span_ms

#: m = log2 of the patch's largest factor (its records are 2^p_e; a collapsed edge's stored
#: negated, common.h patch_factors), -1 when culled.
LEVEL_PREAMBLE = """
inline int patch_level(__global const int *factors, uint p)
{
    int4 f = as_int4(abs((int4)(factors[4 * p], factors[4 * p + 1], factors[4 * p + 2], factors[4 * p + 3])));
    int n = max(max(f.s0, f.s1), max(f.s2, f.s3));
    return f.s0 > 0 ? 31 - (int)clz(n) : -1;
}
"""

_LEVEL_SCANS: dict = {}


def level_scan(context) -> GenericScanKernel:
    """Stream compaction of the patches ``base .. base + N - 1`` of level ``level`` into ``queue``
    (patch order kept), their number into ``count[0]``: pyopencl.algorithm.copy_if's scan, over
    patch numbers instead of an input array, built once per context."""
    if context not in _LEVEL_SCANS:
        _LEVEL_SCANS[context] = GenericScanKernel(
            context, np.uint32, preamble=LEVEL_PREAMBLE,
            arguments="__global const int *factors, uint base, int level, __global uint *queue, __global uint *count",
            input_expr="patch_level(factors, base + i) == level ? 1 : 0", scan_expr="a+b", neutral="0",
            output_statement="if (prev_item != item) queue[prev_item] = base + i; if (i + 1 == N) count[0] = item;")
    return _LEVEL_SCANS[context]


@dataclass
class LevelQueue:
    """The patches of one part of a plan at one level: scene numbers ``patches[:count]``."""

    level: int
    patches: cl_array.Array
    count: int


def plan_by_level(tessellator: Tessellator, scene, request) -> Plan:
    """``tessellator.plan`` with every program the level path needs built first, as the plan
    builds its own (a build after the plan's buffers exist makes Oclgrind's uninitialised-value
    plugin report the scans' output, tests/test_oclgrind.py)."""
    tolerance = request.tolerance_for(scene)
    for kind in (kind for kind in KINDS if kind.count(scene)):
        pattern = request.pattern_for(kind)
        tessellator.programs.compose(kind, pattern, tolerance)
        if pattern.dyadic:
            tessellator.programs.kernel("level_vertices", kind=kind, pattern=pattern)
    level_scan(tessellator.context)
    return tessellator.plan(scene, request)


def level_queues(tessellator: Tessellator, plan: Plan, part, max_level: int) -> tuple[list[LevelQueue], list]:
    """The part's patches partitioned by level 0 .. max_level on the device (patch order kept
    within a level): one compaction scan per level, whose counts are the histogram of levels
    (read back, as the paper reads back its HistoPyramids' tops); and the events."""
    scan = level_scan(tessellator.context)
    queues, events = [], []
    for level in range(max_level + 1):
        queue = cl_array.empty(tessellator.queue, part.count, np.uint32)
        count = cl_array.empty(tessellator.queue, 1, np.uint32)
        events.append(scan(plan.factors, np.uint32(part.base), np.int32(level), queue, count, size=part.count,
                           queue=tessellator.queue))
        queues.append(LevelQueue(level, queue, int(count.get()[0])))
    return queues, events


def emit_by_level(tessellator: Tessellator, plan: Plan) -> Tessellation:
    """Stages 4-5 for the whole plan, stage 4 by level for the parts whose pattern has a template
    (``dyadic``), patch-parallel without forward differencing for the others."""
    started = time.perf_counter()
    vertices = tessellator._vertex_arrays(plan.num_vertices)
    triangles = cl_array.empty(tessellator.queue, (plan.num_indices // 3, 3), np.uint32)
    events = {"queues": [], "vertices": [], "indices": []}
    histogram = {}
    for part in plan.parts:
        patch_range = (part.base, part.base + part.count)
        if part.pattern.dyadic:
            queues, queue_events = level_queues(tessellator, plan, part, plan.request.max_level)
            events["queues"] += queue_events
            kernel = tessellator.programs.kernel("level_vertices", kind=part.kind, pattern=part.pattern)
            for queue in queues:
                histogram[queue.level] = histogram.get(queue.level, 0) + queue.count
                if not queue.count:
                    continue
                size = queue.count * template_size(part.pattern, queue.level)
                global_size = (-(-size // WORK_GROUP) * WORK_GROUP,)
                events["vertices"].append(kernel(
                    tessellator.queue, global_size, None, part.data["controls"].data, plan.factors.data,
                    plan.vertex_offsets.data, plan.objects.data, queue.patches.data, np.uint32(queue.count),
                    np.int32(queue.level), np.uint32(part.base), *(a.data for a in vertices.values())))
        else:
            events["vertices"] += tessellator.stage_vertices(
                part.data["controls"], plan.factors, plan.vertex_offsets, plan.objects, (0, plan.num_vertices),
                patch_range, False, kind=part.kind, patch_base=part.base, out=vertices, pattern=part.pattern)[1]
        events["indices"] += tessellator.stage_indices(
            plan.factors, plan.vertex_offsets, plan.index_offsets, (0, plan.num_indices), patch_range,
            kind=part.pattern, out=triangles)[1]
    tessellator.queue.finish()
    stage_ms = {stage: _span_ms(evs) for stage, evs in events.items() if evs}
    stages_ms = (time.perf_counter() - started) * 1e3
    levels = [histogram.get(level, 0) for level in range(max(histogram, default=-1) + 1)]
    stats = dict(plan.stats, first_patch=0, last_patch=plan.num_patches, level_queues=levels)
    copied = time.perf_counter()
    host = dict(triangles=triangles.get(), factors=np.abs(plan.host_factors()), **{k: a.get() for k, a in vertices.items()})
    wall_ms = {"stages": stages_ms, "read_back": (time.perf_counter() - copied) * 1e3}
    wall_ms["total"] = stage_ms["total_wall"] = stages_ms + wall_ms["read_back"]  # until the host arrays are there
    return Tessellation(stage_ms=stage_ms, stats=stats, wall_ms=wall_ms, **host)


def template_size(pattern, level: int) -> int:
    """Points of P^level (patterns/semi_uniform.h pattern_template_size)."""
    n = 1 << level
    return (n + 1) ** 2 if pattern.domain == "quad" else (n + 1) * (n + 2) // 2
