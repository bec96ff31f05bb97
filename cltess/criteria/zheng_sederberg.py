"""The Zheng-Sederberg bound for rational bicubic patches (docs/design.md section 2; CudaTess
section 3), with the rational second-derivative bounds of docs/rational-bound.md: NumPy mirror
of kernels/criteria/zs.h."""
from __future__ import annotations

import functools
import itertools
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

    The affine interpolant l of p = X / w on any triangle whose corners' u values span at most
    du and v values at most dv satisfies, at the same (u, v) (docs/rational-bound.md):

        Lemma 1:  |p - l| <= (1/8) (M_uu du^2 + 2 M_uv du dv + M_vv dv^2),   M_ab >= sup |p_ab|
        Lemma 3:  |p - l| <= (1/8) (alpha du^2 + gamma dv^2)  if  |D^2 p [h, h]| <= alpha h_u^2 + gamma h_v^2

    The M's come from the rational convex hull of (p_uu, p_uv, p_vv) (Lemma 2,
    second_derivative_hull); Lemma 3's alpha, gamma = rho alpha from the same hull
    (diagonal_majorant), rho = M_vv / M_uu.  Of the two step pairs the one with the larger
    du*dv is taken.  Equal weights: the polynomial Zheng-Sederberg bound, unchanged (Lemma 1 with
    second_derivative_bounds).  In two parts: zs_constants (the patch alone) and zs_constant_steps.
    """
    return zs_constant_steps(zs_constants(patch), eps)


def zs_constants(patch: np.ndarray) -> tuple[float, float, float, float]:
    """(M_uu, M_uv, M_vv, alpha) of one (4, 4, 4) patch: the part of zs_inverse_steps that
    depends on the patch alone (mirror of kernels/criteria/zs.h, zs_constants, which the device
    calls once per patch and scene, kernels/kinds/bezier.h).  Rational: the M's from
    second_derivative_hull, alpha = diagonal_majorant(hull, M_vv / M_uu) (0 where M_uu or M_vv
    is 0).  Equal weights: second_derivative_bounds and alpha = 0 (no Lemma 3)."""
    w = patch[..., 3]
    if (w == w[0, 0]).all():
        return (*second_derivative_bounds(patch), 0.0)
    hull = second_derivative_hull(patch)
    m_uu, m_uv, m_vv = (float(m) for m in np.linalg.norm(hull, axis=-1).max(axis=0))
    alpha = diagonal_majorant(hull, m_vv / m_uu) if m_uu > 0 and m_vv > 0 else 0.0
    return m_uu, m_uv, m_vv, alpha


def zs_constant_steps(constants, eps: float) -> tuple[float, float]:
    """(1/du, 1/dv) from a patch's zs_constants and the tolerance: Lemma 1's steps
    zs_steps(M_uu, M_uv, M_vv, 8 eps), or, where alpha > 0 and its du*dv is larger, Lemma 3's
    du = sqrt(4 eps / alpha), dv = sqrt(4 eps / (rho alpha)), rho = M_vv / M_uu, each at most 1
    (mirror of kernels/criteria/zs.h, zs_constant_steps: what stage 1 evaluates per call)."""
    m_uu, m_uv, m_vv, alpha = (float(x) for x in constants)
    du, dv = zs_steps(m_uu, m_uv, m_vv, 8 * eps)
    if alpha > 0:
        rho = m_vv / m_uu
        du_3, dv_3 = min(math.sqrt(4 * eps / alpha), 1.0), min(math.sqrt(4 * eps / (rho * alpha)), 1.0)
        if du_3 * dv_3 > du * dv:
            du, dv = du_3, dv_3
    return 1 / du, 1 / dv


def second_derivative_bounds(patch: np.ndarray) -> tuple[float, float, float]:
    """Bounds (M_uu, M_uv, M_vv) of |p_uu|, |p_uv|, |p_vv| over [0, 1]^2, p = X / w.

    Rational: the largest norms over second_derivative_hull.  Equal weights w: p_ab = X_ab / w
    directly, and the bounds are 6, 9 and 6 times the largest second differences of the points,
    the polynomial Zheng-Sederberg bound.
    """
    w = patch[..., 3:]
    if not (w == w[0, 0]).all():
        return tuple(float(m) for m in np.linalg.norm(second_derivative_hull(patch), axis=-1).max(axis=0))
    points = patch[..., :3] / w  # [j, i]: u runs along axis 1, v along axis 0
    return (6 * np.linalg.norm(np.diff(points, 2, axis=1), axis=-1).max(),
            9 * np.linalg.norm(np.diff(np.diff(points, axis=1), axis=0), axis=-1).max(),
            6 * np.linalg.norm(np.diff(points, 2, axis=0), axis=-1).max())


def second_derivative_hull(patch: np.ndarray) -> np.ndarray:
    """(100, 3, 3): points H_k = (N_uu,k, N_uv,k, N_vv,k) / W_k whose convex hull holds
    (p_uu, p_uv, p_vv) everywhere on [0, 1]^2, p = X / w (docs/rational-bound.md, Lemma 2).

    Quotient rule: with A_ab = w X_ab - w_ab X and B_a = w X_a - w_a X,

        w^3 p_uu = w A_uu - 2 w_u B_u,   w^3 p_uv = w A_uv - w_u B_v - w_v B_u,
        w^3 p_vv = w A_vv - 2 w_v B_v,

    polynomials of degree (9, 9) whose Bernstein coefficients N_k follow from products of the
    control nets (every derivative net taken at degree (3, 3): CUBIC_DERIVATIVE).  Then
    p_ab = sum_k (W_k B_k / w^3) (N_k / W_k), a convex combination (W_k > 0: w^3's coefficients),
    the same one for all three.  The numerators are translation-invariant; X is taken about the
    box centre to keep the products small.
    """
    w = patch[..., 3:]
    points = patch[..., :3] / w
    centre = (points.min(axis=(0, 1)) + points.max(axis=(0, 1))) / 2
    h = np.concatenate([patch[..., :3] - w * centre, w], axis=-1)  # (X, w), [j, i]
    d_u = lambda a: np.einsum("ki,jic->jkc", CUBIC_DERIVATIVE, a)  # noqa: E731
    d_v = lambda a: np.einsum("kj,jic->kic", CUBIC_DERIVATIVE, a)  # noqa: E731
    h_u, h_v = d_u(h), d_v(h)

    def wedge(a, b):  # a.w b.xyz - b.w a.xyz, as a Bernstein product
        return _bernstein_product(a[..., 3:], b[..., :3]) - _bernstein_product(b[..., 3:], a[..., :3])

    def scaled(a, b):  # a.w b
        return _bernstein_product(a[..., 3:], b)

    b_u, b_v = wedge(h, h_u), wedge(h, h_v)
    numerators = (scaled(h, wedge(h, d_u(h_u))) - 2 * scaled(h_u, b_u),
                  scaled(h, wedge(h, d_v(h_u))) - scaled(h_u, b_v) - scaled(h_v, b_u),
                  scaled(h, wedge(h, d_v(h_v))) - 2 * scaled(h_v, b_v))
    cube = scaled(h, scaled(h, h[..., 3:]))  # w^3
    return np.stack([n / cube for n in numerators], axis=2).reshape(-1, 3, 3)


def diagonal_majorant(hull: np.ndarray, rho: float) -> float:
    """Smallest alpha this bound finds with |H_k[h, h]| <= alpha (h_u^2 + rho h_v^2) for every
    hull point H_k = (a, b, c) and every h, H[h, h] = a h_u^2 + 2 b h_u h_v + c h_v^2
    (docs/rational-bound.md, Lemma 3).

    With h = (cos t, sin t / sqrt(rho)) |h|_rho: H[h, h] / |h|_rho^2 = p + q cos 2t + r sin 2t,
    p = (a + c / rho) / 2, q = (a - c / rho) / 2, r = b / sqrt(rho), a point of an ellipse, and
    |p + v|^2 <= |p|^2 + 2 sqrt((p.q)^2 + (p.r)^2) + s^2 with s the largest singular value of
    [q r].  alpha is the largest of these over k.
    """
    a, b, c = hull[:, 0], hull[:, 1], hull[:, 2]
    p, q, r = (a + c / rho) / 2, (a - c / rho) / 2, b / math.sqrt(rho)
    dot = lambda x, y: (x * y).sum(axis=1)  # noqa: E731
    qq, rr, qr = dot(q, q), dot(r, r), dot(q, r)
    s2 = (qq + rr) / 2 + np.sqrt(((qq - rr) / 2) ** 2 + qr ** 2)
    return float(np.sqrt(dot(p, p) + 2 * np.sqrt(dot(p, q) ** 2 + dot(p, r) ** 2) + s2).max())


# d/dt of a cubic, written again as a cubic: row k holds k (b_k - b_{k-1}) + (3 - k) (b_{k+1} - b_k),
# the hodograph 3 (b_{i+1} - b_i) degree-elevated to 3.  Exact, so it can be applied twice.
CUBIC_DERIVATIVE = np.array([[-3.0, 3, 0, 0], [-1, -1, 2, 0], [0, -2, 1, 1], [0, 0, -3, 3]])


def _binomials(shape) -> np.ndarray:
    """C(n_v, j) C(n_u, i) for a net of the given (n_v + 1, n_u + 1) shape."""
    return _binomial_table(*shape[:2])


@functools.lru_cache(maxsize=None)
def _binomial_table(rows: int, columns: int) -> np.ndarray:
    table = np.outer(*[[math.comb(n - 1, k) for k in range(n)] for n in (rows, columns)])
    table.flags.writeable = False  # shared by every caller
    return table


def _bernstein_product(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Bernstein net of the product of two tensor-product polynomials (nets [j, i, ...], the
    trailing axes multiplied elementwise): in the scaled basis C(n, k) B_k the product is a plain
    convolution of the coefficients (Farin, "Curves and Surfaces for CAGD", 5th ed., 2002)."""
    a_scaled = a * _binomials(a.shape)[..., None]
    b_scaled = b * _binomials(b.shape)[..., None]
    shape = (a.shape[0] + b.shape[0] - 1, a.shape[1] + b.shape[1] - 1)
    out = np.zeros(shape + np.broadcast_shapes(a.shape[2:], b.shape[2:]))
    for j, i in itertools.product(range(a.shape[0]), range(a.shape[1])):
        out[j:j + b.shape[0], i:i + b.shape[1]] += a_scaled[j, i] * b_scaled
    return out / _binomials(shape)[..., None]


def zs_steps(d_uu: float, d_uv: float, d_vv: float, c: float) -> tuple[float, float]:
    """Steps with ``d_uu du^2 + 2 d_uv du dv + d_vv dv^2 <= c`` and du*dv largest, at most 1.

    (1, 1) when it meets the bound.  Otherwise the optimum has du/dv = sqrt(d_vv/d_uu)
    (Lagrange); with s = sqrt(d_uu), t = sqrt(d_vv): du = sqrt(c t / (2 s (s t + d_uv))),
    dv = sqrt(c s / (2 t (s t + d_uv))), docs/design.md's formula without its 0 * inf.  Where that
    optimum lies beyond du = 1 (or dv = 1), the best step pair has du = 1 and the largest dv the
    bound allows there (a stable quadratic root), not the optimum's dv.  Inputs are scaled by
    their max first; a step that still comes out NaN (underflow) becomes 0, i.e. saturated, never
    silently coarse.
    """
    if d_uu + 2 * d_uv + d_vv <= c:
        return 1.0, 1.0
    scale = max(d_uu, d_uv, d_vv)
    a, d, b, c = d_uu / scale, d_uv / scale, d_vv / scale, c / scale

    def largest(quadratic, linear, offset):  # largest x with quadratic x^2 + 2 linear x + offset <= c
        return (c - offset) / (linear + math.sqrt(linear * linear + quadratic * (c - offset)))

    if a > 0 and b > 0:
        s, t = math.sqrt(a), math.sqrt(b)
        du = math.sqrt(c * t / (2 * s * (s * t + d)))
        dv = math.sqrt(c * s / (2 * t * (s * t + d)))
        if du > 1:
            du, dv = 1.0, largest(b, d, a)
        elif dv > 1:
            du, dv = largest(a, d, b), 1.0
    elif a > 0:  # no v curvature: one step in v, solve u alone
        du, dv = largest(a, d, 0.0), 1.0
    elif b > 0:
        du, dv = 1.0, largest(b, d, 0.0)
    else:  # bilinear twist only
        du = dv = math.sqrt(c / (2 * d))
    return tuple(0.0 if math.isnan(x) else min(x, 1.0) for x in (du, dv))
