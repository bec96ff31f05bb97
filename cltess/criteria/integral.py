"""The integral form of the interpolation remainder as a per-triangle bound (issue 9:
docs/rational-bound.md, "The integral-form bound in the engine").  NumPy mirror of
``kernels/criteria/integral_bound.h`` and the host half of ``Request(bound="integral")``.

For a triangle T with corners x_i, barycentric coordinates l_i(x) and h_i = x_i - x,

    |p(x) - l(x)| <= sum_i l_i(x) int_0^1 (1 - t) |D^2 p(x + t h_i)[h_i, h_i]| dt,

and |D^2 p(xi)[h, h]| <= m_uu h_u^2 + 2 m_uv |h_u h_v| + m_vv h_v^2 with m_ab the hull bound
(Lemma 2) of the S x S subpatches meeting a box around xi, or by the square root of the
direction-aware quartic bound over those cells (``direction_form``; docs/rational-bound.md,
"The direction-aware form per cell"), whichever is smaller.  Upper sums over K^2 sub-triangles
and [0, 1] cut in T intervals turn it into a number per triangle; every step is an inequality.

The host part: ``subpatch_majorants`` (float64 de Casteljau subdivision of the (9, 9) nets by
subdivision matrices, then max_k |N_ab,k| / W_k per subpatch) and ``majorant_pyramid`` (max
pooled to every coarser level, rounded up to float32 with a safety factor); the device part,
mirrored here: ``pyramid_query`` (max over the cells a box meets) and ``triangle_bounds``.
"""
from __future__ import annotations

import math

import numpy as np

from .zheng_sederberg import CUBIC_DERIVATIVE, _bernstein_product

#: S = 2^SUBPATCH_LEVELS subpatches per side (64: docs/rational-bound.md, measured).
SUBPATCH_LEVELS = 6
#: Sub-triangles per side of the upper sums tried in turn (t intervals: T = 4 K / 3); a triangle
#: that passes Lemma 1 with its box's majorant skips them (kernels/criteria/integral_bound.h).
SUBDIVISIONS = (6, 12, 24)
#: The majorant table is float64 on the host, stored float32 rounded up and multiplied by this
#: (covers the float64 subdivision's rounding, relative ~1e-14, with room).
TABLE_SAFETY = 1.0 + 1e-6
#: The float32 kernel sums at most 3 * 24^2 * 32 non-negative terms of relative error a few
#: ulp each, and compares bound * BOUND_SAFETY with the tolerance (relative 1e-4 >> 1e-7 * 10).
BOUND_SAFETY = 1.0 + 1e-4
#: Boxes are widened by this (domain units, [0, 1]) before they are rounded to cells, so that a
#: float32 rounding of a corner cannot drop a subpatch the true box meets (ulp of 1.0: 1.2e-7).
BOX_WIDENING = 1e-6
#: A box query looks at no more than this many cells per side; a larger box is looked up on a
#: coarser level of the pyramid (each level halves).
QUERY_SPAN = 4
#: The graded table (issue 9, session 4): besides the uniform pyramid, every patch keeps a
#: tensor grid of cells that are the S x S subpatches in the middle and shrink geometrically
#: towards the four edges (so towards the corners too), where the weights put curvature spikes
#: that decay like 1/distance^2: each octave [2^-(k+1), 2^-k] of the distance to an edge, for
#: 2^-k from 4/S down to 2^-(SUBPATCH_LEVELS + GRADED_DEPTH), is cut into GRADED_OCTAVE_CELLS
#: cells, and the innermost [0, 2^-(SUBPATCH_LEVELS + GRADED_DEPTH)] too (finest cell 1/4096 at
#: the defaults).  Breakpoints are dyadic, exact in float32 (graded_breaks).
GRADED_DEPTH = 4
GRADED_OCTAVE_CELLS = 4
#: A box query reads the graded cells when the box meets fewer than this many per side, else
#: the pyramid (both are majorants; the graded cells nest in the finest pyramid level's).
GRADED_SPAN = 8
#: Floats per cell of a patch's table (a float8 on the device), FORM_COLUMNS: the norms m_uu,
#: m_uv, m_vv (Lemma 2 on the cell), then the range of the quartic |H_k[h, h]|^2's coefficients
#: that can be negative (cell_forms; the "-" ones are minus the minimum, so that every column
#: pools by max and is rounded up).
TABLE_WIDTH = 8
FORM_COLUMNS = ("m_uu", "m_uv", "m_vv", "e22 max", "e31 max", "-e31 min", "e13 max", "-e13 min")
#: The signed quartic coefficients are moved outwards by this times their size's bound before
#: they are rounded up to float32 (their float64 rounding, relative ~1e-15 of that size).
QUARTIC_PAD = 1e-12
#: The kernel's quartic Q(h) = sum of five coefficient x monomial sups (float32) is raised by
#: this times the sum of their absolute values before its square root (the float32 rounding of
#: products of at most five factors and a sum of five terms: about 10 units of 6e-8).
QUARTIC_SLACK = 1e-5
#: The trial scales of today's factors (stage 1's (m, n)), in the order a patch tries them
#: (factors only rise); the last one is today's bound itself (Lemmas 1/3: always certified).
#: (0.78, 0.92, 0.96 added to a first list of ten: on the random patches 4% fewer triangles at
#: eps = 1e-2 of the diagonal, 0.7% at 1e-3, one to three more rounds.)
TRIAL_SCALES = (0.2, 0.25, 0.3, 0.35, 0.42, 0.5, 0.6, 0.7, 0.78, 0.85, 0.92, 0.96, 1.0)


def numerator_nets(patch: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """((10, 10, 3, 3) N_ab nets [j, i, which (uu, uv, vv), xyz], (10, 10) net of w^3), plain
    Bernstein basis (docs/rational-bound.md, Lemma 2; zheng_sederberg.second_derivative_hull
    before its division).  X is centred first (the N_ab are translation-invariant)."""
    patch = np.asarray(patch, float)
    w = patch[..., 3:]
    points = patch[..., :3] / w
    centre = (points.min(axis=(0, 1)) + points.max(axis=(0, 1))) / 2
    h = np.concatenate([patch[..., :3] - w * centre, w], axis=-1)
    d_u = lambda a: np.einsum("ki,jic->jkc", CUBIC_DERIVATIVE, a)  # noqa: E731
    d_v = lambda a: np.einsum("kj,jic->kic", CUBIC_DERIVATIVE, a)  # noqa: E731
    h_u, h_v = d_u(h), d_v(h)

    def wedge(a, b):  # w_a X_b - w_b X_a, degree (6, 6)
        return _bernstein_product(a[..., 3:], b[..., :3]) - _bernstein_product(b[..., 3:], a[..., :3])

    def scaled(a, b):
        return _bernstein_product(a[..., 3:], b)

    b_u, b_v = wedge(h, h_u), wedge(h, h_v)
    numerators = (scaled(h, wedge(h, d_u(h_u))) - 2 * scaled(h_u, b_u),
                  scaled(h, wedge(h, d_v(h_u))) - scaled(h_u, b_v) - scaled(h_v, b_u),
                  scaled(h, wedge(h, d_v(h_v))) - 2 * scaled(h_v, b_v))
    return np.stack(numerators, axis=2), scaled(h, scaled(h, h[..., 3:]))[..., 0]


def subdivision_matrices(pieces: int, degree: int = 9) -> np.ndarray:
    """(pieces, degree + 1, degree + 1): M[s] maps a degree-``degree`` Bernstein net on [0, 1]
    to the net of its restriction to [s / pieces, (s + 1) / pieces] (de Casteljau: right part
    at a, then left part at (b - a) / (1 - a); float64)."""
    return interval_matrices(np.arange(pieces + 1) / pieces, degree)


def interval_matrices(breaks: np.ndarray, degree: int = 9) -> np.ndarray:
    """(len(breaks) - 1, degree + 1, degree + 1): M[s] maps a Bernstein net on [0, 1] to the net
    of its restriction to [breaks[s], breaks[s + 1]] (as subdivision_matrices)."""
    breaks = np.asarray(breaks, float)
    out = np.empty((len(breaks) - 1, degree + 1, degree + 1))
    for s in range(len(breaks) - 1):
        a, b = breaks[s], breaks[s + 1]
        c = np.eye(degree + 1)  # columns: the unit nets
        if a > 0:  # right part at a: points c^(degree - r)_r
            rows, level = [c[-1]], c
            for _ in range(degree):
                level = (1 - a) * level[:-1] + a * level[1:]
                rows.append(level[-1])
            c = np.array(rows[::-1])
        t = (b - a) / (1 - a)
        if t < 1:
            rows, level = [c[0]], c
            for _ in range(degree):
                level = (1 - t) * level[:-1] + t * level[1:]
                rows.append(level[0])
            c = np.array(rows)
        out[s] = c
    return out


def subpatch_majorants(patch: np.ndarray, levels: int = SUBPATCH_LEVELS) -> np.ndarray:
    """(S, S, 3) float64 [v piece, u piece, (uu, uv, vv)], S = 2^levels: max_k |N_ab,k| / W_k of
    each subpatch's nets (Lemma 2 on the subpatch: |p_ab| <= that on it)."""
    return cell_majorants(patch, np.arange((1 << levels) + 1) / (1 << levels))


def graded_breaks(levels: int = SUBPATCH_LEVELS) -> np.ndarray:
    """(G + 1,) float64 breakpoints of the graded cells along u (and v): uniform 2^-levels in
    [4 / S, 1 - 4 / S], octaves of GRADED_OCTAVE_CELLS cells towards 0 and 1 (GRADED_DEPTH)."""
    finest = levels + GRADED_DEPTH
    q = GRADED_OCTAVE_CELLS
    near = {j * 2.0 ** -finest / q for j in range(q + 1)}
    for k in range(finest, levels - 2, -1):  # octave [2^-k, 2^-(k-1)]
        near |= {2.0 ** -k * (1 + j / q) for j in range(q + 1)}
    step = 2.0 ** -levels
    middle = {i * step for i in range(4, (1 << levels) - 3)}
    left = near | middle
    return np.array(sorted(left | {1.0 - x for x in left}))


def graded_count(levels: int = SUBPATCH_LEVELS) -> int:
    """G: graded cells per side."""
    return len(graded_breaks(levels)) - 1


def table_cells(levels: int = SUBPATCH_LEVELS) -> int:
    """float4 rows of one patch's table: its pyramid, then its G x G graded cells."""
    return pyramid_cells(levels) + graded_count(levels) ** 2


def cell_majorants(patch: np.ndarray, breaks: np.ndarray) -> np.ndarray:
    """(G, G, 3) float64 [v cell, u cell, (uu, uv, vv)] of the tensor cells [breaks[i], breaks[i + 1]]
    x [breaks[j], breaks[j + 1]]: max_k |N_ab,k| / W_k of each cell's nets (Lemma 2 on the cell)."""
    return cell_forms(patch, breaks)[..., :3]


def quartic_coefficients(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """(..., 5) float64 coefficients of |H[h, h]|^2 = |a h_u^2 + 2 b h_u h_v + c h_v^2|^2 in the
    monomials h_u^4, h_u^3 h_v, h_u^2 h_v^2, h_u h_v^3, h_v^4 (a, b, c: (..., 3) vectors)."""
    dot = lambda x, y: np.einsum("...c,...c->...", x, y)  # noqa: E731
    return np.stack([dot(a, a), 4 * dot(a, b), 2 * dot(a, c) + 4 * dot(b, b), 4 * dot(b, c), dot(c, c)], axis=-1)


def cell_forms(patch: np.ndarray, breaks: np.ndarray) -> np.ndarray:
    """(G, G, TABLE_WIDTH) float64 [v cell, u cell, FORM_COLUMNS] of the tensor cells [breaks[i],
    breaks[i + 1]] x [breaks[j], breaks[j + 1]]: from each cell's control points H_k = (a_k, b_k,
    c_k) = (N_uu,k, N_uv,k, N_vv,k) / W_k, the norms max_k |a_k|, |b_k|, |c_k| (Lemma 2 on the
    cell) and the range over k of the quartic's coefficients (quartic_coefficients) that can
    be negative: max of e_22, max and -min of e_31 and e_13 (docs/rational-bound.md, "The
    direction-aware form per cell").  The signed ones are moved outwards by QUARTIC_PAD of
    their size's bound (2 |a||c| + 4 |b|^2, 4 |a||b|, 4 |b||c|) for the float64 rounding."""
    numerators, cube = numerator_nets(patch)
    pieces = len(breaks) - 1
    nets = np.concatenate([numerators.reshape(10, 10, 9), cube[..., None]], axis=-1)  # [j, i, c]
    matrices = interval_matrices(breaks)
    along_u = np.einsum("sai,jic->sjac", matrices, nets)  # [u piece, j, i', c]
    # Component-major, [c, u piece, j, i'], so that after the v step a cell's 100 control points
    # are the last, contiguous axis: the dot products and maxima below then run 3x faster than
    # over [.., 3, 3] vectors (quartic_coefficients' layout; 0.3 s a patch instead of 0.9).
    components = np.ascontiguousarray(along_u.transpose(3, 0, 1, 2))
    out = np.empty((pieces, pieces, TABLE_WIDTH))
    for t in range(pieces):  # one v piece at a time: [c, u piece, j', i'] = M[t] along j
        sub = np.matmul(matrices[t], components).reshape(10, pieces, 100)
        weights = sub[9]
        if not (weights > 0).all():
            raise ValueError("w^3 has a non-positive coefficient on a subpatch: weights must be > 0")
        ax, ay, az, bx, by, bz, cx, cy, cz = sub[:9] / weights  # H_k = (a_k, b_k, c_k), [u piece, k]
        norm_a = np.sqrt(ax * ax + ay * ay + az * az)
        norm_b = np.sqrt(bx * bx + by * by + bz * bz)
        norm_c = np.sqrt(cx * cx + cy * cy + cz * cz)
        # quartic_coefficients' e_22, e_31, e_13
        e22 = 2 * (ax * cx + ay * cy + az * cz) + 4 * (bx * bx + by * by + bz * bz)
        e31 = 4 * (ax * bx + ay * by + az * bz)
        e13 = 4 * (bx * cx + by * cy + bz * cz)
        pad22 = QUARTIC_PAD * (2 * norm_a * norm_c + 4 * norm_b ** 2).max(axis=1)
        pad31 = QUARTIC_PAD * (4 * norm_a * norm_b).max(axis=1)
        pad13 = QUARTIC_PAD * (4 * norm_b * norm_c).max(axis=1)
        out[t, :, 0], out[t, :, 1], out[t, :, 2] = norm_a.max(axis=1), norm_b.max(axis=1), norm_c.max(axis=1)
        out[t, :, 3] = e22.max(axis=1) + pad22
        out[t, :, 4] = e31.max(axis=1) + pad31
        out[t, :, 5] = -e31.min(axis=1) + pad31
        out[t, :, 6] = e13.max(axis=1) + pad13
        out[t, :, 7] = -e13.min(axis=1) + pad13
    return out


def norm_forms(majorants: np.ndarray) -> np.ndarray:
    """(..., TABLE_WIDTH) from (..., 3) norms (m_uu, m_uv, m_vv) alone: the quartic columns their
    triangle inequality gives (e_22 <= 2 m_uu m_vv + 4 m_uv^2, |e_31| <= 4 m_uu m_uv, |e_13| <=
    4 m_uv m_vv), so that a table made from norms only is still a valid, if looser, table."""
    m_uu, m_uv, m_vv = np.moveaxis(np.asarray(majorants, float), -1, 0)
    e31, e13 = 4 * m_uu * m_uv, 4 * m_uv * m_vv
    return np.stack([m_uu, m_uv, m_vv, 2 * m_uu * m_vv + 4 * m_uv ** 2, e31, e31, e13, e13], axis=-1)


def pyramid_levels(levels: int = SUBPATCH_LEVELS) -> list[tuple[int, int]]:
    """(offset, side) of each level of a patch's pyramid, finest (side S) first, then S/2 ... 1."""
    out, offset = [], 0
    for level in range(levels, -1, -1):
        out.append((offset, 1 << level))
        offset += 1 << (2 * level)
    return out


def pyramid_cells(levels: int = SUBPATCH_LEVELS) -> int:
    """Cells of one patch's pyramid: S^2 + (S/2)^2 + ... + 1."""
    return ((1 << (2 * levels + 2)) - 1) // 3


def rounded_up(values: np.ndarray) -> np.ndarray:
    """float32 no smaller than values + |values| (TABLE_SAFETY - 1) (next float towards +inf
    where needed; signed values: the quartic columns)."""
    values = values + np.abs(values) * (TABLE_SAFETY - 1)
    stored = values.astype(np.float32)
    low = stored.astype(float) < values
    stored[low] = np.nextafter(stored[low], np.float32(np.inf))
    return stored


def patch_table(patch: np.ndarray, levels: int = SUBPATCH_LEVELS) -> np.ndarray:
    """(table_cells, TABLE_WIDTH) float32 of one patch: majorant_pyramid, then the graded cells'
    cell_forms row by row (v, then u), rounded up likewise.  Only the graded cells are
    subdivided: they nest in the S x S subpatches (the breakpoints include every multiple of
    1/S), so a subpatch's majorant is taken as the max of its graded cells' (each a valid
    majorant on its cell, and no larger than the subpatch's own hull bound: a restriction's
    control points are convex combinations of the whole's)."""
    breaks = graded_breaks(levels)
    graded = cell_forms(patch, breaks)
    side = 1 << levels
    owner = np.floor(breaks[:-1] * side).astype(int)  # the subpatch holding each graded cell, per axis
    subpatches = np.full((side, side, TABLE_WIDTH), -np.inf)
    np.maximum.at(subpatches, (owner[:, None], owner[None, :]), graded)
    out = np.zeros((table_cells(levels), TABLE_WIDTH), np.float32)
    out[:pyramid_cells(levels)] = majorant_pyramid(subpatches)
    out[pyramid_cells(levels):] = rounded_up(graded.reshape(-1, TABLE_WIDTH))
    return out


def majorant_pyramid(majorants: np.ndarray) -> np.ndarray:
    """(cells, TABLE_WIDTH) float32 of one patch: each level's cell_forms columns row by row (v,
    then u), finest first, every coarser cell the max of its four children (every column pools
    by max); rounded up (float32 towards +inf, times TABLE_SAFETY) so the stored values bound the
    float64 ones.  (S, S, 3) norms alone are widened by norm_forms first."""
    if majorants.shape[-1] == 3:
        majorants = norm_forms(majorants)
    rows, level = [], majorants
    while True:
        rows.append(level.reshape(-1, TABLE_WIDTH))
        if level.shape[0] == 1:
            break
        level = np.maximum.reduce([level[0::2, 0::2], level[1::2, 0::2], level[0::2, 1::2], level[1::2, 1::2]])
    return rounded_up(np.concatenate(rows))


def scene_pyramids(patches: np.ndarray, rational: np.ndarray, levels: int = SUBPATCH_LEVELS) -> tuple[np.ndarray, np.ndarray]:
    """((R * table_cells, TABLE_WIDTH) float32 tables (patch_table) of the rational patches, (P,) int32 their
    index (-1: none, a polynomial patch, which keeps today's factors))."""
    index = np.full(len(patches), -1, np.int32)
    index[rational] = np.arange(int(np.count_nonzero(rational)), dtype=np.int32)
    if not rational.any():
        return np.zeros((1, TABLE_WIDTH), np.float32), index
    tables = [patch_table(patch, levels) for patch in np.asarray(patches)[rational]]
    return np.concatenate(tables), index


# --- the per-triangle bound (kernels/criteria/integral_bound.h) --------------------------------

def pyramid_query(pyramid: np.ndarray, levels: int, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """(TABLE_WIDTH,) max of each column (FORM_COLUMNS) over the cells of one patch's table (patch_table) that the
    box [lo, hi] (u, v in [0, 1], widened by BOX_WIDENING) meets: the graded cells if it comes
    within 4 / S of an edge (elsewhere they are the finest subpatches) and meets fewer than
    GRADED_SPAN of them per side, else the pyramid at the finest level where it spans at most
    QUERY_SPAN cells per side (float32 arithmetic as the kernel's).  A pyramid alone (no graded
    rows) reads the pyramid."""
    w = np.float32(BOX_WIDENING)
    edge = np.float32(4) / np.float32(1 << levels)  # graded cells finer than the subpatches only there
    near_edge = (min(np.float32(lo[0]), np.float32(lo[1])) - w < edge
                 or max(np.float32(hi[0]), np.float32(hi[1])) + w > np.float32(1) - edge)
    if len(pyramid) > pyramid_cells(levels) and near_edge:
        breaks = graded_breaks(levels).astype(np.float32)
        count = len(breaks) - 1
        cell = lambda x: min(max(int(np.searchsorted(breaks, x, side="right")) - 1, 0), count - 1)  # noqa: E731
        first = [cell(np.float32(lo[a]) - w) for a in range(2)]
        last = [cell(np.float32(hi[a]) + w) for a in range(2)]
        if last[0] - first[0] < GRADED_SPAN and last[1] - first[1] < GRADED_SPAN:
            cells = pyramid[pyramid_cells(levels):].reshape(count, count, TABLE_WIDTH)
            return cells[first[1]:last[1] + 1, first[0]:last[0] + 1].reshape(-1, TABLE_WIDTH).max(axis=0)
    side = np.float32(1 << levels)
    first = [int(min(max(math.floor((np.float32(lo[a]) - w) * side), 0), side - 1)) for a in range(2)]
    last = [int(min(max(math.floor((np.float32(hi[a]) + w) * side), 0), side - 1)) for a in range(2)]
    level = 0
    while level < levels and (last[0] - first[0] >= QUERY_SPAN or last[1] - first[1] >= QUERY_SPAN):
        first, last, level = [x >> 1 for x in first], [x >> 1 for x in last], level + 1
    offset, n = pyramid_levels(levels)[level]
    cells = pyramid[offset:offset + n * n].reshape(n, n, TABLE_WIDTH)
    return cells[first[1]:last[1] + 1, first[0]:last[0] + 1].reshape(-1, TABLE_WIDTH).max(axis=0)


def sub_triangles(k: int) -> np.ndarray:
    """(k^2, 3, 3) integer barycentric corners (times k) of the k^2 sub-triangles of a triangle,
    in the kernel's order (row i, then j; the upright one, then the inverted one)."""
    out = []
    for i in range(k):
        for j in range(k - i):
            out.append([[i, j, k - i - j], [i + 1, j, k - i - j - 1], [i, j + 1, k - i - j - 1]])
            if i + j < k - 1:
                out.append([[i + 1, j, k - i - j - 1], [i, j + 1, k - i - j - 1], [i + 1, j + 1, k - i - j - 2]])
    return np.array(out, np.int64)


def lemma1_box(pyramid: np.ndarray, levels: int, corners: np.ndarray) -> float:
    """Lemma 1 with the majorant of the triangle's own bounding box (its local sups)."""
    corners = corners.astype(np.float32)
    lo, hi = corners.min(axis=0), corners.max(axis=0)
    m = pyramid_query(pyramid, levels, lo, hi)[:3].astype(np.float32)
    du, dv = hi - lo + np.float32(2) * np.float32(BOX_WIDENING)
    return float((m[0] * du * du + np.float32(2) * m[1] * du * dv + m[2] * dv * dv) / np.float32(8))


def monomial_ranges(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """(8,) float32 of the box lo <= h <= hi (float32 (2,)): max h_u^4, max h_v^4, min and max of
    h_u^2 h_v^2, of h_u^3 h_v and of h_u h_v^3 (the kernel's integral_monomials, same order of
    operations)."""
    f32 = np.float32
    lo, hi = lo.astype(f32), hi.astype(f32)
    square_max = np.maximum(lo * lo, hi * hi)
    square_min = np.where(lo > 0, lo * lo, np.where(hi < 0, hi * hi, f32(0))).astype(f32)
    cube_lo, cube_hi = lo * lo * lo, hi * hi * hi
    u3v = [cube_lo[0] * lo[1], cube_lo[0] * hi[1], cube_hi[0] * lo[1], cube_hi[0] * hi[1]]
    uv3 = [lo[0] * cube_lo[1], hi[0] * cube_lo[1], lo[0] * cube_hi[1], hi[0] * cube_hi[1]]
    return np.array([square_max[0] * square_max[0], square_max[1] * square_max[1],
                     square_min[0] * square_min[1], square_max[0] * square_max[1],
                     min(u3v), max(u3v), min(uv3), max(uv3)], f32)


def direction_form(m: np.ndarray, monomials: np.ndarray) -> np.float32:
    """sqrt of an upper bound of max_k |H_k[h, h]|^2 over the cells of m (a query's TABLE_WIDTH
    maxima) and the h of the box whose monomial_ranges are ``monomials`` (float32, the kernel's
    integral_direction_form): each coefficient's range times its monomial's, the largest product."""
    f32 = np.float32
    m = m.astype(f32)
    quartic_uu, quartic_vv = m[0] * m[0] * monomials[0], m[2] * m[2] * monomials[1]
    e22 = m[3] * monomials[3] if m[3] >= 0 else m[3] * monomials[2]
    e31 = max(m[4] * monomials[5], m[4] * monomials[4], -m[5] * monomials[5], -m[5] * monomials[4])
    e13 = max(m[6] * monomials[7], m[6] * monomials[6], -m[7] * monomials[7], -m[7] * monomials[6])
    total = quartic_uu + quartic_vv + e22 + e31 + e13
    size = quartic_uu + quartic_vv + abs(e22) + abs(e31) + abs(e13)
    return np.sqrt(max(total + f32(QUARTIC_SLACK) * size, f32(0)))


def upper_sum(pyramid: np.ndarray, levels: int, corners: np.ndarray, k: int) -> float:
    """The upper sum of the integral form over the K^2 sub-triangles and T = 4K/3 intervals
    (float32 as the kernel; the max over sub-triangles).  Each term takes the smaller of the
    triangle inequality over the norms and the direction-aware form (direction_form)."""
    f32 = np.float32
    corners = corners.astype(f32)
    t_count = 4 * k // 3
    widening = f32(BOX_WIDENING)
    worst = f32(0)
    for sub in sub_triangles(k):
        q = np.array([[(f32(sub[a, 0]) * corners[0, c] + f32(sub[a, 1]) * corners[1, c] + f32(sub[a, 2]) * corners[2, c])
                       / f32(k) for c in range(2)] for a in range(3)], f32)
        total = f32(0)
        for i in range(3):
            lam = f32(sub[:, i].max()) / f32(k)
            x_i = corners[i]
            h = np.abs(x_i - q).max(axis=0) + widening  # the float32 corners' rounding
            monomials = monomial_ranges((x_i - q).min(axis=0) - widening, (x_i - q).max(axis=0) + widening)
            for s in range(t_count):
                t0, t1 = f32(s) / f32(t_count), f32(s + 1) / f32(t_count)
                weight = (t1 - t0) - (t1 * t1 - t0 * t0) / f32(2)
                pts = np.concatenate([(f32(1) - t0) * q + t0 * x_i, (f32(1) - t1) * q + t1 * x_i])
                m = pyramid_query(pyramid, levels, pts.min(axis=0), pts.max(axis=0)).astype(f32)
                norms = m[0] * h[0] * h[0] + f32(2) * m[1] * h[0] * h[1] + m[2] * h[1] * h[1]
                total += lam * weight * min(norms, direction_form(m, monomials))
        worst = max(worst, total)
    return float(worst)


def triangle_bound(pyramid: np.ndarray, levels: int, corners: np.ndarray, tolerance: float,
                   subdivisions=SUBDIVISIONS) -> float:
    """bound * BOUND_SAFETY / tolerance of one triangle (corners (3, 2) in (u, v)): Lemma 1 with its
    box's majorant, then the upper sums for K in ``subdivisions`` until one is <= tolerance (each
    is a bound: the smallest found is returned)."""
    best = lemma1_box(pyramid, levels, corners) * BOUND_SAFETY
    for k in subdivisions:
        if best <= tolerance:
            break
        best = min(best, upper_sum(pyramid, levels, corners, k) * BOUND_SAFETY)
    return best / tolerance


# --- the trials (the host loop: cltess/backends/opencl/integral.py) -------------------------------

def trial_factors(factors: np.ndarray, trials: np.ndarray, scales=TRIAL_SCALES) -> np.ndarray:
    """(P, 4) int32: stage 1's factors ``factors`` (today's, (m, n, m, n) for a quad) scaled by
    scales[trials] (TRIAL_SCALES unless given) and rounded up, at least 1; 0 (culled) stays 0.
    Never above today's."""
    scales = np.asarray(scales)[trials][:, None]
    scaled = np.ceil(factors * scales - 1e-9).astype(np.int32)
    return np.where(factors > 0, np.clip(scaled, 1, factors), factors).astype(np.int32)
