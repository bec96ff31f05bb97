"""What a tessellation pattern is on the host: its name, domain and device header, and its NumPy
mirror (docs/extending.md, "A pattern")."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np


@dataclass(frozen=True)
class Pattern:
    """A tessellation pattern: where the points of a patch with edge factors f go, and how they
    are connected.

    name:      registry name ("quad_transition").
    domain:    "quad" or "tri": the kinds it serves have this domain.
    edges:     factors per patch it reads (4 for quads, 3 for triangles).
    header:    its device header under kernels/ (the contract of docs/extending.md).
    crack:     the crack policy its boundary needs, a header under kernels/ ("crack/max.h").
    family:    the name that selects it for every domain (``Request(pattern="semi_uniform")``:
               quad_semi_uniform for quads, tri_semi_uniform for triangles).
    dyadic:    it reads dyadic factors 2^p_e: stage 1 rounds the kind's factors up to powers of
               two, capped at 2^max_level (``-D PATTERN_DYADIC``, common.h dyadic_factors).
    fixed_point: its factors are real, as 16.16 fixed-point integers (cltess.patterns.fractional:
               an edge's segments odd_segments(f), placed by fractional_odd), made by a level
               function (cltess.levels) rather than by the kinds' integer stage 1.
    stage1:    its own stage 1 instead of the kind's factors, ``(defines, host)``: stage 1 is
               built with these ``-D`` defines (``(("PATTERN_ESC", 1),)``), and ``host(patches,
               tolerance, max_level, max_factor) -> (records, flags)`` is its NumPy mirror (ESC: the candidate
               masks; cltess/esc/masks.py).
    strips:    for a strip pattern (primitive "strips") whose factors are integers, f -> its strips
               as the device emits them (local numbers, each strip followed by STRIP_RESTART;
               ESC: esc.strip_indices); the NumPy backend's Tessellation.strips.
    layout:    the NumPy mirror, f -> (uv (V, 2) float64, triangles (T, 3) int64 local indices):
               the ring first, then the interior rows, as the device lays the vertices out.
    chords:    f -> the vertices that stage 4 places on a chord of the mesh rather than on the
               surface, ``(vertices (K,), start (K,), end (K,), mu (K,))`` (local numbers):
               vertex k at ``P[start] + mu (P[end] - P[start])``, P the other vertices'
               positions (kernels/patterns/layout.h PATTERN_CHORD_POINTS; place_chords; SD-2's
               tie-zone centres, sd2.sd2_chords); None: none.
    counts_walk: its counts walk the whole pattern rather than a closed form or a table (ESC
               before its tables, esc.ESC_WALK: every band of the 18 coarse triangles): stage 3
               then keeps a work-item per patch over the whole device, never the
               one-work-group launch of stages/offsets.cl (on the H100 that made Teacups' stage 3
               3.05 ms against 0.76).
    """

    name: str
    domain: str
    edges: int
    header: str
    layout: Callable[[tuple], tuple[np.ndarray, np.ndarray]]
    crack: str = "crack/max.h"
    primitive: str = "triangles"
    family: str = ""
    dyadic: bool = False
    fixed_point: bool = False
    stage1: tuple = ()
    strips: Callable | None = None
    chords: Callable | None = None
    counts_walk: bool = False

    @property
    def defines(self) -> dict:
        """What stage 1 is built with for this pattern (-D), besides the tolerance's."""
        return {"PATTERN_DYADIC": 1} if self.dyadic else dict(self.stage1[0]) if self.stage1 else {}

    def counts(self, factors: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(vertex counts (P,), index counts (P,)) of each patch's pattern."""
        layouts = [self.layout(f) for f in factors]
        return (np.array([len(uv) for uv, _ in layouts], np.int64),
                np.array([3 * len(t) for _, t in layouts], np.int64))

    def __repr__(self) -> str:
        return f"<Pattern {self.name}>"


def place_chords(positions: np.ndarray, chords) -> np.ndarray:
    """positions (V, 3) of one patch with its chord vertices (Pattern.chords: vertices, start, end,
    mu) moved onto their chords, ``P[start] + mu (P[end] - P[start])``, exactly P[start] at
    mu = 0.  The NumPy mirror of stage 4's chord points (kernels/stages/rows.h chord_position)."""
    vertices, start, end, mu = chords
    out = np.array(positions, copy=True)
    if len(vertices):
        p0, p1 = out[start], out[end]
        moved = p0 + mu[:, None].astype(out.dtype) * (p1 - p0)
        out[vertices] = np.where(mu[:, None] > 0, moved, p0)
    return out
