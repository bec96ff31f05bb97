"""The error bound with the semi-uniform patterns (issue 11), through the pipeline
(``pattern="semi_uniform"``): |surface(u,v) - mesh(u,v)| <= eps sampled densely inside every
output triangle (snapped ones included), on the scenes of tests/test_bound.py.  Stage 1 rounds
every factor up to 2^p_e (no cap reached: max_level >= log2 max_factor), so each edge keeps at
least the factor its bound asks for; the snapped triangles along an edge below the patch's
level are the ones the bound must also hold for."""
from pathlib import Path

import numpy as np
import pytest

from cltess import reference
from cltess.io import load_scene
from cltess.scene import Camera, Scene
from conftest import BOUND_RATIOS
from support import as_float32, bound_ratio, closed_torus_grid, random_patches

SCENES = Path(__file__).resolve().parent.parent / "scenes"


def snapped_patches(factors, edges):
    """Patches with an edge below the patch's level (the snap at work)."""
    f = factors[:, :edges]
    return int(((f.min(1) < f.max(1)) & (f.min(1) > 0)).sum())


def check_bound(tessellator, scene, name, eps=None, pixels=None, max_factor=64, pn=False, **options):
    max_level = max(6, int(np.ceil(np.log2(max_factor))))
    tess = tessellator.tessellate(scene, eps=eps, pixels=pixels, max_factor=max_factor, pattern="semi_uniform",
                                  max_level=max_level, **options)
    assert tess.stats["saturated"] == 0, "choose a tolerance the factors can meet"
    factors = tess.factors[tess.factors[:, 0] > 0]
    assert (factors & (factors - 1) == 0).all(), "dyadic records"
    if pn:
        from cltess.pipeline import PN

        patches = reference.pn_control_points(PN.prepare(scene, options.get("sharp_edges", "straight"))
                                              .source.astype(np.float64))
        surface, tolerances = reference.pn_surface_points, reference.pn_tolerances
    else:
        patches, surface, tolerances = as_float32(scene.patches), reference.surface_points, reference.patch_tolerances
    if pixels is not None:
        eps, culled = tolerances(patches, pixels=pixels, camera=scene.camera)
        assert np.array_equal(tess.factors[:, 0] == 0, culled)
    snapped = snapped_patches(tess.factors, 3 if pn else 4)
    ratio = bound_ratio(patches, tess, eps, surface=surface)
    BOUND_RATIOS[f"semi-uniform {name} ({tess.num_triangles} triangles, {snapped} snapped patches)"] = ratio
    assert ratio <= 1.0
    return tess, snapped


@pytest.mark.parametrize("eps", [0.05, 0.005])
def test_bound_on_the_teapot(tessellator, eps):
    _, snapped = check_bound(tessellator, load_scene(SCENES / "teapot.bez"), f"teapot eps={eps}", eps=eps)
    assert snapped > 0


@pytest.mark.parametrize("name", ["teacup.bez", "teaspoon.bez", "sphere.bpt", "torus.bpt"])
def test_bound_on_bundled_models(tessellator, name):
    scene = load_scene(SCENES / name)
    size = np.ptp(scene.points.reshape(-1, 3), axis=0).max()
    check_bound(tessellator, scene, f"{name} eps={size * 1e-3:.2g}", eps=size * 1e-3)


@pytest.mark.parametrize("eps", [0.3, 0.1])
def test_bound_on_a_closed_grid_with_random_weights(tessellator, rng, eps):
    _, snapped = check_bound(tessellator, closed_torus_grid(rng, 10, 6, noise=0.1), f"random torus grid eps={eps}",
                             eps=eps, max_factor=512)
    assert snapped > 0


def test_bound_on_random_rational_patches(tessellator, rng):
    scene = Scene(random_patches(rng, 20), np.zeros(20, np.int32), name="random patches")
    check_bound(tessellator, scene, "random rational patches eps=0.2", eps=0.2, max_factor=4096)


def test_bound_in_screen_space_with_culling(tessellator, rng):
    patches = random_patches(rng, 150, spread=3.0)  # weights 0.2 to 5
    camera = Camera(eye=np.array([12.0, 2.0, 1.0]), target=np.zeros(3), fov_y_deg=30, width=200, height=150)
    scene = Scene(patches, np.zeros(150, np.int32), camera, name="random patches")
    tess, snapped = check_bound(tessellator, scene, "random patches, 16 px", pixels=16.0, max_factor=512)
    assert 0 < tess.stats["culled"] < 150 and snapped > 0


@pytest.mark.parametrize("eps", [3e-2, 3e-3])
def test_pn_bound_on_an_icosphere_a_torus_and_a_genus_2_mesh(tessellator, eps):
    from support import genus2, icosphere, torus

    snapped = 0
    for name, mesh in (("icosphere", icosphere(2)), ("torus", torus()), ("genus 2", genus2())):
        scene = Scene.from_trimesh(mesh, name=name)
        snapped += check_bound(tessellator, scene, f"PN {name} eps={eps}", eps=eps, pn=True)[1]
    assert snapped > 0


def test_pn_bound_on_a_noisy_mesh_with_sharp_edges(tessellator, rng):
    from support import icosphere, split_some_vertices

    mesh = icosphere(2)
    mesh = type(mesh)(mesh.vertices * rng.uniform(0.8, 1.2, (len(mesh.vertices), 1)), mesh.faces, process=False)
    mesh = split_some_vertices(rng, mesh, fraction=0.3, noise=0.3)
    tess, snapped = check_bound(tessellator, Scene.from_trimesh(mesh, name="noisy sphere"),
                                "PN noisy split sphere eps=0.003", eps=0.003, pn=True)
    assert tess.stats["sharp_edges"] > 20 and snapped > 0
