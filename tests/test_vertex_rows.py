"""Stage 4 a work-item per (patch, row) (stages/vertex_rows.cl, Tessellator(rows_in_parallel=True)):
bitwise the per-patch kernel's output, for every kind and pattern, whatever the work-items per
patch (issue 15)."""
from pathlib import Path

import numpy as np
import pytest

from cltess.backends.opencl import tessellator as opencl
from cltess.io import load_scene
from cltess.scene import Camera
from cltess.tessellation import HOST_FIELDS

SCENES = Path(__file__).resolve().parent.parent / "scenes"
CASES = [("teapot.bez", dict(eps=1e-3)), ("teapot.bez", dict(eps=1e-3, forward_differencing=False)),
         ("tea_table.json", dict(pixels=0.5)), ("sphere.bpt", dict(eps=1e-3, pattern="semi_uniform")),
         ("cylinder.stl", dict(eps=1e-3)), ("cylinder.stl", dict(eps=1e-3, pattern="semi_uniform")),
         ("torus.bpt", dict(eps=1e-4, max_factor=100)),
         # SD-2 from a level function: fans in the tie zone, whose centres stage 4 puts on chords
         ("cylinder.stl", dict(eps=1e-3, pattern="sd2", level_function="depth", level_factors=(1.0, 7.0),
                               camera=Camera(eye=np.array([3.0, 1.0, 2.0]), target=np.zeros(3))))]


@pytest.fixture(scope="module")
def by_rows(tessellator):
    rows = opencl.Tessellator(tessellator.device, rows_in_parallel=True)
    return rows


@pytest.mark.parametrize("rows_per_patch", [1, 3, opencl.MAX_ROWS_PER_PATCH])
@pytest.mark.parametrize("name, options", CASES)
def test_rows_in_parallel_is_bitwise_the_per_patch_kernel(tessellator, by_rows, monkeypatch, name, options,
                                                           rows_per_patch):
    monkeypatch.setattr(opencl, "MAX_ROWS_PER_PATCH", rows_per_patch)  # few: the last work-item does the rest
    scene = load_scene(SCENES / name)
    expected, got = tessellator.tessellate(scene, **options), by_rows.tessellate(scene, **options)
    assert expected.num_triangles > 0
    for field in HOST_FIELDS:
        assert np.array_equal(getattr(expected, field), getattr(got, field)), field
