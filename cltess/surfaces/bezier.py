"""Rational bicubic Bézier patches, evaluated in NumPy float64: the reference of
kernels/kinds/bezier.h (docs/design.md section 2).

Conventions (see ``cltess/scene.py``): ``patches[p, j, i] = (w*x, w*y, w*z, w)``, edges
numbered counter-clockwise 0: v=0, 1: u=1, 2: v=1, 3: u=0.
"""
from __future__ import annotations

import numpy as np


def bernstein3(t: np.ndarray) -> np.ndarray:
    """(..., 4) cubic Bernstein basis."""
    s = 1 - t
    return np.stack([s ** 3, 3 * t * s * s, 3 * t * t * s, t ** 3], axis=-1)


def bernstein3_derivative(t: np.ndarray) -> np.ndarray:
    """(..., 4) derivatives of the cubic Bernstein basis."""
    s = 1 - t
    return np.stack([-3 * s * s, 3 * s * s - 6 * t * s, 6 * t * s - 3 * t * t, 3 * t * t], axis=-1)


def bernstein2(t: np.ndarray) -> np.ndarray:
    """(..., 3) quadratic Bernstein basis."""
    s = 1 - t
    return np.stack([s * s, 2 * t * s, t * t], axis=-1)


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
    normal = tangent_cross(b, b_u, b_v)
    bad = ~normal_ok(normal, b, b_u, b_v)
    if bad.any():
        limit = limit_normal(patch, u[bad], v[bad], b[bad], b_u[bad], b_v[bad])
        stronger = (limit * limit).sum(1) > (normal[bad] * normal[bad]).sum(1)
        us, vs = u[bad] + NORMAL_SHIFT * (0.5 - u[bad]), v[bad] + NORMAL_SHIFT * (0.5 - v[bad])
        inside = tangent_cross(*homogeneous_and_derivatives(patch, us, vs))
        normal[bad] = np.where(stronger[:, None], limit, inside)
    length = np.linalg.norm(normal, axis=1, keepdims=True)
    return position, np.where(length > 0, normal / np.where(length > 0, length, 1), [0.0, 0.0, 1.0])


def limit_normal(patch, u, v, b, b_u, b_v) -> np.ndarray:
    """D_d(T_u x T_v) = D_d T_u x T_v + T_u x D_d T_v, d = (1/2 - u, 1/2 - v), at (u, v) (N,).

    With D_d p = (d_u T_u + d_v T_v) / B.w.  Where T_u x T_v vanishes on a collapsed edge this is
    the direction the normal tends to (docs/design.md section 2, "the next-order term").
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


def surface_points(patches: np.ndarray, patch_ids: np.ndarray, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Positions (N, 3) of many patches at once: sample n is patch ``patch_ids[n]`` at (u[n], v[n])."""
    # The tensor-product weights B_j(v) B_i(u) first, then one product per sample: the same sums
    # in the same order as einsum("nj,ni,njic->nc"), which loops over all three at once, 2x slower.
    weights = (bernstein3(np.asarray(v, float))[:, :, None] * bernstein3(np.asarray(u, float))[:, None, :])
    b = np.einsum("nk,nkc->nc", weights.reshape(-1, 16), patches.reshape(len(patches), 16, 4)[patch_ids])
    return b[:, :3] / b[:, 3:]


NORMAL_SHIFT = 1.0e-3  # the last resort: how far towards the domain centre a normal is re-evaluated


NORMAL_DEGENERATE = 1.0e-3  # |T_u x T_v| below this times |T_u|^2 + |T_v|^2: use limit_normal


def tangent_cross(b, b_u, b_v):
    """Unnormalised T_u x T_v (N, 3) from B, B_u, B_v (N, 4) (kernels/kinds/bezier.h tangent_cross)."""
    p = b[:, :3] / b[:, 3:]
    t_u = b_u[:, :3] - b_u[:, 3:] * p
    t_v = b_v[:, :3] - b_v[:, 3:] * p
    return np.cross(t_u, t_v)


def normal_ok(normal, b, b_u, b_v):
    """Where T_u x T_v is not (nearly) vanishing: |n|^2 > NORMAL_DEGENERATE^2 (|T_u|^2 + |T_v|^2)^2."""
    p = b[:, :3] / b[:, 3:]
    t_u = b_u[:, :3] - b_u[:, 3:] * p
    t_v = b_v[:, :3] - b_v[:, 3:] * p
    scale = (t_u * t_u).sum(1) + (t_v * t_v).sum(1)
    return (normal * normal).sum(1) > NORMAL_DEGENERATE ** 2 * scale * scale


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
