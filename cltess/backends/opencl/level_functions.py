"""The SD-2 level functions on the device (kernels/criteria/level.h; host side and NumPy mirror:
cltess/levels.py), run between stage 1 and stage 2 for the patches of a fixed-point pattern:

    vertex_levels   one work-item per welded vertex: depth to the eye plane or silhouette cosine
                    (the depth range: pyopencl.array's min and max, unless the request gives it)
    vertex_bounds   the bound-keeping variant: per welded vertex the largest (odd-rounded)
                    stage-1 factor of its edges, by atomic max
    level_factors   one work-item per triangle: its three 16.16 fixed-point edge factors from
                    its corners' values; stage 1's culled and folded triangles stay 0

Stage 2's crack-free max then runs on the fixed-point factors as integers (their order is the
reals' order), and stages 3-5 read them through the pattern (patterns/sd2.h).
"""
from __future__ import annotations

import numpy as np
import pyopencl.array as cl_array

from ...levels import DEPTH_MAPS, LEVEL_FUNCTIONS, camera_frame, welded_corners


def _global_size(n: int) -> tuple[int]:
    from .tessellator import _global_size as size
    return size(n)


def build_level_function_programs(tessellator) -> None:
    """Build the level functions' kernels and pyopencl's float32 min and max reductions now,
    before a plan's buffers exist (Tessellator.compose: a build after them makes Oclgrind's
    uninitialised-value plugin report what the scans write)."""
    for stage in ("vertex_levels", "vertex_bounds", "level_factors"):
        tessellator.programs.kernel(stage)
    probe = cl_array.zeros(tessellator.queue, 1, np.float32)
    cl_array.min(probe).get(), cl_array.max(probe).get()


def level_factors(tessellator, scene, request, part, factors) -> tuple[list, dict]:
    """Overwrite ``factors`` (P, 4) int32 of ``part``'s patches (a PlanPart of a fixed-point
    pattern, stage 1 done) with the level function's fixed-point factors.  Returns (events,
    stats: "level_function", "depth_range" where used)."""
    queue, programs = tessellator.queue, tessellator.programs
    function = request.sd2_level_function
    code = LEVEL_FUNCTIONS[function]
    host = scene.prepared("sd2 welded corners", lambda: welded_corners(scene))
    corners_host, positions_host, normals_host = host
    device = scene.prepared(("sd2 welded corners on", id(tessellator.context)), lambda: tuple(
        cl_array.to_device(queue, np.ascontiguousarray(a)) for a in host))
    corners, positions, normals = device
    count, vertices = part.count, len(positions_host)
    low, high = (float(x) for x in request.level_factors)
    events, stats = [], {"level_function": function}
    levels = cl_array.zeros(queue, max(vertices, 1), np.float32)
    bounds = cl_array.zeros(queue, max(vertices, 1), np.int32)
    near = far = 0.0
    if function in ("depth", "silhouette"):
        camera = request.camera or scene.camera
        eye, forward = camera_frame(camera)
        events.append(programs.kernel("vertex_levels")(
            queue, _global_size(vertices), None, positions.data, normals.data, np.uint32(vertices),
            np.int32(code), np.append(eye, 0).astype(np.float32), np.append(forward, 0).astype(np.float32),
            levels.data))
        if function == "depth":
            if request.depth_range is not None:
                near, far = (float(x) for x in request.depth_range)
            else:  # this frame's range (two reductions read back)
                live = levels[:vertices]
                near, far = float(cl_array.min(live).get()), float(cl_array.max(live).get())
            stats["depth_range"] = (near, far)
    else:
        events.append(programs.kernel("vertex_bounds")(
            queue, _global_size(count), None, factors.data, corners.data, np.uint32(count),
            np.uint32(part.base), bounds.data))
    if function == "silhouette":  # criteria/level.h: range = (band, -, low, high)
        near = float(request.silhouette_band)
    range_args = np.array([near, far, low, high], np.float32)
    events.append(programs.kernel("level_factors")(
        queue, _global_size(count), None, corners.data, levels.data, bounds.data, np.uint32(count),
        np.uint32(part.base), np.int32(code), np.int32(DEPTH_MAPS[request.depth_map]), range_args, factors.data))
    return events, stats
