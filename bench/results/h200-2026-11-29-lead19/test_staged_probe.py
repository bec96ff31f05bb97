import numpy as np
import pytest
from support import random_patches
from support.factors import random_factors
from test_vertices import device_vertices
from test_work_points import CASES, SCENES, same
from cltess.backends.opencl import tessellator as opencl
from cltess.io import load_scene


@pytest.fixture(scope="module")
def staged(tessellator):
    return opencl.Tessellator(tessellator.device, work="staged-prep")


@pytest.mark.parametrize("per_group", [1, 3, None])
@pytest.mark.parametrize("name, options", CASES)
def test_cases(tessellator, staged, name, options, per_group):
    staged.patches_per_group = per_group
    scene = load_scene(SCENES / name)
    expected = opencl.Tessellator(tessellator.device, work="rows-prep").tessellate(scene, **options)
    got = staged.tessellate(scene, **options)
    same(expected, got)


@pytest.mark.parametrize("fd", [False, True])
def test_random(tessellator, staged, rng, fd):
    patches = random_patches(rng, 300, spread=1.0)
    factors = random_factors(rng, 300, high=64)
    staged.patches_per_group = 5
    expected = device_vertices(opencl.Tessellator(tessellator.device, work="rows-prep"), patches, factors, fd)
    got = device_vertices(staged, patches, factors, fd)
    for field in expected:
        assert np.array_equal(expected[field], got[field]), field
