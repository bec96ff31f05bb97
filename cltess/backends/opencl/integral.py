"""Request(bound="integral"): tighter factors for rational Bézier patches, certified triangle by
triangle (issue 9; docs/rational-bound.md, "The integral-form bound in the engine").

1. Stage 1 gives today's factors (the hull bound, Lemmas 1-3); each rational patch starts at
   the smallest of ``TRIAL_SCALES`` times them (never above today's).
2. Stages 2-5 as always (crack-free max, counts, vertices, indices).
3. ``stages/integral_bound.cl`` bounds every emitted triangle of the patches whose final factors
   changed since they were last checked (transition triangles included): the integral form of
   the remainder with the patch's subpatch majorants (``cltess.criteria.integral``).
4. A patch with a triangle over its tolerance takes its next trial; the last is today's factors,
   which Lemmas 1/3 certify for any triangle in a 1/m x 1/n box.  Its neighbours' edge factors
   may rise with it (crack-free max): they are checked again in the next round.
Trials only rise, so factors only rise, capped by today's; the loop ends when a round finds no
triangle over its tolerance, and every emitted triangle is then certified by one bound or the other.

Polynomial patches (equal weights) and PN triangles keep today's factors: the integral form is
for the weight-driven curvature spikes of rational patches (polynomial scenes already need
0.2-1.4x OpenCASCADE's triangles, docs/rational-bound.md), and skipping them saves their tables.
"""
from __future__ import annotations

import time

import numpy as np
import pyopencl.array as cl_array

from ...criteria.integral import (SUBDIVISIONS, SUBPATCH_LEVELS, TRIAL_SCALES, graded_breaks, scene_pyramids, table_cells,
                                  trial_factors)
from ...criteria.tolerance import ObjectSpace, ScreenSpace
from ...kinds import BEZIER, FLAG_CULLED, FLAG_SATURATED

LAST_TRIAL = len(TRIAL_SCALES) - 1
#: A failed patch's next scale is at least its scale times (worst bound / tolerance)^JUMP_POWER:
#: 0.5 would be the scale a bound quadratic in the step asks for; the integral form falls faster
#: than that where the curvature is a spike (smaller boxes see smaller majorants), so less
#: (bench/bound_integral.py measured 0.25).
JUMP_POWER = 0.25


def integral_pyramids(tessellator, scene) -> tuple[cl_array.Array, cl_array.Array, np.ndarray]:
    """(pyramids, pyramid_of on the device, rational (P_bezier,) bool) of a scene's Bézier
    patches, made once per scene (host float64 tables, ``Scene.prepared``) and per context."""
    def host():
        patches = np.asarray(scene.patches, float)
        weights = patches[..., 3].reshape(len(patches), -1)
        rational = (weights != weights[:, :1]).any(axis=1)
        tables, index = scene_pyramids(patches, rational, SUBPATCH_LEVELS)
        return tables, index, rational

    def device():
        tables, index, rational = scene.prepared(("bezier", "integral tables", SUBPATCH_LEVELS), host)
        return tessellator.context, (cl_array.to_device(tessellator.queue, tables),
                                     cl_array.to_device(tessellator.queue, index), rational)

    return scene.prepared(("bezier", "integral tables", SUBPATCH_LEVELS, id(tessellator.context)), device)[1]


def triangle_ratios(tessellator, pyramids, pyramid_of, check, uv, patch_ids, triangles, tolerances,
                    subdivisions=SUBDIVISIONS, levels: int = SUBPATCH_LEVELS, skip_failed: bool = False,
                    worst_of_patch: bool = False):
    """(T,) float32: ``stages/integral_bound.cl`` on triangles (T, 3) of vertices with uv (V, 2)
    and patch_ids (V,): bound / tolerance of each triangle of a patch p with check[p] and a
    pyramid (pyramid_of[p] >= 0), else 0.  pyramids, pyramid_of, tolerances: device arrays (or
    host arrays, uploaded here); K = subdivisions[0], doubled up to subdivisions[-1].
    skip_failed: a patch's triangles stop being evaluated once one is over 1 (their ratio then
    reads 0).  worst_of_patch: return (ratios, (P,) worst ratio of each patch's evaluated ones)."""
    queue = tessellator.queue
    num = len(triangles)
    patches = len(check)
    if not num:
        empty = np.zeros(0, np.float32)
        return (empty, np.zeros(patches, np.float32)) if worst_of_patch else empty
    device = [a if isinstance(a, cl_array.Array) else cl_array.to_device(queue, np.ascontiguousarray(a))
              for a in (pyramids, np.asarray(pyramid_of, np.int32) if not isinstance(pyramid_of, cl_array.Array)
                        else pyramid_of, np.asarray(check, np.int32), np.asarray(uv, np.float32),
                        np.asarray(patch_ids, np.int32), np.asarray(triangles, np.uint32),
                        tolerances if isinstance(tolerances, cl_array.Array) else np.asarray(tolerances, np.float32))]
    ratios = cl_array.empty(queue, num, np.float32)
    worst = cl_array.to_device(queue, np.zeros(patches, np.int32))
    breaks = cl_array.to_device(queue, graded_breaks(levels).astype(np.float32))  # dyadic: exact
    tessellator.programs.kernel("integral_bound")(
        queue, (max(64, -(-num // 64) * 64),), None, *(a.data for a in device[:6]), np.uint32(num),
        np.int32(levels), np.int32(table_cells(levels)), breaks.data, np.int32(len(breaks) - 1),
        np.int32(subdivisions[0]), np.int32(subdivisions[-1]),
        device[6].data, ratios.data, worst.data, np.int32(skip_failed))
    if worst_of_patch:
        return ratios.get(), worst.get().view(np.float32)
    return ratios.get()


def plan_integral(tessellator, scene, request, started: float):
    """The integral-bound loop (module docstring, ``plan_trials``); returns the final Plan, whose
    stats carry "integral_rounds", "integral_checked" (triangle bounds evaluated),
    "integral_at_hull" (rational patches left at today's factors), "integral_patches" (rational
    patches) and "integral_ms" (host wall time of the loop beyond the first plan)."""
    uploaded = {}

    def prepare():
        pyramids, pyramid_of_bezier, rational = integral_pyramids(tessellator, scene)
        return rational, (pyramids, pyramid_of_bezier)

    def ratios_of(tables, check, tess, triangles, tolerances):
        pyramids, pyramid_of_bezier = tables
        if "pyramid_of" not in uploaded:  # every patch's, Bézier patches first
            pyramid_of = np.full(len(check), -1, np.int32)
            pyramid_of[:len(pyramid_of_bezier)] = pyramid_of_bezier.get()
            uploaded["pyramid_of"] = cl_array.to_device(tessellator.queue, pyramid_of)
        pyramid_of = uploaded["pyramid_of"]
        return triangle_ratios(tessellator, pyramids, pyramid_of, check, tess.uv, tess.patch_ids, triangles,
                               tolerances, levels=SUBPATCH_LEVELS, skip_failed=True, worst_of_patch=True)

    plan = plan_trials(tessellator, scene, request, started, "integral", TRIAL_SCALES, JUMP_POWER, prepare, ratios_of)
    plan.integral_trials = plan.trials
    return plan


def plan_trials(tessellator, scene, request, started: float, name: str, scales, jump_power: float,
                prepare, ratios_of):
    """The trial loop of a per-triangle bound (module docstring, steps 1-4) with trial scales
    ``scales`` (the last 1.0: today's factors).  prepare() -> ((P_bezier,) bool: the Bézier
    patches to try, the bound's device data); ratios_of(data, check (P,), tess, triangles (T, 3)
    uint32, tolerances on the device) -> ((T,) bound / tolerance, (P,) the worst of each checked
    patch).  Returns the final Plan, with ``trials`` (P,) and the stats "<name>_rounds",
    "<name>_checked" (triangle bounds evaluated), "<name>_at_hull" (tried patches left at today's
    factors), "<name>_patches" (tried patches) and "<name>_ms" (host wall time of the loop beyond
    the first plan)."""
    from ...bound import scene_tolerances

    last_trial = len(scales) - 1
    data = tessellator.scene_data(scene, request.sharp_edges)
    count = data.num_patches
    bezier = next((part for part in data.parts if part[0] is BEZIER), None)
    state = {}

    def stage1_hook(factors: cl_array.Array, flags: cl_array.Array) -> None:
        if "today" not in state:
            state["today"], state["flags"] = factors.get(), flags.get()
        if "trials" in state:
            factors.set(trial_factors(state["today"], state["trials"], scales).reshape(factors.shape))

    scratch: dict = {}
    plan = tessellator.plan_on(data, request, started, scratch, stage1_hook=stage1_hook)
    loop_started = time.perf_counter()
    trials = np.full(count, last_trial, np.int64)
    tried = np.zeros(count, bool)
    stats = {f"{name}_rounds": 0, f"{name}_checked": 0}
    if bezier is not None:
        tried_bezier, device_data = prepare()
        base, n = bezier[1], bezier[2]
        flags = state["flags"][base:base + n]
        tried[base:base + n] = tried_bezier & ~(flags & (FLAG_CULLED | FLAG_SATURATED)).astype(bool)
        trials[tried] = 0
    if tried.any():
        eps = request.tolerance.eps if isinstance(request.tolerance, ObjectSpace) else None
        pixels = request.tolerance.pixels if isinstance(request.tolerance, ScreenSpace) else None
        tolerances = cl_array.to_device(tessellator.queue, scene_tolerances(scene, eps, pixels, request.sharp_edges, for_factors=True)
                                        .astype(np.float32))
        checked_at = np.full((count, 4), np.iinfo(np.int32).min, np.int32)
        while True:
            state["trials"] = trials
            plan = tessellator.plan_on(data, request, started, scratch, stage1_hook=stage1_hook)
            final = plan.factors.get()
            check = tried & (trials < last_trial) & (final != checked_at).any(axis=1)
            if not check.any():
                break
            stats[f"{name}_rounds"] += 1
            tess = tessellator.emit(plan, 0, plan.num_patches)
            triangles = np.ascontiguousarray(tess.triangles, np.uint32)
            ratios, worst = ratios_of(device_data, check, tess, triangles, tolerances)
            stats[f"{name}_checked"] += int(np.count_nonzero(ratios))
            failing = check & ~(worst <= 1.0)  # a NaN or infinite bound fails too
            passed = check & ~failing
            checked_at[passed] = final[passed]  # certified while its final factors stay these
            if not failing.any():
                break
            factors_tried = trial_factors(state["today"], trials, scales)
            for p in np.flatnonzero(failing):
                # The next trial whose own factors differ, and at least jump_power of the way to
                # where a bound quadratic in the step would pass (bound ~ 1/scale^2).
                target = scales[trials[p]] * min(float(worst[p]), 1e30) ** jump_power
                trials[p] += 1
                while trials[p] < last_trial and (
                        scales[trials[p]] < target
                        or (trial_factors(state["today"][p:p + 1], trials[p:p + 1], scales) == factors_tried[p]).all()):
                    trials[p] += 1
    stats.update({f"{name}_patches": int(tried.sum()),
                  f"{name}_at_hull": int(np.count_nonzero(tried & (trials == last_trial))),
                  f"{name}_ms": (time.perf_counter() - loop_started) * 1e3})
    plan.stats.update(stats)
    plan.trials = trials
    return plan
