"""cltess.batch and ``cltess batch`` (issue 17) on a LocalCluster of 2 worker processes."""
from __future__ import annotations

import json
import os
import shutil
import time
from pathlib import Path

import numpy as np
import pytest
import trimesh

pytest.importorskip("distributed")

import psutil  # noqa: E402 (a dependency of distributed)

from cltess.batch import (BatchOptions, dask_client, expand_inputs, read_manifest,  # noqa: E402
                          split_ranges, tessellate_files, tessellate_split)
from cltess.cli import main  # noqa: E402
from cltess.io import load_scene  # noqa: E402
from cltess.orient import orient_scene  # noqa: E402
from cltess.stream import tessellate_to_file  # noqa: E402

SCENES = Path(__file__).resolve().parent.parent / "scenes"
EPS = 0.01  # coarse: the point is the plumbing, the bytes are compared with one process


@pytest.fixture(scope="module")
def client():
    with dask_client(workers=2, timeout=60) as client:
        pids = list(client.run(os.getpid).values())
        assert len(pids) == 2
        yield client
    deadline = time.monotonic() + 10
    while any(psutil.pid_exists(pid) and psutil.Process(pid).status() != psutil.STATUS_ZOMBIE for pid in pids):
        assert time.monotonic() < deadline, f"worker processes {pids} outlived the cluster"
        time.sleep(0.1)


@pytest.fixture
def inputs(tmp_path):
    """Four bundled scenes (one a .json scene of others) and a truncated .bez file."""
    folder = tmp_path / "in"
    folder.mkdir()
    for name in ("teapot.bez", "teacup.bez", "teaspoon.bez", "table.bpt", "sphere.bpt"):
        shutil.copy(SCENES / name, folder / name)
    (folder / "two.json").write_text(json.dumps({"objects": [{"file": "teacup.bez"}, {"file": "table.bpt"}]}))
    (folder / "broken.bez").write_text("2\n1,2,3\n")
    return folder


def single_process_bytes(tessellator, path, tmp_path, weld=True, **options) -> bytes:
    """What ``cltess tessellate`` writes: the scene oriented, the mesh welded unless told not."""
    out = tmp_path / f"single-{Path(path).name}.ply"
    tessellate_to_file(tessellator, orient_scene(load_scene(path))[0], out, weld=weld, **options)
    return out.read_bytes()


def test_batch_writes_each_output_and_fails_only_the_broken_row(client, inputs, tmp_path, tessellator):
    rows = tessellate_files([inputs], tmp_path / "out", eps=EPS, client=client)
    by_name = {Path(row["input"]).name: row for row in rows}
    assert sorted(by_name) == ["broken.bez", "sphere.bpt", "table.bpt", "teacup.bez", "teapot.bez",
                               "teaspoon.bez", "two.json"]
    broken = by_name.pop("broken.bez")
    assert broken["status"] == "failed" and "line 1" in broken["error"] and "truncated" in broken["error"]
    assert not Path(broken["output"]).exists()
    for name, row in by_name.items():
        assert row["status"] == "done", row["error"]
        output = Path(row["output"])
        assert output == tmp_path / "out" / f"{name}.ply"
        assert output.read_bytes() == single_process_bytes(tessellator, inputs / name, tmp_path, eps=EPS)
        assert row["output_bytes"] == output.stat().st_size and row["triangles"] > 0
        assert row["factors_ms"] >= 0 and row["vertices_ms"] > 0 and row["seconds"] > 0
    manifest = read_manifest(tmp_path / "out")
    assert manifest["rows"] == json.loads(json.dumps(rows))
    assert manifest["options"]["eps"] == EPS
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == sorted(
        [f"{name}.ply" for name in by_name] + ["manifest.json"])  # no temporary or partial file


def test_rerun_skips_what_is_up_to_date(client, inputs, tmp_path):
    out = tmp_path / "out"
    tessellate_files([inputs], out, eps=EPS, client=client)
    first = {Path(row["input"]).name: row for row in read_manifest(out)["rows"]}

    def statuses(**options):
        rows = tessellate_files([inputs], out, eps=options.pop("eps", EPS), client=client, **options)
        return {Path(row["input"]).name: row["status"] for row in rows}

    again = statuses()
    assert again.pop("broken.bez") == "failed"  # failed rows are retried
    assert set(again.values()) == {"skipped"}
    os.utime(inputs / "teapot.bez", ns=(time.time_ns(), time.time_ns() + 10**9))  # touched, same content
    (inputs / "teaspoon.bez").write_text((SCENES / "teacup.bez").read_text())  # changed
    (out / "table.bpt.ply").unlink()  # output gone
    with open(inputs / "teacup.bez", "a") as handle:  # a file a .json scene names changed
        handle.write("\n")
    changed = statuses()
    assert changed["teapot.bez"] == "skipped" and changed["sphere.bpt"] == "skipped"
    assert changed["teaspoon.bez"] == changed["table.bpt"] == changed["teacup.bez"] == changed["two.json"] == "done"
    assert (out / "table.bpt.ply").exists()
    skipped = {Path(row["input"]).name: row for row in read_manifest(out)["rows"]}["sphere.bpt"]
    assert skipped["triangles"] == first["sphere.bpt"]["triangles"]  # keeps what it recorded
    assert set(statuses(eps=EPS / 2).values()) == {"done", "failed"}  # new options: all redone


def test_verify_puts_the_device_measurement_in_the_manifest(client, inputs, tmp_path, tessellator):
    """--verify (Tessellator.verify, on the worker's device) gives each row verify_ratio and
    verify_patch, equal to the single-process measurement; a rerun without a measurement redoes it."""
    files = [inputs / "teapot.bez", inputs / "sphere.bpt"]
    plain = tessellate_files(files[:1], tmp_path / "out", eps=EPS, client=client)
    assert plain[0]["verify_ratio"] is None
    rows = tessellate_files(files, tmp_path / "out", eps=EPS, client=client, verify=True)
    for path, row in zip(files, rows):
        assert row["status"] == "done"  # the teapot's too: asked for now, not measured then
        scene = load_scene(path)
        plan = tessellator.plan(scene, eps=EPS)
        expected = tessellator.verify(scene, plan, tessellator.emit(plan, 0, plan.num_patches))
        assert row["verify_ratio"] == pytest.approx(expected["verify_ratio"], rel=1e-5)
        assert row["verify_patch"] == expected["verify_patch"] and 0.1 < row["verify_ratio"] <= 1
    again = tessellate_files(files, tmp_path / "out", eps=EPS, client=client, verify=True)
    assert [r["status"] for r in again] == ["skipped", "skipped"]
    assert json.loads((tmp_path / "out" / "manifest.json").read_text())["rows"][0]["verify_ratio"] is not None
    with pytest.raises(ValueError, match="--verify"):
        tessellate_files(files[:1], tmp_path / "split", eps=EPS, client=client, verify=True, split=2)


def test_check_bound_measures_each_output_as_the_tests_do(client, inputs, tmp_path, tessellator):
    """--check-bound reads each output back and measures it (cltess.bound), as support.bound_ratio
    measures the in-memory mesh; OBJ keeps no patch ids, so its ratio stays unknown."""
    from support import bound_ratio

    files = [inputs / "teapot.bez", inputs / "sphere.bpt"]
    with pytest.raises(ValueError, match="--no-weld"):
        tessellate_files(files, tmp_path / "welded", eps=EPS, client=client, check_bound=True)
    rows = tessellate_files(files, tmp_path / "out", eps=EPS, client=client, check_bound=True, weld=False)
    for path, row in zip(files, rows):
        scene = load_scene(path)
        expected = bound_ratio(np.asarray(scene.patches, float), tessellator.tessellate(scene, eps=EPS), EPS, order=4)
        assert row["worst_bound_ratio"] == pytest.approx(expected, rel=1e-12)
        assert 0.1 < row["worst_bound_ratio"] <= 1
    rows = tessellate_files(files[:1], tmp_path / "out", eps=EPS, client=client, check_bound=True, weld=False)
    assert rows[0]["status"] == "skipped" and rows[0]["worst_bound_ratio"] is not None
    [npz] = tessellate_files(files[:1], tmp_path / "npz", eps=EPS, client=client, check_bound=True, format="npz",
                             weld=False)
    assert npz["worst_bound_ratio"] == rows[0]["worst_bound_ratio"]
    [obj] = tessellate_files(files[:1], tmp_path / "obj", eps=EPS, client=client, check_bound=True, format="obj",
                             weld=False)
    assert obj["status"] == "done" and obj["worst_bound_ratio"] is None


def test_bound_of_pn_triangles_and_of_a_mixed_scene(tessellator):
    from support import bound_ratio, genus2

    from cltess import Scene, reference
    from cltess.bound import worst_bound_ratio
    from cltess.pipeline import PN

    mesh = Scene.from_trimesh(genus2(resolution=1))
    tess = tessellator.tessellate(mesh, eps=2e-3)
    controls = reference.pn_control_points(np.asarray(PN.prepare(mesh).source, float))
    expected = bound_ratio(controls, tess, 2e-3, order=4, surface=reference.pn_surface_points)
    assert worst_bound_ratio(mesh, tess, eps=2e-3) == pytest.approx(expected, rel=1e-12)
    assert 0.1 < expected <= 1
    mixed = load_scene(SCENES / "tea_table.json")
    mixed = Scene(mixed.patches, mixed.object_ids, meshes=mesh.meshes, name="mixed")
    tess = tessellator.tessellate(mixed, eps=2e-3, max_factor=256)
    assert 0.1 < worst_bound_ratio(mixed, tess, eps=2e-3) <= 1


def test_split_scene_is_byte_identical_to_one_process(client, tmp_path, tessellator):
    row = tessellate_split(SCENES / "teapot.bez", tmp_path / "teapot.ply", client=client, parts=7, eps=1e-3,
                           max_factor=256)
    assert row["status"] == "done" and row["parts"] == 7 and row["worker"] == "0,1"
    expected = single_process_bytes(tessellator, SCENES / "teapot.bez", tmp_path, weld=False, eps=1e-3,
                                    max_factor=256)
    assert (tmp_path / "teapot.ply").read_bytes() == expected
    assert row["output_bytes"] == len(expected)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["single-teapot.bez.ply", "teapot.ply"]


def test_split_mesh_scene_in_small_batches_is_byte_identical(client, tmp_path, tessellator):
    """PN triangles (their stage-4 controls come from stage 1), ranges that start inside a kind,
    and a memory cap that makes every worker emit its range in several batches."""
    mesh_path = tmp_path / "genus.obj"
    trimesh.creation.torus(2.0, 0.7, major_sections=24, minor_sections=12).export(mesh_path)
    scene = tmp_path / "mixed.json"
    shutil.copy(SCENES / "teacup.bez", tmp_path / "teacup.bez")
    scene.write_text(json.dumps({"objects": [{"file": "teacup.bez"}, {"file": "genus.obj", "object_id": 5}]}))
    options = BatchOptions(eps=2e-3, max_memory=3 * 200_000)
    row = tessellate_split(scene, tmp_path / "mixed.ply", options, client=client, parts=5)
    assert row["parts"] > 5  # the cap asked for more ranges than 5
    expected = single_process_bytes(tessellator, scene, tmp_path, weld=False, eps=2e-3)
    assert (tmp_path / "mixed.ply").read_bytes() == expected


def test_split_of_a_broken_scene_leaves_nothing(client, inputs, tmp_path):
    rows = tessellate_files([inputs / "broken.bez", inputs / "teacup.bez"], tmp_path / "out", eps=EPS,
                            client=client, split=3)
    assert [row["status"] for row in rows] == ["failed", "done"]
    assert "line 1" in rows[0]["error"]
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["manifest.json", "teacup.bez.ply"]


def test_split_ranges_cover_the_patches_in_about_equal_output():
    rng = np.random.default_rng(17)
    sizes = np.concatenate([[0], np.cumsum(rng.integers(0, 1000, 500))])
    for parts, cap in ((1, 10**9), (4, 10**9), (7, 10**9), (3, 20_000), (1000, 10**9)):
        ranges = split_ranges(sizes, 10, 490, parts, cap)
        assert ranges[0][0] == 10 and ranges[-1][1] == 490
        assert all(a < b for a, b in ranges) and all(b == c for (_, b), (c, _) in zip(ranges, ranges[1:]))
        assert len(ranges) >= min(parts, 480, -(-int(sizes[490] - sizes[10]) // cap))
        biggest = max(sizes[b] - sizes[a] for a, b in ranges)
        assert biggest <= max(cap, (sizes[490] - sizes[10]) / len(ranges)) + 1000


def test_upload_plan_emits_what_the_plan_emits(tessellator):
    """The pipeline entry point the workers use: a plan read back and put on another queue
    gives the same stages 4-5 output for any range, without running stages 1-3."""
    from cltess.pipeline import Tessellator

    plan = tessellator.plan(load_scene(SCENES / "tea_table.json"), eps=0.01)
    host = plan.to_host()
    other = Tessellator(tessellator.device)
    for first, last in ((0, plan.num_patches), (3, 40), (plan.num_patches - 5, plan.num_patches)):
        uploaded = other.upload_plan(host, first, last)
        assert not uploaded.events  # no stage 1-3 ran
        expected, got = tessellator.emit(plan, first, last), other.emit(uploaded, first, last)
        for name in ("positions", "normals", "uv", "patch_ids", "object_ids", "triangles", "factors"):
            assert np.array_equal(getattr(got, name), getattr(expected, name)), name


def test_inputs_expand_folders_and_globs_and_refuse_clashes(tmp_path, inputs):
    names = [name for _, name in expand_inputs([inputs / "tea*.bez", inputs, str(inputs / "sphere.bpt")])]
    assert names[:3] == ["teacup.bez", "teapot.bez", "teaspoon.bez"] and len(names) == 7
    (tmp_path / "b").mkdir()
    shutil.copy(SCENES / "teapot.bez", tmp_path / "b" / "teapot.bez")
    with pytest.raises(ValueError, match="would both write teapot.bez"):
        expand_inputs([inputs / "teapot.bez", tmp_path / "b" / "teapot.bez"])
    with pytest.raises(ValueError, match="no such file"):
        expand_inputs([tmp_path / "missing.bez"])
    with pytest.raises(ValueError, match="names no scene file"):
        expand_inputs([str(tmp_path / "*.nothing")])
    (inputs / "out").mkdir()
    (inputs / "out" / "teapot.bez.ply").write_bytes(b"ply\n")  # an earlier run's output, a mesh file
    assert len(expand_inputs([inputs], exclude=inputs / "out")) == 7
    assert len(expand_inputs([inputs])) == 8


# --------------------------------------------------------------------------- the command line


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def test_cli_batch_reports_the_failed_input_and_exits_3(client, capsys, inputs, tmp_path):
    out = tmp_path / "out"
    code, stdout, stderr = run(capsys, "batch", inputs / "teapot.bez", inputs / "broken.bez", "--eps", EPS,
                               "-o", out, "--scheduler", client.scheduler.address)
    assert code == 3
    assert "1 done, 0 up to date, 1 failed" in stdout
    assert "cltess: error: 1 of 2 inputs failed" in stderr and "broken.bez: line 1" in stderr
    assert "Traceback" not in stderr and "[" in stderr  # the progress bar
    assert sorted(p.name for p in out.iterdir()) == ["manifest.json", "teapot.bez.ply"]
    code, stdout, _ = run(capsys, "batch", inputs / "teapot.bez", "--eps", EPS, "-o", out, "-q",
                          "--scheduler", client.scheduler.address)
    assert code == 0 and stdout == ""


def test_cli_batch_split_writes_what_tessellate_writes(client, capsys, tmp_path):
    code, stdout, stderr = run(capsys, "batch", SCENES / "teacup.bez", "--eps", 1e-3, "--split", 3, "-o",
                               tmp_path / "out", "--scheduler", client.scheduler.address)
    assert code == 0, stderr
    assert "1 done, 0 up to date, 0 failed" in stdout
    code, _, stderr = run(capsys, "tessellate", SCENES / "teacup.bez", "--eps", 1e-3, "--no-weld",
                         "-o", tmp_path / "one.ply", "-q")
    assert code == 0, stderr
    assert (tmp_path / "out" / "teacup.bez.ply").read_bytes() == (tmp_path / "one.ply").read_bytes()
    assert read_manifest(tmp_path / "out")["rows"][0]["parts"] == 3


def test_cli_batch_semi_uniform_by_level_writes_what_tessellate_writes(client, capsys, tmp_path):
    """batch --pattern semi-uniform --max-level 4 --emit by-level, whole and split, gives
    tessellate's bytes with the same options (by level = per patch without forward differencing)."""
    options = ["--pattern", "semi-uniform", "--max-level", "4"]
    for split in ([], ["--split", "3"]):
        out = tmp_path / f"out{len(split)}"
        code, stdout, stderr = run(capsys, "batch", SCENES / "teacup.bez", "--eps", 1e-3, *options, "--emit",
                                   "by-level", *split, "--no-weld", "-o", out, "--scheduler", client.scheduler.address)
        assert code == 0, stderr
        assert "1 done, 0 up to date, 0 failed" in stdout
        code, _, stderr = run(capsys, "tessellate", SCENES / "teacup.bez", "--eps", 1e-3, *options, "--no-fd",
                              "--no-weld", "-o", tmp_path / "one.ply", "-q")
        assert code == 0, stderr
        assert (out / "teacup.bez.ply").read_bytes() == (tmp_path / "one.ply").read_bytes(), split


def test_cli_batch_on_its_own_local_cluster(capsys, inputs, tmp_path):
    before = {child.pid for child in psutil.Process().children(recursive=True)}
    code, stdout, stderr = run(capsys, "batch", inputs / "tea*.bez", "--eps", EPS, "-o", tmp_path / "out",
                               "--workers", "2", "--format", "obj")
    assert code == 0, stderr
    left = [" ".join(c.cmdline()) for c in psutil.Process().children(recursive=True)
            if c.pid not in before and c.is_running() and c.status() != psutil.STATUS_ZOMBIE]
    # multiprocessing's resource tracker stays for the life of this process, as it should
    left = [cmdline for cmdline in left if "resource_tracker" not in cmdline]
    assert not left, f"the local cluster left processes behind: {left}"
    assert "3 done, 0 up to date, 0 failed" in stdout
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == [
        "manifest.json", "teacup.bez.obj", "teapot.bez.obj", "teaspoon.bez.obj"]


@pytest.mark.parametrize("arguments, fragment", [
    (["nothing-*.bez", "--eps", "0.01"], "names no scene file"),
    (["missing.bez", "--eps", "0.01"], "missing.bez: no such file"),
    (["{teapot}", "--eps", "0.01", "--split", "2", "--format", "obj"], "cannot be split"),
    (["{teapot}", "--eps", "0.01", "--scheduler", "tcp://127.0.0.1:1", "--workers", "2"], "--workers"),
    (["{teapot}", "--eps", "0"], "must be a finite number > 0"),
    (["{teapot}", "--eps", "0.01", "--split", "2", "--check-bound", "--no-weld"], "cannot be used with --split"),
    (["{teapot}", "--eps", "0.01", "--check-bound"], "add --no-weld"),
    (["{teapot}", "--eps", "0.01", "--split", "2", "--weld"], "--weld cannot be used with --split"),
    (["{teapot}", "--eps", "0.01", "--pixels", "1"], "not allowed with argument"),
    (["{teapot}", "--eps", "0.01", "--emit", "by-level"], "--emit by-level needs --pattern semi-uniform"),
])
def test_cli_batch_bad_arguments_exit_2_before_any_work(capsys, tmp_path, monkeypatch, arguments, fragment):
    monkeypatch.chdir(tmp_path)
    arguments = [a.replace("{teapot}", str(SCENES / "teapot.bez")) for a in arguments]
    code, _, stderr = run(capsys, "batch", *arguments, "-o", tmp_path / "out")
    assert code == 2
    assert "cltess: error:" in stderr and fragment in stderr and "Traceback" not in stderr
    assert not (tmp_path / "out").exists()
