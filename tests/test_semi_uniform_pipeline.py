"""The semi-uniform patterns through the pipeline (issue 11): on closed scenes, welding bitwise
equal positions gives a watertight, consistently wound mesh with no T-junction
(cltess.checks.t_junctions), forward differencing on and off, with edges snapped below their
patch's level; the OpenCL and NumPy backends agree on the factors and counts; and a transition
request leaves the pattern out of stage 1 (factors not rounded)."""
from pathlib import Path

import numpy as np
import pytest

from cltess.backends.numpy import NumpyBackend
from cltess.checks import t_junctions
from cltess.formats import load_scene
from cltess.request import Request
from cltess.scene import Scene
from support import closed_torus_grid, genus2, icosphere, torus, weld_exact

SCENES = Path(__file__).resolve().parent.parent / "scenes"


def snapped_patches(factors, edges):
    f = factors[:, :edges]
    return int(((f.min(1) < f.max(1)) & (f.min(1) > 0)).sum())


def check_closed(tessellator, scene, edges, **options):
    """Watertight, consistently wound, no T-junction; returns (welded mesh, snapped patches)."""
    tess = tessellator.tessellate(scene, pattern="semi_uniform", **options)
    assert tess.stats["saturated"] == 0
    assert sum(tess.stats["patch_levels"]) == scene.num_patches - tess.stats["culled"]
    mesh = weld_exact(tess.positions, tess.triangles)
    assert mesh.is_watertight, f"{scene.name}: {len(mesh.edges) - 2 * len(mesh.edges_unique)} unmatched edge uses"
    assert mesh.is_winding_consistent
    assert t_junctions(tess.positions, tess.triangles, tess.object_ids).tolist() == []
    return mesh, snapped_patches(tess.factors, edges)


@pytest.mark.parametrize("fd", [True, False], ids=["fd", "direct"])
def test_bezier_closed_scenes_are_watertight_without_t_junctions(tessellator, rng, fd):
    cases = [(load_scene(SCENES / "sphere.bpt"), dict(eps=5e-2)), (load_scene(SCENES / "sphere.bpt"), dict(eps=1e-3)),
             (load_scene(SCENES / "torus.bpt"), dict(eps=1e-2)),
             (closed_torus_grid(rng, 14, 9, noise=0.15), dict(eps=0.3, max_factor=512, max_level=9)),
             (closed_torus_grid(rng, 14, 9, noise=0.15), dict(eps=0.1, max_factor=512, max_level=9))]
    snapped = []
    for scene, options in cases:
        mesh, count = check_closed(tessellator, scene, 4, forward_differencing=fd, **options)
        snapped.append(count)
        if scene.name == "sphere":
            assert abs(mesh.volume - 4 / 3 * np.pi) < 4 * np.pi * options["eps"]
    assert snapped[0] > 0 and all(count > 0 for count in snapped[2:]), snapped


@pytest.mark.parametrize("fd", [True, False], ids=["fd", "direct"])
@pytest.mark.parametrize("eps", [1e-2, 3e-3])
def test_pn_closed_meshes_are_watertight_without_t_junctions(tessellator, eps, fd):
    snapped = 0
    for name, mesh, genus in (("icosphere", icosphere(2), 0), ("torus", torus(), 1), ("genus 2", genus2(), 2)):
        welded, count = check_closed(tessellator, Scene.from_trimesh(mesh, name=name), 3, eps=eps,
                                     forward_differencing=fd)
        assert welded.euler_number == 2 - 2 * genus and welded.volume > 0
        snapped += count
    assert snapped > 0


def test_backends_agree(tessellator):
    """The NumPy backend's stage 1-3 mirror (dyadic rounding, crack-free max, the pattern's
    counts) gives the device's factors and counts on a scene of both kinds."""
    from oclgrind_scenarios import icosphere_mesh

    teapot = load_scene(SCENES / "teapot.bez")
    scene = Scene(teapot.patches, teapot.object_ids, None, "mixed", [icosphere_mesh(object_id=7)])
    for max_level in (6, 3):
        request = Request.of(eps=5e-3, pattern="semi_uniform", max_level=max_level)
        plan = tessellator.plan(scene, request)
        expected = NumpyBackend().plan(scene, request)
        assert np.array_equal(plan.host_factors(), expected.factors)
        assert np.array_equal(plan.vertex_offsets.get(), expected.vertex_offsets)
        assert np.array_equal(plan.index_offsets.get(), expected.index_offsets)
        assert plan.stats["patch_levels"] == expected.stats["patch_levels"]
        assert plan.stats["saturated"] == expected.stats["saturated"]
    assert plan.stats["saturated"] > 0 and len(plan.stats["patch_levels"]) == 4  # capped at level 3


def test_family_and_pattern_names(tessellator):
    """"semi_uniform" picks each kind's semi-uniform pattern; a pattern name only its domain's
    kind (the other keeps its own, unrounded); "transition" is the default."""
    from oclgrind_scenarios import icosphere_mesh

    teapot = load_scene(SCENES / "teapot.bez")
    scene = Scene(teapot.patches[:4], teapot.object_ids[:4], None, "mixed", [icosphere_mesh()])
    both = tessellator.plan(scene, Request.of(eps=5e-3, pattern="semi_uniform"))
    assert [p.pattern.name for p in both.parts] == ["quad_semi_uniform", "tri_semi_uniform"]
    quads = tessellator.plan(scene, Request.of(eps=5e-3, pattern="quad_semi_uniform"))
    assert [p.pattern.name for p in quads.parts] == ["quad_semi_uniform", "tri_transition"]
    plain = tessellator.plan(scene, Request.of(eps=5e-3))
    assert [p.pattern.name for p in plain.parts] == ["quad_transition", "tri_transition"]
    f, g = quads.host_factors(), plain.host_factors()
    assert np.array_equal(f[4:], g[4:]) and not np.array_equal(f[:4], g[:4])
    assert "patch_levels" not in plain.stats
    with pytest.raises(ValueError, match="unknown pattern"):
        Request.of(eps=1e-3, pattern="uniform")
    for bad in (-1, 15, 2.0, True):
        with pytest.raises(ValueError, match="max_level"):
            Request.of(eps=1e-3, max_level=bad)
