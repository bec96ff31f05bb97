"""Stage 4 by level, beside the patch-parallel stage 4 (Dyken, Reimers and Seland 2009, section
4.2; docs/design.md section 5): the patches of a pattern with a template (the semi-uniform ones)
are partitioned by their level m on the device, one ``pyopencl.algorithm.copy_if`` per level
(the paper's CUDA remark: one stream compaction per bucket; its counts are the histogram of
levels, the only read-back), and each level's queue is evaluated by one launch of
``stages/level_vertices.cl`` over (queue slot, template point of P^m), the paper's instanced
draw of the level's template.  Other patterns keep the patch-parallel stage 4; stage 5 is the
patch-parallel one for all.

The vertices are those of ``Tessellator.emit`` without forward differencing, bit for bit and in
the same places, so the output is the same mesh (tests/test_semi_uniform_levels.py)."""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import pyopencl.algorithm as cl_algorithm
import pyopencl.array as cl_array

from ...tessellation import Tessellation
from .tessellator import WORK_GROUP, Plan, Tessellator, _span_ms

#: m = log2 of the patch's largest factor (its records are 2^p_e), -1 when culled.
LEVEL_PREAMBLE = """
inline int patch_level(__global const int *factors, uint p)
{
    int n = max(max(factors[4 * p], factors[4 * p + 1]), max(factors[4 * p + 2], factors[4 * p + 3]));
    return factors[4 * p] > 0 ? 31 - (int)clz(n) : -1;
}
"""


@dataclass
class LevelQueue:
    """The patches of one part of a plan at one level: scene numbers ``patches[:count]``."""

    level: int
    patches: cl_array.Array
    count: int


def level_queues(tessellator: Tessellator, plan: Plan, part, max_level: int) -> tuple[list[LevelQueue], list]:
    """The part's patches partitioned by level 0 .. max_level on the device (patch order kept
    within a level), and the events."""
    patches = cl_array.arange(tessellator.queue, part.base, part.base + part.count, dtype=np.uint32)
    queues, events = [], []
    for level in range(max_level + 1):
        out, count, event = cl_algorithm.copy_if(
            patches, "patch_level(factors, ary[i]) == level", preamble=LEVEL_PREAMBLE,
            extra_args=[("factors", plan.factors), ("level", np.int32(level))], queue=tessellator.queue)
        events.append(event)
        queues.append(LevelQueue(level, out, int(count.get())))
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
    stage_ms["total_wall"] = (time.perf_counter() - started) * 1e3
    levels = [histogram.get(level, 0) for level in range(max(histogram, default=-1) + 1)]
    stats = dict(plan.stats, first_patch=0, last_patch=plan.num_patches, level_queues=levels)
    return Tessellation(triangles=triangles.get(), factors=plan.host_factors(), stage_ms=stage_ms, stats=stats,
                        **{k: a.get() for k, a in vertices.items()})


def template_size(pattern, level: int) -> int:
    """Points of P^level (patterns/semi_uniform.h pattern_template_size)."""
    n = 1 << level
    return (n + 1) ** 2 if pattern.domain == "quad" else (n + 1) * (n + 2) // 2
