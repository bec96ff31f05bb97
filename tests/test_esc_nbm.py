"""ESC's per-patch power-basis matrix NBM = N B N^T and its Horner evaluator (docs/esc.md
section 1): NumPy mirror against the Bernstein evaluation in float64, and the device's
NBM-Horner against direct evaluation and forward differencing in float32."""
import numpy as np

from cltess.surfaces.bezier import evaluate
from cltess.surfaces.nbm import POWER_BASIS, evaluate_nbm, power_basis_matrix
from support import random_patches


def test_power_basis_is_the_bernstein_basis():
    t = np.linspace(0, 1, 7)
    bernstein = np.stack([(1 - t) ** 3, 3 * t * (1 - t) ** 2, 3 * t * t * (1 - t), t ** 3], 1)
    powers = np.stack([t ** 0, t, t * t, t ** 3], 1)
    assert np.allclose(powers @ POWER_BASIS, bernstein, atol=1e-15)


def test_nbm_horner_equals_bernstein_in_float64(rng):
    for patch in random_patches(rng, 20, spread=1.0):
        u, v = rng.random(64), rng.random(64)
        expected, expected_normal = evaluate(patch, u, v)
        got, got_normal = evaluate_nbm(power_basis_matrix(patch)[0], u, v)
        assert np.abs(got - expected).max() < 1e-12 * max(1.0, np.abs(expected).max())
        assert np.abs(got_normal - expected_normal).max() < 1e-9


def test_nbm_device_against_direct_and_forward_differencing(tessellator, rng):
    """All three within float32 error of the float64 surface.  Measured (200 patches, weights
    0.2-5): direct 9e-8, NBM of the centred patch 2e-6 - 6e-6, NBM of the raw patch 2.5e-5 -
    6e-5, forward differencing 2e-7 - 1e-6 of the patch size: the power basis cancels."""
    from cltess.esc.evaluate import evaluate_grid
    patches = random_patches(rng, 200, spread=1.0)
    n = 12
    t = np.linspace(0, 1, n + 1)
    u, v = np.meshgrid(t, t)
    exact = np.stack([evaluate(p, u.ravel(), v.ravel())[0] for p in patches]).reshape(len(patches), n + 1, n + 1, 3)
    scale = np.abs(exact).max()
    errors = {}
    for method in ("direct", "nbm", "fd", "nbm_raw"):
        positions, normals, _ = evaluate_grid(tessellator.queue, patches, n, method)
        assert np.isfinite(positions).all()
        errors[method] = np.abs(positions - exact).max() / scale
    assert errors["direct"] < 2e-6
    assert errors["nbm"] < 2e-5
    assert errors["nbm"] < errors["nbm_raw"]  # centring first (as kind_load does) pays
    assert errors["fd"] < 2e-5
