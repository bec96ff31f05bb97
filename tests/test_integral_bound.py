"""bench/integral_bound.py (issue 9, the integral form of the remainder): an experiment, but it
claims a proof for the triangles it evaluates, so check the claim against dense float64
sampling: subpatch majorants hold on their subpatches, and the upper sums hold on triangles."""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "bench"))
integral_bound = pytest.importorskip("integral_bound")
ratio_floor = pytest.importorskip("ratio_floor")

from cltess.surfaces.bezier import surface_points  # noqa: E402
from support import random_patches  # noqa: E402


def test_subpatch_majorants_hold_on_their_subpatches(rng):
    for patch in random_patches(rng, 4):
        majorants = integral_bound.subpatch_majorants(patch, 3)  # (3, 8, 8)
        s = (np.arange(8)[:, None] + np.linspace(0, 1, 7)[None]) / 8  # samples of each piece, ends included
        for j in range(8):
            for i in range(8):
                u, v = (x.ravel() for x in np.meshgrid(s[i], s[j]))
                found = np.array([np.linalg.norm(d, axis=1).max() for d in ratio_floor.second_derivatives(patch, u, v)])
                assert (found <= majorants[:, j, i] * (1 + 1e-9)).all(), (i, j, found, majorants[:, j, i])
        whole = integral_bound.subpatch_majorants(patch, 0)[:, 0, 0]
        assert (majorants.max(axis=(1, 2)) <= whole * (1 + 1e-9)).all()  # subdividing never loosens


@pytest.mark.parametrize("k, t_count", [(2, 2), (6, 8)])
def test_upper_sums_bound_the_interpolation_error_on_triangles(rng, k, t_count):
    order = 12
    bary = np.array([(a, b, order - a - b) for a in range(order + 1) for b in range(order + 1 - a)], float) / order
    for patch in random_patches(rng, 3):
        table = integral_bound.RangeMax(integral_bound.subpatch_majorants(patch, 5))
        corners = rng.uniform(0, 1, (40, 3, 2))
        corners[:10, 0] = [[0.0, 0.0]] * 10  # some at the patch's corner, where the spikes are
        bounds = integral_bound.triangle_bounds(corners, table, k, t_count)
        uv_c = corners.reshape(-1, 2)
        at_corners = surface_points(patch[None], np.zeros(len(uv_c), int), uv_c[:, 0], uv_c[:, 1]).reshape(40, 3, 3)
        uv = np.einsum("sk,tkc->tsc", bary, corners).reshape(-1, 2)
        exact = surface_points(patch[None], np.zeros(len(uv), int), uv[:, 0], uv[:, 1]).reshape(40, -1, 3)
        error = np.linalg.norm(exact - np.einsum("sk,tkc->tsc", bary, at_corners), axis=-1).max(axis=1)
        assert (error <= bounds).all(), (error / bounds).max()
        assert (error > 0.05 * bounds).any()  # and not idle
