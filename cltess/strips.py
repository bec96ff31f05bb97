"""Triangle strips, the output primitive of the strip patterns (SD-2, ESC).

One convention everywhere (host and device, NPZ and every exporter):

* strips are one ``uint32`` index array, strips separated by ``STRIP_RESTART`` (0xFFFFFFFF, the
  primitive-restart index of OpenGL ``GL_PRIMITIVE_RESTART_FIXED_INDEX``, Vulkan and D3D for
  32-bit indices), so no degenerate joins: a renderer draws them in one call and a reader can
  expand them without guessing which zero-area triangles were joins;
* strip ``a b c d e ...`` is the triangles ``(a b c), (c b d), (c d e), (e d f), ...``: triangle
  ``i`` is ``(s[i], s[i+1], s[i+2])`` for even ``i`` and ``(s[i+1], s[i], s[i+2])`` for odd ``i``,
  so every triangle keeps the first one's winding (OpenGL's rule);
* a strip of fewer than three indices draws nothing and is not written.
"""
from __future__ import annotations

import numpy as np

#: Primitive-restart marker between strips (uint32 all ones).  kernels/common.h STRIP_RESTART.
STRIP_RESTART = np.uint32(0xFFFFFFFF)


def strip_triangle_count(lengths) -> int:
    """Triangles drawn by strips of these lengths (indices per strip, restart markers excluded)."""
    lengths = np.asarray(lengths, np.int64)
    return int(np.maximum(lengths - 2, 0).sum())


def strip_index_count(lengths) -> int:
    """Indices of strips of these lengths joined with one restart marker between strips."""
    lengths = np.asarray(lengths, np.int64)
    return int(lengths.sum() + max(len(lengths) - 1, 0))


def join_strips(strips) -> np.ndarray:
    """One uint32 index array from a list of strips (sequences of indices), restart-separated."""
    parts = []
    for strip in strips:
        strip = np.asarray(strip, np.int64)
        if strip.ndim != 1 or len(strip) < 3:
            raise ValueError(f"a strip needs at least 3 indices, got {strip.tolist()}")
        if (strip < 0).any() or (strip >= STRIP_RESTART).any():
            raise ValueError("strip indices must be in 0 .. 2^32 - 2")
        if parts:
            parts.append(np.array([STRIP_RESTART], np.int64))
        parts.append(strip)
    return np.concatenate(parts).astype(np.uint32) if parts else np.zeros(0, np.uint32)


def split_strips(indices: np.ndarray) -> list[np.ndarray]:
    """The strips of a restart-separated index array (empty runs dropped)."""
    indices = np.asarray(indices)
    cuts = np.flatnonzero(indices == STRIP_RESTART)
    runs = np.split(indices, cuts)
    return [run[run != STRIP_RESTART] for run in runs if (run != STRIP_RESTART).sum()]


def expand_strips(indices: np.ndarray, drop_degenerate: bool = False) -> np.ndarray:
    """(T, 3) triangles of a restart-separated strip index array, winding per the module rule.

    drop_degenerate: leave out triangles with a repeated index (a strip pattern may repeat a
    vertex to turn a corner; those triangles have zero area and are not in its triangle list).
    """
    indices = np.asarray(indices, np.uint32)
    triangles = []
    for strip in split_strips(indices):
        if len(strip) < 3:
            raise ValueError(f"a strip of {len(strip)} indices draws nothing and must not be written")
        i = np.arange(len(strip) - 2)
        odd = (i % 2).astype(bool)
        first = np.where(odd, strip[i + 1], strip[i])
        second = np.where(odd, strip[i], strip[i + 1])
        triangles.append(np.stack([first, second, strip[i + 2]], axis=1))
    out = np.concatenate(triangles) if triangles else np.zeros((0, 3), np.uint32)
    if drop_degenerate:
        out = out[(out[:, 0] != out[:, 1]) & (out[:, 1] != out[:, 2]) & (out[:, 0] != out[:, 2])]
    return out.astype(np.uint32)
