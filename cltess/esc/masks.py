"""ESC's stage 1 in NumPy float64: the distance test per candidate as bit masks, packed into the
record of cltess/patterns/esc.py.  Mirror of kernels/criteria/esc_distance.h (docs/esc.md)."""
from __future__ import annotations

import numpy as np

from ..criteria.base import DEFAULT_MAX_FACTOR
from ..criteria.zheng_sederberg import zs_factors
from ..kinds.base import FLAG_CULLED, FLAG_SATURATED
from ..patterns.esc import (BOUNDARY_EDGES, COARSE_EDGES, MAX_LEVEL, PATCH_EDGE_AGAINST, PATCH_EDGE_COARSE,
                            pack, pole_edges, reverse_bits)
from ..scene import boundary_curves
from ..surfaces.bezier import evaluate


def edge_reversed(controls: np.ndarray) -> bool:
    """Whether the canonical direction of an edge with controls (4, 4) (float32 values, as the
    device sees them) runs against them: c3..c0 lexicographically smaller than c0..c3, comparing
    c0 with c3, then c1 with c2, by x, y, z, w (criteria/esc_distance.h esc_edge_reversed)."""
    for k in (0, 1):
        a, b = controls[k], controls[3 - k]
        for c in range(4):
            if a[c] != b[c]:
                return bool(b[c] < a[c])
    return False


def curve_points(controls: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Projected points of a rational cubic with homogeneous controls (4, 4) at t."""
    t = np.asarray(t, float)[:, None]
    s = 1 - t
    h = s ** 3 * controls[0] + 3 * t * s * s * controls[1] + 3 * t * t * s * controls[2] + t ** 3 * controls[3]
    return h[:, :3] / h[:, 3:]


def patch_steps(factor: int, level: int) -> int:
    """Steps per coarse edge of a patch whose bound asks for `factor` segments per patch side, on
    the lattice of level L (docs/esc.md decision 5): the fewest d dividing n = L + 1 with
    3 d >= factor, else n (criteria/esc_distance.h esc_patch_steps).  Its level L_p = d - 1."""
    n = level + 1
    return next((d for d in range(1, n) if n % d == 0 and 3 * d >= factor), n)


def candidate_tested(k: int, steps: int, level: int) -> bool:
    """Whether candidate k / (L + 1) is one of a patch's with `steps` steps per coarse edge."""
    return (k * steps) % (level + 1) == 0


def chord_bits(points: np.ndarray, level: int, eps: float, steps: int | None = None) -> int:
    """L bits of a coarse edge from its surface points (L + 2, 3), ends first and last; only the
    candidates of a patch with `steps` steps per coarse edge tested (all when None)."""
    n = level + 1
    steps = n if steps is None else steps
    bits = 0
    for k in range(1, n):
        if not candidate_tested(k, steps, level):
            continue
        chord = points[0] * (n - k) / n + points[-1] * k / n
        if np.linalg.norm(points[k] - chord) > eps:
            bits |= 1 << (k - 1)
    return bits


def patch_masks(patch: np.ndarray, eps: float, level: int, steps: int | None = None) -> tuple[np.ndarray, tuple]:
    """(33 masks in canonical directions, per patch edge whether its curve's canonical direction
    runs against counter-clockwise) of one (4, 4, 4) homogeneous patch; steps: its own steps per
    coarse edge (patch_steps; all L candidates tested when None)."""
    n, m = level + 1, 3 * (level + 1)
    masks = np.zeros(33, np.int64)
    for c, (start, end) in enumerate(COARSE_EDGES):
        if c in BOUNDARY_EDGES:
            continue
        k = np.arange(n + 1)
        x = (n * start[0] + k * (end[0] - start[0])) / m
        y = (n * start[1] + k * (end[1] - start[1])) / m
        masks[c] = chord_bits(evaluate(patch, x, y)[0], level, eps, steps)
    curves = boundary_curves(patch[None])[0]  # (4 edges, 4 controls, 4), counter-clockwise
    reversed_edges = []
    for e in range(4):
        controls = curves[e]
        flip = edge_reversed(controls.astype(np.float32))
        reversed_edges.append(flip)
        canonical = controls[::-1] if flip else controls
        points = curve_points(canonical, np.arange(m + 1) / m)
        canonical_bits = 0
        for s in range(3):
            canonical_bits |= chord_bits(points[s * n:s * n + n + 1], level, eps, steps) << (s * level)
        ccw = reverse_bits(canonical_bits, 3 * level) if flip else canonical_bits
        for s, c in enumerate(PATCH_EDGE_COARSE[e]):
            mask = (ccw >> (s * level)) & ((1 << level) - 1)
            masks[c] = reverse_bits(mask, level) if PATCH_EDGE_AGAINST[e] else mask
    return masks, tuple(reversed_edges)


def pole_bits(curves: np.ndarray) -> np.ndarray:
    """(P,) bit e set where patch edge e is a pole: its boundary curve's float32 controls (P, 4, 4, 4)
    are one point, c_k.xyz / c_k.w all equal compared by float32 products (criteria/esc_distance.h)."""
    curves = np.asarray(curves, np.float32)
    point = (curves[..., :3] * curves[:, :, :1, 3:] == curves[:, :, :1, :3] * curves[..., 3:]).all(axis=(2, 3))
    return (point * (1 << np.arange(4))).sum(axis=1).astype(np.int64)


def patch_levels(factors: np.ndarray, max_level: int) -> np.ndarray:
    """(P,) each patch's level L_p = patch_steps - 1 from its stage-1 bound factors (P, 4) (the
    Bezier kind's Zheng-Sederberg factors (m, n, m, n); 0 for culled patches)."""
    level = min(max_level, MAX_LEVEL)
    factors = np.asarray(factors, np.int64).reshape(-1, 4)
    return np.array([patch_steps(int(max(f[0], f[1])), level) - 1 for f in factors], np.int64)


def esc_stage(patches: np.ndarray, tolerance, max_level: int, max_factor: int = DEFAULT_MAX_FACTOR,
              levels: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(records (P, 4) int32, flags (P,)) of patches (P, 4, 4, 4) homogeneous for a tolerance
    (ObjectSpace / ScreenSpace): the lattice of L = min(max_level, 3), each patch testing the
    candidates of its level L_p (patch_levels of the Zheng-Sederberg factors, or `levels` given:
    (P,) levels whose L_p + 1 divides L + 1).  FLAG_SATURATED where the bound asks for more
    segments than the lattice has (or than max_factor)."""
    patches = np.asarray(patches, np.float64).reshape(-1, 4, 4, 4)
    points = (patches[..., :3] / patches[..., 3:]).reshape(len(patches), -1, 3)
    eps, culled = tolerance.reference(points.min(axis=1), points.max(axis=1))
    level = min(max_level, MAX_LEVEL)
    factors, _, saturated = zs_factors(patches, eps, culled, max_factor)
    bound = factors[:, :2].max(axis=1)
    if levels is None:
        levels = patch_levels(factors, level)
    elif any((level + 1) % (int(lp) + 1) for lp in levels):
        raise ValueError(f"patch levels must have L_p + 1 dividing {level + 1}")
    curves = boundary_curves(patches).astype(np.float32)  # (P, 4 edges, 4 controls, 4), as the device sees them
    poles = pole_bits(curves)
    levels = np.where(poles > 0, level, levels)  # a patch at a pole: the full level (docs/esc.md decision 5)
    records = np.zeros((len(patches), 4), np.int32)
    for p, patch in enumerate(patches):
        if not culled[p]:
            masks, flips = patch_masks(patch, float(eps[p]), level, int(levels[p]) + 1)
            masks[list(pole_edges(int(poles[p])))] = (1 << level) - 1  # the pole rule (docs/esc.md)
            records[p] = pack(level, masks, flips)
    flags = np.where(culled, FLAG_CULLED, np.where(saturated | (bound > 3 * (level + 1)), FLAG_SATURATED, 0))
    return records, flags.astype(np.int32)
