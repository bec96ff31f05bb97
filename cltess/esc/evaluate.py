"""ESC's evaluators on the device, for the accuracy test and the speed bench (docs/esc.md
section 1): direct Bernstein evaluation, NBM-Horner (kernels/kinds/bezier_nbm.h) and forward
differencing, each on an n x n grid per patch (kernels/esc/evaluate_grid.cl)."""
from __future__ import annotations

import numpy as np
import pyopencl as cl
import pyopencl.array as cl_array

from ..backends.opencl.programs import correctly_rounded_division, kernel_dir

METHODS = {"direct": 0, "nbm": 1, "fd": 2, "nbm_raw": 3}
_PROGRAMS: dict = {}


def grid_kernel(context: cl.Context) -> cl.Kernel:
    """evaluate_grid built against common.h, kinds/bezier.h and kinds/bezier_nbm.h (cached)."""
    if context not in _PROGRAMS:
        folder = kernel_dir()
        source = "".join(f'#include "{h}"\n' for h in ("common.h", "kinds/bezier.h", "kinds/bezier_nbm.h"))
        source += (folder / "esc" / "evaluate_grid.cl").read_text()
        options = ["-I", str(folder)] + correctly_rounded_division(context.devices[0])
        _PROGRAMS[context] = cl.Kernel(cl.Program(context, source).build(options=options), "evaluate_grid")
    return _PROGRAMS[context]


def evaluate_grid(queue: cl.CommandQueue, patches: np.ndarray, n: int, method: str,
                  repeat: int = 1) -> tuple[np.ndarray, np.ndarray, float]:
    """(positions (P, n+1, n+1, 3), normals, best kernel seconds of `repeat` runs) of the patches
    (P, 4, 4, 4) homogeneous, evaluated on the device by `method` (METHODS)."""
    count = len(patches)
    controls = cl_array.to_device(queue, np.ascontiguousarray(patches.reshape(count, 16, 4), np.float32))
    positions = cl_array.empty(queue, (count, n + 1, n + 1, 3), np.float32)
    normals = cl_array.empty(queue, (count, n + 1, n + 1, 3), np.float32)
    kernel = grid_kernel(queue.context)
    best = float("inf")
    for _ in range(repeat):
        event = kernel(queue, (count,), None, controls.data, np.uint32(count), np.int32(n),
                       np.int32(METHODS[method]), positions.data, normals.data)
        event.wait()
        try:
            best = min(best, (event.profile.end - event.profile.start) * 1e-9)
        except cl.Error:  # a queue without profiling
            best = float("nan")
    return positions.get(), normals.get(), best
