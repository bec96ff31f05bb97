"""Point placement on an edge for a real (fractional) factor: D3D11's ``fractional_odd`` spacing
(the reference tessellator that Mesa's tessellators carry; docs/sd2.md section 1), the NumPy
mirror of ``fractional_location`` in kernels/common.h.

A real factor ``r >= 1`` is carried as a 16.16 fixed-point integer ``fixed = round(r * 2^16)``
(as D3D's tessellator does), so that the two patches of an edge see bitwise the same factor and
its crack-free maximum is an integer max.  The edge gets ``n = odd_segments(fixed)`` segments,
the smallest odd number ``>= r``: points ``k = 0 .. n``, point ``k`` and point ``n - k`` mirror
each other (placed from the nearer end, so the points are the same walked from either end), and
as ``r`` grows every point moves continuously: at an odd whole ``r`` the points are ``k / r``;
past it two new points split off one point (``split_point``) and move apart, reaching ``k / (r + 2)``
at the next odd whole number.  Ends always included: point 0 is 0 and point n is 1.
"""
from __future__ import annotations

import numpy as np

#: 1.0 in the 16.16 fixed-point factors of fractional patterns.  kernels/common.h FIXED_ONE.
FIXED_ONE = 1 << 16


def to_fixed(factor) -> np.ndarray:
    """16.16 fixed-point factors of real factors (rounded to nearest), at least 1.0."""
    factor = np.asarray(factor, np.float64)
    return np.maximum(np.rint(factor * FIXED_ONE), FIXED_ONE).astype(np.int64)


def from_fixed(fixed) -> np.ndarray:
    return np.asarray(fixed, np.float64) / FIXED_ONE


def _halves(fixed: int) -> tuple[int, int, int]:
    """(floor, ceil, fraction in 1/2^17) of the half factor (r + 1) / 2 (fractional_odd), exactly:
    twice it is fixed + 1.0, a 16.16 number, so the half is one in 15.17."""
    twice = int(fixed) + FIXED_ONE
    return twice >> 17, (twice + 2 * FIXED_ONE - 1) >> 17, twice & (2 * FIXED_ONE - 1)


def odd_segments(fixed) -> int:
    """Segments of an edge of real factor fixed / 2^16: the smallest odd number >= it."""
    _, ceil_half, _ = _halves(fixed)
    return 2 * ceil_half - 1


def _remove_msb(x: int) -> int:
    return x - (1 << (x.bit_length() - 1)) if x > 0 else 0


def split_point(fixed) -> int:
    """The near-half index past which points sit one index lower on the floor factor (D3D's
    splitPointOnFloorHalfTessFactor: the point that splits in two as the factor grows)."""
    floor_half, ceil_half, _ = _halves(fixed)
    if floor_half == ceil_half:
        return ceil_half + 1  # never: r is odd and whole
    if floor_half == 1:
        return 0
    return (_remove_msb(floor_half - 1) << 1) + 1


def near_location(fixed, i: int) -> np.float32:
    """float32 location, from its nearer end, of the point i < (n + 1) / 2 of an edge: the lerp
    between its place on the floor odd factor and on the ceiling one by the half factor's
    fraction, in the device's operation order (kernels/common.h fractional_location)."""
    floor_half, ceil_half, fraction = _halves(fixed)
    i = int(i)
    on_floor = i - 1 if i > split_point(fixed) else i
    f32 = np.float32
    a = f32(on_floor) / f32(2 * floor_half - 1)
    b = f32(i) / f32(2 * ceil_half - 1)
    t = f32(fraction) * f32(0.5 / FIXED_ONE)
    return f32(a + t * (b - a))


def locations(fixed) -> np.ndarray:
    """(n + 1,) float32 locations of the points k = 0 .. n of an edge, walked from its start:
    the near half placed by ``near_location``, the far half mirrored as 1 - location."""
    n = odd_segments(fixed)
    out = np.empty(n + 1, np.float32)
    for k in range(n + 1):
        near = min(k, n - k)
        at = near_location(fixed, near)
        out[k] = at if k == near else np.float32(1.0) - at
    return out
