"""What the engine can represent, checked up front in one place (issue 9, items 1 and 4).

Edge factors.  The pattern routines of kernels/cltess.h count and number a patch's vertices
and triangles in 32-bit integers.  With every factor in 1..M, the largest value each of their
integer expressions takes is (M = max_factor; core factors are at most M):

==============================================  ==========================  ======
expression (kernels/cltess.h)                   worst case                  type
==============================================  ==========================  ======
quad_vertex_count: f0+f1+f2+f3 + (a-1)(b-1)     4M + (M-1)^2 = (M+1)^2      int
quad_triangles Bresenham: (2o+1) * along        (2M-1) M                    int
tri_vertex_count: 3M + (n-1)(n-2) / 2          <= M^2 (M >= 5)             int
tri_triangles Bresenham: 2 (k+1) fe             2 M^2                       int
put_triangle slot: 3 count + 2                  3 (2M^2 - 1) + 2            uint
==============================================  ==========================  ======

(a quad patch has at most 2 M^2 triangles, a triangle patch at most M^2).  ``MAX_FACTOR`` is
the largest M for which all of them fit; a larger ``max_factor`` is refused by
:func:`check_max_factor`, which both the command line and ``Tessellator`` call.  Global vertex
numbers are uint32 too (the triangles' indices), so a plan's total must be at most 2^32
(:func:`check_totals`); the scan itself runs in uint64.

Floats.  The device computes in float32: input that is finite in float64 but not once rounded
to float32 (or whose products overflow there) would come out as NaN or infinity.
:data:`HOMOGENEOUS_MAX` and :data:`WEIGHT_MIN` bound what the readers, ``Scene`` and
``TriangleMesh`` accept (:func:`float32_problem`).
"""
from __future__ import annotations

import numbers

import numpy as np

INT32_MAX = 2**31 - 1
UINT32_MAX = 2**32 - 1


def kernel_integer_extremes(m: int) -> dict[str, tuple[int, int]]:
    """Worst case, over all factors in 1..m, of each integer expression of the pattern
    routines (table above): name -> (worst value, largest value of its type)."""
    return {
        "quad vertex count (int)": ((m + 1) ** 2, INT32_MAX),
        "quad stitch test (int)": ((2 * m - 1) * m, INT32_MAX),
        "triangle vertex count (int)": (max(3 * m + (m - 1) * (m - 2) // 2, (m - 1) * (m - 2)), INT32_MAX),
        "triangle stitch test (int)": (2 * m * m, INT32_MAX),
        "index slot of the last triangle (uint)": (3 * (2 * m * m - 1) + 2, UINT32_MAX),
    }


def _fits(m: int) -> bool:
    return all(value <= limit for value, limit in kernel_integer_extremes(m).values())


def _largest_fitting_factor() -> int:
    low, high = 1, 2**16  # _fits(low), not _fits(high)
    while high - low > 1:
        middle = (low + high) // 2
        low, high = (middle, high) if _fits(middle) else (low, middle)
    return low


#: The largest max_factor whose per-patch counts the kernels' 32-bit integers hold (26754).
MAX_FACTOR = _largest_fitting_factor()

#: Largest |component| of a homogeneous control point (w x, w y, w z, w) or mesh position accepted.
#: The kernels multiply two of them (tangent cross products, squared lengths) with small
#: integer coefficients: (2**60)**2 * 2**7 stays below float32's largest, 2**128.
HOMOGENEOUS_MAX = 2.0**60
#: Smallest weight accepted: its square, 2**-120, is still a normal float32 (2**-126 and up).
WEIGHT_MIN = 2.0**-60
#: eps or pixels must be a normal float32.
TOLERANCE_RANGE = (float(np.finfo(np.float32).tiny), float(np.finfo(np.float32).max))


def float32_problem(points: np.ndarray) -> tuple[int, str] | None:
    """The first row of ``points`` (N, 4) homogeneous, or (N, 3) positions, that the device's
    float32 arithmetic cannot take, and why; None if all are fine."""
    points = np.asarray(points, np.float64).reshape(-1, points.shape[-1])
    with np.errstate(invalid="ignore"):
        too_large = ~(np.abs(points) <= HOMOGENEOUS_MAX).all(axis=1)
        too_light = points[:, 3] < WEIGHT_MIN if points.shape[1] == 4 else np.zeros(len(points), bool)
    bad = too_large | too_light
    if not bad.any():
        return None
    k = int(np.argmax(bad))
    if too_light[k]:
        return k, (f"weight {float(points[k, 3])!r} is below 2**-60 ({WEIGHT_MIN:.3g}): too small for the "
                   "device's float32 arithmetic")
    what = "homogeneous point (w x, w y, w z, w)" if points.shape[1] == 4 else "position"
    return k, (f"{what} {np.array2string(points[k], precision=6)} has a component beyond +-2**60 "
               f"({HOMOGENEOUS_MAX:.3g}): too large for the device's float32 arithmetic")


def check_tolerance_value(name: str, value: float) -> None:
    """eps or pixels: ValueError unless a normal, finite float32 (it is passed as one)."""
    low, high = TOLERANCE_RANGE
    if not low <= value <= high:
        raise ValueError(f"{name} must be between {low:.3g} and {high:.3g} (a float32), got {value!r}")


def check_max_factor(value) -> int:
    """``value`` as an int in 1..MAX_FACTOR, else ValueError saying why."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise ValueError(f"max_factor must be an integer, got {value!r}")
    value = int(value)
    if not 1 <= value <= MAX_FACTOR:
        raise ValueError(f"max_factor must be in 1..{MAX_FACTOR} (the largest factor whose per-patch "
                         f"vertex and index counts fit the kernels' 32-bit integers), got {value}")
    return value


class OutputTooLarge(MemoryError, ValueError):
    """The output cannot be made within what the caller chose (a memory cap, a format that
    cannot be streamed, 32-bit vertex numbers): a usage error (the command line exits with 2),
    unlike the device running out of memory.  A MemoryError, as it used to be, and a ValueError."""


#: Patches a scene may have: kernels take patch counts as uint and patch-edge counts
#: (4 per patch) as uint, and patch ids are int32.
MAX_PATCHES = 2**30 - 1


def check_patch_count(name: str, count: int) -> None:
    if count > MAX_PATCHES:
        raise OutputTooLarge(f"{name}: {count} patches, more than the {MAX_PATCHES} the kernels number")


def check_totals(name: str, num_vertices: int) -> None:
    """A plan's vertex total (a Python int, summed by the uint64 scan): the triangles number
    vertices globally in uint32.  Per patch at most (MAX_FACTOR + 1)**2 < 2**30 vertices and
    6 MAX_FACTOR**2 < 2**32 indices, over at most 2**30 patches: the uint64 scan cannot wrap."""
    if num_vertices > UINT32_MAX + 1:
        raise OutputTooLarge(f"{name}: the output would have {num_vertices} vertices, more than the "
                             f"2**32 that 32-bit triangle indices can number; raise the tolerance or "
                             "lower max_factor")


#: The output's float32 coordinates resolve a tolerance of at least this many float32 steps at
#: the scene's largest coordinate.  Evaluating a vertex in float32 and storing it costs a few
#: steps (de Casteljau on the boundary, the centre added back, the final rounding: up to
#: sqrt(3)/2 of a step alone; 2-3 steps measured on the translated sphere and teapot), on top of
#: an approximation error the factors bound by eps: at 16 steps that is at most about 1/5 of eps.
EPS_FLOAT32_STEPS = 16


def largest_coordinate(scene) -> float:
    """The largest |x|, |y| or |z| the scene's surfaces can reach: of the Bézier patches'
    Cartesian control points (the surface lies in their hull, weights > 0) and mesh vertices."""
    extents = [0.0]
    if len(scene.patches):
        cartesian = scene.patches[..., :3] / scene.patches[..., 3:]  # max |x| without a second array
        extents.append(float(np.maximum(cartesian.max(), -cartesian.min())))
    extents += [float(np.abs(mesh.vertices).max()) for mesh in scene.meshes]
    return max(extents)


def eps_below_float32(scene, eps: float) -> str | None:
    """Why ``eps`` is below what float32 output coordinates can represent at the scene's
    extent (fewer than EPS_FLOAT32_STEPS float32 steps at its largest coordinate), or None."""
    largest = largest_coordinate(scene)
    step = float(np.spacing(np.float32(largest)))
    if eps >= EPS_FLOAT32_STEPS * step:
        return None
    from .criteria.tolerance import FLOAT32_TOLERANCE_STEPS

    raised = (f"; patches whose tolerance would be below {FLOAT32_TOLERANCE_STEPS:g} float32 steps where they lie "
              f"get that instead (up to {FLOAT32_TOLERANCE_STEPS * step:.3g} here)"
              if eps < FLOAT32_TOLERANCE_STEPS * step else "")
    return (f"eps {eps:g} is below {EPS_FLOAT32_STEPS} float32 steps ({EPS_FLOAT32_STEPS * step:.3g}) at the "
            f"scene's largest coordinate, {largest:.6g}: the output's float32 coordinates cannot resolve it, "
            f"so the error bound may not hold{raised}; move the scene nearer the origin or raise eps")
