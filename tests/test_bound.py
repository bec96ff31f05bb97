"""The error bound is kept: |surface(u,v) - mesh(u,v)| <= eps, sampled densely inside every
output triangle, both taken at the same (u, v), with every pattern family whose factors come from
the bound: the transition pattern (its transition strips included) and the semi-uniform patterns
(issue 11: stage 1 rounds every factor up to 2^p_e, no cap reached since max_level >= log2
max_factor, so each edge keeps at least the factor its bound asks for; the snapped triangles
along an edge below the patch's level are the ones the bound must also hold for)."""
from pathlib import Path

import numpy as np
import pytest

from cltess import reference
from cltess.io import load_scene
from cltess.scene import Camera, Scene
from conftest import BOUND_RATIOS
from support import as_float32, bound_ratio, closed_torus_grid, random_patches

SCENES = Path(__file__).resolve().parent.parent / "scenes"


@pytest.fixture(params=["transition", "semi_uniform"])
def pattern(request):
    return request.param


def uneven_patches(factors, edges):
    """Patches whose edge factors differ: transition strips, or (semi-uniform) snapped edges."""
    f = factors[:, :edges]
    return int(((f.min(1) < f.max(1)) & (f.min(1) > 0)).sum())


def check_bound(tessellator, scene, name, pattern, eps=None, pixels=None, max_factor=64, pn=False, **options):
    """Tessellates scene with pattern, checks the bound; returns the tessellation and how many
    patches have uneven edge factors (the triangles the plain grid does not have)."""
    if pattern == "semi_uniform":
        options["max_level"] = max(6, int(np.ceil(np.log2(max_factor))))
    tess = tessellator.tessellate(scene, eps=eps, pixels=pixels, max_factor=max_factor, pattern=pattern, **options)
    assert tess.stats["saturated"] == 0, "choose a tolerance the factors can meet"
    if pattern == "semi_uniform":
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
    uneven = uneven_patches(tess.factors, 3 if pn else 4)
    ratio = bound_ratio(patches, tess, eps, surface=surface)
    label = f"{'PN ' if pn else ''}{name}, {pattern}"
    BOUND_RATIOS[f"{label} ({tess.num_triangles} triangles, {uneven} with uneven edges)"] = ratio
    print(f"{label}: worst ratio {ratio:.4f}, {uneven} patches with uneven edges")
    assert ratio <= 1.0
    return tess, uneven


@pytest.mark.parametrize("eps", [0.05, 0.005])
def test_bound_on_the_teapot(tessellator, pattern, eps):
    _, uneven = check_bound(tessellator, load_scene(SCENES / "teapot.bez"), f"teapot eps={eps}", pattern, eps=eps)
    assert uneven > 0


@pytest.mark.parametrize("name", ["teacup.bez", "teaspoon.bez", "sphere.bpt", "torus.bpt"])
def test_bound_on_bundled_models(tessellator, pattern, name):
    scene = load_scene(SCENES / name)
    size = np.ptp(scene.points.reshape(-1, 3), axis=0).max()
    check_bound(tessellator, scene, f"{name} eps={size * 1e-3:.2g}", pattern, eps=size * 1e-3)


@pytest.mark.parametrize("eps", [0.3, 0.1])
def test_bound_on_a_closed_grid_with_random_weights(tessellator, pattern, rng, eps):
    _, uneven = check_bound(tessellator, closed_torus_grid(rng, 10, 6, noise=0.1), f"random torus grid eps={eps}",
                            pattern, eps=eps, max_factor=512)
    assert uneven > 0


@pytest.mark.parametrize("eps", [0.2, 0.03])
def test_bound_on_random_rational_patches(tessellator, pattern, rng, eps):
    scene = Scene(random_patches(rng, 20), np.zeros(20, np.int32), name="random patches")
    check_bound(tessellator, scene, f"random rational patches eps={eps}", pattern, eps=eps, max_factor=4096)


def test_bound_in_screen_space_with_culling(tessellator, pattern, rng):
    patches = random_patches(rng, 150, spread=3.0)  # weights 0.2 to 5
    camera = Camera(eye=np.array([12.0, 2.0, 1.0]), target=np.zeros(3), fov_y_deg=30, width=200, height=150)
    scene = Scene(patches, np.zeros(150, np.int32), camera, name="random patches")
    tess, uneven = check_bound(tessellator, scene, "random patches, 16 px", pattern, pixels=16.0, max_factor=512)
    assert 0 < tess.stats["culled"] < 150 and uneven > 0


# --- PN triangles: the surface is the PN patch of each input triangle, at the same (u, v) --------

@pytest.mark.parametrize("eps", [3e-2, 3e-3])
def test_pn_bound_on_an_icosphere_a_torus_and_a_genus_2_mesh(tessellator, pattern, eps):
    from support import genus2, icosphere, torus

    uneven = sum(check_bound(tessellator, Scene.from_trimesh(mesh, name=name), f"{name} eps={eps}", pattern,
                             eps=eps, pn=True)[1]
                 for name, mesh in (("icosphere", icosphere(2)), ("torus", torus()), ("genus 2", genus2())))
    assert uneven > 0


@pytest.mark.parametrize("sharp_edges", ["straight", "average", "keep"])
def test_pn_bound_on_a_noisy_mesh_with_sharp_edges(tessellator, pattern, rng, sharp_edges):
    """Random vertex noise (factors vary a lot between neighbours: many uneven edges) and split
    vertices with perturbed normals (sharp edges), under each sharp-edge choice."""
    from support import icosphere, split_some_vertices

    mesh = icosphere(2)
    mesh = type(mesh)(mesh.vertices * rng.uniform(0.8, 1.2, (len(mesh.vertices), 1)), mesh.faces, process=False)
    mesh = split_some_vertices(rng, mesh, fraction=0.3, noise=0.3)
    tess, uneven = check_bound(tessellator, Scene.from_trimesh(mesh, name="noisy sphere"),
                               f"noisy split sphere eps=0.003 sharp={sharp_edges}", pattern, eps=0.003, pn=True,
                               sharp_edges=sharp_edges)
    assert tess.stats["sharp_edges"] > 20 and uneven > 0


def test_pn_bound_in_screen_space_with_culling(tessellator, pattern):
    from support import genus2

    camera = Camera(eye=np.array([2.5, -2.0, 1.5]), target=np.array([2.5, 1.5, 0.5]), fov_y_deg=40,
                    width=400, height=300)
    scene = Scene.from_trimesh(genus2(), camera=camera, name="genus 2")
    tess, uneven = check_bound(tessellator, scene, "genus-2, 0.5 px, camera inside", pattern, pixels=0.5,
                               max_factor=256, pn=True)
    assert 0 < tess.stats["culled"] < scene.num_patches and uneven > 0


def far_pixel_scene(tmp_path, offset):
    """The teapot with a camera 10 units away, both moved by (offset, offset, offset)."""
    import json

    path = tmp_path / f"far{offset:g}.json"
    path.write_text(json.dumps({
        "objects": [{"file": str(SCENES / "teapot.bez"),
                     "transform": [[1, 0, 0, offset], [0, 1, 0, offset], [0, 0, 1, offset], [0, 0, 0, 1]]}],
        "camera": {"eye": [offset, offset - 10.0, offset + 3.0], "target": [offset, offset, offset + 1.0],
                   "fov_y_deg": 45.0, "width": 400, "height": 300}}))
    return path


@pytest.mark.parametrize("offset, pixels, warned", [(0.0, 0.2, False), (1e5, 8.0, False), (1e5, 0.2, True)])
def test_pixels_far_from_the_origin_hold_the_bound_or_warn_before_running(tessellator, capsys, tmp_path,
                                                                          offset, pixels, warned):
    """Issue 9: far from the origin a pixel tolerance can ask for less than float32 output can
    hold; --pixels is checked per patch (cltess.bound.tolerances_below_float32) and warned
    about before the run, and where it is not warned about the bound holds."""
    from cltess.cli import main
    from cltess.io import load_scene as load

    path = far_pixel_scene(tmp_path, offset)
    out = tmp_path / "m.npz"
    code = main(["tessellate", str(path), "--pixels", str(pixels), "-q", "-o", str(out)])
    err = capsys.readouterr().err
    assert code == 0, err
    assert ("float32 steps" in err) == warned, err
    if warned:
        assert f"cltess: warning: {path}: --pixels {pixels:g} gives" in err
    scene = load(path)
    tess = tessellator.tessellate(scene, pixels=pixels, max_factor=4096)
    eps, _ = reference.patch_tolerances(as_float32(scene.patches), pixels=pixels, camera=scene.camera)
    ratio = bound_ratio(scene.patches, tess, eps)
    assert warned or ratio <= 1.0, ratio
    if warned:  # those patches get FLOAT32_TOLERANCE_STEPS float32 steps instead, and the warning says so
        assert "float32 steps instead of a finer tolerance" in err, err
