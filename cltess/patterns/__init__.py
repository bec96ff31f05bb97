"""Tessellation patterns by name (docs/extending.md: to add one, write its NumPy mirror here and
its header under kernels/patterns/, and add it to PATTERNS).  A family name ("transition",
"semi_uniform") selects the family's pattern of each domain (``pattern_named``)."""
from .base import Pattern
from .esc import ESC
from .quad_transition import QUAD_TRANSITION, quad_pattern
from .sd2 import SD2
from .semi_uniform import QUAD_SEMI_UNIFORM, TRI_SEMI_UNIFORM
from .tri_transition import TRI_TRANSITION, tri_pattern

PATTERNS: dict[str, Pattern] = {p.name: p for p in (QUAD_TRANSITION, TRI_TRANSITION, QUAD_SEMI_UNIFORM,
                                                     TRI_SEMI_UNIFORM, SD2, ESC)}
#: Family names, each with one pattern per domain.
FAMILIES: tuple[str, ...] = tuple(dict.fromkeys(p.family for p in PATTERNS.values() if p.family))


def pattern_named(name: str, domain: str) -> Pattern | None:
    """The pattern called ``name`` (a pattern or a family name) for a domain, or None when it has
    none for that domain."""
    chosen = PATTERNS.get(name)
    if chosen is not None:
        return chosen if chosen.domain == domain else None
    return next((p for p in PATTERNS.values() if p.family == name and p.domain == domain), None)


__all__ = ["ESC", "FAMILIES", "PATTERNS", "Pattern", "SD2", "QUAD_SEMI_UNIFORM", "QUAD_TRANSITION", "TRI_SEMI_UNIFORM",
           "TRI_TRANSITION", "pattern_named", "quad_pattern", "tri_pattern"]
