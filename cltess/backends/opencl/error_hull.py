"""Request(bound="error-hull"): tighter factors for Bézier patches, certified triangle by
triangle by the error hull (issue 9; docs/rational-bound.md, "The error-hull bound").

The trial loop of ``integral.plan_trials`` (stage 1's hull-bound factors scaled by
``error_hull.TRIAL_SCALES``, rising per patch until every emitted triangle of it passes), with
``stages/error_hull_bound.cl`` as the per-triangle bound: no tables, only each patch's 16
centred control points (``cltess.criteria.error_hull.centred_nets``).  Rational and polynomial
Bézier patches alike (w = 1 is the special case W_k = 1); PN triangles keep today's factors.
"""
from __future__ import annotations

import numpy as np
import pyopencl.array as cl_array

from ...criteria.error_hull import TRIAL_SCALES, centred_nets
from .integral import plan_trials

#: A failed patch's next scale is at least its scale times (worst bound / tolerance)^JUMP_POWER
#: (integral.JUMP_POWER); 0.5 would be the scale a bound quadratic in the step asks for.
JUMP_POWER = 0.25


def error_hull_nets(tessellator, scene) -> tuple[cl_array.Array, cl_array.Array]:
    """(nets (P_bezier * 16,) float4, radii (P_bezier,)) on the device, made once per scene and
    context (``Scene.prepared``)."""
    def host():
        return centred_nets(np.asarray(scene.patches, float))

    def device():
        nets, radii = scene.prepared(("bezier", "error hull nets"), host)
        return tessellator.context, (cl_array.to_device(tessellator.queue, np.ascontiguousarray(nets)),
                                     cl_array.to_device(tessellator.queue, radii))

    return scene.prepared(("bezier", "error hull nets", id(tessellator.context)), device)[1]


def error_hull_ratios(tessellator, nets, radii, check, uv, patch_ids, triangles, tolerances,
                      skip_failed: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """((T,) float32 bound / tolerance of each triangle (T, 3) (vertices with uv (V, 2) and
    patch_ids (V,)) of a patch p with check[p], else 0; (P,) the worst of each patch's evaluated
    ones): ``stages/error_hull_bound.cl``.  nets, radii: ``error_hull_nets`` (or host arrays);
    tolerances (P,): device or host.  skip_failed: a patch's triangles stop being evaluated once
    one is over 1 (their ratio then reads 0)."""
    queue = tessellator.queue
    num, patches = len(triangles), len(check)
    if not num:
        return np.zeros(0, np.float32), np.zeros(patches, np.float32)
    device = [a if isinstance(a, cl_array.Array) else cl_array.to_device(queue, np.ascontiguousarray(a))
              for a in (nets, radii, np.asarray(check, np.int32), np.asarray(uv, np.float32),
                        np.asarray(patch_ids, np.int32), np.asarray(triangles, np.uint32),
                        tolerances if isinstance(tolerances, cl_array.Array) else np.asarray(tolerances, np.float32))]
    ratios = cl_array.empty(queue, num, np.float32)
    worst = cl_array.to_device(queue, np.zeros(patches, np.int32))
    tessellator.programs.kernel("error_hull_bound")(
        queue, (-(-num // 64) * 64,), None, *(a.data for a in device[:6]), np.uint32(num), device[6].data,
        ratios.data, worst.data, np.int32(skip_failed))
    return ratios.get(), worst.get().view(np.float32)


def plan_error_hull(tessellator, scene, request, started: float):
    """The trial loop with the error hull; returns the final Plan, whose stats carry
    "error_hull_rounds", "error_hull_checked", "error_hull_at_hull", "error_hull_patches",
    "error_hull_ms" (integral.plan_trials)."""
    def prepare():
        return np.ones(scene.num_bezier, bool), error_hull_nets(tessellator, scene)

    def ratios_of(device_data, check, tess, triangles, tolerances):
        nets, radii = device_data
        return error_hull_ratios(tessellator, nets, radii, check, tess.uv, tess.patch_ids, triangles, tolerances,
                                 skip_failed=True)

    return plan_trials(tessellator, scene, request, started, "error_hull", TRIAL_SCALES, JUMP_POWER, prepare, ratios_of)
