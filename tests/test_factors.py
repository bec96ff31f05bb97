"""Stage 1 (kernels/factors.cl, Tessellator.stage_factors) against reference.zs_factors."""
import numpy as np
import pyopencl.array as cl_array
import pytest
from hypothesis import given, settings, strategies as st

from cltess import reference
from cltess.scene import Camera
from support import as_float32, random_patches


def device_factors(tessellator, patches, eps=None, pixels=None, camera=None, max_factor=64):
    data = cl_array.to_device(tessellator.queue, patches.reshape(len(patches), 16, 4).astype(np.float32))
    factors, flags, _ = tessellator.stage_factors(data, eps, pixels, camera, max_factor)
    return factors.get(), flags.get()


def assert_factors_match(got, expected, unclamped, rounding=1e-4):
    """Equal, except where float32 rounding may tip a ceil: 1/du within ``rounding`` (relative)
    of an integer."""
    near_integer = (np.abs(unclamped - np.round(unclamped)) < rounding * np.maximum(unclamped, 1)).any(1)
    differs = (got != expected).any(1)
    assert not (differs & ~near_integer).any(), np.nonzero(differs & ~near_integer)
    assert differs.sum() <= max(2, len(got) // 500)


@pytest.mark.parametrize("eps", [0.03, 0.2, 1.0])
def test_factors_match_reference_on_random_rational_patches(tessellator, rng, eps):
    patches = random_patches(rng, 1000)
    got, flags = device_factors(tessellator, patches, eps=eps)
    expected, unclamped, saturated = reference.zs_factors(as_float32(patches),
                                                           reference.patch_factor_tolerances(as_float32(patches), eps)[0])
    assert_factors_match(got, expected, unclamped)
    assert np.array_equal(flags & 1, saturated.astype(int))
    assert (got[:, 0] == got[:, 2]).all() and (got[:, 1] == got[:, 3]).all()


def test_saturated_patches_are_flagged_and_clamped(tessellator, rng):
    patches = random_patches(rng, 500)
    got, flags = device_factors(tessellator, patches, eps=1e-3, max_factor=16)
    expected, _, saturated = reference.zs_factors(as_float32(patches), reference.patch_factor_tolerances(
        as_float32(patches), 1e-3)[0], max_factor=16)
    assert saturated.sum() > 100
    assert got.max() == 16 and np.array_equal(flags & 1, saturated.astype(int))


def test_screen_space_tolerance_and_culling_match_reference(tessellator, rng):
    patches = random_patches(rng, 1000)
    camera = Camera(eye=np.array([20.0, 3.0, 1.0]), target=np.zeros(3), fov_y_deg=40)
    got, flags = device_factors(tessellator, patches, pixels=0.5, camera=camera, max_factor=4096)
    eps, culled = reference.patch_factor_tolerances(as_float32(patches), pixels=0.5, camera=camera)
    expected, unclamped, _ = reference.zs_factors(as_float32(patches), eps, culled, max_factor=4096)
    assert 0 < culled.sum() < len(patches)
    assert np.array_equal((flags & 2) > 0, culled)
    assert (got[culled] == 0).all()
    assert_factors_match(got, expected, unclamped)


@pytest.mark.parametrize("pixels", [None, 1e-4])
def test_tolerance_is_raised_to_the_float32_floor_where_the_patch_lies(tessellator, rng, pixels):
    """Issue 9: no patch gets a tolerance below FLOAT32_TOLERANCE_STEPS float32 steps at its
    largest coordinate (kernels/criteria/tolerance.h), on the device as in the mirror."""
    from cltess.criteria.tolerance import FLOAT32_TOLERANCE_STEPS

    patches = as_float32(random_patches(rng, 1000, spread=30.0))
    camera = Camera(eye=np.array([90.0, 9.0, 3.0]), target=np.zeros(3), fov_y_deg=40)
    eps = None if pixels else 1e-6
    got, flags = device_factors(tessellator, patches, eps=eps, pixels=pixels, camera=camera, max_factor=4096)
    tolerance, culled = reference.patch_tolerances(patches, eps=eps, pixels=pixels, camera=camera)
    points = patches[..., :3] / patches[..., 3:]
    floor = FLOAT32_TOLERANCE_STEPS * np.spacing(np.abs(points).reshape(len(points), -1).max(1).astype(np.float32))
    raised = tolerance == floor
    assert raised[~culled].sum() > 50 and (tolerance >= floor).all()
    spent = reference.patch_factor_tolerances(patches, eps=eps, pixels=pixels, camera=camera)[0]  # less the rounding
    expected, unclamped, _ = reference.zs_factors(patches, spent, culled, max_factor=4096)
    assert np.array_equal((flags & 2) > 0, culled)
    # The float32 constants of patches ~100 from the origin carry ~1e-5 relative error (w X
    # rounded before centring), so a ceil may tip a little farther from an integer than near it.
    assert_factors_match(got, expected, unclamped, rounding=1e-3)


def test_planar_bilinear_patch_gets_factor_one(tessellator):
    grid = np.stack(np.meshgrid(np.arange(4.0), np.arange(4.0), [0.0], indexing="xy"), -1)[:, :, 0]
    patch = np.concatenate([grid, np.ones((4, 4, 1))], -1)[None]
    got, _ = device_factors(tessellator, patch, eps=1e-6)
    assert got.tolist() == [[1, 1, 1, 1]]


def second_derivatives(patch, u, v):
    """|p_uu|, |p_uv|, |p_vv| (N,) of p = X / w at (u, v), by the quotient rule."""
    def basis(t):
        s = 1 - t
        return (reference.bernstein3(t), reference.bernstein3_derivative(t),
                np.stack([6 * s, 18 * t - 12, 6 - 18 * t, 6 * t], -1))
    bu, bv = basis(u), basis(v)
    h = {(a, b): np.einsum("nj,ni,jic->nc", bv[b], bu[a], patch) for a in range(3) for b in range(3)}
    w = {k: x[:, 3:] for k, x in h.items()}
    p = h[0, 0][:, :3] / w[0, 0]
    p_u, p_v = [(h[k][:, :3] - w[k] * p) / w[0, 0] for k in ((1, 0), (0, 1))]
    p_uu = (h[2, 0][:, :3] - 2 * w[1, 0] * p_u - w[2, 0] * p) / w[0, 0]
    p_vv = (h[0, 2][:, :3] - 2 * w[0, 1] * p_v - w[0, 2] * p) / w[0, 0]
    p_uv = (h[1, 1][:, :3] - w[1, 0] * p_v - w[0, 1] * p_u - w[1, 1] * p) / w[0, 0]
    return [np.linalg.norm(x, axis=1) for x in (p_uu, p_uv, p_vv)]


def test_second_derivative_bounds_hold_and_are_tight(rng):
    """reference.second_derivative_bounds >= |p_ab| sampled densely (a proof may not fail), and
    within 20% of the sampled maximum on the exact sphere and torus (the bound is not slack; the
    torus's quarter-circle patches are the loosest, 13-16%)."""
    from support import SCENES
    from cltess.io import load_scene

    t = np.linspace(0, 1, 41)
    u, v = [x.ravel() for x in np.meshgrid(t, t)]
    patches = np.concatenate([random_patches(rng, 100), load_scene(SCENES / "sphere.bpt").patches[:8],
                              load_scene(SCENES / "torus.bpt").patches[:4]])
    for k, patch in enumerate(patches):
        bounds = reference.second_derivative_bounds(patch)
        sampled = [x.max() for x in second_derivatives(patch, u, v)]
        assert all(s <= b * (1 + 1e-9) for s, b in zip(sampled, bounds)), (k, sampled, bounds)
        if k >= 100:
            assert all(b <= 1.2 * s for s, b in zip(sampled, bounds)), (k, sampled, bounds)


def test_diagonal_majorant_holds_in_every_direction(rng):
    """|H_k[h, h]| <= alpha (h_u^2 + rho h_v^2) for every hull point and many directions h, and
    alpha is attained within 10% on some direction (Lemma 3 of docs/rational-bound.md)."""
    angle = np.linspace(0, np.pi, 721)
    h_u, h_v = np.cos(angle), np.sin(angle)
    for patch in random_patches(rng, 30):
        hull = reference.second_derivative_hull(patch)
        for rho in (0.1, 1.0, 7.0):
            alpha = reference.diagonal_majorant(hull, rho)
            form = (hull[:, None, 0] * (h_u * h_u)[:, None] + 2 * hull[:, None, 1] * (h_u * h_v)[:, None]
                    + hull[:, None, 2] * (h_v * h_v)[:, None])  # (K, directions, 3)
            ratio = np.linalg.norm(form, axis=-1) / (alpha * (h_u * h_u + rho * h_v * h_v))
            assert ratio.max() <= 1 + 1e-12 and ratio.max() > 0.9, ratio.max()


@settings(max_examples=30, deadline=None)
@given(d_uu=st.floats(0, 1e3), d_uv=st.floats(0, 1e3), d_vv=st.floats(0, 1e3), c=st.floats(1e-6, 1e2))
def test_zs_steps_keep_the_bound_and_are_at_most_one(d_uu, d_uv, d_vv, c):
    du, dv = reference.zs_steps(d_uu, d_uv, d_vv, c)
    assert 0 < du <= 1 and 0 < dv <= 1, (du, dv)
    error = d_uu * du * du + 2 * d_uv * du * dv + d_vv * dv * dv
    assert error <= c * (1 + 1e-9)
    # Nothing wasted: (1, 1), or on the bound's boundary (no larger step would do).
    assert (du, dv) == (1.0, 1.0) or error >= c * (1 - 1e-6), (du, dv, error, c)


def test_zs_steps_take_the_whole_unit_step_when_the_optimum_lies_beyond_it():
    """d_uu tiny (a nearly straight u direction): the Lagrange optimum has du >> 1; cut to du = 1,
    dv must come from the bound at du = 1 (about 0.414 here), not from the optimum (1e-81)."""
    du, dv = reference.zs_steps(5e-324, 1.0, 1.0, 1.0)
    assert du == 1.0 and abs(dv - (2 ** 0.5 - 1)) < 1e-12
    assert reference.zs_steps(5e-324, 0.0, 0.0, 1.0) == (1.0, 1.0)


# --- PN triangles: pn_factors derives the control points and the Filip factors ----------------

def device_pn_factors(tessellator, triangles, eps=None, pixels=None, camera=None, max_factor=64):
    data = cl_array.to_device(tessellator.queue, triangles)
    controls, factors, flags, _ = tessellator.stage_pn_factors(data, eps, pixels, camera, max_factor)
    return controls.get(), factors.get(), flags.get()


def test_pn_control_points_match_reference(tessellator, rng):
    from support import random_pn_triangles

    triangles = random_pn_triangles(rng, 2000)
    controls, _, _ = device_pn_factors(tessellator, triangles, eps=0.1)
    expected = reference.pn_control_points(triangles.astype(np.float64))
    scale = np.abs(triangles[:, :3, :3]).max()
    assert np.abs(controls - expected).max() < 2e-6 * scale
    # Corners exact, weights 1 for points and 0 for normals; normal field controls unit.
    assert np.array_equal(controls[:, :3, :3], triangles[:, :3, :3])
    assert (controls[:, :10, 3] == 1).all() and (controls[:, 10:, 3] == 0).all()
    assert np.allclose(np.linalg.norm(controls[:, 13:16, :3], axis=2), 1, atol=1e-5)


@pytest.mark.parametrize("eps", [0.003, 0.03, 0.3])
def test_pn_factors_match_reference_on_random_triangles(tessellator, rng, eps):
    from support import random_pn_triangles

    triangles = random_pn_triangles(rng, 3000)
    controls, got, flags = device_pn_factors(tessellator, triangles, eps=eps)
    expected, unclamped, saturated = reference.pn_factors(controls.astype(np.float64),
                                                           reference.pn_factor_tolerances(controls, eps)[0])
    assert_factors_match(got[:, :3], expected[:, :3], unclamped)
    assert (got[:, 3] == 0).all() and (got[:, :3] >= 1).all()
    assert np.array_equal(flags & 1, saturated.astype(int))
    assert len(np.unique(got[:, :3])) > 5


def test_folded_triangles_get_no_factors(tessellator, rng):
    """Two corners at one point (reference.pn_folded): factor 0 and flag bit 2."""
    from support import random_pn_triangles

    triangles = random_pn_triangles(rng, 30)
    triangles[::3, 1, :3] = triangles[::3, 0, :3]
    triangles[1::3, 2, :3] = triangles[1::3, 1, :3]
    controls, got, flags = device_pn_factors(tessellator, triangles, eps=0.01)
    folded = reference.pn_folded(controls)
    assert folded.sum() == 20 and (got[folded] == 0).all() and (flags[folded] == 4).all()
    assert (got[~folded, :3] > 0).all() and not (flags[~folded] & 4).any()
    assert np.array_equal(reference.pn_factors(controls.astype(np.float64), reference.pn_factor_tolerances(controls, 0.01)[0])[0] == 0,
                          np.repeat(folded[:, None], 4, 1) | (np.arange(4) == 3))


def test_pn_screen_space_tolerance_and_culling_match_reference(tessellator, rng):
    from support import random_pn_triangles

    triangles = random_pn_triangles(rng, 3000)
    camera = Camera(eye=np.array([12.0, 3.0, 1.0]), target=np.zeros(3), fov_y_deg=40)
    controls, got, flags = device_pn_factors(tessellator, triangles, pixels=0.5, camera=camera, max_factor=4096)
    eps, culled = reference.pn_factor_tolerances(controls.astype(np.float64), pixels=0.5, camera=camera)
    expected, unclamped, _ = reference.pn_factors(controls.astype(np.float64), eps, culled, max_factor=4096)
    assert 0 < culled.sum() < len(triangles)
    assert np.array_equal((flags & 2) > 0, culled)
    assert (got[culled] == 0).all()
    assert_factors_match(got[:, :3], expected[:, :3], unclamped)


def test_pn_saturated_triangles_are_flagged_and_clamped(tessellator, rng):
    from support import random_pn_triangles

    triangles = random_pn_triangles(rng, 500)
    controls, got, flags = device_pn_factors(tessellator, triangles, eps=1e-4, max_factor=8)
    _, _, saturated = reference.pn_factors(controls.astype(np.float64), reference.pn_factor_tolerances(controls, 1e-4)[0],
                                          max_factor=8)
    assert saturated.sum() > 100
    assert got.max() == 8 and np.array_equal(flags & 1, saturated.astype(int))


def test_flat_triangles_and_straight_edges_get_factor_one(tessellator, rng):
    """Normals equal to the face normal (or zero edge normals: straight edges) make the patch the
    flat triangle: zero second derivatives (up to float32 rounding), factor 1."""
    from support import random_pn_triangles

    triangles = random_pn_triangles(rng, 200)
    corners = triangles[:, :3, :3].astype(np.float64)
    face = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    face /= np.linalg.norm(face, axis=1, keepdims=True)
    triangles[:, 3:12, :3] = face[:, None]
    triangles[100:, 6:12, :3] = 0.0
    _, got, flags = device_pn_factors(tessellator, triangles, eps=1e-4)
    assert (got[:, :3] == 1).all() and not flags.any()


def test_pn_filip_bound_derivatives_of_a_known_patch():
    """A patch that is the quadratic map b(u, v, w) = (u, v, u^2): D_{d20, d20} b = (0, 0, 2) for
    d20 = e_u - e_w, d01 = e_v - e_u gives (0, 0, 2) too and d12 = e_w - e_v gives 0; the bounds
    are exact for a quadratic (the second-difference controls are all equal)."""
    # Cubic control points of the polynomial (u, v, u^2) by degree elevation: u^2 = u^2 (u+v+w).
    controls = np.zeros((1, 16, 4))
    for k, (i, j, l) in enumerate(reference.CUBIC):
        u_part = i / 3
        v_part = j / 3
        uu = i * (i - 1) / 6  # u^2 in cubic Bernstein form: b_ijk = i (i-1) / 6
        controls[0, k, :3] = (u_part, v_part, uu)
    bounds = reference.pn_second_derivative_bounds(controls)[0]
    assert np.allclose(bounds, [[2, 0, 2], [0, 0, 0], [2, 0, 2]])
