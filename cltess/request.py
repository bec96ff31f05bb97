"""What a tessellation is asked for, as one frozen, validated value (OpenSubdiv's
``Tessellation::Options`` in spirit): the tolerance, the factor cap, forward differencing, the
sharp-edge mode and the pattern.  Backends take a ``Request``; ``Tessellator.tessellate(scene,
eps=..., ...)`` builds one from its keyword arguments (``Request.of``)."""
from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

from .criteria.base import DEFAULT_MAX_FACTOR
from .criteria.tolerance import ObjectSpace, ScreenSpace
from .kinds import SHARP_EDGE_MODES
from .limits import MAX_FACTOR, check_max_factor, check_patch_count, check_tolerance_value
from .patterns import FAMILIES, PATTERNS, pattern_named
from .patterns.semi_uniform import DEFAULT_MAX_LEVEL

#: The largest max_level: 2^level within the kernels' factor limit (cltess.limits.MAX_FACTOR).
MAX_LEVEL = MAX_FACTOR.bit_length() - 1
#: Request.bound's values: the hull bound's factors (docs/rational-bound.md), or tighter ones
#: certified triangle by triangle: rational Bézier patches by the integral form of the remainder,
#: or every Bézier patch by the error hull (Bernstein net of p - l).
BOUNDS = ("hull", "integral", "error-hull")
#: The bounds that scale the transition pattern's factors by trials (plan_trials).
TRIAL_BOUNDS = ("integral", "error-hull")
#: Request.emit's values: stages 4-5 per patch, or by level (cltess/backends/opencl/levels.py).
EMIT_MODES = ("per_patch", "by_level")
from .scene import Camera, Scene
from .levels import DEFAULT_LEVEL_FACTORS, DEFAULT_SILHOUETTE_BAND, DEPTH_MAPS, LEVEL_FUNCTIONS


@dataclass(frozen=True)
class Request:
    """tolerance:   ObjectSpace(eps), or ScreenSpace(pixels, camera) where camera None means the
                    scene's camera.
    max_factor:     the largest edge factor (where the bound needs more, the patch is saturated).
    forward_differencing: stage 4 walks the interior rows by forward differences (else direct).
    sharp_edges:    what a mesh edge with different normals on its sides becomes ("straight",
                    "average" or "keep"; cltess.kinds.pn.pn_edge_normals); other kinds ignore it.
    pattern:        a registered pattern name for the kinds of its domain (the others keep their
                    own), a family name ("transition", "semi_uniform": its pattern of each kind's
                    domain), or None for each kind's own.
    max_level:      a dyadic pattern's (semi-uniform) largest edge level: factors are rounded up
                    to 2^ceil(log2 f), at most 2^max_level (beyond it the patch is saturated);
                    other patterns ignore it.
    emit:           how stages 4-5 run: "per_patch" (one work-item per patch), or "by_level"
                    (the semi-uniform patterns' patches in one queue per level, each evaluated
                    from the level's template, Dyken et al. 2009 section 4.2; direct evaluation;
                    other patterns' patches per patch).  The same mesh either way, bit for bit
                    (per_patch without forward differencing).
    level_function: the SD-2 pattern's edge factors (cltess.levels): "depth", "silhouette" or
                    "bound" (the error bound kept; the default for pattern "sd2"); giving one
                    selects pattern "sd2" for the triangle kinds.
    level_factors:  (low, high) real factors of "depth" (far, near) and "silhouette" (plain,
                    crossed edges), within 1 .. max_factor.
    depth_map:      "linear" (g1) or "quadratic" (g2) for "depth".
    depth_range:    (near, far) depths mapped onto (high, low); None: this frame's range.
    silhouette_band: "silhouette": the width, in cosine of the angle between normal and view, of
                    the ramp from high (at the silhouette) to low; continuous in the view for
                    band > 0 (default 0.25), the paper's two classes (which pop) for 0.
    camera:         the camera of "depth" and "silhouette" (None: the scene's).
    bound:          "hull" (stage 1's factors), "integral": rational Bézier patches try smaller
                    factors, each emitted triangle bounded by the integral form of the remainder
                    (cltess/backends/opencl/integral.py), or "error-hull": every Bézier patch
                    tries smaller factors, each emitted triangle bounded by the Bernstein net of
                    its error (cltess/backends/opencl/error_hull.py); OpenCL backend, integer
                    patterns only.
    """

    tolerance: ObjectSpace | ScreenSpace
    max_factor: int = DEFAULT_MAX_FACTOR
    forward_differencing: bool = True
    sharp_edges: str = "straight"
    pattern: str | None = None
    max_level: int = DEFAULT_MAX_LEVEL
    emit: str = "per_patch"
    level_function: str | None = None
    level_factors: tuple = DEFAULT_LEVEL_FACTORS
    depth_map: str = "linear"
    depth_range: tuple | None = None
    camera: Camera | None = None
    bound: str = "hull"
    silhouette_band: float = DEFAULT_SILHOUETTE_BAND

    def __post_init__(self):
        value = self.tolerance.eps if isinstance(self.tolerance, ObjectSpace) else self.tolerance.pixels
        name = "eps" if isinstance(self.tolerance, ObjectSpace) else "pixels"
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
            raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
        check_tolerance_value(name, value)
        check_max_factor(self.max_factor)
        if self.sharp_edges not in SHARP_EDGE_MODES:
            raise ValueError(f"sharp_edges must be one of {', '.join(SHARP_EDGE_MODES)}, got {self.sharp_edges!r}")
        if self.pattern is not None and self.pattern not in PATTERNS and self.pattern not in FAMILIES:
            raise ValueError(f"unknown pattern {self.pattern!r}; expected one of {', '.join((*FAMILIES, *PATTERNS))}")
        if not (isinstance(self.max_level, numbers.Integral) and not isinstance(self.max_level, bool)
                and 0 <= self.max_level <= MAX_LEVEL):
            raise ValueError(f"max_level must be an integer in 0..{MAX_LEVEL}, got {self.max_level!r}")
        if self.emit not in EMIT_MODES:
            raise ValueError(f"emit must be one of {', '.join(EMIT_MODES)}, got {self.emit!r}")
        if self.level_function is not None and self.level_function not in LEVEL_FUNCTIONS:
            raise ValueError(f"level_function must be one of {', '.join(LEVEL_FUNCTIONS)}, got {self.level_function!r}")
        if self.level_function is not None and self.pattern not in (None, "sd2"):
            raise ValueError(f"level_function needs pattern 'sd2', got pattern {self.pattern!r}")
        low_high = tuple(self.level_factors) if isinstance(self.level_factors, (tuple, list)) else ()
        if len(low_high) != 2 or not all(isinstance(x, numbers.Real) and math.isfinite(x) for x in low_high) \
                or not 1 <= low_high[0] <= low_high[1] <= (self.max_factor if self.level_function else math.inf):
            raise ValueError(f"level_factors must be (low, high) with 1 <= low <= high <= max_factor "
                             f"({self.max_factor}), got {self.level_factors!r}")
        if self.depth_map not in DEPTH_MAPS:
            raise ValueError(f"depth_map must be one of {', '.join(DEPTH_MAPS)}, got {self.depth_map!r}")
        if self.depth_range is not None and not (
                len(self.depth_range) == 2 and all(isinstance(x, numbers.Real) and math.isfinite(x)
                                                   for x in self.depth_range)
                and self.depth_range[0] < self.depth_range[1]):
            raise ValueError(f"depth_range must be (near, far) with near < far, got {self.depth_range!r}")
        if self.bound not in BOUNDS:
            raise ValueError(f"bound must be one of {', '.join(BOUNDS)}, got {self.bound!r}")
        if self.bound in TRIAL_BOUNDS and (self.level_function is not None or self.pattern not in (None, "transition", "quad_transition")):
            raise ValueError(f"bound {self.bound!r} scales the transition pattern's factors; it cannot be used with "
                             f"pattern {self.pattern or 'sd2'!r}")
        if not (isinstance(self.silhouette_band, numbers.Real) and 0 <= self.silhouette_band <= 2):
            raise ValueError(f"silhouette_band must be a number in 0..2 (a cosine range), got {self.silhouette_band!r}")
        if self.camera is not None and not isinstance(self.camera, Camera):
            raise ValueError(f"camera must be a cltess.scene.Camera, got {type(self.camera).__name__}")

    @classmethod
    def of(cls, eps: float | None = None, pixels: float | None = None, **options) -> "Request":
        """From the loose keyword arguments of ``Tessellator.tessellate``: exactly one of eps and
        pixels (the screen-space tolerance uses the scene's camera)."""
        if (eps is None) == (pixels is None):
            raise ValueError("give exactly one of eps (object space) and pixels (screen space)")
        tolerance = ObjectSpace(eps) if eps is not None else ScreenSpace(pixels, None)
        return cls(tolerance, **options)

    def tolerance_for(self, scene: Scene) -> ObjectSpace | ScreenSpace:
        """The tolerance with the scene's camera filled in."""
        if isinstance(self.tolerance, ScreenSpace) and self.tolerance.camera is None:
            return ScreenSpace(self.tolerance.pixels, scene.camera)
        return self.tolerance

    def check(self, scene: Scene) -> None:
        """What the request needs of the scene: patches, and a camera for a pixel tolerance."""
        if isinstance(self.tolerance, ScreenSpace) and self.tolerance.camera is None and scene.camera is None:
            raise ValueError(f"{scene.name}: a pixel tolerance needs a camera in the scene")
        if self.level_function in ("depth", "silhouette") and self.camera is None and scene.camera is None:
            raise ValueError(f"{scene.name}: level function {self.level_function!r} needs a camera "
                             "(Request.camera, or one in the scene)")
        if scene.num_patches == 0:
            raise ValueError(f"{scene.name}: the scene has no patches")
        check_patch_count(scene.name, scene.num_patches)

    def pattern_for(self, kind):
        """The pattern a kind is tessellated with: the requested one where its domain is the
        kind's, else the kind's own."""
        pattern = "sd2" if self.level_function is not None and self.pattern is None else self.pattern
        chosen = pattern_named(pattern, kind.domain) if pattern is not None else None
        return chosen if chosen is not None else kind.pattern

    @property
    def sd2_level_function(self) -> str:
        """The level function the SD-2 pattern's factors come from ("bound" unless given)."""
        return self.level_function or "bound"
