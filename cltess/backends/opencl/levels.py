"""Stages 4-5 by level, beside the patch-parallel stages 4-5 (Dyken, Reimers and Seland 2009,
section 4.2; docs/design.md section 5): ``Request(emit="by_level")``, ``--emit by-level``.

For the parts of a plan whose pattern has a template (``Pattern.dyadic``: the semi-uniform ones):

1. **Queues.**  The patches are partitioned by their level m on the device by *one* stream
   compaction (``level_scan``: pyopencl's scan with copy_if's output statement) over the
   level-major sequence (level 0's patches, level 1's, ...), so that every level's queue keeps
   patch order and the queues lie one after the other in one buffer.  The scan also writes where
   each level's queue ends: those M + 1 numbers, the histogram of levels, are the only read-back
   (the paper reads back its HistoPyramids' tops).
2. **Vertices.**  One launch per level over (queue slot, template point of P^m)
   (``stages/level_vertices.cl``; the template: the lattice points of P^m, built once on the host
   and uploaded, ``patterns/semi_uniform.py point_template``).
3. **Triangles.**  One launch per level over (queue slot, interior template triangle)
   (``stages/level_indices.cl`` level_interior: the snap never moves nor drops an interior
   triangle, so each lands at a fixed place, ``interior_template``), and one over the queue slots
   for the band along the boundary, where the snap drops triangles (level_band, O(2^m) each).

Every work-item of a launch does the same work.  The pattern emits a patch's interior triangles
first, then its band's (``pattern_primitives``), so the counts of stage 3 stay those of the
per-patch record, and the output is that of ``Tessellator.emit`` without forward differencing,
bit for bit and in the same places (tests/test_semi_uniform_levels.py).  Other parts keep the
patch-parallel stages.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import pyopencl.array as cl_array

from ...patterns.semi_uniform import interior_template, point_template
from ...tessellation import Tessellation
from .scan_kernel import GenericScanKernel
from .events import span_ms
from .plan import Plan
from .tessellator import WORK_GROUP, Tessellator

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
_TEMPLATES: dict = {}


def level_scan(context, wide: bool = False) -> GenericScanKernel:
    """Stream compaction of the patches ``base .. base + count - 1`` by level, over the
    level-major sequence i = level * count + k (patch base + k at level i / count; N =
    (max_level + 1) * count): ``queue`` gets level 0's patches, then level 1's, each in patch
    order; ``ends[level]`` the number of patches of levels <= level.  pyopencl.algorithm.copy_if's
    scan over virtual input, built once per context; ``wide``: 64-bit indices, for N >= 2^31.
    Its items are ulong: with uint ones, Oclgrind's uninitialised-value pass reported the queues
    of the whole by-level scenarios too (tests/oclgrind_scenarios.py, UNINITIALIZED_SKIPPED)."""
    if (context, wide) not in _LEVEL_SCANS:
        _LEVEL_SCANS[context, wide] = GenericScanKernel(
            context, np.uint64, preamble=LEVEL_PREAMBLE, index_dtype=np.int64 if wide else np.int32,
            arguments="__global const int *factors, uint base, uint count, __global uint *queue, __global ulong *ends",
            input_expr="patch_level(factors, base + i % count) == (int)(i / count) ? 1 : 0",
            scan_expr="a+b", neutral="0",
            output_statement="if (prev_item != item) queue[prev_item] = base + i % count; "
                             "if ((i + 1) % count == 0) ends[i / count] = item;")
    return _LEVEL_SCANS[context, wide]


def level_templates(tessellator: Tessellator, domain: str, level: int) -> tuple[cl_array.Array, cl_array.Array]:
    """Level ``level``'s templates on the tessellator's device, uploaded once per context: the
    points of P^m (S, 2) int32 and its interior triangles (T, 3) uint32 (patterns/semi_uniform.py)."""
    key = (tessellator.context, domain, level)
    if key not in _TEMPLATES:
        _TEMPLATES[key] = tuple(cl_array.to_device(tessellator.queue, np.ascontiguousarray(a))
                                for a in (point_template(domain, level), interior_template(domain, level)))
    return _TEMPLATES[key]


def plan_by_level(tessellator: Tessellator, scene, request) -> Plan:
    """``tessellator.plan`` for ``request`` with emit="by_level" (whatever the request says)."""
    from dataclasses import replace

    return tessellator.plan(scene, replace(request, emit="by_level"))


@dataclass
class LevelQueues:
    """The patches of one part of a plan, ``first .. last - 1``, by level: level l's are the scene
    numbers ``patches[starts[l]:starts[l + 1]]``."""

    first: int
    last: int
    patches: cl_array.Array
    starts: list

    def count(self, level: int) -> int:
        return self.starts[level + 1] - self.starts[level]

    @property
    def histogram(self) -> list[int]:
        return [self.count(level) for level in range(len(self.starts) - 1)]


def level_queues(tessellator: Tessellator, plan: Plan, first: int, last: int, max_level: int) -> tuple[LevelQueues, list]:
    """Patches ``first .. last - 1`` (of one part) partitioned by level 0 .. max_level on the
    device by one compaction scan (patch order kept within a level), and its events; the queue
    ends are read back (M + 1 numbers)."""
    count = last - first
    patches = cl_array.empty(tessellator.queue, max(count, 1), np.uint32)
    ends = cl_array.empty(tessellator.queue, max_level + 1, np.uint64)  # every entry written
    size = (max_level + 1) * count
    event = level_scan(tessellator.context, size >= 2**31)(
        plan.factors, np.uint32(first), np.uint32(count), patches, ends, size=size, queue=tessellator.queue)
    return LevelQueues(first, last, patches, [0] + ends.get().astype(int).tolist()), [event]


def _global(size: int) -> tuple[int]:
    """A global size of whole work-groups of WORK_GROUP (the level kernels are launched with that
    local size: PoCL's own choice made stage 4 by level about 1.8 times slower)."""
    return (max(WORK_GROUP, -(-size // WORK_GROUP) * WORK_GROUP),)


def emit_by_level(tessellator: Tessellator, plan: Plan, first: int = 0, last: int | None = None) -> Tessellation:
    """Stages 4-5 for patches ``first .. last - 1`` of a plan (``Tessellator.emit``'s batches),
    by level for the parts whose pattern has a template (``dyadic``), patch-parallel without
    forward differencing for the others.  stats["level_queues"]: the patches per level."""
    last = plan.num_patches if last is None else last
    started = time.perf_counter()
    vertex_range, index_range = plan.vertex_range(first, last), plan.index_range(first, last)
    vertices = tessellator._vertex_arrays(vertex_range[1] - vertex_range[0])
    triangles = cl_array.empty(tessellator.queue, ((index_range[1] - index_range[0]) // 3, 3), np.uint32)
    events = dict(plan.events) if first == 0 else {}
    events.update(queues=[], vertices=[], indices=[])
    histogram = {}
    vertex_base, index_base = np.uint64(vertex_range[0]), np.uint64(index_range[0])
    parts = [(part, max(first, part.base), min(last, part.base + part.count)) for part in plan.parts]
    parts = [(part, lo, hi) for part, lo, hi in parts if lo < hi]
    queues = {}
    for part, lo, hi in parts:  # 1. one scan per part, its queue ends read back
        if part.pattern.dyadic:
            queues[part.base], queue_events = level_queues(tessellator, plan, lo, hi, plan.request.max_level)
            events["queues"] += queue_events
            for level, size in enumerate(queues[part.base].histogram):
                histogram[level] = histogram.get(level, 0) + size
    programs = tessellator.programs
    common = (plan.factors.data, plan.vertex_offsets.data)

    def by_level(part):
        """(level, its queue's kernel arguments, its templates) of the part's non-empty queues."""
        for level, size in enumerate(queues[part.base].histogram):
            if size:
                yield (level, size, (queues[part.base].patches.data, np.uint32(queues[part.base].starts[level]),
                                     np.uint32(size)), level_templates(tessellator, part.pattern.domain, level))

    for part, lo, hi in parts:  # 2. vertices: one launch per level over (slot, template point)
        if not part.pattern.dyadic:
            events["vertices"] += tessellator.stage_vertices(
                part.data["controls"], plan.factors, plan.vertex_offsets, plan.objects, vertex_range, (lo, hi),
                False, kind=part.kind, patch_base=part.base, out=vertices, pattern=part.pattern)[1]
            continue
        kernel = programs.kernel("level_vertices", kind=part.kind, pattern=part.pattern)
        for level, size, slots, (points, _) in by_level(part):
            events["vertices"].append(kernel(
                tessellator.queue, _global(size * len(points)), (WORK_GROUP,), part.data["controls"].data, *common,
                plan.objects.data, *slots, points.data, np.uint32(len(points)), np.int32(level),
                np.uint32(part.base), vertex_base, *(a.data for a in vertices.values())))
    for part, lo, hi in parts:  # 3. triangles: per level over (slot, interior triangle), then the bands
        if not part.pattern.dyadic:
            events["indices"] += tessellator.stage_indices(
                plan.factors, plan.vertex_offsets, plan.index_offsets, index_range, (lo, hi), kind=part.pattern,
                out=triangles)[1]
            continue
        interior_kernel = programs.kernel("level_indices", pattern=part.pattern, entry="level_interior")
        band_kernel = programs.kernel("level_indices", pattern=part.pattern, entry="level_band")
        for level, size, slots, (_, interior) in by_level(part):
            if len(interior):
                events["indices"].append(interior_kernel(
                    tessellator.queue, _global(size * len(interior)), (WORK_GROUP,), *common, plan.index_offsets.data,
                    *slots, interior.data, np.uint32(len(interior)), index_base, triangles.data))
            events["indices"].append(band_kernel(
                tessellator.queue, _global(size), (WORK_GROUP,), *common, plan.index_offsets.data, *slots, index_base,
                triangles.data))
    tessellator.queue.finish()
    stage_ms = {stage: span_ms(evs) for stage, evs in events.items() if evs}
    stages_ms = (time.perf_counter() - (plan.started if first == 0 else started)) * 1e3
    levels = [histogram.get(level, 0) for level in range(max(histogram, default=-1) + 1)]
    stats = dict(plan.stats, first_patch=first, last_patch=last, level_queues=levels)
    copied = time.perf_counter()
    host = dict(triangles=triangles.get(), factors=np.abs(plan.host_factors()[first:last]),
                **{k: a.get() for k, a in vertices.items()})
    wall_ms = {"stages": stages_ms, "read_back": (time.perf_counter() - copied) * 1e3}
    wall_ms["total"] = stage_ms["total_wall"] = stages_ms + wall_ms["read_back"]  # until the host arrays are there
    return Tessellation(stage_ms=stage_ms, stats=stats, wall_ms=wall_ms, **host)


def template_size(pattern, level: int) -> int:
    """Points of P^level (patterns/semi_uniform.h pattern_template_size)."""
    return len(point_template(pattern.domain, level))
