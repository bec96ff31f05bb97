"""The error bound is kept: |surface(u,v) - mesh(u,v)| <= eps, sampled densely inside every
output triangle (transition strips included), both taken at the same (u, v)."""
from pathlib import Path

import numpy as np
import pytest

from cltess import reference
from cltess.formats import load_scene
from cltess.scene import Camera, Scene
from conftest import BOUND_RATIOS
from support import as_float32, bound_ratio, closed_torus_grid, random_patches

SCENES = Path(__file__).resolve().parent.parent / "scenes"


def check_bound(tessellator, scene, name, eps=None, pixels=None, max_factor=64):
    tess = tessellator.tessellate(scene, eps=eps, pixels=pixels, max_factor=max_factor)
    assert tess.stats["saturated"] == 0, "choose a tolerance the factors can meet"
    if pixels is not None:
        eps, culled = reference.patch_tolerances(as_float32(scene.patches), pixels=pixels, camera=scene.camera)
        assert np.array_equal(tess.factors[:, 0] == 0, culled)
    final = tess.factors
    transition = ((final[:, 0] != final[:, 2]) | (final[:, 1] != final[:, 3])).sum()
    ratio = bound_ratio(as_float32(scene.patches), tess, eps)
    BOUND_RATIOS[f"{name} ({tess.num_triangles} triangles, {transition} patches with transitions)"] = ratio
    print(f"{name}: worst ratio {ratio:.4f}, {transition} patches with transition strips")
    assert ratio <= 1.0
    return tess


@pytest.mark.parametrize("eps", [0.05, 0.005])
def test_bound_on_the_teapot(tessellator, eps):
    check_bound(tessellator, load_scene(SCENES / "teapot.bez"), f"teapot eps={eps}", eps=eps)


@pytest.mark.parametrize("name", ["teacup.bez", "teaspoon.bez", "sphere.bpt"])
def test_bound_on_bundled_models(tessellator, name):
    scene = load_scene(SCENES / name)
    size = np.ptp(scene.points.reshape(-1, 3), axis=0).max()
    check_bound(tessellator, scene, f"{name} eps={size * 1e-3:.2g}", eps=size * 1e-3)


@pytest.mark.parametrize("eps", [0.3, 0.1])
def test_bound_on_a_closed_grid_with_random_weights(tessellator, rng, eps):
    tess = check_bound(tessellator, closed_torus_grid(rng, 10, 6, noise=0.1), f"random torus grid eps={eps}",
                       eps=eps, max_factor=512)
    assert ((tess.factors[:, 0] != tess.factors[:, 2]) | (tess.factors[:, 1] != tess.factors[:, 3])).any()


def test_bound_in_screen_space_with_culling(tessellator, rng):
    patches = random_patches(rng, 150, spread=3.0)  # weights 0.2 to 5
    camera = Camera(eye=np.array([12.0, 2.0, 1.0]), target=np.zeros(3), fov_y_deg=30, width=200, height=150)
    scene = Scene(patches, np.zeros(150, np.int32), camera, name="random patches")
    tess = check_bound(tessellator, scene, "random patches, 16 px", pixels=16.0, max_factor=512)
    assert 0 < tess.stats["culled"] < 150
