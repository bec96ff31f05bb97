"""Issue 9 item 9: --verify and Tessellator.verify measure the actual error on the device
(kernels/stages/verify.cl), in agreement with the float64 host measurements (cltess.bound and
tests/support.bound_ratio) within 1%, and say where the worst deviation is."""
import json
from pathlib import Path

import numpy as np
import pytest

from cltess.bound import scene_tolerances, worst_bound_ratio
from cltess.cli import main
from cltess.formats import load_scene
from cltess.scene import Scene
from support import bound_ratio, icosphere, torus

SCENES = Path(__file__).resolve().parent.parent / "scenes"
ORDER = 6  # Tessellator.verify's default: 28 points per triangle


def bound_scenes():
    yield "teapot", load_scene(SCENES / "teapot.bez"), 3e-3
    yield "sphere", load_scene(SCENES / "sphere.bpt"), 1e-3
    yield "torus", load_scene(SCENES / "torus.bpt"), 3e-3
    yield "pn torus", Scene.from_trimesh(torus(), name="pn torus"), 1e-3
    yield "pn icosphere", Scene.from_trimesh(icosphere(1), name="pn icosphere"), 1e-2


@pytest.mark.parametrize("fd", [True, False], ids=["fd", "direct"])
def test_verify_agrees_with_the_float64_measurement(tessellator, fd):
    for name, scene, eps in bound_scenes():
        plan = tessellator.plan(scene, eps=eps, forward_differencing=fd)
        tess = tessellator.emit(plan, 0, plan.num_patches)
        verified = tessellator.verify(scene, plan, tess)
        host = worst_bound_ratio(scene, tess, eps=eps, order=ORDER)
        assert verified["verify_triangles"] == len(tess.triangles) and verified["verify_stride"] == 1
        assert abs(verified["verify_ratio"] - host) <= 0.01 * host, name
        assert 0.2 < host <= 1.0, name  # a real measurement near the bound, not a vacuous one
        if name in ("sphere", "torus", "teapot"):  # the second independent measure (Bézier only)
            assert abs(verified["verify_ratio"] - bound_ratio(scene.patches, tess, eps, order=ORDER)) <= 0.01 * host


def test_verify_names_the_triangle_and_patch_where_the_worst_deviation_is(tessellator):
    scene, eps = load_scene(SCENES / "teapot.bez"), 1e-3
    plan = tessellator.plan(scene, eps=eps)
    tess = tessellator.emit(plan, 0, plan.num_patches)
    verified = tessellator.verify(scene, plan, tess)
    triangle = verified["verify_triangle"]
    assert tess.patch_ids[tess.triangles[triangle, 0]] == verified["verify_patch"]

    class One:  # the mesh of that one triangle
        positions, uv, patch_ids, triangles = tess.positions, tess.uv, tess.patch_ids, tess.triangles[triangle:triangle + 1]

    assert abs(worst_bound_ratio(scene, One, eps=eps, order=ORDER) - verified["verify_ratio"]) < 1e-3


def test_verify_sees_a_missed_bound(tessellator):
    """Saturated patches (max_factor too low) miss the bound: verify says by how much, as the host does."""
    scene, eps = load_scene(SCENES / "sphere.bpt"), 1e-4
    plan = tessellator.plan(scene, eps=eps, max_factor=4)
    tess = tessellator.emit(plan, 0, plan.num_patches)
    verified = tessellator.verify(scene, plan, tess)
    host = worst_bound_ratio(scene, tess, eps=eps, order=ORDER)
    assert verified["verify_ratio"] > 10 and abs(verified["verify_ratio"] - host) <= 0.01 * host


def test_verify_samples_every_kth_triangle_above_the_limit_and_batches_sample_alike(tessellator):
    scene, eps = load_scene(SCENES / "teapot.bez"), 1e-3
    plan = tessellator.plan(scene, eps=eps)
    whole = tessellator.emit(plan, 0, plan.num_patches)
    full = tessellator.verify(scene, plan, whole)
    sampled = tessellator.verify(scene, plan, whole, max_triangles=10_000)
    stride = sampled["verify_stride"]
    assert stride == -(-len(whole.triangles) // 10_000) > 1
    assert sampled["verify_triangles"] == len(range(0, len(whole.triangles), stride))
    assert sampled["verify_ratio"] <= full["verify_ratio"] and sampled["verify_triangle"] % stride == 0
    from cltess.backends.opencl.tessellator import combine_verified

    ranges = plan.batch_ranges(plan.output_bytes // 5)
    assert len(ranges) > 1
    for max_triangles, single in ((None, full), (10_000, sampled)):
        parts = [tessellator.verify(scene, plan, tessellator.emit(plan, a, b), max_triangles=max_triangles or 4_000_000)
                 for a, b in ranges]
        combined = combine_verified(parts)
        assert {k: v for k, v in combined.items() if k != "verify_ms"} == \
               {k: v for k, v in single.items() if k != "verify_ms"}


def test_scene_tolerances_are_the_bound_tests_tolerances():
    scene = load_scene(SCENES / "teapot.bez")
    assert np.array_equal(scene_tolerances(scene, eps=0.01), np.full(scene.num_patches, 0.01))


def test_cli_verify_prints_the_measurement_beside_eps_and_stores_it(capsys, tmp_path):
    out = tmp_path / "sphere.npz"
    code = main(["tessellate", str(SCENES / "sphere.bpt"), "--eps", "1e-3", "--verify", "-o", str(out)])
    printed = capsys.readouterr().out
    assert code == 0
    line = next(l for l in printed.splitlines() if l.startswith("verified"))
    stats = json.loads(str(np.load(out)["stats_json"]))["stats"]
    assert f"= {stats['verify_ratio']:.4f} x tolerance (requested eps 0.001)" in line
    assert f"at patch {stats['verify_patch']}, triangle {stats['verify_triangle']}" in line
    assert 0.3 < stats["verify_ratio"] <= 1.0


def test_cli_verify_warns_when_the_measurement_exceeds_eps(capsys, tmp_path):
    code = main(["tessellate", str(SCENES / "sphere.bpt"), "--eps", "1e-4", "--max-factor", "4", "--verify",
                 "-q", "-o", str(tmp_path / "s.ply")])
    err = capsys.readouterr().err
    assert code == 0 and "measured deviation" in err and "times the tolerance" in err


def test_cli_without_verify_measures_nothing(capsys, tmp_path):
    out = tmp_path / "sphere.npz"
    assert main(["tessellate", str(SCENES / "sphere.bpt"), "--eps", "1e-2", "-o", str(out)]) == 0
    assert "verified" not in capsys.readouterr().out
    assert "verify_ratio" not in json.loads(str(np.load(out)["stats_json"]))["stats"]


@pytest.mark.parametrize("max_factor", [1024, 3], ids=["bound met", "saturated"])
def test_verify_against_the_host_on_random_rational_patches(tessellator, rng, max_factor):
    """Random rational patches (weights 0.2-5, with transitions), and the same clamped so that
    they miss the bound: the device measurement is the host's within 1%."""
    from support import random_patches

    scene = Scene(random_patches(rng, 40), np.arange(40, dtype=np.int32), name="random")
    eps = 0.02
    plan = tessellator.plan(scene, eps=eps, max_factor=max_factor)
    tess = tessellator.emit(plan, 0, plan.num_patches)
    verified = tessellator.verify(scene, plan, tess)
    host = worst_bound_ratio(scene, tess, eps=eps, order=ORDER)
    assert abs(verified["verify_ratio"] - host) <= 0.01 * host
    assert (tess.stats["saturated"] > 0) == (max_factor == 3) == (host > 1.0)


def test_verify_order_and_sampling_follow_the_arguments(tessellator):
    scene, eps = load_scene(SCENES / "torus.bpt"), 3e-3
    plan = tessellator.plan(scene, eps=eps)
    tess = tessellator.emit(plan, 0, plan.num_patches)
    for order in (1, 3, 9):  # order 1: the corners only, where surface and mesh meet
        verified = tessellator.verify(scene, plan, tess, order=order)
        host = worst_bound_ratio(scene, tess, eps=eps, order=order)
        assert verified["verify_order"] == order
        assert abs(verified["verify_ratio"] - host) <= 0.01 * host + 1e-4
    assert tessellator.verify(scene, plan, tess, order=1)["verify_ratio"] < 1e-3
