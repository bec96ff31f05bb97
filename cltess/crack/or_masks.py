"""The crack policy "or_masks" of the ESC pattern: NumPy mirror of kernels/crack/or_masks.h.
Each patch edge ORs the boundary candidate bits of every patch edge of its group into its own
record (both sides store them in the curve's canonical direction); other records take the max as
crack/max.h; culled stay 0; collapsed edges are stored negated (stages/crack_free.cl)."""
from __future__ import annotations

import numpy as np

from ..patterns.esc import ALIVE, BOUNDARY_BITS


def crack_free_masks(records: np.ndarray, group_of: np.ndarray, group_start: np.ndarray,
                     members: np.ndarray, collapsed_edges: np.ndarray | None = None) -> np.ndarray:
    """records (P, 4) int32 of stage 1, edge groups over its 4P entries -> (P, 4) int32."""
    flat = np.asarray(records).reshape(-1).astype(np.int64)
    out = np.zeros_like(flat)
    for edge, group in enumerate(group_of):
        own = flat[edge]
        if own <= 0:
            continue
        others = flat[members[group_start[group]:group_start[group + 1]]]
        if own & ALIVE:
            own |= int(np.bitwise_or.reduce(np.where(others > 0, others & BOUNDARY_BITS, 0)))
        else:
            own = max(own, int(others.max()))
        out[edge] = -own if collapsed_edges is not None and collapsed_edges[edge] else own
    return out.reshape(np.shape(records)).astype(np.int32)


#: Crack policies by header (Pattern.crack), host side.
def policy(header: str):
    """The NumPy mirror of a crack policy header."""
    from .adjacency import crack_free_factors
    return {"crack/max.h": crack_free_factors, "crack/or_masks.h": crack_free_masks}[header]
