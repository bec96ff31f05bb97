"""The bound's per-patch constants (M_uu, M_uv, M_vv, alpha; criteria/zs.h zs_constants): made
by stage 1 for each patch it sees, kept with the scene per context (Tessellator.upload,
patch_constants, Scene.prepared), equal to the float64 reference (zs_constants); keeping them
changes nothing but the time."""
import numpy as np
import pyopencl.array as cl_array
import pytest

from cltess.backends.opencl.tessellator import Tessellator
from cltess.criteria import ObjectSpace
from cltess.criteria.tolerance import patch_factor_tolerances
from cltess.criteria.zheng_sederberg import zs_constant_steps, zs_constants, zs_factors
from cltess.io import load_scene
from cltess.kinds import BEZIER
from cltess.scene import Camera, Scene
from support import SCENES, as_float32, random_patches

#: Relative float32 error allowed on a constant: each hull coefficient is a sum of up to 768
#: triple products (docs/rational-bound.md, "Float32"); measured at most 2.4e-6 (Intel, PoCL).
CONSTANT_RTOL = 2e-5


def stage_1(tessellator, patches, eps, max_factor=4096):
    """(factors, flags, the constants stage 1 left) of one stage-1 run on fresh constants."""
    count = len(patches)
    data = tessellator.upload(BEZIER, np.ascontiguousarray(patches.reshape(-1, 16, 4), np.float32))
    factors = cl_array.empty(tessellator.queue, (count, 4), np.int32)
    flags = cl_array.empty(tessellator.queue, count, np.int32)
    tessellator.stage_factors_of(BEZIER, data, ObjectSpace(eps), max_factor, factors, flags)
    return factors.get(), flags.get(), data["source"].get().astype(np.float64)


def test_constants_equal_the_reference_on_random_patches(tessellator, rng):
    polynomial = random_patches(rng, 50)
    polynomial[..., :3] /= polynomial[..., 3:]
    polynomial[..., 3] = 1.0
    wide = random_patches(rng, 50) * [1, 1, 1, 0.01]  # tiny weights: points 100x farther out
    patches = as_float32(np.concatenate([random_patches(rng, 400), polynomial, wide,
                                         load_scene(SCENES / "sphere.bpt").patches,
                                         load_scene(SCENES / "torus.bpt").patches]))
    _, _, got = stage_1(tessellator, patches, 0.05)
    expected = np.array([zs_constants(patch) for patch in patches])
    assert (expected[400:450, 3] == 0).all() and (got[400:450, 3] == 0).all()  # polynomial: no Lemma 3
    error = np.abs(got - expected) / np.maximum(np.abs(expected), 1e-30)
    assert error.max() <= CONSTANT_RTOL, (error.max(axis=0), np.unravel_index(error.argmax(), error.shape))
    for eps in (0.01, 0.3):  # the steps stage 1 derives from them
        inverse = np.array([zs_constant_steps(c, eps) for c in got])
        exact = np.array([zs_constant_steps(c, eps) for c in expected])
        assert np.allclose(inverse, exact, rtol=2 * CONSTANT_RTOL)


def test_culled_patches_are_left_for_later(rng):
    """Screen space: the constants are made for the visible patches only (the first call costs
    what stage 1 always cost), and for the others when a later camera sees them."""
    patches = random_patches(rng, 300, spread=3.0)
    near = Camera(eye=np.array([12.0, 2.0, 1.0]), target=np.zeros(3), fov_y_deg=20, width=200, height=150)
    scene = Scene(patches, np.zeros(300, np.int32), near, name="random")
    tessellator = Tessellator()
    tess = tessellator.tessellate(scene, pixels=2.0, max_factor=4096)
    culled = tess.factors[:, 0] == 0
    assert 0 < culled.sum() < 300
    constants = tessellator.patch_constants(BEZIER, 300, scene).get()
    assert (constants[culled, 0] == -1).all() and (constants[~culled, 0] >= 0).all()
    scene.camera = Camera(eye=np.array([40.0, 2.0, 1.0]), target=np.zeros(3), fov_y_deg=60, width=200, height=150)
    wide = tessellator.tessellate(scene, pixels=2.0, max_factor=4096)
    seen = wide.factors[:, 0] > 0
    constants = tessellator.patch_constants(BEZIER, 300, scene).get()
    assert (constants[seen, 0] >= 0).all() and seen.sum() > (~culled).sum()
    fresh = Tessellator().tessellate(Scene(patches, np.zeros(300, np.int32), scene.camera), pixels=2.0,
                                     max_factor=4096)
    assert np.array_equal(wide.factors, fresh.factors) and np.array_equal(wide.triangles, fresh.triangles)


def test_constants_are_kept_per_scene_and_context(rng, monkeypatch):
    from cltess.backends.opencl import tessellator as opencl_tessellator

    patches = random_patches(rng, 40)
    scene = Scene(patches, np.zeros(40, np.int32), name="random")
    first, same_device = Tessellator(), Tessellator()  # one context per device (shared_context)
    monkeypatch.setattr(opencl_tessellator, "_CONTEXTS", {})
    second = Tessellator()  # a context of its own
    a = first.tessellate(scene, eps=0.05)
    kept = first.patch_constants(BEZIER, 40, scene)
    assert kept is first.patch_constants(BEZIER, 40, scene)
    assert (kept.get()[:, 0] >= 0).all()
    b = first.tessellate(scene, eps=0.05)
    assert np.array_equal(a.factors, b.factors) and np.array_equal(a.triangles, b.triangles)
    assert same_device.patch_constants(BEZIER, 40, scene) is kept
    assert second.patch_constants(BEZIER, 40, scene) is not kept  # its own context
    # another tolerance with the kept constants: as on a fresh scene
    kept_run = first.tessellate(scene, eps=0.01)
    fresh = first.tessellate(Scene(patches, np.zeros(40, np.int32)), eps=0.01)
    assert np.array_equal(kept_run.factors, fresh.factors)
    # new arrays on the scene: made again
    scene.patches = np.array(patches[::-1])
    assert first.patch_constants(BEZIER, 40, scene) is not kept
    again = first.tessellate(scene, eps=0.01)
    assert np.array_equal(again.factors, fresh.factors[::-1])


@pytest.mark.parametrize("eps", [0.01, 0.3])
def test_factors_from_kept_constants_equal_the_reference(tessellator, rng, eps):
    """Stage 1 twice on the same constants (made, then read) against the float64 reference,
    factor for factor except where 1/du lies within float32 rounding of an integer (then by
    one)."""
    patches = as_float32(random_patches(rng, 500))
    count = len(patches)
    data = tessellator.upload(BEZIER, np.ascontiguousarray(patches.reshape(-1, 16, 4), np.float32))
    expected, unclamped, _ = zs_factors(patches, patch_factor_tolerances(patches, eps)[0], max_factor=4096)
    tipping = (np.abs(unclamped - np.round(unclamped)) < 1e-4 * unclamped).any(axis=1)
    runs = []
    for _ in range(2):
        factors = cl_array.empty(tessellator.queue, (count, 4), np.int32)
        flags = cl_array.empty(tessellator.queue, count, np.int32)
        tessellator.stage_factors_of(BEZIER, data, ObjectSpace(eps), 4096, factors, flags)
        runs.append(factors.get())
    assert np.array_equal(runs[0], runs[1])
    assert np.array_equal(runs[1][~tipping], expected[~tipping]) and np.abs(runs[1] - expected).max() <= 1
