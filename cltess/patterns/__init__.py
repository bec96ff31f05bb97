"""Tessellation patterns by name (docs/extending.md: to add one, write its NumPy mirror here and
its header under kernels/patterns/, and add it to PATTERNS)."""
from .base import Pattern
from .quad_transition import QUAD_TRANSITION, quad_pattern
from .tri_transition import TRI_TRANSITION, tri_pattern

PATTERNS: dict[str, Pattern] = {p.name: p for p in (QUAD_TRANSITION, TRI_TRANSITION)}

__all__ = ["PATTERNS", "Pattern", "QUAD_TRANSITION", "TRI_TRANSITION", "quad_pattern", "tri_pattern"]
