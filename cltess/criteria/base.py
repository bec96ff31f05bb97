"""What every criterion shares: the factor cap, and how requirements combine.

A criterion turns a tolerance into inverse steps per edge (docs/design.md sections 2 and 3);
several requirements on one edge combine by their max (the finest wins), as Skia's
``LinearTolerances.accumulate`` does.
"""
from __future__ import annotations

import numpy as np

DEFAULT_MAX_FACTOR = 64


def combine(*inverse_steps: np.ndarray) -> np.ndarray:
    """The requirement of several criteria on the same edges: the largest inverse step."""
    return np.maximum.reduce([np.asarray(x, float) for x in inverse_steps])
