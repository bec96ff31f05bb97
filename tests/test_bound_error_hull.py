"""Request(bound="error-hull") (issue 9; docs/rational-bound.md, "The error-hull bound"): the
kernel against its NumPy mirror, the per-triangle bound against dense float64 measurement (a
hypothesis test), every emitted triangle certified (transition triangles included), factors never
above the hull bound's, watertight closed scenes, the measured ratio's floor, the option."""
import functools
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cltess.backends.opencl.error_hull import error_hull_ratios
from cltess.criteria import error_hull
from cltess.io import load_scene
from cltess.reference import surface_points
from cltess.scene import Scene
from support import SCENES, closed_torus_grid, random_patches, weld_exact
from test_bound_integral import dense_errors


def polynomial(patches: np.ndarray) -> np.ndarray:
    """The patches with every weight 1 (their control points kept)."""
    points = patches[..., :3] / patches[..., 3:]
    return np.concatenate([points, np.ones(points.shape[:-1] + (1,))], axis=-1)


def random_triangles(rng, count: int) -> np.ndarray:
    """(count, 3, 2) float32 triangles in [0, 1]^2 of sizes from 1/50 to the whole domain."""
    size = rng.choice([0.02, 0.1, 0.4, 1.0], (count, 1, 1))
    corners = rng.uniform(0, 1, (count, 3, 2)) * size + rng.uniform(0, 1, (count, 1, 2)) * (1 - size)
    return corners.astype(np.float32)


def kernel_ratios(tessellator, patches, corners, owner, tolerances, check=None):
    nets, radii = error_hull.centred_nets(patches)
    uv = corners.reshape(-1, 2)
    patch_ids = np.repeat(owner, 3).astype(np.int32)
    triangles = np.arange(3 * len(corners), dtype=np.uint32).reshape(-1, 3)
    check = np.ones(len(patches), np.int32) if check is None else check
    return error_hull_ratios(tessellator, nets, radii, check, uv, patch_ids, triangles,
                             np.asarray(tolerances, np.float32))


def test_kernel_matches_the_numpy_mirror(tessellator, rng):
    """Rational and polynomial patches (w = 1): the float32 kernel within 1e-3 or its rounding
    allowance of the float64 mirror (same boxes, same allowances), and each patch's worst the max of its triangles'."""
    rational = random_patches(rng, 3)
    patches = np.concatenate([rational, polynomial(rational[:1])])
    nets, radii = error_hull.centred_nets(patches)
    count = 60
    corners = random_triangles(rng, count)
    owner = rng.integers(0, 4, count)
    tolerances = rng.uniform(0.01, 0.5, 4)
    check = np.array([1, 1, 0, 1], np.int32)
    got, worst = kernel_ratios(tessellator, patches, corners, owner, tolerances, check)
    compared = 0
    for t in range(count):
        p = owner[t]
        if not check[p]:
            assert got[t] == 0
            continue
        want = error_hull.triangle_ratio(nets[p], float(radii[p]), corners[t].astype(float), float(np.float32(tolerances[p])))
        if np.isinf(want):
            assert np.isinf(got[t])
            continue
        if (got[t] > 1) == (want > 1):  # else a box on the threshold was cut on one side only
            # float32 against float64: |E_k| is a difference of terms up to W_k (radius + |L|),
            # rounded within the NET_STEPS allowance (corners' |L| < 3 radius)
            rounding = error_hull.NET_STEPS * error_hull.UNIT * 4 * float(radii[p]) / float(np.float32(tolerances[p]))
            assert got[t] == pytest.approx(want, rel=1e-3, abs=rounding), t
            compared += 1
    assert compared > count // 2
    for p in range(4):
        mine = got[owner == p]
        assert worst[p] == (mine.max() if len(mine) else 0)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1), size=st.sampled_from([0.01, 0.05, 0.2, 0.6, 1.0]),
       weight_spread=st.sampled_from([1.0, 3.0, 25.0]), tolerance=st.sampled_from([1e-4, 1e-3, 1e-2, 1e-1]))
def test_a_certified_triangle_is_within_its_bound(tessellator, seed, size, weight_spread, tolerance):
    """For any patch (weights up to weight_spread apart, or all 1) and triangle, once the kernel
    certifies it (ratio <= 1, the tolerance raised tenfold until it does), its bound ratio *
    tolerance >= |p - l| measured in float64 at barycentric points of order 16 (l: the affine
    interpolant of the exact surface points at the float32 corners)."""
    rng = np.random.default_rng(seed)
    patch = random_patches(rng, 1)
    w = np.exp(rng.uniform(0, np.log(weight_spread), (1, 4, 4)))
    patch = np.concatenate([patch[..., :3] / patch[..., 3:] * w[..., None], w[..., None]], axis=-1)
    corners = (rng.uniform(0, 1, (1, 3, 2)) * size + rng.uniform(0, 1 - size, (1, 1, 2))).astype(np.float32)
    while True:
        ratios, _ = kernel_ratios(tessellator, patch, corners, np.zeros(1, int), [tolerance])
        if ratios[0] <= 1:
            break
        tolerance *= 10
    uv = corners.reshape(-1, 2)
    positions = surface_points(patch, np.zeros(3, int), uv[:, 0].astype(float), uv[:, 1].astype(float))
    error = dense_errors(patch, positions, uv, np.zeros(3, int), np.arange(3).reshape(1, 3), order=16)
    assert error[0] <= ratios[0] * tolerance


def test_the_bound_certifies_at_twice_the_error(tessellator, rng):
    """Each small triangle (its own patch) with a tolerance of twice its measured error: most are
    certified (the boxes' error hull converges to the error), and each certified one within its
    bound; so a test of the bound can fail."""
    count = 60
    patches = random_patches(rng, count)
    corners = random_triangles(rng, count) * np.float32(0.1) + np.float32(0.3)
    owner = np.arange(count)
    uv = corners.reshape(-1, 2)
    ids = np.repeat(owner, 3)
    positions = surface_points(patches, ids, uv[:, 0].astype(float), uv[:, 1].astype(float))
    error = dense_errors(patches, positions, uv, ids, np.arange(3 * count).reshape(-1, 3), order=16)
    tolerances = (2 * error).astype(np.float32)
    ratios, _ = kernel_ratios(tessellator, patches, corners, owner, tolerances)
    certified = ratios <= 1
    assert certified.mean() > 0.5
    assert (error[certified] <= ratios[certified] * tolerances[certified]).all()


def test_centred_nets_keep_the_surface_and_refuse_bad_weights(rng):
    patches = random_patches(rng, 3)
    nets, radii = error_hull.centred_nets(patches)
    centre = (patches[..., :3] / patches[..., 3:]).reshape(3, -1, 3)
    centre = (centre.min(axis=1) + centre.max(axis=1)) / 2
    for p in range(3):
        x = rng.uniform(0, 1, 2)
        exact = surface_points(patches, np.array([p]), np.array([x[0]]), np.array([x[1]]))[0]
        assert np.allclose(error_hull.point(nets[p].astype(float), x) + centre[p], exact, atol=1e-5)
        assert radii[p] >= (np.linalg.norm(nets[p, :, :3], axis=1) / nets[p, :, 3]).max()
    bad = patches.copy()
    bad[0, 1, 1, 3] = 0.0
    with pytest.raises(ValueError, match="positive weights"):
        error_hull.centred_nets(bad)


def _plans(tessellator, scene, eps):
    return (tessellator.plan(scene, eps=eps, bound="error-hull", max_factor=4096),
            tessellator.plan(scene, eps=eps, max_factor=4096))


@pytest.mark.parametrize("relative_eps", [3e-2, 3e-3])
def test_every_emitted_triangle_is_certified_on_a_rational_grid(tessellator, rng, relative_eps):
    """A closed grid of rational patches: patches end at different trials, so transition triangles
    join different factors.  Every emitted triangle is of a patch at today's factors or bounded
    by the kernel within its tolerance; the mesh is closed, manifold and within eps."""
    scene = closed_torus_grid(rng, 4, 3, weights=(0.2, 5.0))
    eps = relative_eps * scene.diagonal
    plan, hull = _plans(tessellator, scene, eps)
    final, today = plan.factors.get(), hull.factors.get()
    assert (np.abs(final) <= np.abs(today)).all()
    assert plan.num_indices < hull.num_indices
    last = len(error_hull.TRIAL_SCALES) - 1
    assert len(set(plan.trials.tolist())) > 1
    tess = tessellator.emit(plan, 0, plan.num_patches)
    assert np.isfinite(tess.positions).all() and np.isfinite(tess.normals).all()
    patches = np.asarray(scene.patches, float)
    owner = tess.patch_ids[tess.triangles[:, 0]]
    from cltess.bound import scene_tolerances
    tolerances = scene_tolerances(scene, eps, for_factors=True)
    ratios, _ = kernel_ratios(tessellator, patches, tess.uv[tess.triangles], owner, tolerances)
    assert ((plan.trials[owner] == last) | (ratios <= 1.0)).all()
    f = np.abs(final)
    assert ((f[owner][:, 0] != f[owner][:, 2]) | (f[owner][:, 1] != f[owner][:, 3])).any()  # transition triangles
    error = dense_errors(patches, tess.positions, tess.uv, tess.patch_ids, tess.triangles)
    assert error.max() <= eps
    _, uses = np.unique(np.sort(weld_exact(tess.positions, tess.triangles).edges, axis=1), axis=0, return_counts=True)
    assert (uses == 2).all()


@functools.cache
def bundled_scene(name: str) -> Scene:
    """One Scene object per bundled file for this module's cases: the integral bound's host
    tables (about 1 CPU-second per rational patch, kept in Scene.prepared) are then made once
    per scene, not once per case."""
    return load_scene(SCENES / name)


@pytest.mark.parametrize("bound", ["error-hull", "integral"])  # the two bounds of the trial loop
@pytest.mark.parametrize("name", ["sphere.bpt", "torus.bpt"])
@pytest.mark.parametrize("relative_eps", [3e-2, 3e-3])
def test_closed_rational_scenes_stay_watertight(tessellator, name, relative_eps, bound):
    scene = bundled_scene(name)
    eps = relative_eps * scene.diagonal
    plan = tessellator.plan(scene, eps=eps, bound=bound, max_factor=4096)
    hull = tessellator.plan(scene, eps=eps, max_factor=4096)
    assert (np.abs(plan.factors.get()) <= np.abs(hull.factors.get())).all()
    tess = tessellator.emit(plan, 0, plan.num_patches)
    assert np.isfinite(tess.positions).all() and np.isfinite(tess.normals).all()
    mesh = weld_exact(tess.positions, tess.triangles)
    _, uses = np.unique(np.sort(mesh.edges, axis=1), axis=0, return_counts=True)
    assert (uses == 2).all()
    error = dense_errors(np.asarray(scene.patches, float), tess.positions, tess.uv, tess.patch_ids, tess.triangles,
                         order=6)
    assert error.max() <= eps


def test_the_measured_ratio_floor_on_random_rational_patches(tessellator):
    """bench/occ_compare.py's 20 random rational patches at eps = 1e-2 of their diagonal: the
    measured worst deviation between 0.4 and 1 of eps (issue 9; with the hull bound 0.29), in
    under 0.1 of the hull bound's triangles."""
    sys.path.insert(0, str(SCENES.parent / "bench"))
    from occ_compare import diagonal, measured_deviation, random_rational_patches

    patches = random_rational_patches()
    scene = Scene(patches, np.zeros(len(patches), np.int32), name="random")
    eps = 1e-2 * diagonal(patches)
    plan, hull = _plans(tessellator, scene, eps)
    assert plan.num_indices < 0.1 * hull.num_indices
    tess = tessellator.emit(plan, 0, plan.num_patches)
    tris = tess.triangles.astype(np.int64)
    ratio = measured_deviation(patches, tess.positions, tess.uv, tess.patch_ids[tris[:, 0]], tris) / eps
    assert 0.4 <= ratio <= 1.0


def test_polynomial_patches_take_fewer_triangles_within_the_bound(tessellator):
    """The teapot (w = 1): fewer triangles than the hull bound, and within eps."""
    scene = load_scene(SCENES / "teapot.bez")
    eps = 1e-2
    plan, hull = _plans(tessellator, scene, eps)
    assert plan.stats["error_hull_patches"] == scene.num_bezier
    assert plan.num_indices < hull.num_indices
    assert (np.abs(plan.factors.get()) <= np.abs(hull.factors.get())).all()
    tess = tessellator.emit(plan, 0, plan.num_patches)
    error = dense_errors(np.asarray(scene.patches, float), tess.positions, tess.uv, tess.patch_ids, tess.triangles,
                         order=6)
    assert error.max() <= eps


def test_cli_bound_error_hull(tmp_path):
    out = tmp_path / "r.ply"
    run = subprocess.run([sys.executable, "-m", "cltess", "tessellate", str(SCENES / "torus.bpt"), "--eps", "0.02",
                          "--bound", "error-hull", "--verify", "-o", str(out)], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert "error hull rounds" in run.stdout and "warning" not in run.stderr
    refused = subprocess.run([sys.executable, "-m", "cltess", "tessellate", str(SCENES / "torus.bpt"), "--eps", "0.1",
                              "--bound", "error-hull", "--pattern", "semi-uniform", "-o", str(tmp_path / "t.ply")],
                             capture_output=True, text=True)
    assert refused.returncode == 2 and "--bound error-hull" in refused.stderr and not (tmp_path / "t.ply").exists()
