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


def assert_factors_match(got, expected, unclamped):
    """Equal, except where float32 rounding may tip a ceil: 1/du within 1e-4 of an integer."""
    near_integer = (np.abs(unclamped - np.round(unclamped)) < 1e-4 * np.maximum(unclamped, 1)).any(1)
    differs = (got != expected).any(1)
    assert not (differs & ~near_integer).any(), np.nonzero(differs & ~near_integer)
    assert differs.sum() <= max(2, len(got) // 500)


@pytest.mark.parametrize("eps", [0.03, 0.2, 1.0])
def test_factors_match_reference_on_random_rational_patches(tessellator, rng, eps):
    patches = random_patches(rng, 3000)
    got, flags = device_factors(tessellator, patches, eps=eps)
    expected, unclamped, saturated = reference.zs_factors(as_float32(patches), np.full(len(patches), eps))
    assert_factors_match(got, expected, unclamped)
    assert np.array_equal(flags & 1, saturated.astype(int))
    assert (got[:, 0] == got[:, 2]).all() and (got[:, 1] == got[:, 3]).all()


def test_saturated_patches_are_flagged_and_clamped(tessellator, rng):
    patches = random_patches(rng, 500)
    got, flags = device_factors(tessellator, patches, eps=1e-3, max_factor=16)
    expected, _, saturated = reference.zs_factors(as_float32(patches), np.full(len(patches), 1e-3), max_factor=16)
    assert saturated.sum() > 100
    assert got.max() == 16 and np.array_equal(flags & 1, saturated.astype(int))


def test_screen_space_tolerance_and_culling_match_reference(tessellator, rng):
    patches = random_patches(rng, 3000)
    camera = Camera(eye=np.array([20.0, 3.0, 1.0]), target=np.zeros(3), fov_y_deg=40)
    got, flags = device_factors(tessellator, patches, pixels=0.5, camera=camera, max_factor=4096)
    eps, culled = reference.patch_tolerances(as_float32(patches), pixels=0.5, camera=camera)
    expected, unclamped, _ = reference.zs_factors(as_float32(patches), eps, culled, max_factor=4096)
    assert 0 < culled.sum() < len(patches)
    assert np.array_equal((flags & 2) > 0, culled)
    assert (got[culled] == 0).all()
    assert_factors_match(got, expected, unclamped)


def test_planar_bilinear_patch_gets_factor_one(tessellator):
    grid = np.stack(np.meshgrid(np.arange(4.0), np.arange(4.0), [0.0], indexing="xy"), -1)[:, :, 0]
    patch = np.concatenate([grid, np.ones((4, 4, 1))], -1)[None]
    got, _ = device_factors(tessellator, patch, eps=1e-6)
    assert got.tolist() == [[1, 1, 1, 1]]


@settings(max_examples=30, deadline=None)
@given(d_uu=st.floats(0, 1e3), d_uv=st.floats(0, 1e3), d_vv=st.floats(0, 1e3), c=st.floats(1e-6, 1e2))
def test_zs_steps_keep_the_bound_and_are_at_most_one(d_uu, d_uv, d_vv, c):
    du, dv = reference.zs_steps(d_uu, d_uv, d_vv, c)
    assert 0 < du <= 1 and 0 < dv <= 1, (du, dv)
    assert d_uu * du * du + 2 * d_uv * du * dv + d_vv * dv * dv <= c * (1 + 1e-9)
