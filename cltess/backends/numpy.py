"""The NumPy backend: the five stages in float64 NumPy over the kinds' surfaces, the patterns'
mirrors, the criteria and the crack policy (slow, obviously right; docs/design.md section 1).
The same ``plan`` / ``emit`` contract as the OpenCL backend, so tests compare backends
generically; its output matches the OpenCL one up to float32 rounding, not bitwise."""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..crack.adjacency import crack_free_factors, merge_edge_groups  # noqa: F401 (re-exported)
from ..crack.or_masks import policy as crack_policy
from ..kinds import FACTOR_SLOTS, FLAG_CULLED, FLAG_SATURATED, KINDS
from ..kinds import kind as kind_named
from ..patterns import quad_pattern, tri_pattern
from ..patterns.base import place_chords
from ..patterns.semi_uniform import dyadic_factors, level_histogram
from ..request import Request
from ..scene import Scene
from ..surfaces.bezier import evaluate
from ..surfaces.pn import pn_evaluate
from ..tessellation import Tessellation, VERTEX_RECORD


def counts(factors: np.ndarray, kind="bezier") -> tuple[np.ndarray, np.ndarray]:
    """(vertex counts (P,), index counts (P,)) of each patch's pattern; kind: a registered kind or
    its name (its default pattern)."""
    return kind_named(kind).pattern.counts(factors)


def dyadic_stage(factors: np.ndarray, flags: np.ndarray, max_level: int) -> tuple[np.ndarray, np.ndarray]:
    """Stage 1's rounding for a dyadic pattern (kernels/stages/factors.cl, -D PATTERN_DYADIC):
    factors 2^min(ceil(log2 f), max_level), 0 kept; saturated where the cap lowered a factor."""
    rounded = dyadic_factors(factors, max_level)
    capped = (rounded < factors).any(axis=1)
    return rounded, flags | np.where(capped, FLAG_SATURATED, 0).astype(flags.dtype)


def offsets(counts_: np.ndarray) -> np.ndarray:
    """Exclusive scan with the total appended: (P+1,)."""
    return np.concatenate([[0], np.cumsum(counts_)]).astype(np.int64)


def tessellate(patches: np.ndarray, factors: np.ndarray, object_ids: np.ndarray | None = None,
               pattern=None, evaluator=None, patch_base: int = 0, chords=None) -> dict:
    """Vertices and triangles of all patches at the given final factors (direct evaluation).

    Returns a dict of positions (V, 3), normals (V, 3), uv (V, 2), patch_ids (V,),
    object_ids (V,), triangles (T, 3): the layout the kernels write.  pattern, evaluator:
    quad_pattern and evaluate by default (pn_tessellate passes the PN ones); patch ids are
    ``patch_base + p``.  chords: the pattern's vertices on chords (Pattern.chords), or None.
    """
    pattern, evaluator = pattern or quad_pattern, evaluator or evaluate
    object_ids = np.zeros(len(patches), np.int32) if object_ids is None else object_ids
    out = {k: [] for k in ("positions", "normals", "uv", "patch_ids", "object_ids", "triangles")}
    first = 0
    for p, f in enumerate(factors):
        uv, tris = pattern(f)
        if not len(uv):
            continue
        pos, nrm = evaluator(patches[p], uv[:, 0], uv[:, 1])
        if chords is not None:  # stage 4's chord points (kernels/stages/rows.h chord_position)
            pos = place_chords(pos, chords(f))
        out["positions"].append(pos)
        out["normals"].append(nrm)
        out["uv"].append(uv)
        out["patch_ids"].append(np.full(len(uv), patch_base + p))
        out["object_ids"].append(np.full(len(uv), object_ids[p]))
        out["triangles"].append(tris + first)
        first += len(uv)
    shapes = {"positions": (0, 3), "normals": (0, 3), "uv": (0, 2), "patch_ids": (0,),
              "object_ids": (0,), "triangles": (0, 3)}
    return {k: np.concatenate(v) if v else np.zeros(shapes[k]) for k, v in out.items()}


def pn_tessellate(controls: np.ndarray, factors: np.ndarray, object_ids: np.ndarray | None = None,
                  patch_base: int = 0) -> dict:
    """tessellate for PN triangles: tri_pattern, pn_evaluate (ring points as boundary_point
    places them, evaluated directly).  Patch ids are ``patch_base + t``."""
    return tessellate(controls, factors, object_ids, tri_pattern, pn_evaluate, patch_base)


@dataclass
class NumpyPlan:
    """Stages 1-3 of the NumPy backend: per kind (kind, pattern, base, count, controls), the
    final factors and the offsets, all host arrays."""

    name: str
    num_patches: int
    parts: list
    objects: np.ndarray
    factors: np.ndarray
    vertex_offsets: np.ndarray
    index_offsets: np.ndarray
    stats: dict = field(default_factory=dict)

    @property
    def num_vertices(self) -> int:
        return int(self.vertex_offsets[-1])

    @property
    def num_indices(self) -> int:
        return int(self.index_offsets[-1])


def _fractional_output(plan, first: int, last: int):
    """(factors: segments, real factors, strips) of patches first..last-1 where a pattern is
    fractional (SD-2; as the OpenCL backend's Plan.output_factors and strip emission)."""
    from ..patterns.fractional import FIXED_ONE, odd_segments
    from ..patterns.sd2 import sd2_strip_indices
    from ..strips import STRIP_RESTART

    factors = plan.factors[first:last].copy()
    real = factors.astype(np.float32)
    strips = []
    for _, pattern, base, count, _ in plan.parts:
        lo, hi = max(first, base), min(last, base + count)
        if lo >= hi or not pattern.fixed_point:
            continue
        for p in range(lo, hi):
            row = plan.factors[p]
            real[p - first] = row / np.float32(FIXED_ONE)
            factors[p - first] = [odd_segments(x) if x > 0 else 0 for x in row]
            real[p - first, 3] = factors[p - first, 3] = 0  # slot 3: the SD-2 hint, not an edge
            local = sd2_strip_indices(row)
            strips.append(np.where(local == STRIP_RESTART, local, local + plan.vertex_offsets[p]))
    strips = np.concatenate(strips).astype(np.uint32) if strips else np.zeros(0, np.uint32)
    return factors, real, strips[:-1] if len(strips) else strips


def _strip_output(plan, first: int, last: int) -> np.ndarray:
    """The strips of patches first..last-1 of a strip pattern with integer factors (ESC), as the
    OpenCL backend emits them (strips.emit_strips): global numbers, the last restart dropped."""
    from ..strips import STRIP_RESTART

    strips = []
    for _, pattern, base, count, _ in plan.parts:
        for p in range(max(first, base), min(last, base + count)) if pattern.strips else ():
            local = pattern.strips(plan.factors[p])
            strips.append(np.where(local == STRIP_RESTART, local, local + plan.vertex_offsets[p]))
    strips = np.concatenate(strips).astype(np.uint32) if strips else np.zeros(0, np.uint32)
    return strips[:-1] if len(strips) else strips


class NumpyBackend:
    """``plan(scene, request)`` and ``emit(plan, first, last)`` in NumPy (cltess.backends.base)."""

    name = "numpy"

    def tessellate(self, scene: Scene, request: Request) -> Tessellation:
        plan = self.plan(scene, request)
        return self.emit(plan, 0, plan.num_patches, request)

    def plan(self, scene: Scene, request: Request) -> NumpyPlan:
        request.check(scene)
        if request.bound != "hull":  # its loop needs stages 2-5 and the kernel per round
            raise ValueError(f"bound={request.bound!r} runs on the OpenCL backend (cltess.Tessellator), "
                             "not the NumPy reference")
        parts, inputs, factors, flags, base = [], [], [], [], 0
        for kind in KINDS:
            count = kind.count(scene)
            if not count:
                continue
            host = kind.prepare(scene, request.sharp_edges)
            controls, f, fl = kind.reference_factors(host.source, request.tolerance_for(scene), request.max_factor)
            pattern = request.pattern_for(kind)
            if pattern.dyadic:  # stage 1's rounding (common.h dyadic_factors)
                f, fl = dyadic_stage(f, fl, request.max_level)
            if pattern.stage1:  # the pattern's own stage 1 (ESC: candidate masks)
                f, fl = pattern.stage1[1](controls, request.tolerance_for(scene), request.max_level, request.max_factor)
            if pattern.fixed_point:  # a level function's fixed-point factors (SD-2)
                from ..levels import reference_level_factors
                f, level_stats = reference_level_factors(scene, request, f)
            parts.append((kind, pattern, base, count, controls))
            inputs.append(host)
            factors.append(f)
            flags.append(fl)
            base += count
        factors, flags = np.concatenate(factors), np.concatenate(flags)
        groups = merge_edge_groups([(host.groups, kind.edges, b) for host, (kind, _, b, _, _) in zip(inputs, parts)],
                                   base, FACTOR_SLOTS)
        crack = next((p.crack for _, p, _, _, _ in parts if p.crack != "crack/max.h"), "crack/max.h")
        final = crack_policy(crack)(factors, groups.group_of, groups.group_start, groups.members,
                                    groups.collapsed_edges)
        vertex_counts, index_counts = np.zeros(base, np.int64), np.zeros(base, np.int64)
        for _, pattern, b, count, _ in parts:
            vertex_counts[b:b + count], index_counts[b:b + count] = pattern.counts(final[b:b + count])
        stats = {"patches": base, "culled": int(np.count_nonzero(flags & FLAG_CULLED)),
                 "saturated": int(np.count_nonzero(flags & FLAG_SATURATED))}
        if any(pattern.fixed_point for _, pattern, _, _, _ in parts):
            stats.update(level_stats)
        if any(pattern.dyadic for _, pattern, _, _, _ in parts):
            stats["patch_levels"] = level_histogram(np.concatenate(
                [final[b:b + count] for _, pattern, b, count, _ in parts if pattern.dyadic]))
        return NumpyPlan(scene.name, base, parts, np.concatenate([h.objects for h in inputs]), final,
                         offsets(vertex_counts), offsets(index_counts), stats)

    def emit(self, plan: NumpyPlan, first: int, last: int, request: Request | None = None) -> Tessellation:
        started = time.perf_counter()
        pieces = []
        for kind, pattern, base, count, controls in plan.parts:
            lo, hi = max(first, base), min(last, base + count)
            if lo >= hi:
                continue
            out = tessellate(controls[lo - base:hi - base], plan.factors[lo:hi], plan.objects[lo:hi],
                             pattern.layout, kind.surface.evaluate, lo, pattern.chords)
            out["triangles"] = out["triangles"] + plan.vertex_offsets[lo]
            pieces.append(out)
        arrays = {name: np.concatenate([p[name] for p in pieces]).astype(dtype).reshape((-1, *shape))
                  if pieces else np.zeros((0, *shape), dtype) for name, dtype, shape in VERTEX_RECORD}
        triangles = np.concatenate([p["triangles"] for p in pieces]).astype(np.uint32) if pieces \
            else np.zeros((0, 3), np.uint32)
        factors, real_factors, strips = plan.factors[first:last], None, None
        if any(pattern.fixed_point for _, pattern, _, _, _ in plan.parts):
            factors, real_factors, strips = _fractional_output(plan, first, last)
        elif any(pattern.strips for _, pattern, _, _, _ in plan.parts):  # ESC's strips
            strips = _strip_output(plan, first, last)
        return Tessellation(triangles=triangles.reshape(-1, 3), factors=factors, strips=strips,
                            real_factors=real_factors,
                            stage_ms={"total_wall": (time.perf_counter() - started) * 1e3},
                            stats=dict(plan.stats, first_patch=first, last_patch=last), **arrays)
