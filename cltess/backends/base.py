"""What every backend offers (docs/extending.md, "A backend"): stages 1-3 for a whole scene as a
plan, then stages 4-5 for any range of its patches.  The OpenCL backend
(``cltess.backends.opencl.Tessellator``) and the NumPy one (``cltess.backends.numpy``) both do."""
from __future__ import annotations

from typing import Protocol

from ..request import Request
from ..scene import Scene
from ..tessellation import Tessellation


class Plan(Protocol):
    """Stages 1-3 done: the final factors and the offsets, wherever the backend keeps them."""

    num_patches: int
    num_vertices: int
    num_indices: int
    stats: dict


class Backend(Protocol):
    name: str

    def plan(self, scene: Scene, request: Request) -> Plan:
        """Stages 1-3: factors, crack-free factors, counts and offsets of every patch."""

    def emit(self, plan: Plan, first: int, last: int) -> Tessellation:
        """Stages 4-5 for patches first .. last-1: their vertices and triangles, the triangles
        numbering the vertices globally (so batches concatenate to the single-pass mesh)."""
