"""The Zheng-Sederberg bound for rational bicubic patches (docs/design.md section 2; CudaTess
section 3): NumPy mirror of kernels/criteria/zs.h."""
from __future__ import annotations

import math

import numpy as np

from .base import DEFAULT_MAX_FACTOR


def zs_factors(patches: np.ndarray, eps: np.ndarray, culled: np.ndarray | None = None,
               max_factor: int = DEFAULT_MAX_FACTOR) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Zheng-Sederberg factors (docs/design.md section 2; CudaTess section 3, "Tessellation factors").

    Returns (factors (P, 4) int32 ordered by edge, unclamped (P, 2) float64 = (1/du, 1/dv),
    saturated (P,) bool).  Culled patches get factor 0 and are never saturated.
    """
    count = len(patches)
    culled = np.zeros(count, bool) if culled is None else culled
    factors = np.zeros((count, 4), np.int32)
    unclamped = np.zeros((count, 2))
    saturated = np.zeros(count, bool)
    for p in range(count):
        if culled[p]:
            continue
        inv_du, inv_dv = zs_inverse_steps(patches[p], eps[p])
        unclamped[p] = inv_du, inv_dv
        m, n = (min(max(math.ceil(x), 1), max_factor) if math.isfinite(x) else max_factor
                for x in (inv_du, inv_dv))
        saturated[p] = not (inv_du <= max_factor and inv_dv <= max_factor)
        factors[p] = m, n, m, n
    return factors, unclamped, saturated


def zs_inverse_steps(patch: np.ndarray, eps: float) -> tuple[float, float]:
    """(1/du, 1/dv) maximising du*dv under the error bound, for one (4, 4, 4) patch.

    Zheng-Sederberg for rational patches, in the form that bounds the error at the same (u, v)
    against the *affine* interpolant l of the samples.  With X = w (P - c) about the box centre
    c: w (p - l) = X - w l =: F vanishes at the triangle's corners, so
    |F| <= (1/8)(F_uu du^2 + 2 F_uv du dv + F_vv dv^2) and |p - l| <= |F| / min w, where

        |F_uu| <= |X_uu| + r |w_uu| + 2 |w_u| |l_u|,   |l_u| <= sup |p_u| <= (|X_u| + r |w_u|) / min w

    and likewise F_vv, F_uv (= X_uv - w_uv l - w_u l_v - w_v l_u).  The |X|, |w| derivative
    bounds come from the control-point differences (6 and 9 for second, 3 for first).  With
    equal weights the w terms vanish and this is the paper's bound exactly; the paper's
    ``max(r - eps, 0)`` bounds the distance to the projective interpolant L_X / L_w instead,
    which is not the same (u, v) when the weights differ (docs/design.md section 2).
    """
    points = patch[..., :3] / patch[..., 3:]
    centre = (points.min(axis=(0, 1)) + points.max(axis=(0, 1))) / 2
    w = patch[..., 3]
    x = patch[..., :3] - w[..., None] * centre  # translate to the box centre first
    r = np.linalg.norm(points - centre, axis=-1).max()
    w_min = w.min()

    def norm_max(d):
        return np.abs(d).max() if d.ndim == 2 else np.linalg.norm(d, axis=-1).max()

    # [j, i]: u differences run along axis 1, v differences along axis 0.
    def second_u(a): return a[:, 2:] - 2 * a[:, 1:-1] + a[:, :-2]
    def second_v(a): return a[2:] - 2 * a[1:-1] + a[:-2]
    def mixed(a): return a[1:, 1:] - a[1:, :-1] - a[:-1, 1:] + a[:-1, :-1]
    def first_u(a): return a[:, 1:] - a[:, :-1]
    def first_v(a): return a[1:] - a[:-1]

    w_u, w_v = 3 * norm_max(first_u(w)), 3 * norm_max(first_v(w))
    slope_u = (3 * norm_max(first_u(x)) + r * w_u) / w_min  # bounds |p_u|, hence |l_u|
    slope_v = (3 * norm_max(first_v(x)) + r * w_v) / w_min
    d_uu = 6 * norm_max(second_u(x)) + r * 6 * norm_max(second_u(w)) + 2 * w_u * slope_u
    d_vv = 6 * norm_max(second_v(x)) + r * 6 * norm_max(second_v(w)) + 2 * w_v * slope_v
    d_uv = 9 * norm_max(mixed(x)) + r * 9 * norm_max(mixed(w)) + w_u * slope_v + w_v * slope_u
    du, dv = zs_steps(d_uu, d_uv, d_vv, 8 * eps * w_min)
    return 1 / du, 1 / dv


def zs_steps(d_uu: float, d_uv: float, d_vv: float, c: float) -> tuple[float, float]:
    """Steps with ``d_uu du^2 + 2 d_uv du dv + d_vv dv^2 <= c`` and du*dv largest, at most 1.

    The optimum has du/dv = sqrt(d_vv/d_uu) (Lagrange); with s = sqrt(d_uu), t = sqrt(d_vv):
    du = sqrt(c t / (2 s (s t + d_uv))), dv = sqrt(c s / (2 t (s t + d_uv))) (docs/design.md
    section 2) without its 0 * inf.  Inputs are scaled by their max first; a step that still comes
    out NaN (underflow) becomes 0, i.e. saturated, never silently coarse.
    """
    scale = max(d_uu, d_uv, d_vv)
    if not scale > 0:
        return 1.0, 1.0
    a, d, b, c = d_uu / scale, d_uv / scale, d_vv / scale, c / scale
    if a > 0 and b > 0:
        s, t = math.sqrt(a), math.sqrt(b)
        du = math.sqrt(c * t / (2 * s * (s * t + d))) if s * (s * t + d) > 0 else math.inf
        dv = math.sqrt(c * s / (2 * t * (s * t + d))) if t * (s * t + d) > 0 else math.inf
    elif a > 0:  # no v curvature: one step in v, solve u alone (stable quadratic root)
        dv, du = 1.0, c / (d + math.sqrt(d * d + a * c))
    elif b > 0:
        du, dv = 1.0, c / (d + math.sqrt(d * d + b * c))
    else:  # bilinear twist only
        du = dv = math.sqrt(c / (2 * d))
    return tuple(0.0 if math.isnan(x) else min(x, 1.0) for x in (du, dv))
