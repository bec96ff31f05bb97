"""The per-patch power-basis matrix of ESC (Hu et al. 2014, eq. 8): ``NBM = N B N^T`` once per
patch, then ``Q(u, v) = U . NBM . V^T`` with ``U = (1, u, u^2, u^3)`` evaluated by Horner.
NumPy float64 mirror of kernels/kinds/bezier_nbm.h (docs/esc.md section 1).

Conventions as cltess/surfaces/bezier.py: ``patches[p, j, i]`` is the control point of row j
(v) and column i (u), homogeneous ``(w x, w y, w z, w)``.  ``NBM[a, b]`` multiplies ``u^a v^b``.
"""
from __future__ import annotations

import numpy as np

#: Cubic Bernstein -> power basis: B_i(t) = sum_a t^a N[a, i] (kernels/kinds/bezier_nbm.h NBM_N).
POWER_BASIS = np.array([[1, 0, 0, 0],
                        [-3, 3, 0, 0],
                        [3, -6, 3, 0],
                        [-1, 3, -3, 1]], np.float64)


def power_basis_matrix(patches: np.ndarray) -> np.ndarray:
    """(P, 4, 4, 4) NBM[p, a, b, c] = sum_{i,j} N[a, i] N[b, j] patches[p, j, i, c] (stage 1 of ESC)."""
    patches = np.asarray(patches, np.float64).reshape(-1, 4, 4, 4)
    return np.einsum("ai,bj,pjic->pabc", POWER_BASIS, POWER_BASIS, patches)


def horner(nbm: np.ndarray, u, v) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Homogeneous Q, Q_u, Q_v (each (N, 4)) of one (4, 4, 4) NBM at (u, v) (N,), by Horner in v
    for each power of u, then in u."""
    u, v = np.atleast_1d(np.asarray(u, float)), np.atleast_1d(np.asarray(v, float))
    rows = np.broadcast_to(nbm[:, 3], (len(v), 4, 4)).copy()
    rows_v = np.zeros_like(rows)
    for b in (2, 1, 0):  # r_a(v) = ((m_a3 v + m_a2) v + m_a1) v + m_a0 and its derivative
        rows_v = rows_v * v[:, None, None] + rows
        rows = rows * v[:, None, None] + nbm[:, b][None]
    q, q_u, q_v = rows[:, 3], np.zeros_like(rows[:, 3]), rows_v[:, 3]
    for a in (2, 1, 0):
        q_u = q_u * u[:, None] + q
        q = q * u[:, None] + rows[:, a]
        q_v = q_v * u[:, None] + rows_v[:, a]
    return q, q_u, q_v


def evaluate_nbm(nbm: np.ndarray, u, v) -> tuple[np.ndarray, np.ndarray]:
    """Positions and unit normals (N, 3) of a rational patch from its NBM (no degenerate-normal
    fall-back: cltess.surfaces.bezier.evaluate has it)."""
    q, q_u, q_v = horner(nbm, u, v)
    position = q[:, :3] / q[:, 3:]
    t_u = q_u[:, :3] - q_u[:, 3:] * position
    t_v = q_v[:, :3] - q_v[:, 3:] * position
    normal = np.cross(t_u, t_v)
    length = np.linalg.norm(normal, axis=1, keepdims=True)
    return position, np.where(length > 0, normal / np.where(length > 0, length, 1), [0.0, 0.0, 1.0])
