"""The whole pipeline (cltess/pipeline.py) on real scenes: independent evaluator, collapsed
edges, counts versus emitted data, batches, bad tolerances."""
from pathlib import Path

import numpy as np
import pytest

from cltess import reference
from cltess.io import load_scene
from support import as_float32, closed_torus_grid

SCENES = Path(__file__).resolve().parent.parent / "scenes"


@pytest.fixture(scope="module")
def teapot():
    return load_scene(SCENES / "teapot.bez")


def test_positions_agree_with_geomdl_on_the_teapot(tessellator, teapot):
    """geomdl evaluates each patch as a clamped degree-3 B-spline surface: an independent evaluator."""
    from geomdl import BSpline

    tess = tessellator.tessellate(teapot, eps=0.01)
    worst = 0.0
    for p in range(teapot.num_patches):
        surface = BSpline.Surface()
        surface.degree_u = surface.degree_v = 3
        # geomdl's first index runs along u: control point (u=i, v=j) = points[j, i]
        surface.ctrlpts2d = [[list(teapot.points[p, j, i]) for j in range(4)] for i in range(4)]
        surface.knotvector_u = surface.knotvector_v = [0, 0, 0, 0, 1, 1, 1, 1]
        mine = tess.patch_ids == p
        expected = np.array(surface.evaluate_list([tuple(map(float, uv)) for uv in tess.uv[mine]]))
        worst = max(worst, np.abs(tess.positions[mine] - expected).max())
    print(f"teapot vs geomdl: worst position difference {worst:.2e}")
    assert worst < 2e-6 * np.abs(teapot.points).max()


def test_collapsed_edges_give_finite_unit_normals(tessellator, teapot):
    tess = tessellator.tessellate(teapot, eps=0.005)
    assert np.isfinite(tess.normals).all()
    assert np.allclose(np.linalg.norm(tess.normals, axis=1), 1, atol=1e-5)
    # The lid's top and the bottom's centre lie on the z axis; their normals point along it.
    on_axis = np.linalg.norm(tess.positions[:, :2], axis=1) < 1e-6
    assert on_axis.sum() >= 8
    assert (np.abs(tess.normals[on_axis, 2]) > 0.999).all()


def test_normals_point_like_the_reference(tessellator, teapot):
    tess = tessellator.tessellate(teapot, eps=0.01, forward_differencing=False)
    expected = reference.tessellate(as_float32(teapot.patches), tess.factors)
    assert (np.sum(tess.normals * expected["normals"], axis=1) > 0.999).all()


def test_counts_agree_with_emitted_data_and_indices_are_in_range(tessellator, rng):
    scene = closed_torus_grid(rng, 9, 5, noise=0.2)
    tess = tessellator.tessellate(scene, eps=0.05)
    vertex_counts, index_counts = reference.counts(tess.factors)
    assert np.array_equal(np.bincount(tess.patch_ids, minlength=scene.num_patches), vertex_counts)
    assert len(tess.triangles) * 3 == index_counts.sum() == 3 * tess.stats["triangles"]
    assert tess.triangles.max() < len(tess.positions)
    # Every triangle's vertices come from one patch, and none is degenerate (no patch here is).
    owner = tess.patch_ids[tess.triangles]
    assert (owner == owner[:, :1]).all()
    assert (np.bincount(owner[:, 0], minlength=scene.num_patches) * 3 == index_counts).all()
    p = tess.positions[tess.triangles].astype(float)
    area = np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
    assert area.min() > 0


def test_only_patches_with_a_collapsed_edge_have_degenerate_triangles(tessellator, teapot):
    tess = tessellator.tessellate(teapot, eps=0.01)
    p = tess.positions[tess.triangles].astype(float)
    area = np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
    degenerate_patches = set(tess.patch_ids[tess.triangles[area == 0, 0]].tolist())
    collapsed = {p for p in range(teapot.num_patches)
                 if any(np.ptp(c, axis=0).max() == 0 for c in
                        (teapot.points[p, 0], teapot.points[p, 3], teapot.points[p, :, 0], teapot.points[p, :, 3]))}
    assert degenerate_patches <= collapsed and collapsed


def test_batches_concatenate_to_the_single_pass_result(tessellator, rng):
    scene = closed_torus_grid(rng, 8, 5, noise=0.2)
    whole = tessellator.tessellate(scene, eps=0.05)
    plan, batches = tessellator.tessellate_in_batches(scene, max_output_bytes=whole.num_vertices * 8, eps=0.05)
    batches = list(batches)
    assert len(batches) >= 5
    for name in ("positions", "normals", "uv", "patch_ids", "object_ids", "triangles", "factors"):
        joined = np.concatenate([getattr(b, name) for b in batches])
        assert np.array_equal(joined, getattr(whole, name)), name


def test_a_cap_smaller_than_one_patch_is_a_clear_error(tessellator, teapot):
    with pytest.raises(MemoryError, match="patch .* alone needs"):
        plan, batches = tessellator.tessellate_in_batches(teapot, max_output_bytes=1000, eps=0.001)


@pytest.mark.parametrize("kwargs, message", [
    ({"eps": 0.0}, "eps must be"), ({"eps": -1.0}, "eps must be"), ({"eps": float("nan")}, "eps must be"),
    ({}, "exactly one"), ({"eps": 0.1, "pixels": 1.0}, "exactly one"),
    ({"pixels": 1.0}, "needs a camera"), ({"eps": 0.1, "max_factor": 0}, "max_factor")])
def test_bad_tolerances_are_refused(tessellator, teapot, kwargs, message):
    with pytest.raises(ValueError, match=message):
        tessellator.tessellate(teapot, **kwargs)


@pytest.mark.parametrize("centre", [(0.0, 0.0, 0.0), (20.0, 20.0, 20.0), (300.0, -100.0, 50.0)])
def test_normals_at_collapsed_edges_far_from_the_origin(tessellator, centre):
    """The sphere's poles are collapsed edges; moved far away, float32 makes their four control
    points only nearly equal.  The limit normal (second derivatives) must still point outwards:
    a step inwards gave 1% of the normals wrong, some flipped."""
    from cltess.scene import Scene

    sphere = load_scene(SCENES / "sphere.bpt")
    scene = Scene.from_points(sphere.points * 0.2 + np.array(centre), sphere.weights)
    tess = tessellator.tessellate(scene, eps=1e-4, max_factor=128)
    outwards = tess.positions - np.array(centre, np.float32)
    outwards /= np.linalg.norm(outwards, axis=1, keepdims=True)
    error = np.linalg.norm(tess.normals - outwards, axis=1)
    print(f"sphere at {centre}: worst normal error {error.max():.1e}")
    assert error.max() < 0.01


def test_a_scene_is_prepared_once_and_cannot_change_under_its_cache(tessellator, monkeypatch):
    """Adjacency and uploads are cached on the scene (the benchmark found them dominating end
    to end); the arrays they come from are read-only, so the cache cannot go stale."""
    from cltess.crack import adjacency  # the Bézier kind's groups: adjacency.scene_edge_groups

    calls = []
    real = adjacency.edge_groups
    monkeypatch.setattr(adjacency, "edge_groups", lambda patches: calls.append(1) or real(patches))
    scene = load_scene(SCENES / "teapot.bez")
    first = tessellator.tessellate(scene, eps=0.01)
    second = tessellator.tessellate(scene, eps=0.002)
    assert len(calls) == 1 and second.num_triangles > first.num_triangles
    with pytest.raises(ValueError, match="read-only"):
        scene.patches[0, 0, 0, 0] = 1.0
    moved = scene.patches.copy()
    moved[..., 2] += moved[..., 3]  # z + 1 for every control point
    scene.patches = moved  # new arrays: prepared afresh
    third = tessellator.tessellate(scene, eps=0.01)
    assert len(calls) == 2 and np.allclose(third.positions[:, 2], first.positions[:, 2] + 1, atol=1e-5)
