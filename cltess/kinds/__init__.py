"""Patch kinds by name, in scene patch order (docs/extending.md: to add one, write its host side
here, its NumPy surface in cltess/surfaces/ and its header under kernels/kinds/, and add it to
KINDS)."""
from .base import FACTOR_SLOTS, FLAG_CULLED, FLAG_FOLDED, FLAG_SATURATED, KindInput, PatchKind
from .bezier import BEZIER, BezierKind
from .pn import PN, SHARP_EDGE_MODES, PNKind, mesh_edge_groups, pn_edge_normals

#: The kinds in scene patch order (cltess.scene numbers the Bézier patches first, then the faces).
KINDS: tuple[PatchKind, ...] = (BEZIER, PN)


def kind(name) -> PatchKind:
    """The registered kind of that name (or the kind itself)."""
    if isinstance(name, PatchKind):
        return name
    for k in KINDS:
        if k.name == name:
            return k
    raise ValueError(f"unknown patch kind {name!r}; expected one of {', '.join(k.name for k in KINDS)}")


__all__ = ["BEZIER", "FACTOR_SLOTS", "FLAG_CULLED", "FLAG_FOLDED", "FLAG_SATURATED", "KINDS", "PN", "SHARP_EDGE_MODES", "BezierKind", "KindInput", "PNKind",
           "PatchKind", "kind", "mesh_edge_groups", "pn_edge_normals"]
