"""The bound's per-patch constants (M_uu, M_uv, M_vv, alpha), made on the device once per scene
(kernels/stages/constants.cl, criteria/zs.h zs_constants) and cached per context
(Tessellator.upload, Scene.prepared): equal to the float64 reference (zs_constants), and the
cache changes nothing but the time."""
import numpy as np
import pyopencl.array as cl_array
import pytest

from cltess.backends.opencl.tessellator import Tessellator
from cltess.criteria.zheng_sederberg import zs_constant_steps, zs_constants
from cltess.io import load_scene
from cltess.kinds import BEZIER
from cltess.scene import Scene
from support import SCENES, as_float32, random_patches

#: Relative float32 error allowed on a constant: each hull coefficient is a sum of up to 768
#: triple products (docs/rational-bound.md, "Float32"); measured at most 2.4e-6 (Intel, PoCL).
CONSTANT_RTOL = 2e-5


def device_constants(tessellator, patches):
    controls = cl_array.to_device(tessellator.queue, np.ascontiguousarray(patches.reshape(-1, 16, 4), np.float32))
    return tessellator.patch_constants(BEZIER, controls).get().astype(np.float64)


def test_constants_equal_the_reference_on_random_patches(tessellator, rng):
    polynomial = random_patches(rng, 50)
    polynomial[..., :3] /= polynomial[..., 3:]
    polynomial[..., 3] = 1.0
    wide = random_patches(rng, 50) * [1, 1, 1, 0.01]  # the same patches, tiny weights
    patches = as_float32(np.concatenate([random_patches(rng, 400), polynomial, wide,
                                         load_scene(SCENES / "sphere.bpt").patches,
                                         load_scene(SCENES / "torus.bpt").patches]))
    got = device_constants(tessellator, patches)
    expected = np.array([zs_constants(patch) for patch in patches])
    assert got.shape == expected.shape
    assert (expected[400:450, 3] == 0).all() and (got[400:450, 3] == 0).all()  # polynomial: no Lemma 3
    error = np.abs(got - expected) / np.maximum(np.abs(expected), 1e-30)
    assert error.max() <= CONSTANT_RTOL, (error.max(axis=0), np.unravel_index(error.argmax(), error.shape))
    # and the steps stage 1 derives from them agree with the reference's
    for eps in (0.01, 0.3):
        inverse = np.array([zs_constant_steps(c, eps) for c in got])
        exact = np.array([zs_constant_steps(c, eps) for c in expected])
        assert np.allclose(inverse, exact, rtol=2 * CONSTANT_RTOL)


def test_constants_are_made_once_per_scene_and_context(rng):
    patches = random_patches(rng, 40)
    scene = Scene(patches, np.zeros(40, np.int32), name="random")
    first, second = Tessellator(), Tessellator()  # two contexts
    a = first.tessellate(scene, eps=0.05)
    assert "constants" in a.stage_ms
    b = first.tessellate(scene, eps=0.05)
    assert "constants" not in b.stage_ms  # cached
    assert np.array_equal(a.factors, b.factors) and np.array_equal(a.triangles, b.triangles)
    assert "constants" in second.tessellate(scene, eps=0.05).stage_ms  # its own context
    # another tolerance with the cached constants: as on a fresh scene
    cached = first.tessellate(scene, eps=0.01)
    fresh = first.tessellate(Scene(patches, np.zeros(40, np.int32)), eps=0.01)
    assert "constants" not in cached.stage_ms and "constants" in fresh.stage_ms
    assert np.array_equal(cached.factors, fresh.factors)
    # new arrays on the scene: made again
    scene.patches = np.array(patches[::-1])
    again = first.tessellate(scene, eps=0.01)
    assert "constants" in again.stage_ms
    assert np.array_equal(again.factors, fresh.factors[::-1])


@pytest.mark.parametrize("eps", [0.01, 0.3])
def test_factors_from_constants_equal_the_reference(tessellator, rng, eps):
    """Stage 1 from the cached constants against the float64 reference, factor for factor
    except where 1/du lies within float32 rounding of an integer (then by one)."""
    from cltess.criteria.zheng_sederberg import zs_factors

    patches = as_float32(random_patches(rng, 500))
    tess = tessellator.plan(Scene(patches, np.zeros(500, np.int32)), eps=eps, max_factor=4096)
    got = np.abs(tess.host_factors())
    # stage 1 before crack-freeness: the plan's factors are final, so compare stage 1 directly
    factors, flags, _ = tessellator.stage_factors(
        cl_array.to_device(tessellator.queue, patches.reshape(-1, 16, 4).astype(np.float32)), eps, None, None, 4096)
    expected, unclamped, _ = zs_factors(patches, np.full(len(patches), eps), max_factor=4096)
    tipping = (np.abs(unclamped - np.round(unclamped)) < 1e-4 * unclamped).any(axis=1)
    stage_1 = factors.get()
    assert np.array_equal(stage_1[~tipping], expected[~tipping]) and np.abs(stage_1 - expected).max() <= 1
    assert (got >= stage_1).all()  # crack-freeness only raises
