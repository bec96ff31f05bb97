"""The error-hull bound (issue 9; docs/rational-bound.md, "The error-hull bound"): a per-triangle
bound of a rational bicubic patch's interpolation error from the Bernstein net of the error itself.
NumPy float64 mirror of ``kernels/criteria/error_hull.h`` and the host half of
``Request(bound="error-hull")`` (``centred_nets``).

For a triangle with corners x_i in (u, v), P_i = p(x_i) and l their affine interpolant, on a box
B of the domain p - l = (X - w l) / w, with X the weighted numerator and w the weight.  X and w
restricted to B are (3, 3) Bernstein nets; l is affine, so bilinear on B with its corner values
as (1, 1) net; X - w l and w elevated are (4, 4) nets E, W with p - l = sum B_k W_k (E_k / W_k)
/ sum B_k W_k, a convex combination when every W_k > 0, so |p - l| <= max_k |E_k| / W_k on B.
The triangle's bounding box is the first box; a box over the tolerance is cut in four, down to
DEPTH halvings, keeping the quarters that meet the triangle.  Polynomial patches (w = 1) are the
special case W_k = 1.
"""
from __future__ import annotations

import numpy as np

#: Box halvings, at most: a triangle whose box at this depth is still over the tolerance fails.
DEPTH = 4
#: float32's unit roundoff, 2^-24.
UNIT = 2.0 ** -24
#: The float32 rounding of |E_k| (in units of W_k (radius + max |L|)), of W_k (relative units) and
#: of p(x_i) (units of radius): twice the counts of docs/rational-bound.md ("float32 rounding of
#: the error hull": 31, 28 and 49 units).
NET_STEPS = 64.0
WEIGHT_STEPS = 32.0
POINT_STEPS = 96.0
#: A box is dropped (does not meet the triangle) only when the box widened by this much in (u, v)
#: lies strictly outside an edge: more than the float32 rounding of the side tests (4 units).
MEET_WIDENING = 1e-6
#: A triangle whose determinant's float32 rounding bound (8 units of |e1u e2v| + |e1v e2u|) is not
#: below this fraction of |det| fails (INFINITY): the first-order rounding analysis needs it small.
CONDITION = 1e-2
#: Trial scales of today's factors for the trial loop (cltess/backends/opencl/error_hull.py), in the
#: order a patch tries them: from a factor of 1 for most patches (0.01) up to today's (1.0).
TRIAL_SCALES = (0.01, 0.03, 0.06, 0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.42, 0.5, 0.6, 0.7, 0.78, 0.85, 0.92, 0.96, 1.0)


def centred_nets(patches: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """((P, 16, 4) float32 homogeneous control points [4 j + i, (X, w)] (j along v), centred on
    each patch's control-point box (X - w c: p - l is translation-invariant), (P,) float32
    radii max_k |X_k| / w_k of the float32 points, rounded up).  Weights must be > 0."""
    patches = np.asarray(patches, float).reshape(-1, 16, 4)
    w = patches[..., 3:]
    if not (w > 0).all():
        raise ValueError("the error-hull bound needs positive weights")
    points = patches[..., :3] / w
    centre = (points.min(axis=1) + points.max(axis=1)) / 2
    nets = np.concatenate([patches[..., :3] - w * centre[:, None], w], axis=-1).astype(np.float32)
    radii = (np.linalg.norm(nets[..., :3].astype(float), axis=-1) / nets[..., 3].astype(float)).max(axis=1)
    radii = (radii * (1 + 1e-6)).astype(np.float32)
    low = radii.astype(float) < radii * (1 + 1e-6)
    radii[low] = np.nextafter(radii[low], np.float32(np.inf))
    return nets, radii


def basis(t: float) -> np.ndarray:
    """(4,) the cubic Bernstein basis at t."""
    s = 1.0 - t
    return np.array([s ** 3, 3 * s * s * t, 3 * s * t * t, t ** 3])


def restriction(a: float, b: float) -> np.ndarray:
    """(4, 4) M with M @ c the Bernstein coefficients on [a, b] of the cubic with coefficients c
    on [0, 1]: row k the coefficients of (1 - a + a z)^(3 - k) (1 - b + b z)^k."""
    rows = []
    for k in range(4):
        row = np.array([1.0])
        for t in [a] * (3 - k) + [b] * k:
            row = np.convolve(row, [1 - t, t])
        rows.append(row)
    return np.array(rows)


def point(net: np.ndarray, x) -> np.ndarray:
    """p(x) (3,) from a (16, 4) homogeneous net."""
    h = np.einsum("j,i,jic->c", basis(x[1]), basis(x[0]), net.reshape(4, 4, 4))
    return h[:3] / h[3]


def meets(lo, hi, corners: np.ndarray) -> bool:
    """Whether the box [lo, hi] widened by MEET_WIDENING meets the triangle (separating edges)."""
    lo, hi = np.asarray(lo) - MEET_WIDENING, np.asarray(hi) + MEET_WIDENING
    box = np.array([[lo[0], lo[1]], [hi[0], lo[1]], [lo[0], hi[1]], [hi[0], hi[1]]])
    for k in range(3):
        a, b, c = corners[k], corners[(k + 1) % 3], corners[(k + 2) % 3]
        n = np.array([a[1] - b[1], b[0] - a[0]])
        inside, side = n @ (c - a), (box - a) @ n
        if (inside > 0 and (side < 0).all()) or (inside < 0 and (side > 0).all()):
            return False
    return True


def affine(y, corners: np.ndarray, values: np.ndarray) -> tuple[np.ndarray, float]:
    """(l(y), the kernel's rounding allowance of its float32 value: error_hull_affine)."""
    e1, e2, r = corners[1] - corners[0], corners[2] - corners[0], np.asarray(y) - corners[0]
    det = e1[0] * e2[1] - e1[1] * e2[0]
    det_abs = abs(e1[0] * e2[1]) + abs(e1[1] * e2[0])
    lam1, lam2 = (r[0] * e2[1] - r[1] * e2[0]) / det, (e1[0] * r[1] - e1[1] * r[0]) / det
    n1_abs, n2_abs = abs(r[0] * e2[1]) + abs(r[1] * e2[0]), abs(e1[0] * r[1]) + abs(e1[1] * r[0])
    delta1 = 2 * (4 * UNIT * (n1_abs + abs(lam1) * det_abs) / abs(det) + UNIT * abs(lam1))
    delta2 = 2 * (4 * UNIT * (n2_abs + abs(lam2) * det_abs) / abs(det) + UNIT * abs(lam2))
    d1, d2 = values[1] - values[0], values[2] - values[0]
    size1, size2 = np.linalg.norm(d1), np.linalg.norm(d2)
    slack = 2 * (delta1 * size1 + delta2 * size2
                 + 6 * UNIT * (np.linalg.norm(values[0]) + abs(lam1) * size1 + abs(lam2) * size2))
    return values[0] + lam1 * d1 + lam2 * d2, slack


def elevated(net: np.ndarray) -> np.ndarray:
    """(5, 5, ...) the (4, 4) net of a (4, 4, ...) one (degree elevation in both directions)."""
    def once(a, axis):
        a = np.moveaxis(a, axis, 0)
        out = np.zeros((5,) + a.shape[1:])
        for b in range(5):
            if b < 4:
                out[b] += (4 - b) / 4 * a[b]
            if b > 0:
                out[b] += b / 4 * a[b - 1]
        return np.moveaxis(out, 0, axis)
    return once(once(net, 0), 1)


def box_bound(net: np.ndarray, radius: float, lo, hi, corners: np.ndarray, values: np.ndarray) -> float:
    """max_k |E_k| / W_k on the box [lo, hi] plus the kernel's rounding allowances (error_hull_box)."""
    restricted = np.einsum("bj,ai,jic->bac", restriction(lo[1], hi[1]), restriction(lo[0], hi[0]),
                           net.reshape(4, 4, 4).astype(float))
    at = [affine(y, corners, values) for y in ((lo[0], lo[1]), (hi[0], lo[1]), (lo[0], hi[1]), (hi[0], hi[1]))]
    linear = np.array([a[0] for a in at]).reshape(2, 2, 3)  # [d, c]
    # the (4, 4) net of w l: sum over j + d = b, i + c = a of alpha alpha w_ji L_dc
    wl = np.zeros((5, 5, 3))
    for d in range(2):
        for c in range(2):
            part = np.zeros((5, 5, 3))
            part[d:d + 4, c:c + 4] = restricted[..., 3:] * linear[d, c]
            weights = np.outer([_alpha(b, d) for b in range(5)], [_alpha(a, c) for a in range(5)])
            wl += weights[..., None] * part
    error = elevated(restricted[..., :3]) - wl
    weights = elevated(restricted[..., 3])
    if not (weights > 0).all():
        return np.inf
    worst = (np.linalg.norm(error, axis=-1) / weights).max() * (1 + WEIGHT_STEPS * UNIT)
    corner_max = max(np.linalg.norm(a[0]) for a in at)
    return float(worst * (1 + 4 * UNIT) + NET_STEPS * UNIT * (radius + corner_max) + max(a[1] for a in at))


def _alpha(b: int, d: int) -> float:
    """The weight of a cubic's (b - d)-th coefficient times a linear's d-th in the quartic's b-th."""
    if not 0 <= b - d <= 3:
        return 0.0
    return b / 4 if d else (4 - b) / 4


def triangle_ratio(net: np.ndarray, radius: float, corners: np.ndarray, tolerance: float) -> float:
    """bound / tolerance of one triangle (corners (3, 2) in (u, v)) of the patch with centred net
    (16, 4) and radius (centred_nets): the largest over the boxes kept when every one is within
    the tolerance, else the first box at depth DEPTH over it (> 1); inf for a triangle too thin
    (CONDITION).  The kernel's error_hull_ratio in float64, same boxes in the same order."""
    corners = np.asarray(corners, float)
    e1, e2 = corners[1] - corners[0], corners[2] - corners[0]
    det = e1[0] * e2[1] - e1[1] * e2[0]
    if not 8 * UNIT * (abs(e1[0] * e2[1]) + abs(e1[1] * e2[0])) < CONDITION * abs(det):
        return np.inf
    values = np.array([point(net, x) for x in corners])
    point_slack = POINT_STEPS * UNIT * radius
    stack = [(corners.min(axis=0), corners.max(axis=0), 0)]
    worst = 0.0
    while stack:
        lo, hi, level = stack.pop()
        ratio = (box_bound(net, radius, lo, hi, corners, values) + point_slack) / tolerance
        if ratio <= 1:
            worst = max(worst, ratio)
            continue
        if level == DEPTH:
            return ratio
        mid = (lo + hi) / 2
        quarters = [((lo[0], lo[1]), (mid[0], mid[1])), ((mid[0], lo[1]), (hi[0], mid[1])),
                    ((lo[0], mid[1]), (mid[0], hi[1])), ((mid[0], mid[1]), (hi[0], hi[1]))]
        stack += [(np.array(q_lo), np.array(q_hi), level + 1) for q_lo, q_hi in quarters if meets(q_lo, q_hi, corners)]
    return worst

