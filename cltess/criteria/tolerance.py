"""The tolerance field: how much error each patch may have, and which patches are culled
(docs/design.md section 7).  NumPy mirror of kernels/criteria/tolerance.h, and the host objects
that choose it: ``ObjectSpace(eps)`` or ``ScreenSpace(pixels, camera)``.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from ..scene import Camera, pixel_size_at_unit_depth

#: No patch gets a tolerance below this many float32 steps (ulps) at its largest coordinate
#: (kernels/criteria/tolerance.h FLOAT32_TOLERANCE_STEPS, checked equal by
#: tests/contracts/test_constants.py; docs/design.md section 7): the output's float32 coordinates
#: cannot hold a finer one, and below about one step neighbouring vertices round to one point
#: (the sphere translated by 1e5 welded with degenerate triangles and non-manifold edges at 0.45
#: steps, cleanly from 0.9; 2 keeps the translated sphere and torus clean up to 1e6).
#: It is FLOAT32_ROUNDING_STEPS plus the 2 steps the factors kept at least before that allowance.
FLOAT32_TOLERANCE_STEPS = 6.0
#: Float32 steps of each patch's tolerance that its factors leave to rounding (kernels/criteria/
#: tolerance.h FLOAT32_ROUNDING_STEPS; docs/design.md section 7): the control points rounded to
#: float32, the move to the patch's centre and the output's rounding each move a point by up to
#: sqrt(3)/2 step.  Without it the sphere at +1e5 measured 1.12 eps at eps = 1e-2 of its diagonal
#: (2.4 steps of rounding), with no warning.
FLOAT32_ROUNDING_STEPS = 4.0


def float32_step(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """(P,) float64: one float32 step at the largest |coordinate| of each box lo, hi (P, 3)."""
    largest = np.maximum(np.abs(lo), np.abs(hi)).max(axis=1).astype(np.float32)
    return np.spacing(largest).astype(np.float64)


def float32_tolerance_floor(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """(P,) float64: FLOAT32_TOLERANCE_STEPS float32 steps at the largest |coordinate| of each
    box lo, hi (P, 3), as kernels/criteria/tolerance.h float32_tolerance_floor computes it."""
    return FLOAT32_TOLERANCE_STEPS * float32_step(lo, hi)


def factor_tolerances(lo: np.ndarray, hi: np.ndarray, tolerance: np.ndarray) -> np.ndarray:
    """What the factors may spend of each patch's tolerance: less the rounding allowance
    (tolerance.h factor_tolerance)."""
    return tolerance - FLOAT32_ROUNDING_STEPS * float32_step(lo, hi)


@dataclass(frozen=True)
class ObjectSpace:
    """Every patch gets ``eps`` (object units)."""

    eps: float
    defines = {}

    def reference(self, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(what the factors may spend (P,), culled (P,)) for patches in boxes lo, hi (P, 3):
        stage 1's mirror (factor_tolerances of box_tolerances)."""
        eps, culled = box_tolerances(lo, hi, eps=self.eps)
        return factor_tolerances(lo, hi, eps), culled

    def kernel_args(self) -> tuple:
        """eps, view, frustum, pixels, pixel_size: the tolerance arguments of stages/factors.cl."""
        view, frustum, _ = camera_arguments(None)
        return np.float32(self.eps), view, frustum, np.float32(0.0), np.float32(0.0)


@dataclass(frozen=True)
class ScreenSpace:
    """``pixels`` on the screen of ``camera``: eps = pixels * nearest depth * pixel size;
    patches outside the frustum are culled."""

    pixels: float
    camera: Camera
    defines = {"TOLERANCE_SCREEN": "1"}

    def reference(self, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        eps, culled = box_tolerances(lo, hi, pixels=self.pixels, camera=self.camera)
        return factor_tolerances(lo, hi, eps), culled

    def kernel_args(self) -> tuple:
        view, frustum, pixel_size = camera_arguments(self.camera)
        return np.float32(0.0), view, frustum, np.float32(self.pixels), np.float32(pixel_size)


def patch_tolerances(patches: np.ndarray, eps: float | None = None, pixels: float | None = None,
                     camera: Camera | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Per-patch object-space tolerance and culling.

    patches: (P, 4, 4, 4).  Returns (eps (P,) float64, culled (P,) bool).
    Object space: every patch gets ``eps``.  Screen space: ``eps = pixels * depth *
    2 tan(fov_y/2) / height`` with ``depth`` the nearest depth of the patch's bounding box in
    front of the camera; boxes entirely outside one frustum plane are culled.
    """
    points = (patches[..., :3] / patches[..., 3:]).reshape(len(patches), -1, 3)
    return box_tolerances(points.min(axis=1), points.max(axis=1), eps, pixels, camera)


def patch_factor_tolerances(patches: np.ndarray, eps: float | None = None, pixels: float | None = None,
                            camera: Camera | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(what each patch's factors may spend (P,), culled (P,)): patch_tolerances less the float32
    rounding allowance (factor_tolerances), what stage 1 and its mirror (``reference``) use."""
    points = (patches[..., :3] / patches[..., 3:]).reshape(len(patches), -1, 3)
    lo, hi = points.min(axis=1), points.max(axis=1)
    eps, culled = box_tolerances(lo, hi, eps, pixels, camera)
    return factor_tolerances(lo, hi, eps), culled


def box_tolerances(lo: np.ndarray, hi: np.ndarray, eps: float | None = None, pixels: float | None = None,
                   camera: Camera | None = None) -> tuple[np.ndarray, np.ndarray]:
    """patch_tolerances for patches given by their bounding boxes lo, hi (P, 3); either
    tolerance is raised to float32_tolerance_floor(lo, hi) where it is below."""
    count = len(lo)
    floor = float32_tolerance_floor(lo, hi)
    if pixels is None:
        return np.maximum(np.full(count, float(eps)), floor), np.zeros(count, bool)
    corners = np.stack([np.where([(c >> a) & 1 for a in range(3)], hi, lo) for c in range(8)], axis=1)
    view = camera.view_matrix()
    cam = corners @ view[:3, :3].T + view[:3, 3]  # (P, 8, 3)
    depth = -cam[..., 2]
    tan_y = math.tan(math.radians(camera.fov_y_deg) / 2)
    tan_x = tan_y * camera.width / camera.height
    outside = [depth < camera.near, depth > camera.far,
               cam[..., 0] > tan_x * depth, cam[..., 0] < -tan_x * depth,
               cam[..., 1] > tan_y * depth, cam[..., 1] < -tan_y * depth]
    culled = np.any([o.all(axis=1) for o in outside], axis=0)
    nearest = np.maximum(depth.min(axis=1), camera.near)
    return np.maximum(pixels * nearest * camera.pixel_size_at_unit_depth(), floor), culled


def camera_arguments(camera: Camera | None):
    """(view float16 row-major, frustum (tan_x, tan_y, near, far) float4, pixel size at depth 1).
    Along a camera path only the view changes: the rest is made once per lens
    (``lens_arguments``)."""
    import pyopencl as cl  # the cl vector types; imported here so the mirror needs no platform

    if camera is None:
        return lens_arguments(None)
    # (frombuffer: ndarray.view to a struct dtype runs NumPy's Python-level _view_is_safe, 3 µs)
    view = np.frombuffer(camera.view_matrix(np.float32), cl.cltypes.float16)[0]
    return (view, *lens_arguments(camera.fov_y_deg, camera.width, camera.height, camera.near, camera.far))


@functools.lru_cache(maxsize=64)
def lens_arguments(fov_y_deg: float | None, width: int = 0, height: int = 0, near: float = 0.0,
                   far: float = 0.0) -> tuple:
    """(frustum (tan_x, tan_y, near, far) float4, pixel size at depth 1) of a camera's lens, made
    once per lens: ``camera_arguments`` runs once per frame, and NumPy's making of a struct
    costs a few µs each (bench/RESULTS.md, "Issue 15: a recorded frame").  None: no camera (the
    view, frustum and pixel size all zero).  The struct is shared by every call: read only."""
    import pyopencl as cl

    if fov_y_deg is None:
        return np.zeros(16, np.float32).view(cl.cltypes.float16)[0], \
            np.zeros(4, np.float32).view(cl.cltypes.float4)[0], 0.0
    tan_y = math.tan(math.radians(fov_y_deg) / 2)
    frustum = np.array([tan_y * width / height, tan_y, near, far], np.float32)
    return frustum.view(cl.cltypes.float4)[0], pixel_size_at_unit_depth(fov_y_deg, height)
