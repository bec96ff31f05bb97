"""Benchmark suite: the CudaTess paper's Tables 1 and 2 on any OpenCL device (issue 4).

Importable pieces:

* scene generators sized like the paper's, each with a camera (1024x768, 45 degree field of
  view) for a 0.5 px screen-space tolerance: :func:`tea_table`, :func:`bigguy_copies`
  (killeroo, herd), :func:`sphere_field` (spheres, close-up); PN meshes as ``trimesh``
  meshes with vertex normals: :func:`double_torus`, :func:`elephant`, :func:`star_field`,
  :func:`model_zoo`;
* :func:`numpy_evaluate` (Bézier) and :func:`pn_numpy_evaluate` (PN), the baseline: a plain,
  fully vectorised NumPy evaluation (einsum over Bernstein bases, float64) of positions and
  normals at exactly the pipeline's vertices (its uv and patch ids, so the same factors);
* :func:`write_bandwidth`, the memory-write baseline (a large ``numpy`` fill);
* :class:`AllocationTracker`, the peak device memory of a run (live bytes of every
  ``pyopencl.Buffer`` created while it is active);
* :func:`run_suite` and the table formatters behind ``cltess bench``.

Timing method, per scene: one warm-up run with forward differencing (FD) on and one with it
off (these also build the kernels), then ``repeat`` runs of each; every figure is the median
of those runs, and the spread is (max - min) / median.  Stage times are device milliseconds
from OpenCL profiling events (``Tessellation.stage_ms``); "end to end" is the pipeline's
``total_wall`` (= ``wall_ms["total"]``): from the call until the caller holds the host arrays
(upload, the five stages, the two total read-backs, and the read-back of every output array:
a copy, or on a CPU device a mapping of the buffers).  ``wall_ms["stages"]`` (until the device
stages finish) and ``wall_ms["read_back"]`` are recorded beside it as "stages_wall" and
"read_back".  The host adjacency (and the rest of a patch kind's host preparation) runs once
per scene and is cached on it (``Scene.prepared``), so the warm-up pays it and the timed runs
do not; it is timed alone beside them, and so is the NumPy baseline (median of ``repeat`` runs).
"""
from .baselines import numpy_evaluate, pn_controls, pn_numpy_evaluate, write_bandwidth  # noqa: F401
from .report import format_tables, write_json  # noqa: F401
from .scenes import *  # noqa: F401,F403
from .suite import *  # noqa: F401,F403
