"""PN triangles (Vlachos et al. 2001), evaluated in NumPy float64: the reference of
kernels/kinds/pn.h (docs/design.md section 3; CudaTess section 4).

Input per triangle (T, 12, 4), as cltess.kinds.pn uploads it: [0..2] positions P1 P2 P3, [3..5]
vertex normals N1 N2 N3, [6 + 2e], [7 + 2e] the normals edge e's boundary curve uses at its
start (corner e) and end (corner e+1).  Control points (T, 16, 4), the layout of
kernels/kinds/pn.h: the ten b_ijk in CUBIC order (w = 1), the six n_ijk in QUADRATIC order
(w = 0).  Domain: barycentric (u, v, w = 1-u-v) of P1, P2, P3; edge e runs from corner e to
corner e+1.
"""
from __future__ import annotations

import math

import numpy as np


CUBIC = ((3, 0, 0), (0, 3, 0), (0, 0, 3), (2, 1, 0), (1, 2, 0), (0, 2, 1), (0, 1, 2), (1, 0, 2),
         (2, 0, 1), (1, 1, 1))


QUADRATIC = ((2, 0, 0), (0, 2, 0), (0, 0, 2), (1, 1, 0), (0, 1, 1), (1, 0, 1))


_CUBIC_AT = {ijk: k for k, ijk in enumerate(CUBIC)}


#: d_e, the domain direction of edge e in barycentric coordinates: corner e to corner e+1.
EDGE_DIRECTIONS = np.array([[-1, 1, 0], [0, -1, 1], [1, 0, -1]])


PN_NORMAL_VANISHES = 1.0e-5  # a PN normal field shorter than this has no direction


def pn_edge_control(p_near: np.ndarray, p_far: np.ndarray, n_near: np.ndarray) -> np.ndarray:
    """(2 p_near + p_far - ((p_far - p_near) . n_near) n_near) / 3: a boundary curve's inner
    control point next to p_near (n_near = 0: the straight edge's)."""
    w = ((p_far - p_near) * n_near).sum(-1, keepdims=True)
    return (2 * p_near + p_far - w * n_near) / 3


def pn_end_control(p_near: np.ndarray, p_far: np.ndarray, n_near: np.ndarray) -> np.ndarray:
    """An edge end's inner control point from its input row (x, y, z, w): PN's
    (``pn_edge_control``) for w = 0, at a crease end (w != 0, t = n_near.xyz) p_near + ((p_far -
    p_near) . t) / 3 t (kernels/kinds/pn.h pn_end_control)."""
    t = n_near[..., :3]
    crease = p_near + ((p_far - p_near) * t).sum(-1, keepdims=True) / 3 * t
    return np.where(n_near[..., 3:] != 0, crease, pn_edge_control(p_near, p_far, t))


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
    P, N = triangles[:, 0:3, :3], triangles[:, 3:6, :3]
    out = np.zeros((len(triangles), 16, 4))
    out[:, :10, 3] = 1.0
    out[:, 0:3, :3] = P
    for e in range(3):
        p, q = P[:, e], P[:, (e + 1) % 3]
        out[:, 3 + 2 * e, :3] = pn_end_control(p, q, triangles[:, 6 + 2 * e])
        out[:, 4 + 2 * e, :3] = pn_end_control(q, p, triangles[:, 7 + 2 * e])
        d = q - p
        length2 = (d * d).sum(-1, keepdims=True)
        v = np.where(length2 > 0, 2 * (d * (N[:, e] + N[:, (e + 1) % 3])).sum(-1, keepdims=True)
                     / np.where(length2 > 0, length2, 1), 0.0)
        out[:, 13 + e, :3] = _unit_or_zero(N[:, e] + N[:, (e + 1) % 3] - v * d)
    mean_edge = out[:, 3:9, :3].mean(axis=1)
    centre = P.mean(axis=1)
    average = triangles[:, 3, 3:] != 0  # eq. 5 of Dyken et al. 2008 (kinds/pn.py PN_AVERAGE_CENTRE)
    out[:, 9, :3] = np.where(average, mean_edge, mean_edge + (mean_edge - centre) / 2)
    out[:, 10:13, :3] = N
    return out


def pn_folded(controls: np.ndarray) -> np.ndarray:
    """(T,) bool: two corners at exactly one point.  Such a triangle is a zero-area fold whose
    other two edges coincide; pn_factors gives it factor 0 (no output) and its neighbours meet
    directly (adjacency.mesh_edge_groups leaves its edges out)."""
    p = np.asarray(controls)[:, :3, :3]
    return np.any([(p[:, a] == p[:, (a + 1) % 3]).all(axis=1) for a in range(3)], axis=0)


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


#: The surface interface every kind's module offers (cltess.kinds.base.PatchKind.surface).
evaluate = pn_evaluate
surface_points = pn_surface_points
