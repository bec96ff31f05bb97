"""Plain NumPy reference of every pipeline stage: slow, float64, obviously right.

Each function mirrors one kernel in ``kernels/`` (same name, same layout) so that the tests can
check the kernel against it on random input.  Nothing here is used on the fast path.

Conventions (see ``cltess/scene.py``): ``patches[p, j, i] = (w*x, w*y, w*z, w)``, edges
numbered counter-clockwise 0: v=0, 1: u=1, 2: v=1, 3: u=0.
"""
from __future__ import annotations

import math

import numpy as np

from .scene import Camera, boundary_curves

DEFAULT_MAX_FACTOR = 64


# --- stage 1: tolerances and Zheng-Sederberg factors (DESIGN.md sections 2 and 7) -------------

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


def box_tolerances(lo: np.ndarray, hi: np.ndarray, eps: float | None = None, pixels: float | None = None,
                   camera: Camera | None = None) -> tuple[np.ndarray, np.ndarray]:
    """patch_tolerances for patches given by their bounding boxes lo, hi (P, 3)."""
    count = len(lo)
    if pixels is None:
        return np.full(count, float(eps)), np.zeros(count, bool)
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
    return pixels * nearest * camera.pixel_size_at_unit_depth(), culled


def zs_factors(patches: np.ndarray, eps: np.ndarray, culled: np.ndarray | None = None,
               max_factor: int = DEFAULT_MAX_FACTOR) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Zheng-Sederberg factors (DESIGN.md section 2; CudaTess section 3, "Tessellation factors").

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
    second_derivative_bounds).
    """
    w = patch[..., 3]
    if (w == w[0, 0]).all():
        du, dv = zs_steps(*second_derivative_bounds(patch), 8 * eps)
        return 1 / du, 1 / dv
    hull = second_derivative_hull(patch)
    m_uu, m_uv, m_vv = np.linalg.norm(hull, axis=-1).max(axis=0)
    du, dv = zs_steps(m_uu, m_uv, m_vv, 8 * eps)
    if m_uu > 0 and m_vv > 0:
        rho = m_vv / m_uu
        alpha = diagonal_majorant(hull, rho)
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
    return np.outer(*[[math.comb(n - 1, k) for k in range(n)] for n in shape[:2]])


def _bernstein_product(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Bernstein net of the product of two tensor-product polynomials (nets [j, i, ...], the
    trailing axes multiplied elementwise): in the scaled basis C(n, k) B_k the product is a plain
    convolution of the coefficients (Farin, "Curves and Surfaces for CAGD", 5th ed., 2002)."""
    a_scaled = a * _binomials(a.shape)[..., None]
    b_scaled = b * _binomials(b.shape)[..., None]
    shape = (a.shape[0] + b.shape[0] - 1, a.shape[1] + b.shape[1] - 1)
    out = np.zeros(shape + np.broadcast_shapes(a.shape[2:], b.shape[2:]))
    for j, i in np.ndindex(*a.shape[:2]):
        out[j:j + b.shape[0], i:i + b.shape[1]] += a_scaled[j, i] * b_scaled
    return out / _binomials(shape)[..., None]


def zs_steps(d_uu: float, d_uv: float, d_vv: float, c: float) -> tuple[float, float]:
    """Steps with ``d_uu du^2 + 2 d_uv du dv + d_vv dv^2 <= c`` and du*dv largest, at most 1.

    (1, 1) when it meets the bound.  Otherwise the optimum has du/dv = sqrt(d_vv/d_uu)
    (Lagrange); with s = sqrt(d_uu), t = sqrt(d_vv): du = sqrt(c t / (2 s (s t + d_uv))),
    dv = sqrt(c s / (2 t (s t + d_uv))), DESIGN.md's formula without its 0 * inf.  Where that
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


# --- stage 2: crack-free factors (DESIGN.md section 4) ------------------------------------------

def crack_free_factors(factors: np.ndarray, group_of: np.ndarray, group_start: np.ndarray,
                       members: np.ndarray) -> np.ndarray:
    """Each patch edge takes the max factor over all patch edges of its group; culled stay 0.

    factors: (P, 4); group_of: (4P,); group_start: (G+1,); members: (4P,).  Returns (P, 4).
    """
    flat = factors.reshape(-1)
    out = np.zeros_like(flat)
    for edge, group in enumerate(group_of):
        if flat[edge] == 0:
            continue
        out[edge] = max(flat[members[k]] for k in range(group_start[group], group_start[group + 1]))
    return out.reshape(factors.shape)


# --- patterns (DESIGN.md section 5): local vertex parameters and triangles ----------------------

def quad_pattern(f: tuple[int, int, int, int]) -> tuple[np.ndarray, np.ndarray]:
    """The tessellation pattern of a quad patch with edge factors f (CudaTess Fig. 3).

    Vertex layout, boundary first: the ring of ``R = f0+f1+f2+f3`` boundary points walking
    counter-clockwise from (0, 0) (edge e, point k at ``t = k / f_e``), then the inner grid
    ``(i / A, j / B)`` for ``j = 1..B-1``, ``i = 1..A-1`` row by row.

    Uniform (f0 = f2 and f1 = f3): the regular A x B grid, A = f0, B = f1.  Otherwise the core
    factors are ``A = max(min(f0, f2), 2)``, ``B = max(min(f1, f3), 2)``; the inner grid's cells
    are split regularly and each edge's strip between boundary and inner grid is stitched
    Bresenham-style, advancing the side whose next segment midpoint comes first.

    Returns (uv (V, 2) float64, triangles (T, 3) int64 local indices, counter-clockwise in uv).
    Culled patches (any factor 0) have no vertices and no triangles.
    """
    f = [int(x) for x in f]
    if min(f) <= 0:
        return np.zeros((0, 2)), np.zeros((0, 3), np.int64)
    uniform = f[0] == f[2] and f[1] == f[3]
    a = f[0] if uniform else max(min(f[0], f[2]), 2)
    b = f[1] if uniform else max(min(f[1], f[3]), 2)
    ring_size = sum(f)
    base = np.cumsum([0] + f)

    def ring(e, k):
        return (base[e] + k) % ring_size

    def inner(i, j):
        return ring_size + (j - 1) * (a - 1) + (i - 1)

    uv = []
    for e in range(4):
        for k in range(f[e]):
            t = k / f[e]
            uv.append([(t, 0.0), (1.0, t), (1.0 - t, 1.0), (0.0, 1.0 - t)][e])
    uv += [(i / a, j / b) for j in range(1, b) for i in range(1, a)]

    def grid(i, j):
        if j == 0:
            return ring(0, i)
        if i == a:
            return ring(1, j)
        if j == b:
            return ring(2, a - i)
        if i == 0:
            return ring(3, b - j)
        return inner(i, j)

    tris = []

    def cells(i0, i1, j0, j1):
        for j in range(j0, j1):
            for i in range(i0, i1):
                tris.append((grid(i, j), grid(i + 1, j), grid(i + 1, j + 1)))
                tris.append((grid(i, j), grid(i + 1, j + 1), grid(i, j + 1)))

    if uniform:
        cells(0, a, 0, b)
    else:
        cells(1, a - 1, 1, b - 1)
        inner_edge = [lambda k: inner(1 + k, 1), lambda k: inner(a - 1, 1 + k),
                      lambda k: inner(a - 1 - k, b - 1), lambda k: inner(1, b - 1 - k)]
        for e in range(4):
            outer_n, core = f[e], (a if e % 2 == 0 else b)
            inner_n = core - 2
            o = k = 0
            while o < outer_n or k < inner_n:
                if k == inner_n or (o < outer_n and (2 * o + 1) * core <= (2 * k + 3) * outer_n):
                    tris.append((ring(e, o), ring(e, o + 1), inner_edge[e](k)))
                    o += 1
                else:
                    tris.append((ring(e, o), inner_edge[e](k + 1), inner_edge[e](k)))
                    k += 1
    return np.array(uv, float).reshape(-1, 2), np.array(tris, np.int64).reshape(-1, 3)


# --- stage 3: counts and offsets --------------------------------------------------------------

def counts(factors: np.ndarray, kind: str = "bezier") -> tuple[np.ndarray, np.ndarray]:
    """(vertex counts (P,), index counts (P,)) of each patch's pattern; kind "bezier" (quad_pattern)
    or "pn" (tri_pattern)."""
    pattern = {"bezier": quad_pattern, "pn": tri_pattern}[kind]
    patterns = [pattern(f) for f in factors]
    return (np.array([len(uv) for uv, _ in patterns], np.int64),
            np.array([3 * len(t) for _, t in patterns], np.int64))


def offsets(counts_: np.ndarray) -> np.ndarray:
    """Exclusive scan with the total appended: (P+1,)."""
    return np.concatenate([[0], np.cumsum(counts_)]).astype(np.int64)


# --- surface evaluation (DESIGN.md section 2) ---------------------------------------------------

def bernstein3(t: np.ndarray) -> np.ndarray:
    """(..., 4) cubic Bernstein basis."""
    s = 1 - t
    return np.stack([s ** 3, 3 * t * s * s, 3 * t * t * s, t ** 3], axis=-1)


def bernstein3_derivative(t: np.ndarray) -> np.ndarray:
    """(..., 4) derivatives of the cubic Bernstein basis."""
    s = 1 - t
    return np.stack([-3 * s * s, 3 * s * s - 6 * t * s, 6 * t * s - 3 * t * t, 3 * t * t], axis=-1)


def homogeneous_and_derivatives(patch: np.ndarray, u: np.ndarray, v: np.ndarray):
    """B, B_u, B_v (each (N, 4)) of one (4, 4, 4) patch at parameters u, v (N,)."""
    bu, bv = bernstein3(u), bernstein3(v)
    du, dv = bernstein3_derivative(u), bernstein3_derivative(v)
    return (np.einsum("nj,ni,jic->nc", bv, bu, patch), np.einsum("nj,ni,jic->nc", bv, du, patch),
            np.einsum("nj,ni,jic->nc", dv, bu, patch))


def evaluate(patch: np.ndarray, u, v) -> tuple[np.ndarray, np.ndarray]:
    """Positions and unit normals (N, 3) of a (4, 4, 4) rational patch at (u, v) (N,).

    Normal ``T_u x T_v`` with ``T_u = B_u.xyz - B_u.w p`` (t_u up to the factor 1/B.w).  Where
    it (nearly) vanishes, at a collapsed edge, the normal is its first-order term towards the
    domain centre d = (1/2 - u, 1/2 - v) (``limit_normal``); if that vanishes too, the normal a
    step inside; else +z.
    """
    u, v = np.atleast_1d(np.asarray(u, float)), np.atleast_1d(np.asarray(v, float))
    b, b_u, b_v = homogeneous_and_derivatives(patch, u, v)
    position = b[:, :3] / b[:, 3:]
    normal = _normal(b, b_u, b_v)
    bad = ~_normal_ok(normal, b, b_u, b_v)
    if bad.any():
        limit = limit_normal(patch, u[bad], v[bad], b[bad], b_u[bad], b_v[bad])
        stronger = (limit * limit).sum(1) > (normal[bad] * normal[bad]).sum(1)
        us, vs = u[bad] + NORMAL_SHIFT * (0.5 - u[bad]), v[bad] + NORMAL_SHIFT * (0.5 - v[bad])
        inside = _normal(*homogeneous_and_derivatives(patch, us, vs))
        normal[bad] = np.where(stronger[:, None], limit, inside)
    length = np.linalg.norm(normal, axis=1, keepdims=True)
    return position, np.where(length > 0, normal / np.where(length > 0, length, 1), [0.0, 0.0, 1.0])


def limit_normal(patch, u, v, b, b_u, b_v) -> np.ndarray:
    """D_d(T_u x T_v) = D_d T_u x T_v + T_u x D_d T_v, d = (1/2 - u, 1/2 - v), at (u, v) (N,).

    With D_d p = (d_u T_u + d_v T_v) / B.w.  Where T_u x T_v vanishes on a collapsed edge this is
    the direction the normal tends to (DESIGN.md section 2, "the next-order term").
    patch: one (4, 4, 4) patch, or (N, 4, 4, 4), one per sample."""
    patch = np.broadcast_to(patch, (len(u), 4, 4, 4))
    lin_u, lin_v = np.stack([1 - u, u], -1), np.stack([1 - v, v], -1)
    d2u = patch[:, :, 2:] - 2 * patch[:, :, 1:-1] + patch[:, :, :-2]                      # (N, 4, 2, 4)
    d2v = patch[:, 2:] - 2 * patch[:, 1:-1] + patch[:, :-2]                               # (N, 2, 4, 4)
    duv = patch[:, 1:, 1:] - patch[:, 1:, :-1] - patch[:, :-1, 1:] + patch[:, :-1, :-1]   # (N, 3, 3, 4)
    b_uu = 6 * np.einsum("nj,ni,njic->nc", bernstein3(v), lin_u, d2u)
    b_vv = 6 * np.einsum("nj,ni,njic->nc", lin_v, bernstein3(u), d2v)
    b_uv = 9 * np.einsum("nj,ni,njic->nc", bernstein2(v), bernstein2(u), duv)
    d_u, d_v = (0.5 - u)[:, None], (0.5 - v)[:, None]
    p = b[:, :3] / b[:, 3:]
    t_u, t_v = b_u[:, :3] - b_u[:, 3:] * p, b_v[:, :3] - b_v[:, 3:] * p
    dp = (d_u * t_u + d_v * t_v) / b[:, 3:]
    ds_u, ds_v = d_u * b_uu + d_v * b_uv, d_u * b_uv + d_v * b_vv
    dt_u = ds_u[:, :3] - ds_u[:, 3:] * p - b_u[:, 3:] * dp
    dt_v = ds_v[:, :3] - ds_v[:, 3:] * p - b_v[:, 3:] * dp
    return np.cross(dt_u, t_v) + np.cross(t_u, dt_v)


def bernstein2(t: np.ndarray) -> np.ndarray:
    """(..., 3) quadratic Bernstein basis."""
    s = 1 - t
    return np.stack([s * s, 2 * t * s, t * t], axis=-1)


def surface_points(patches: np.ndarray, patch_ids: np.ndarray, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Positions (N, 3) of many patches at once: sample n is patch ``patch_ids[n]`` at (u[n], v[n])."""
    b = np.einsum("nj,ni,njic->nc", bernstein3(np.asarray(v, float)), bernstein3(np.asarray(u, float)),
                  patches[patch_ids])
    return b[:, :3] / b[:, 3:]


NORMAL_SHIFT = 1.0e-3  # the last resort: how far towards the domain centre a normal is re-evaluated


def _normal(b, b_u, b_v):
    p = b[:, :3] / b[:, 3:]
    t_u = b_u[:, :3] - b_u[:, 3:] * p
    t_v = b_v[:, :3] - b_v[:, 3:] * p
    return np.cross(t_u, t_v)


def _normal_ok(normal, b, b_u, b_v):
    p = b[:, :3] / b[:, 3:]
    t_u = b_u[:, :3] - b_u[:, 3:] * p
    t_v = b_v[:, :3] - b_v[:, 3:] * p
    scale = (t_u * t_u).sum(1) + (t_v * t_v).sum(1)
    return (normal * normal).sum(1) > NORMAL_DEGENERATE ** 2 * scale * scale


NORMAL_DEGENERATE = 1.0e-3  # |T_u x T_v| below this times |T_u|^2 + |T_v|^2: use limit_normal
PN_NORMAL_VANISHES = 1.0e-5  # a PN normal field shorter than this has no direction


# --- stages 4 and 5: the whole tessellation --------------------------------------------------

def tessellate(patches: np.ndarray, factors: np.ndarray, object_ids: np.ndarray | None = None,
               pattern=None, evaluator=None, patch_base: int = 0) -> dict:
    """Vertices and triangles of all patches at the given final factors (direct evaluation).

    Returns a dict of positions (V, 3), normals (V, 3), uv (V, 2), patch_ids (V,),
    object_ids (V,), triangles (T, 3): the layout the kernels write.  pattern, evaluator:
    quad_pattern and evaluate by default (pn_tessellate passes the PN ones); patch ids are
    ``patch_base + p``.
    """
    pattern, evaluator = pattern or quad_pattern, evaluator or evaluate
    object_ids = np.zeros(len(patches), np.int32) if object_ids is None else object_ids
    out = {k: [] for k in ("positions", "normals", "uv", "patch_ids", "object_ids", "triangles")}
    first = 0
    for p, f in enumerate(factors):
        uv, tris = pattern(f)
        if not len(uv):
            continue
        pos, nrm = evaluator(patches[p], uv[:, 0], uv[:, 1])
        out["positions"].append(pos)
        out["normals"].append(nrm)
        out["uv"].append(uv)
        out["patch_ids"].append(np.full(len(uv), patch_base + p))
        out["object_ids"].append(np.full(len(uv), object_ids[p]))
        out["triangles"].append(tris + first)
        first += len(uv)
    shapes = {"positions": (0, 3), "normals": (0, 3), "uv": (0, 2), "patch_ids": (0,),
              "object_ids": (0,), "triangles": (0, 3)}
    return {k: np.concatenate(v) if v else np.zeros(shapes[k]) for k, v in out.items()}


def boundary_point(curve: np.ndarray, k: int, f: int) -> np.ndarray:
    """Point k of f+1 on a rational cubic boundary curve (4, 4), placed symmetrically.

    The kernel evaluates from the nearer end so both patches sharing the curve, walking it in
    opposite directions, do the same arithmetic (Mesa's tessellator places points likewise).
    """
    if k == 0:  # the corner, exactly (the kernel returns the control point itself)
        return curve[0, :3] / curve[0, 3]
    b = curve if 2 * k <= f else curve[::-1]
    t = min(k, f - k) / f
    c = bernstein3(np.array(t)) @ b
    return c[:3] / c[3]


# --- PN triangles (DESIGN.md section 3; CudaTess section 4) ------------------------------------
#
# Input per triangle (T, 12, 4), as uploaded by the pipeline: [0..2] positions P1 P2 P3, [3..5]
# vertex normals N1 N2 N3, [6 + 2e], [7 + 2e] the normals edge e's boundary curve uses at its
# start (corner e) and end (corner e+1).  Control points (T, 16, 4), the layout of
# kernels/cltess.h: the ten b_ijk in CUBIC order (w = 1), the six n_ijk in QUADRATIC order (w = 0).
# Domain: barycentric (u, v, w = 1-u-v) of P1, P2, P3; edge e runs from corner e to corner e+1.

CUBIC = ((3, 0, 0), (0, 3, 0), (0, 0, 3), (2, 1, 0), (1, 2, 0), (0, 2, 1), (0, 1, 2), (1, 0, 2),
         (2, 0, 1), (1, 1, 1))
QUADRATIC = ((2, 0, 0), (0, 2, 0), (0, 0, 2), (1, 1, 0), (0, 1, 1), (1, 0, 1))
_CUBIC_AT = {ijk: k for k, ijk in enumerate(CUBIC)}
#: d_e, the domain direction of edge e in barycentric coordinates: corner e to corner e+1.
EDGE_DIRECTIONS = np.array([[-1, 1, 0], [0, -1, 1], [1, 0, -1]])


def pn_edge_control(p_near: np.ndarray, p_far: np.ndarray, n_near: np.ndarray) -> np.ndarray:
    """(2 p_near + p_far - ((p_far - p_near) . n_near) n_near) / 3: a boundary curve's inner
    control point next to p_near (n_near = 0: the straight edge's)."""
    w = ((p_far - p_near) * n_near).sum(-1, keepdims=True)
    return (2 * p_near + p_far - w * n_near) / 3


def _unit_or_zero(a: np.ndarray) -> np.ndarray:
    length = np.linalg.norm(a, axis=-1, keepdims=True)
    return np.where(length > 0, a / np.where(length > 0, length, 1), 0.0)


def pn_control_points(triangles: np.ndarray) -> np.ndarray:
    """Control points and normal field (T, 16, 4) from the triangle input (T, 12, 4), Vlachos et al.

    b300 = P1 ...; the inner control points of edge e from its end normals (input [6 + 2e],
    [7 + 2e]); b111 = E + (E - V) / 2 with E the mean of the six, V of the corners; n200 = N1 ...,
    n110 = normalize(N1 + N2 - v12 (P2 - P1)), v12 = 2 (P2 - P1).(N1 + N2) / |P2 - P1|^2 (0 when
    P1 = P2).  Mirror of kernels/cltess.h pn_control_points.
    """
    triangles = np.asarray(triangles, float)
    P, N, E = triangles[:, 0:3, :3], triangles[:, 3:6, :3], triangles[:, 6:12, :3]
    out = np.zeros((len(triangles), 16, 4))
    out[:, :10, 3] = 1.0
    out[:, 0:3, :3] = P
    for e in range(3):
        p, q = P[:, e], P[:, (e + 1) % 3]
        out[:, 3 + 2 * e, :3] = pn_edge_control(p, q, E[:, 2 * e])
        out[:, 4 + 2 * e, :3] = pn_edge_control(q, p, E[:, 2 * e + 1])
        d = q - p
        length2 = (d * d).sum(-1, keepdims=True)
        v = np.where(length2 > 0, 2 * (d * (N[:, e] + N[:, (e + 1) % 3])).sum(-1, keepdims=True)
                     / np.where(length2 > 0, length2, 1), 0.0)
        out[:, 13 + e, :3] = _unit_or_zero(N[:, e] + N[:, (e + 1) % 3] - v * d)
    mean_edge = out[:, 3:9, :3].mean(axis=1)
    centre = P.mean(axis=1)
    out[:, 9, :3] = mean_edge + (mean_edge - centre) / 2
    out[:, 10:13, :3] = N
    return out


def pn_second_derivative_bounds(controls: np.ndarray) -> np.ndarray:
    """(T, 3, 3) bounds D[a, b] >= sup |D_{d_a} D_{d_b} b| over the triangle: 6 times the largest
    norm of the three control points of (Delta_a Delta_b b), Delta_e b_I = b_{I+e_{e+1}} - b_{I+e_e}
    (DESIGN.md section 3)."""
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


def pn_folded(controls: np.ndarray) -> np.ndarray:
    """(T,) bool: two corners at exactly one point.  Such a triangle is a zero-area fold whose
    other two edges coincide; pn_factors gives it factor 0 (no output) and its neighbours meet
    directly (adjacency.mesh_edge_groups leaves its edges out)."""
    p = np.asarray(controls)[:, :3, :3]
    return np.any([(p[:, a] == p[:, (a + 1) % 3]).all(axis=1) for a in range(3)], axis=0)


def tri_pattern(f) -> tuple[np.ndarray, np.ndarray]:
    """The tessellation pattern of a triangle patch with edge factors f (CudaTess Fig. 5).

    Core factor ``N = max(f0, f1, f2)``.  Vertex layout, boundary first: the ring of
    ``R = f0+f1+f2`` points counter-clockwise from P1 (edge e, point k at ``t = k / f_e``), then
    the factor-N grid's interior points ``(i / N, j / N)``, rows ``j = 1..N-2``, ``i = 1..N-1-j``
    (u, v: the barycentric coordinates of P1, P2).

    Triangles: the regular factor-N grid, less the band along each edge whose factor is below N
    (a transition edge: at most two); each band is stitched Bresenham-style between the edge's
    f_e segments and the grid row one step inside it, whose point m stands at (m + 1/2) / N
    along the edge, advancing the side whose next segment midpoint comes first.  Where two
    transition bands meet, each row stops at the crossing point of the two rows.  Every triangle
    keeps the Filip bound: in coordinates along two edge directions scaled by their factors, its
    smallest enclosing circle has radius^2 <= 1/2, as the core's grid triangles do (tests).

    Returns (uv (V, 2) float64, triangles (T, 3) int64 local, counter-clockwise in uv).  Culled
    (factor 0) triangles have none.  Factors (1, 1, 1) give the one triangle (0, 1, 2).
    """
    f = [int(x) for x in f[:3]]
    if min(f) <= 0:
        return np.zeros((0, 2)), np.zeros((0, 3), np.int64)
    n = max(f)
    ring_size = sum(f)
    base = [0, f[0], f[0] + f[1]]
    t = [int(fe < n) for fe in f]

    def ring(e, k):
        return (base[e] + k) % ring_size

    def grid(i, j):
        k = n - i - j
        if i == n:
            return 0
        if j == n:
            return base[1]
        if k == n:
            return base[2]
        if k == 0:
            return ring(0, j)
        if i == 0:
            return ring(1, k)
        if j == 0:
            return ring(2, i)
        return ring_size + (j - 1) * (2 * n - 2 - j) // 2 + (i - 1)

    def row(e, m):
        c = [0, 0, 0]
        c[e], c[(e + 1) % 3], c[(e + 2) % 3] = n - 1 - m, m, 1
        return grid(c[0], c[1])

    uv = []
    for e in range(3):
        for k in range(f[e]):
            s, r = k / f[e], (f[e] - k) / f[e]
            uv.append([(r, s), (0.0, r), (s, 0.0)][e])
    uv += [(i / n, j / n) for j in range(1, n - 1) for i in range(1, n - j)]

    tris = []
    m = n - sum(t)
    for j in range(m):
        for i in range(m - j):
            a, b = t[1] + i, t[2] + j
            tris.append((grid(a + 1, b), grid(a, b + 1), grid(a, b)))
            if i + j < m - 1:
                tris.append((grid(a + 1, b), grid(a + 1, b + 1), grid(a, b + 1)))
    for e in range(3):
        if not t[e]:
            continue
        fe, o = f[e], 0
        k, k_end = t[(e + 2) % 3], n - 1 - t[(e + 1) % 3]
        while o < fe or k < k_end:
            if k == k_end or (o < fe and (2 * o + 1) * n <= 2 * (k + 1) * fe):
                tris.append((ring(e, o), ring(e, o + 1), row(e, k)))
                o += 1
            else:
                tris.append((ring(e, o), row(e, k + 1), row(e, k)))
                k += 1
    return np.array(uv, float).reshape(-1, 2), np.array(tris, np.int64).reshape(-1, 3)


def _pn_basis(u: np.ndarray, v: np.ndarray):
    """(N, 10) cubic and (N, 6) quadratic Bernstein-triangle bases at (u, v, 1-u-v)."""
    w = 1 - u - v
    cubic = np.stack([math.factorial(3) / (math.factorial(i) * math.factorial(j) * math.factorial(k))
                      * u ** i * v ** j * w ** k for i, j, k in CUBIC], axis=-1)
    quadratic = np.stack([2 / (math.factorial(i) * math.factorial(j) * math.factorial(k))
                          * u ** i * v ** j * w ** k for i, j, k in QUADRATIC], axis=-1)
    return cubic, quadratic


def pn_evaluate(controls: np.ndarray, u, v) -> tuple[np.ndarray, np.ndarray]:
    """Positions and unit normals (N, 3) of one PN triangle (16, 4) at barycentric (u, v) (N,).

    The normal is the normalised quadratic normal field; where it vanishes, the flat triangle's
    normal (else +z)."""
    u, v = np.atleast_1d(np.asarray(u, float)), np.atleast_1d(np.asarray(v, float))
    controls = np.asarray(controls, float)
    cubic, quadratic = _pn_basis(u, v)
    position = cubic @ controls[:10, :3]
    normal = quadratic @ controls[10:16, :3]
    face = _unit_or_zero(np.cross(controls[1, :3] - controls[0, :3], controls[2, :3] - controls[0, :3]))
    fallback = face if (face != 0).any() else np.array([0.0, 0.0, 1.0])
    ok = (normal * normal).sum(1) > PN_NORMAL_VANISHES ** 2
    return position, np.where(ok[:, None], _unit_or_zero(normal), fallback)


def pn_surface_points(controls: np.ndarray, patch_ids: np.ndarray, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Positions (N, 3) of many PN triangles: sample n is triangle ``patch_ids[n]`` at (u[n], v[n])."""
    cubic, _ = _pn_basis(np.asarray(u, float), np.asarray(v, float))
    return np.einsum("nk,nkc->nc", cubic, np.asarray(controls, float)[patch_ids, :10, :3])


def pn_tessellate(controls: np.ndarray, factors: np.ndarray, object_ids: np.ndarray | None = None,
                  patch_base: int = 0) -> dict:
    """tessellate for PN triangles: tri_pattern, pn_evaluate (ring points as boundary_point
    places them, evaluated directly).  Patch ids are ``patch_base + t``."""
    return tessellate(controls, factors, object_ids, tri_pattern, pn_evaluate, patch_base)


__all__ = ["patch_tolerances", "box_tolerances", "zs_factors", "zs_steps", "crack_free_factors", "quad_pattern",
           "counts", "offsets", "evaluate", "surface_points", "tessellate", "boundary_point", "boundary_curves",
           "pn_control_points", "pn_edge_control", "pn_second_derivative_bounds", "pn_inverse_steps",
           "pn_tolerances", "pn_factors", "pn_folded", "tri_pattern", "pn_evaluate", "pn_surface_points", "pn_tessellate"]
