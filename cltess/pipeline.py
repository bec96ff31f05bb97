"""The engine's former home, kept as re-exports for one release: the OpenCL backend is
``cltess.backends.opencl``, the kinds ``cltess.kinds``."""
from .backends.opencl.programs import STAGES, Programs, kernel_dir
from .backends.opencl.plan import Plan, PlanPart
from .backends.opencl.tessellator import WORK_GROUP, Tessellator
from .kinds import BEZIER, FACTOR_SLOTS, KINDS, PN, BezierKind, KindInput, PatchKind, PNKind
from .tessellation import BYTES_PER_INDEX, BYTES_PER_VERTEX

__all__ = ["BEZIER", "BYTES_PER_INDEX", "BYTES_PER_VERTEX", "FACTOR_SLOTS", "KINDS", "PN", "STAGES", "WORK_GROUP",
           "BezierKind", "KindInput", "PNKind", "PatchKind", "Plan", "PlanPart", "Programs", "Tessellator",
           "kernel_dir"]
