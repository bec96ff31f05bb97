"""Stage 4's normals of every pattern on multi-patch scenes, on the test's device against the NumPy
backend: unit length and the reference's direction at every vertex.

Positions, uv and triangles can be bitwise right while the normals are not: on Intel's CPU runtime
ESC's normals came out scrambled across the vector lanes (patches p % 4 != 0) while everything
else matched (docs/esc.md, "Normals on Intel's CPU runtime").  Many patches per scene, so every
lane of a vectorised stage 4 is covered."""
from pathlib import Path

import numpy as np
import pytest

from cltess.backends.numpy import NumpyBackend
from cltess.io import load_scene
from cltess.request import Request

SCENES = Path(__file__).resolve().parent.parent / "scenes"

#: Every pattern family and pattern that runs on Bezier patches (cltess.patterns.PATTERNS).
PATTERNS = ("esc", "transition", "semi_uniform", "sd2")
UNIT = 1e-4        # | |n| - 1 |: normals are normalised in float32
SAME_DIRECTION = 0.999  # n . n_reference: float32 against float64 at the same domain point


@pytest.mark.parametrize("pattern", PATTERNS)
@pytest.mark.parametrize("scene_name, eps", [("teapot.bez", 0.1), ("teacup.bez", 0.02)])
def test_normals_are_unit_and_equal_the_numpy_backend(tessellator, pattern, scene_name, eps):
    scene = load_scene(SCENES / scene_name)
    request = Request.of(eps=eps, pattern=pattern)
    device, host = tessellator.tessellate(scene, request), NumpyBackend().tessellate(scene, request)
    assert np.abs(device.uv - host.uv).max() < 1e-6  # the same vertices, in the same order
    length = np.linalg.norm(device.normals, axis=1)
    along = np.einsum("ij,ij->i", device.normals, host.normals)
    bad = (np.abs(length - 1.0) > UNIT) | (along < SAME_DIRECTION)
    patches = np.unique(device.patch_ids[bad])
    assert not bad.any(), (f"{pattern} on {scene_name}: {bad.sum()} of {len(bad)} normals wrong, on patches "
                           f"{patches[:12].tolist()} (|n| down to {length.min():.3f})")
