"""Request(bound="integral") (issue 9: the integral form of the remainder in the engine,
docs/rational-bound.md): the kernel against its NumPy mirror, the per-triangle bound against
dense float64 measurement (transition triangles included), factors never above the hull
bound's, watertight closed scenes, finite output, the option's validation."""
import re
import subprocess
import sys

import numpy as np
import pytest

from cltess.backends.opencl.integral import LAST_TRIAL, triangle_ratios
from cltess.backends.opencl.programs import kernel_dir
from cltess.criteria import integral
from cltess.io import load_scene
from cltess.reference import surface_points
from cltess.request import Request
from cltess.scene import Scene
from support import SCENES, closed_torus_grid, random_patches, weld_exact

LEVELS = 4  # small pyramids for the mirror tests (the engine's: integral.SUBPATCH_LEVELS)


def dense_errors(patches, positions, uv, patch_ids, triangles, order=12) -> np.ndarray:
    """(T,) max |p(u, v) - mesh(u, v)| over barycentric points of order ``order`` (float64, at
    the mesh's float32 vertex positions and (u, v))."""
    bary = np.array([(i, j, order - i - j) for i in range(order + 1) for j in range(order + 1 - i)], float) / order
    tris = np.asarray(triangles, np.int64)
    out = np.zeros(len(tris))
    for start in range(0, len(tris), 2000):
        t = tris[start:start + 2000]
        pid = np.repeat(patch_ids[t[:, 0]], len(bary))
        at = np.einsum("sk,tkc->tsc", bary, uv[t].astype(float)).reshape(-1, 2)
        mesh = np.einsum("sk,tkc->tsc", bary, positions[t].astype(float)).reshape(-1, 3)
        exact = surface_points(patches, pid, at[:, 0], at[:, 1])
        out[start:start + 2000] = np.linalg.norm(exact - mesh, axis=1).reshape(len(t), -1).max(axis=1)
    return out


def test_host_and_device_constants_agree():
    header = (kernel_dir() / "criteria" / "integral_bound.h").read_text()
    define = lambda name: re.search(rf"#define {name} ([0-9.e+-]+)f?", header).group(1)  # noqa: E731
    assert float(define("INTEGRAL_BOX_WIDENING")) == integral.BOX_WIDENING
    assert int(define("INTEGRAL_QUERY_SPAN")) == integral.QUERY_SPAN
    assert np.float32(define("INTEGRAL_BOUND_SAFETY")) == np.float32(integral.BOUND_SAFETY)
    assert np.float32(define("INTEGRAL_QUARTIC_SLACK")) == np.float32(integral.QUARTIC_SLACK)
    assert int(define("INTEGRAL_GRADED_SPAN")) == integral.GRADED_SPAN
    k = integral.SUBDIVISIONS  # the kernel doubles K from the first to the last
    assert all(b == 2 * a for a, b in zip(k, k[1:]))


def test_cell_forms_equal_a_cell_by_cell_computation(rng):
    """cell_forms (component-major, vectorised over cells) against each cell's nets restricted
    one at a time and quartic_coefficients, the formula it states: equal to float64 rounding
    (QUARTIC_PAD's margin is 1e-12 of each column's size; the two differ by ~1e-16 of it)."""
    breaks = np.array([0.0, 0.125, 0.4, 0.5, 1.0])
    matrices = integral.interval_matrices(breaks)
    for patch in random_patches(rng, 3):
        forms = integral.cell_forms(patch, breaks)
        numerators, cube = integral.numerator_nets(patch)
        nets = np.concatenate([numerators.reshape(10, 10, 9), cube[..., None]], axis=-1)  # [j, i, c]
        for t in range(len(breaks) - 1):
            for u in range(len(breaks) - 1):
                cell = np.einsum("bj,ai,jic->bac", matrices[t], matrices[u], nets).reshape(100, 10)
                h = (cell[:, :9] / cell[:, 9:]).reshape(100, 3, 3)
                norms = np.linalg.norm(h, axis=-1)
                e = integral.quartic_coefficients(h[:, 0], h[:, 1], h[:, 2])
                expected = [*norms.max(axis=0), e[:, 2].max(), e[:, 1].max(), -e[:, 1].min(), e[:, 3].max(),
                            -e[:, 3].min()]
                size = [(2 * norms[:, 0] * norms[:, 2] + 4 * norms[:, 1] ** 2).max()] * 2 + \
                    [(4 * norms[:, 0] * norms[:, 1]).max()] * 2 + [(4 * norms[:, 1] * norms[:, 2]).max()] * 2
                scale = np.concatenate([norms.max(axis=0), size])
                got = forms[t, u] - np.concatenate([[0, 0, 0], integral.QUARTIC_PAD * np.array(size)[[0, 2, 2, 4, 4]]])
                assert np.all(np.abs(got - expected) <= 1e-14 * scale[:8]), (t, u)


def test_subpatch_majorants_hold_and_pyramid_bounds_them(rng):
    sys.path.insert(0, str(SCENES.parent / "bench"))
    from ratio_floor import second_derivatives

    for patch in random_patches(rng, 3):
        majorants = integral.subpatch_majorants(patch, 3)  # (8, 8, 3)
        s = (np.arange(8)[:, None] + np.linspace(0, 1, 6)[None]) / 8
        for j in range(8):
            for i in range(8):
                u, v = (x.ravel() for x in np.meshgrid(s[i], s[j]))
                found = np.array([np.linalg.norm(d, axis=1).max() for d in second_derivatives(patch, u, v)])
                assert (found <= majorants[j, i] * (1 + 1e-9)).all()
        pyramid = integral.majorant_pyramid(majorants)
        assert (pyramid[:64, :3].astype(float) >= majorants.reshape(-1, 3)).all()  # rounded up
        assert np.allclose(pyramid[-1, :3], majorants.max(axis=(0, 1)), rtol=1e-5)  # the coarsest: the max


@pytest.mark.parametrize("levels", [3, integral.SUBPATCH_LEVELS])
def test_graded_breaks_are_dyadic_nested_and_graded(levels):
    """The graded cells: exact in float32, symmetric, nested in the 2^levels subpatches, and each
    cell beyond the innermost ones at most a quarter of its distance to the edge
    (GRADED_OCTAVE_CELLS = 4)."""
    breaks = integral.graded_breaks(levels)
    assert breaks[0] == 0 and breaks[-1] == 1 and (np.diff(breaks) > 0).all()
    assert (breaks.astype(np.float32).astype(float) == breaks).all()
    assert np.array_equal(breaks, 1 - breaks[::-1])
    assert set(np.arange((1 << levels) + 1) / (1 << levels)) <= set(breaks.tolist())
    innermost = 2.0 ** -(levels + integral.GRADED_DEPTH)  # [0, innermost]: GRADED_OCTAVE_CELLS equal cells
    left = np.flatnonzero((breaks[:-1] >= innermost) & (breaks[1:] <= 0.5))
    assert (breaks[left + 1] - breaks[left] <= breaks[left] / integral.GRADED_OCTAVE_CELLS).all()
    finest = 2.0 ** -(levels + integral.GRADED_DEPTH) / integral.GRADED_OCTAVE_CELLS
    assert breaks[1] == finest and len(breaks) - 1 == integral.graded_count(levels)
    assert integral.table_cells(levels) == integral.pyramid_cells(levels) + integral.graded_count(levels) ** 2


def test_graded_cells_hold_and_the_table_is_no_looser(rng):
    """Each graded cell's stored majorant bounds |p_ab| sampled densely in it (the corner cells,
    where the spikes are, and random ones), and the table's pyramid is no larger than the direct
    subpatch majorants' (it is pooled from the graded cells)."""
    sys.path.insert(0, str(SCENES.parent / "bench"))
    from ratio_floor import second_derivatives

    levels = 3
    breaks = integral.graded_breaks(levels)
    count = len(breaks) - 1
    for patch in random_patches(rng, 2):
        table = integral.patch_table(patch, levels)
        graded = table[integral.pyramid_cells(levels):, :3].reshape(count, count, 3).astype(float)
        cells = [(0, 0), (count - 1, count - 1), (0, count - 1), (1, 2)] + [tuple(c) for c in rng.integers(0, count, (6, 2))]
        for j, i in cells:
            s_u = np.linspace(breaks[i], breaks[i + 1], 7)
            s_v = np.linspace(breaks[j], breaks[j + 1], 7)
            u, v = (x.ravel() for x in np.meshgrid(s_u, s_v))
            found = np.array([np.linalg.norm(d, axis=1).max() for d in second_derivatives(patch, u, v)])
            assert (found <= graded[j, i]).all(), (j, i)
        direct = integral.majorant_pyramid(integral.subpatch_majorants(patch, levels))
        assert (table[:integral.pyramid_cells(levels), :3] <= direct[:, :3]).all()
        # the quartic columns: never above what the norms' triangle inequality gives
        assert (table[:integral.pyramid_cells(levels), 3:] <= direct[:, 3:] * (1 + 1e-5) + 1e-30).all()


def test_direction_aware_form_holds_and_is_no_looser(rng):
    """The direction-aware form (docs/rational-bound.md, "The direction-aware form per cell"):
    for boxes of h and cells of the graded table, direction_form(cell's columns, the box's
    monomial ranges) >= |D^2 p(xi)[h, h]| sampled densely (xi in the cell, h in the box), and
    never above the norms' form m_uu H_u^2 + 2 m_uv H_u H_v + m_vv H_v^2 (H: the box's largest
    |h| per axis) beyond float32 rounding; and it is strictly smaller somewhere (not idle)."""
    sys.path.insert(0, str(SCENES.parent / "bench"))
    from ratio_floor import second_derivatives

    levels = 3
    breaks = integral.graded_breaks(levels)
    count = len(breaks) - 1
    tighter = 0
    for patch in random_patches(rng, 2):
        table = integral.patch_table(patch, levels)
        graded = table[integral.pyramid_cells(levels):].reshape(count, count, integral.TABLE_WIDTH)
        for j, i in [(0, 0), (count - 1, 0), (count // 2, count // 2)] + [tuple(c) for c in rng.integers(0, count, (4, 2))]:
            u, v = (x.ravel() for x in np.meshgrid(np.linspace(breaks[i], breaks[i + 1], 5),
                                                   np.linspace(breaks[j], breaks[j + 1], 5)))
            d_uu, d_uv, d_vv = second_derivatives(patch, u, v)
            for _ in range(6):
                centre = rng.normal(size=2)
                half = np.abs(rng.normal(size=2)) * rng.choice([0.01, 0.3, 2.0])
                lo, hi = (centre - half).astype(np.float32), (centre + half).astype(np.float32)
                form = float(integral.direction_form(graded[j, i], integral.monomial_ranges(lo, hi)))
                h_u, h_v = (x.ravel() for x in np.meshgrid(np.linspace(lo[0], hi[0], 5), np.linspace(lo[1], hi[1], 5)))
                values = (d_uu[:, None] * (h_u * h_u)[None, :, None] + 2 * d_uv[:, None] * (h_u * h_v)[None, :, None]
                          + d_vv[:, None] * (h_v * h_v)[None, :, None])
                assert np.linalg.norm(values, axis=-1).max() <= form, (j, i)
                m = graded[j, i].astype(float)
                big = np.maximum(np.abs(lo), np.abs(hi)).astype(float)
                norms = m[0] * big[0] ** 2 + 2 * m[1] * big[0] * big[1] + m[2] * big[1] ** 2
                assert form <= norms * (1 + 1e-4)
                tighter += form < 0.9 * norms
    assert tighter > 0


def test_graded_tables_cut_the_corner_spike_patches(tessellator):
    """bench/occ_compare.py's random patches 2 and 11 (a corner weight 0.3-0.4 among 3-5: curvature
    ~ 1/distance^2 towards that corner) at eps = 1e-2 of the 20 patches' diagonal: with the graded
    cells the integral bound needs under 0.3 of the hull bound's triangles (with the 64 x 64
    pyramid alone: 0.95, 8,794 of 9,280), and the mesh is within eps."""
    sys.path.insert(0, str(SCENES.parent / "bench"))
    from occ_compare import diagonal, random_rational_patches

    every = random_rational_patches()
    patches = every[[2, 11]]
    scene = Scene(patches, np.zeros(2, np.int32), name="corner spikes")
    eps = 1e-2 * diagonal(every)
    plan, hull = _integral_and_hull(tessellator, scene, eps)
    assert plan.num_indices < 0.3 * hull.num_indices
    tess = tessellator.emit(plan, 0, plan.num_patches)
    assert dense_errors(patches, tess.positions, tess.uv, tess.patch_ids, tess.triangles, 6).max() <= eps


@pytest.mark.parametrize("subdivisions", [(2,), (2, 4)])
def test_kernel_matches_the_numpy_mirror(tessellator, rng, subdivisions):
    patches = random_patches(rng, 3)
    pyramids, index = integral.scene_pyramids(patches, np.ones(3, bool), LEVELS)
    cells = integral.table_cells(LEVELS)
    count = 30
    corners = rng.uniform(0, 1, (count, 3, 2)).astype(np.float32)
    corners[:8] *= rng.uniform(0.02, 0.3, (8, 1, 1)).astype(np.float32)  # small, near a corner
    owner = rng.integers(0, 3, count)
    tolerances = rng.uniform(0.05, 5.0, 3)
    uv = corners.reshape(-1, 2)
    patch_ids = np.repeat(owner, 3).astype(np.int32)
    triangles = np.arange(3 * count, dtype=np.uint32).reshape(count, 3)
    check = np.array([1, 1, 0], np.int32)
    got = triangle_ratios(tessellator, pyramids, index, check, uv, patch_ids, triangles,
                          tolerances.astype(np.float32), subdivisions, LEVELS)
    for t in range(count):
        p = owner[t]
        if not check[p]:
            assert got[t] == 0
            continue
        want = integral.triangle_bound(pyramids[p * cells:(p + 1) * cells], LEVELS, corners[t],
                                       np.float32(tolerances[p]), subdivisions)
        assert got[t] == pytest.approx(want, rel=2e-5), t


def test_triangle_bounds_hold_on_random_triangles(tessellator, rng):
    """The engine's bound (kernel, engine's levels and K) >= the error densely measured."""
    patches = random_patches(rng, 4)
    pyramids, index = integral.scene_pyramids(patches, np.ones(4, bool))
    count = 200
    corners = rng.uniform(0, 1, (count, 3, 2))
    corners[:60] = corners[:60] * rng.uniform(0.01, 0.2, (60, 1, 1))  # near corner (0, 0), where spikes are
    corners = corners.astype(np.float32)
    owner = rng.integers(0, 4, count)
    uv = corners.reshape(-1, 2)
    patch_ids = np.repeat(owner, 3)
    positions = surface_points(patches, patch_ids, uv[:, 0].astype(float), uv[:, 1].astype(float))
    triangles = np.arange(3 * count).reshape(count, 3)
    error = dense_errors(patches, positions, uv, patch_ids, triangles)
    tolerance = np.full(4, 1e-3, np.float32)  # small: every triangle takes the upper sums up to K = 24
    ratios = triangle_ratios(tessellator, pyramids, index, np.ones(4, np.int32), uv, patch_ids, triangles, tolerance)
    assert (error <= ratios * 1e-3).all(), (error / (ratios * 1e-3)).max()
    assert (error > 0.3 * ratios * 1e-3).any()  # and not idle


def _integral_and_hull(tessellator, scene, eps):
    integral_plan = tessellator.plan(scene, eps=eps, bound="integral", max_factor=4096)
    hull_plan = tessellator.plan(scene, eps=eps, max_factor=4096)
    return integral_plan, hull_plan


@pytest.mark.parametrize("relative_eps", [3e-2, 3e-3])
def test_every_emitted_triangle_is_certified_on_a_rational_grid(tessellator, rng, relative_eps):
    """A closed grid of rational patches (weights 0.2 to 5): patches end at different trials,
    so transition triangles join different factors.  Every emitted triangle is either of a patch
    at today's factors or bounded by the kernel <= its tolerance, and that bound holds."""
    scene = closed_torus_grid(rng, 4, 3, weights=(0.2, 5.0))
    eps = relative_eps * scene.diagonal
    plan, hull = _integral_and_hull(tessellator, scene, eps)
    final, today = plan.factors.get(), hull.factors.get()
    assert (np.abs(final) <= np.abs(today)).all()  # never above the hull bound's
    assert plan.num_indices < hull.num_indices
    trials = plan.integral_trials
    assert len(set(trials.tolist())) > 1  # patches at different trials
    tess = tessellator.emit(plan, 0, plan.num_patches)
    assert np.isfinite(tess.positions).all() and np.isfinite(tess.normals).all()
    patches = np.asarray(scene.patches, float)
    pyramids, index = integral.scene_pyramids(patches, np.ones(len(patches), bool))
    owner = tess.patch_ids[tess.triangles[:, 0]]
    ratios = triangle_ratios(tessellator, pyramids, index, np.ones(len(patches), np.int32), tess.uv,
                             tess.patch_ids, tess.triangles, np.full(len(patches), eps, np.float32))
    certified = (trials[owner] == LAST_TRIAL) | (ratios <= 1.0)
    assert certified.all()
    f = np.abs(final)
    transition = (f[owner][:, 0] != f[owner][:, 2]) | (f[owner][:, 1] != f[owner][:, 3])
    assert transition.any()  # crack-free raised an edge factor somewhere
    error = dense_errors(patches, tess.positions, tess.uv, tess.patch_ids, tess.triangles)
    checked = trials[owner] < LAST_TRIAL
    assert (error[checked] <= ratios[checked] * eps).all()
    assert error.max() <= eps
    mesh = weld_exact(tess.positions, tess.triangles)
    edges = np.sort(mesh.edges, axis=1)
    _, uses = np.unique(edges, axis=0, return_counts=True)
    assert (uses == 2).all()  # closed, manifold


def test_polynomial_patches_keep_the_hull_factors(tessellator):
    scene = load_scene(SCENES / "teapot.bez")
    plan, hull = _integral_and_hull(tessellator, scene, 1e-2)
    assert (plan.factors.get() == hull.factors.get()).all()
    assert plan.stats["integral_patches"] == 0 and plan.stats["integral_rounds"] == 0


def test_screen_space_and_a_mixed_scene(tessellator, rng):
    """Polynomial and rational patches together, eps per patch: the certified bound holds."""
    patches = np.concatenate([random_patches(rng, 4), load_scene(SCENES / "teapot.bez").patches[:4]])
    scene = Scene(patches, np.zeros(len(patches), np.int32), name="mixed")
    eps = 1e-2 * scene.diagonal
    plan, hull = _integral_and_hull(tessellator, scene, eps)
    assert plan.stats["integral_patches"] == 4
    final, today = plan.factors.get(), hull.factors.get()
    assert (final <= today).all() and (final[4:] == today[4:]).all()
    tess = tessellator.emit(plan, 0, plan.num_patches)
    assert dense_errors(patches, tess.positions, tess.uv, tess.patch_ids, tess.triangles, 8).max() <= eps


def test_trial_factors_never_exceed_todays(rng):
    today = rng.integers(0, 5000, (200, 4)).astype(np.int32)
    today[:20] = 0  # culled
    for trial in range(len(integral.TRIAL_SCALES)):
        got = integral.trial_factors(today, np.full(200, trial))
        assert (got <= today).all() and ((got >= 1) | (today == 0)).all()
    assert (integral.trial_factors(today, np.full(200, LAST_TRIAL)) == today).all()


def test_request_and_cli_refuse_what_the_option_cannot_do(tmp_path):
    with pytest.raises(ValueError, match="bound must be one of"):
        Request.of(eps=1.0, bound="exact")
    with pytest.raises(ValueError, match="cannot be used with pattern"):
        Request.of(eps=1.0, bound="integral", pattern="semi_uniform")
    from cltess.backends.numpy import NumpyBackend
    from cltess.session import Session

    scene = load_scene(SCENES / "torus.bpt")
    with pytest.raises(ValueError, match="OpenCL backend"):
        NumpyBackend().plan(scene, Request.of(eps=1.0, bound="integral"))
    with pytest.raises(ValueError, match="Session"):
        Session(scene, eps=1.0, bound="integral").tessellate()
    run = subprocess.run([sys.executable, "-m", "cltess", "tessellate", str(SCENES / "torus.bpt"), "--eps", "0.1",
                          "--bound", "integral", "--pattern", "semi-uniform", "-o", str(tmp_path / "t.ply")],
                         capture_output=True, text=True)
    assert run.returncode == 2 and "--bound integral" in run.stderr and not (tmp_path / "t.ply").exists()


def test_cli_bound_integral_writes_fewer_triangles(tmp_path):
    out = tmp_path / "r.ply"
    run = subprocess.run([sys.executable, "-m", "cltess", "tessellate", str(SCENES / "torus.bpt"), "--eps", "0.02",
                          "--bound", "integral", "--verify", "-o", str(out)], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert "integral rounds" in run.stdout and "warning" not in run.stderr
