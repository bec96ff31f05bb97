"""What a patch kind is on the host (docs/extending.md, "A kind"): how its part of a scene is
prepared, uploaded and numbered, which device header and pattern it uses, and its NumPy
reference (``surface``, ``reference_factors``) for the NumPy backend and the tests."""
from __future__ import annotations

from dataclasses import dataclass, field
from types import ModuleType

import numpy as np

from ..crack.adjacency import EdgeGroups
from ..patterns import Pattern
from ..scene import Scene

#: Factors per patch in the shared (P, 4) array (kernels/common.h FACTOR_SLOTS); a kind uses
#: its first ``edges``, the rest are 0.
FACTOR_SLOTS = 4
#: Stage 1's flags per patch (kernels/common.h FLAG_*).
FLAG_SATURATED, FLAG_CULLED, FLAG_FOLDED = 1, 2, 4


@dataclass
class KindInput:
    """A kind's part of a scene, prepared on the host: what is uploaded and what stage 2 needs.

    source:  the float32 array its stage-1 kernel reads, one row per patch.
    objects: (n,) int32 object id per patch.
    groups:  its patch-edges (``edges`` per patch) grouped into shared edges.
    stats:   extra counts for the summary (e.g. sharp edges).
    """

    source: np.ndarray
    objects: np.ndarray
    groups: EdgeGroups
    stats: dict = field(default_factory=dict)


class PatchKind:
    """One patch type (a plug-in; registry ``cltess.kinds.KINDS``).

    name:    its name ("bezier", "pn").
    domain:  "quad" or "tri": the patterns it can use.
    edges:   boundary curves per patch (at most FACTOR_SLOTS).
    header:  its device header under kernels/ (the kind contract of docs/extending.md).
    pattern: its default pattern (a ``cltess.patterns.Pattern`` of its domain).
    per_patch_constants: whether stage 1 reads, as its source, one float4 per patch that it
             makes itself on the patch's first visible call (``.x < 0``: not made yet) and keeps
             there: the part of the kind's bound that depends on the patch alone, cached on the
             scene per OpenCL context (``Tessellator.upload``).  Stage 1 then reads the patches
             from the controls.
    surface: its NumPy surface module (``cltess.surfaces.<kind>``): ``evaluate(controls, u, v)
             -> (positions, normals)`` of one patch and ``surface_points(controls, ids, u, v)``
             of many, the mirrors of the kernels' evaluation.
    """

    name = ""
    domain = ""
    edges = 0
    header = ""
    pattern: Pattern
    per_patch_constants = False
    surface: ModuleType

    def count(self, scene: Scene) -> int:
        """How many patches of this kind the scene has."""
        raise NotImplementedError

    def prepare(self, scene: Scene, sharp_edges: str = "straight") -> KindInput:
        """The kind's part of the scene on the host (sharp_edges: for kinds with sharp edges)."""
        raise NotImplementedError

    def controls_shape(self, count: int) -> tuple:
        """Shape of what stage 1 writes and stage 4 reads (float32), or None when stage 4 reads
        the source itself."""
        return None

    def reference_factors(self, source: np.ndarray, tolerance, max_factor: int):
        """NumPy stage 1: (controls (what surface.evaluate takes per patch, float64), factors (n, 4)
        int32, flags (n,) int32)."""
        raise NotImplementedError

    def __repr__(self) -> str:
        return f"<PatchKind {self.name}>"
