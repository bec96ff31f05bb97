"""Per-kind test input, so that contract tests run the same checks over every registered kind
(cltess.kinds.KINDS): random stage-1 source rows, and closed surfaces for watertightness."""
from __future__ import annotations

import numpy as np

from cltess.scene import Scene

from . import closed_torus_grid, random_patches, random_pn_triangles, torus


def random_source(rng: np.random.Generator, kind, count: int) -> np.ndarray:
    """(count, rows, 4) float32 stage-1 input of a kind, random (rational weights, bent normals)."""
    if kind.name == "bezier":
        return random_patches(rng, count).reshape(count, 16, 4).astype(np.float32)
    if kind.name == "pn":
        return random_pn_triangles(rng, count).astype(np.float32)
    raise NotImplementedError(f"no random input for kind {kind.name}: add it to tests/support/kinds.py")


def closed_scene(rng: np.random.Generator, kind) -> tuple[Scene, float]:
    """A closed surface of the kind, and a tolerance at which its patches meet with different
    factors, none saturated."""
    if kind.name == "bezier":
        return closed_torus_grid(rng, 6, 4), 0.1
    if kind.name == "pn":
        return Scene.from_trimesh(torus(), name="torus"), 0.003
    raise NotImplementedError(f"no closed scene for kind {kind.name}: add it to tests/support/kinds.py")


def kind_for(pattern):
    """A registered kind of the pattern's domain (to run the pattern's device code)."""
    from cltess.kinds import KINDS

    return next(kind for kind in KINDS if kind.domain == pattern.domain)
