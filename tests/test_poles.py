"""Issue 9 item 2: collapsed edges (a sphere's poles, the teapot lid's centre) are watertight.

A collapsed edge's four control points are one point with different weights.  The host marks it
(cltess.crack.adjacency: EdgeGroups.collapsed_edges), stage 2 stores its factor negated, every
point on it is its first corner, every corner projects to exactly its float32 point
(cltess.scene.exact_corners), and the pattern leaves out the triangles with a side on it
(kernels/common.h patch_factors).  So exact welding gives closed meshes with one position per
pole and no degenerate triangles, also far from the origin."""
from pathlib import Path

import numpy as np
import pyopencl.array as cl_array
import pytest

from cltess.backends.numpy import NumpyBackend
from cltess.bound import worst_bound_ratio
from cltess.crack.adjacency import edge_groups
from cltess.formats import load_scene
from cltess.patterns import QUAD_TRANSITION
from cltess.request import Request
from cltess.scene import exact_corners
from support import translated_scene

SCENES = Path(__file__).resolve().parent.parent / "scenes"


def welded_edges(tess):
    """(faces of the exactly welded mesh, welded positions float64, use count of every edge)."""
    _, first, remap = np.unique(tess.positions.view(np.dtype((np.void, 12))).ravel(),
                                return_index=True, return_inverse=True)
    faces = remap.ravel()[tess.triangles.astype(np.int64)]
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    _, uses = np.unique(edges, axis=0, return_counts=True)
    return faces, tess.positions[first].astype(np.float64), uses


def assert_clean(tess, closed=True):
    faces, points, uses = welded_edges(tess)
    repeated = (faces[:, 0] == faces[:, 1]) | (faces[:, 1] == faces[:, 2]) | (faces[:, 2] == faces[:, 0])
    assert not repeated.any(), f"{repeated.sum()} triangles with a repeated vertex"
    area = np.linalg.norm(np.cross(points[faces[:, 1]] - points[faces[:, 0]],
                                   points[faces[:, 2]] - points[faces[:, 0]]), axis=1)
    assert (area > 0).all(), f"{(area == 0).sum()} zero-area triangles"
    assert (uses <= 2).all(), f"{(uses > 2).sum()} non-manifold edges"
    if closed:
        assert (uses == 2).all(), f"{(uses == 1).sum()} boundary edges"


@pytest.mark.parametrize("fd", [True, False], ids=["fd", "direct"])
@pytest.mark.parametrize("name, offset, relative_eps", [
    ("sphere.bpt", 0, 1e-2), ("sphere.bpt", 0, 1e-3), ("sphere.bpt", 1e3, 1e-3), ("sphere.bpt", 1e5, 1e-2),
    ("torus.bpt", 0, 1e-3), ("torus.bpt", 1e3, 1e-3), ("torus.bpt", 1e5, 1e-2),
    # eps below one float32 step at 1e5 (0.44 and 0.04 steps on the sphere): the tolerance is
    # raised to criteria.tolerance.FLOAT32_TOLERANCE_STEPS there (the sphere welded with 4 and
    # 2,302 degenerate triangles before); 1e6 with 2 steps still clean
    ("sphere.bpt", 1e5, 1e-3), ("sphere.bpt", 1e5, 1e-4), ("torus.bpt", 1e5, 1e-4),
    ("sphere.bpt", 1e6, 1e-4), ("torus.bpt", 1e6, 1e-4)])
def test_closed_rational_scenes_weld_to_closed_manifolds(tessellator, name, offset, relative_eps, fd):
    scene, diagonal = translated_scene(SCENES / name, offset)
    tess = tessellator.tessellate(scene, eps=relative_eps * diagonal, forward_differencing=fd)
    assert_clean(tess)
    if name == "sphere.bpt":  # each pole is one float32 position
        for pole in (offset + np.array([0.0, 0.0, 1.0]), offset + np.array([0.0, 0.0, -1.0])):
            near = np.linalg.norm(tess.positions.astype(np.float64) - pole, axis=1) < 1e-4 * diagonal
            assert near.any() and len(np.unique(tess.positions[near], axis=0)) == 1


@pytest.mark.parametrize("eps", [1e-2, 1e-3])
def test_teapot_lid_and_bottom_have_no_degenerate_triangles(tessellator, eps):
    scene = load_scene(SCENES / "teapot.bez")
    assert edge_groups(scene.patches).collapsed > 0
    tess = tessellator.tessellate(scene, eps=eps)
    assert_clean(tess, closed=False)  # the Utah teapot is open (spout, handle ends)
    assert worst_bound_ratio(scene, tess, eps=eps) <= 1.0


@pytest.mark.parametrize("eps", [3e-2, 1e-3, 3e-4])
def test_sphere_meets_the_bound_with_collapsed_edges(tessellator, eps):
    scene = load_scene(SCENES / "sphere.bpt")
    tess = tessellator.tessellate(scene, eps=eps)
    assert edge_groups(scene.patches).collapsed > 0
    assert worst_bound_ratio(scene, tess, eps=eps, order=6) <= 1.0


def test_collapsed_edges_are_stored_negated_and_reported_positive(tessellator):
    scene = load_scene(SCENES / "sphere.bpt")
    plan = tessellator.plan(scene, eps=1e-3)
    stored = plan.host_factors()
    collapsed = edge_groups(scene.patches).collapsed_edges.reshape(-1, 4)
    assert collapsed.any() and np.array_equal(stored < 0, collapsed)
    tess = tessellator.emit(plan, 0, plan.num_patches)
    assert (tess.factors > 0).all() and np.array_equal(tess.factors, np.abs(stored))


def test_opencl_agrees_with_the_numpy_backend_on_the_sphere(tessellator):
    scene = load_scene(SCENES / "sphere.bpt")
    request = Request.of(eps=1e-3)
    ours, mirror = tessellator.tessellate(scene, request), NumpyBackend().tessellate(scene, request)
    assert np.array_equal(ours.triangles, mirror.triangles)
    assert np.allclose(ours.uv, mirror.uv, atol=1e-6)
    assert np.allclose(ours.positions, mirror.positions, atol=1e-5)


def test_collapsed_edge_masks_on_the_device_equal_the_mirror(tessellator, rng):
    """Stages 3 and 5 with random factors and random collapsed edges (negated), uniform patches
    and factors 1 included, against the mirror: counts, triangles, and no triangle has two
    vertices on one collapsed edge."""
    count = 800
    factors = rng.integers(1, 12, size=(count, 4)).astype(np.int32)
    uniform = rng.random(count) < 0.3
    factors[uniform, 2:] = factors[uniform, :2]
    factors = np.where(rng.random((count, 4)) < 0.3, -factors, factors).astype(np.int32)
    factors[::50] = 0  # culled
    device = cl_array.to_device(tessellator.queue, factors)
    vertex_offsets, index_offsets, _ = tessellator.stage_counts(device, [(QUAD_TRANSITION, 0, count)])
    layouts = [QUAD_TRANSITION.layout(f) for f in factors]
    assert np.array_equal(vertex_offsets.get()[1:], np.cumsum([len(uv) for uv, _ in layouts]))
    assert np.array_equal(index_offsets.get()[1:], np.cumsum([3 * len(t) for _, t in layouts]))
    total = int(index_offsets[count].get())
    triangles, _ = tessellator.stage_indices(device, vertex_offsets, index_offsets, (0, total), (0, count),
                                             kind=QUAD_TRANSITION)
    starts = vertex_offsets.get()[:-1]
    assert np.array_equal(triangles.get(), np.concatenate([t + s for (_, t), s in zip(layouts, starts)]))
    for f, (uv, tris) in zip(factors, layouts):
        for e in np.flatnonzero(f < 0):
            side = [uv[:, 1] == 0, uv[:, 0] == 1, uv[:, 1] == 1, uv[:, 0] == 0][e]
            assert (side[tris].sum(axis=1) < 2).all()


def test_exact_corners_project_to_their_float32_points(rng):
    points = (rng.standard_normal((20000, 3)) * np.array([[1.0], [1e3], [1e5], [1e-3]]).repeat(5000, 0))
    weights = rng.uniform(0.7, 1.3, (20000, 1))
    homogeneous = np.concatenate([points * weights, weights], axis=1).astype(np.float32)
    exact = exact_corners(homogeneous, points.astype(np.float32))
    hits = (exact[:, :3] / exact[:, 3:] == points.astype(np.float32)).all(axis=1)
    assert hits.mean() > 0.99
    assert np.abs(exact[:, 3] / homogeneous[:, 3] - 1).max() < 3e-6  # weights barely move
    assert np.array_equal(exact_corners(homogeneous, points.astype(np.float32)), exact)  # deterministic


def test_the_cli_raises_a_tolerance_below_float32_steps_says_so_and_welds_clean(capsys, tmp_path):
    """Issue 9: the sphere moved by 1e5 with eps 0.001 (0.13 float32 steps there) gets 6 steps
    per patch instead (criteria.tolerance.FLOAT32_TOLERANCE_STEPS), the warning before the run
    says so, and the written mesh welds closed with no degenerate triangle."""
    import json
    from types import SimpleNamespace

    from cltess.cli import main

    scene = tmp_path / "far.json"
    scene.write_text(json.dumps({"objects": [{"file": str(SCENES / "sphere.bpt"), "transform": [
        [1, 0, 0, 1e5], [0, 1, 0, 1e5], [0, 0, 1, 1e5], [0, 0, 0, 1]]}]}))
    out = tmp_path / "far.npz"
    assert main(["tessellate", str(scene), "--eps", "0.001", "-q", "-o", str(out)]) == 0
    err = capsys.readouterr().err
    assert f"cltess: warning: {scene}: eps 0.001 is below 16 float32 steps" in err
    assert "get that instead (up to 0.0469 here)" in err
    with np.load(out) as mesh:
        assert_clean(SimpleNamespace(positions=mesh["positions"], triangles=mesh["triangles"]))
