"""The Filip bound for PN triangles (docs/design.md section 3; CudaTess section 4): NumPy mirror
of kernels/criteria/filip.h."""
from __future__ import annotations

import numpy as np

from ..scene import Camera
from ..surfaces.pn import _CUBIC_AT, pn_folded
from .base import DEFAULT_MAX_FACTOR
from .tolerance import box_tolerances, factor_tolerances


def pn_second_derivative_bounds(controls: np.ndarray) -> np.ndarray:
    """(T, 3, 3) bounds D[a, b] >= sup |D_{d_a} D_{d_b} b| over the triangle: 6 times the largest
    norm of the three control points of (Delta_a Delta_b b), Delta_e b_I = b_{I+e_{e+1}} - b_{I+e_e}
    (docs/design.md section 3)."""
    b = np.asarray(controls, float)[:, :10, :3]
    bounds = np.zeros((len(b), 3, 3))
    for a in range(3):
        for c in range(3):
            worst = np.zeros(len(b))
            for base in range(3):
                total = 0.0
                for x, sx in (((a + 1) % 3, 1), (a, -1)):
                    for y, sy in (((c + 1) % 3, 1), (c, -1)):
                        ijk = [0, 0, 0]
                        ijk[base] += 1
                        ijk[x] += 1
                        ijk[y] += 1
                        total = total + sx * sy * b[:, _CUBIC_AT[tuple(ijk)]]
                worst = np.maximum(worst, np.linalg.norm(total, axis=-1))
            bounds[:, a, c] = 6 * worst
    return bounds


def pn_inverse_steps(controls: np.ndarray, eps: np.ndarray) -> np.ndarray:
    """(T, 3) 1/delta_e from the Filip bound (CudaTess section 4):
    (1/8) (D_ee + max(D_e,e+1, D_e,e+2)) delta_e^2 <= eps / 2."""
    d = pn_second_derivative_bounds(controls)
    eps = np.broadcast_to(np.asarray(eps, float), (len(d),))
    out = np.zeros((len(d), 3))
    for e in range(3):
        curvature = d[:, e, e] + np.maximum(d[:, e, (e + 1) % 3], d[:, e, (e + 2) % 3])
        out[:, e] = np.sqrt(curvature / (4 * eps))
    return out


def pn_tolerances(controls: np.ndarray, eps: float | None = None, pixels: float | None = None,
                  camera: Camera | None = None) -> tuple[np.ndarray, np.ndarray]:
    """patch_tolerances for PN triangles: the box of the ten control points."""
    points = np.asarray(controls, float)[:, :10, :3]
    return box_tolerances(points.min(axis=1), points.max(axis=1), eps, pixels, camera)


def pn_factor_tolerances(controls: np.ndarray, eps: float | None = None, pixels: float | None = None,
                         camera: Camera | None = None) -> tuple[np.ndarray, np.ndarray]:
    """pn_tolerances less the float32 rounding allowance (tolerance.factor_tolerances): what
    stage 1's factors spend."""
    points = np.asarray(controls, float)[:, :10, :3]
    lo, hi = points.min(axis=1), points.max(axis=1)
    eps, culled = box_tolerances(lo, hi, eps, pixels, camera)
    return factor_tolerances(lo, hi, eps), culled


def pn_factors(controls: np.ndarray, eps: np.ndarray, culled: np.ndarray | None = None,
               max_factor: int = DEFAULT_MAX_FACTOR) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Filip factors: (factors (T, 4) int32 = (f0, f1, f2, 0), unclamped (T, 3) = 1/delta_e,
    saturated (T,) bool).  Culled and folded (pn_folded) triangles get factor 0 and are never
    saturated."""
    count = len(controls)
    culled = np.zeros(count, bool) if culled is None else culled
    culled = culled | pn_folded(controls)
    unclamped = pn_inverse_steps(controls, eps)
    unclamped[culled] = 0
    finite = np.isfinite(unclamped)
    clamped = np.where(finite & (unclamped <= max_factor), np.maximum(np.ceil(np.where(finite, unclamped, 1)), 1),
                       max_factor)
    factors = np.zeros((count, 4), np.int32)
    factors[:, :3] = np.where(culled[:, None], 0, clamped)
    saturated = ~culled & ~(unclamped <= max_factor).all(axis=1)
    return factors, unclamped, saturated
