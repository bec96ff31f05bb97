"""The command line: argument validation, error reporting, exit codes, summary.

Most tests replace ``cltess.pipeline`` with a fake (``fake_pipeline``) so that they check the
CLI's own behaviour; ``test_tessellate_end_to_end`` runs the real pipeline once.
"""
from __future__ import annotations

import os
import subprocess
import sys
import types
from pathlib import Path

import numpy as np
import pyopencl as cl
import pytest
import trimesh

from cltess import cli
from cltess.cli import main
from cltess.backends.opencl.share_cuda import sharing_apis
from cltess.device import DEVICE_ENV_VAR, list_devices
from cltess.limits import OutputTooLarge
from cltess.scene import Scene
from cltess.tessellation import Tessellation
from support.device_faults import UNKNOWN_CPU_LOG, UNKNOWN_CPU_REASON, fresh_probes, pocl_fails_to_build

REPO = Path(__file__).resolve().parents[1]


def flat_patch_bpt(path: Path, bad_line: int | None = None) -> Path:
    """A one-patch .bpt (a bent unit square); ``bad_line`` (1-based) gets a non-number."""
    lines = ["1", "3 3"]
    for j in range(4):
        for i in range(4):
            lines.append(f"{i / 3} {j / 3} {0.1 * (i - 1.5) ** 2}")
    if bad_line is not None:
        lines[bad_line - 1] = "0.0 zero 0.0"
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.fixture(autouse=True)
def no_device_env(monkeypatch):
    monkeypatch.delenv(DEVICE_ENV_VAR, raising=False)


@pytest.fixture
def scene_file(tmp_path) -> Path:
    return flat_patch_bpt(tmp_path / "patch.bpt")


def small_tessellation(stats_extra: dict | None = None, saturated: int = 0) -> Tessellation:
    positions = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], np.float32)
    return Tessellation(
        positions=positions, normals=np.tile(np.float32([0, 0, 1]), (4, 1)), uv=positions[:, :2].copy(),
        patch_ids=np.zeros(4, np.int32), object_ids=np.zeros(4, np.int32),
        triangles=np.array([[0, 1, 2], [1, 3, 2]], np.uint32), factors=np.ones((1, 4), np.int32),
        stage_ms={"factors": 0.5, "indices": 0.25},
        stats={"patches": 1, "culled": 0, "saturated": saturated, "vertices": 4, "triangles": 2,
               **(stats_extra or {})},
    )


class FakeTessellator:
    """Stands in for cltess.pipeline.Tessellator; records its calls."""

    calls: list = []
    result: Tessellation | BaseException = small_tessellation()

    def __init__(self, device=None):
        self.device = device

    def tessellate(self, scene, eps=None, pixels=None, max_factor=64, forward_differencing=True):
        return self.emit(self.plan(scene, eps, pixels, max_factor), 0, 1, forward_differencing)

    # The CLI streams through cltess.stream, which calls plan() once and emit() per batch.
    def plan(self, scene, eps=None, pixels=None, max_factor=64, pattern=None, max_level=6, emit="per_patch"):
        FakeTessellator.calls.append(dict(scene=scene, eps=eps, pixels=pixels, max_factor=max_factor,
                                          pattern=pattern, max_level=max_level, emit=emit, device=self.device))
        if isinstance(FakeTessellator.result, BaseException):
            raise FakeTessellator.result
        return FakePlan(FakeTessellator.result)

    def emit(self, plan, first, last, forward_differencing=True):
        FakeTessellator.calls[-1]["forward_differencing"] = forward_differencing
        result = FakeTessellator.result
        result.stats.update(first_patch=first, last_patch=last)
        return result


class FakePlan:
    """One batch holding the whole fake result."""

    def __init__(self, tess):
        self.stats, self.num_patches = dict(tess.stats), 1
        self.num_vertices, self.num_indices = tess.num_vertices, 3 * tess.num_triangles
        self.output_bytes = 0

    def batch_ranges(self, max_output_bytes):
        return [(0, 1)]


@pytest.fixture
def fake_pipeline(monkeypatch):
    module = types.ModuleType("cltess.pipeline")
    module.Tessellator = FakeTessellator
    monkeypatch.setitem(sys.modules, "cltess.pipeline", module)
    monkeypatch.setattr(FakeTessellator, "calls", [])
    monkeypatch.setattr(FakeTessellator, "result", small_tessellation())
    return FakeTessellator


def run(capsys, *argv) -> tuple[int, str, str]:
    code = main([str(a) for a in argv])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def assert_clean_error(err: str, *fragments: str) -> None:
    assert "cltess: error:" in err
    assert "Traceback" not in err
    for fragment in fragments:
        assert fragment in err


# --------------------------------------------------------------------------- devices


def test_devices_lists_pocl_with_default_marker(capsys):
    code, out, err = run(capsys, "devices")
    assert code == 0 and err == ""
    assert "Portable Computing Language" in out
    device_lines = [line for line in out.splitlines() if line.startswith("  ")]
    assert sum(line.lstrip().startswith("*") for line in device_lines) == 1
    assert "CPU" in out
    for info in list_devices():  # the APIs Session(share=...) can hand a device's output to
        line = next(line for line in device_lines if f" {info.name}  [" in line)
        apis = sharing_apis(info.device)
        assert (f"  shares with {', '.join(apis)}  " in line) if apis else "shares with" not in line


def test_devices_without_platform_exits_1_with_install_hint(capsys, monkeypatch):
    monkeypatch.setattr(cl, "get_platforms", lambda: [])
    code, out, err = run(capsys, "devices")
    assert code == 1
    assert_clean_error(err, "pip install")


def test_devices_with_unmatched_env_var_still_lists(capsys, monkeypatch):
    monkeypatch.setenv(DEVICE_ENV_VAR, "no-such-device")
    code, out, err = run(capsys, "devices")
    assert code == 0
    assert "Portable Computing Language" in out and "*" not in out
    assert "warning" in err and "no-such-device" in err


def test_devices_shows_each_verdict_and_never_stars_a_failing_device(capsys, monkeypatch, tmp_path):
    fresh_probes(monkeypatch, tmp_path)
    pocl_fails_to_build(monkeypatch)
    code, out, err = run(capsys, "devices")
    assert code == 0
    pocl_name = next(info.name for info in list_devices() if info.matches("pocl"))
    pocl_line = next(line for line in out.splitlines() if pocl_name in line)
    assert pocl_line.endswith(f"fails to build: {UNKNOWN_CPU_REASON}")
    assert not pocl_line.lstrip().startswith("*")
    assert "valid target CPU" not in out  # the full log only with --verbose
    assert all(line.endswith("usable") for line in out.splitlines()
               if line.startswith("  ") and pocl_name not in line and not line.startswith("      "))
    code, out, err = run(capsys, "devices", "--verbose")
    assert code == 0 and "valid target CPU values" in out


def test_named_failing_device_exits_1_with_a_short_error(capsys, monkeypatch, tmp_path, scene_file):
    fresh_probes(monkeypatch, tmp_path)
    pocl_fails_to_build(monkeypatch)
    out_path = tmp_path / "out.ply"
    code, out, err = run(capsys, "tessellate", scene_file, "--eps", "1e-3", "--device", "pocl", "-o", out_path)
    assert code == 1 and out == ""
    pocl_name = next(info.name for info in list_devices() if info.matches("pocl"))
    assert_clean_error(err, pocl_name, UNKNOWN_CPU_REASON, "--verbose")
    assert len(err.strip().splitlines()) == 1 and "valid target CPU" not in err
    assert not out_path.exists()
    code, out, err = run(capsys, "tessellate", scene_file, "--eps", "1e-3", "--device", "pocl", "-o", out_path,
                         "--verbose")
    assert code == 1 and UNKNOWN_CPU_LOG in err and "Traceback" not in err
    assert not out_path.exists()


# --------------------------------------------------------------------------- argument validation


@pytest.mark.parametrize("arguments, fragment", [
    (["--eps", "0"], "--eps"),
    (["--eps", "-1e-3"], "--eps"),
    (["--eps", "nan"], "--eps"),
    (["--eps", "inf"], "--eps"),
    (["--eps", "abc"], "--eps"),
    (["--pixels", "0"], "--pixels"),
    (["--pixels", "-inf"], "--pixels"),
    (["--eps", "1e-3", "--max-factor", "0"], "--max-factor"),
    (["--eps", "1e-3", "--max-factor", "2.5"], "--max-factor"),
    (["--eps", "1e-3", "--pixels", "1"], "not allowed"),
    (["--eps", "1e-3", "--pattern", "uniform"], "--pattern"),
    (["--eps", "1e-3", "--max-level", "15"], "--max-level"),
    (["--eps", "1e-3", "--max-level", "-1"], "--max-level"),
    (["--eps", "1e-3", "--emit", "queued"], "--emit"),
    ([], "--eps"),
])
def test_bad_arguments_exit_2_before_any_work(capsys, tmp_path, scene_file, fake_pipeline, arguments, fragment):
    out_path = tmp_path / "out.ply"
    code, out, err = run(capsys, "tessellate", scene_file, *arguments, "-o", out_path)
    assert code == 2
    assert_clean_error(err, fragment)
    assert "usage:" in err
    assert not out_path.exists()
    assert fake_pipeline.calls == []


def test_emit_by_level_needs_the_semi_uniform_pattern(capsys, tmp_path, scene_file, fake_pipeline):
    out_path = tmp_path / "out.ply"
    code, _, err = run(capsys, "tessellate", scene_file, "--eps", "1e-3", "--emit", "by-level", "-o", out_path)
    assert code == 2
    assert_clean_error(err, "--emit by-level needs --pattern semi-uniform")
    assert not out_path.exists() and fake_pipeline.calls == []


def test_missing_output_option_exits_2(capsys, scene_file, fake_pipeline):
    code, _, err = run(capsys, "tessellate", scene_file, "--eps", "1e-3")
    assert code == 2
    assert_clean_error(err, "-o")


def test_unknown_output_extension_checked_before_loading(capsys, tmp_path, monkeypatch, fake_pipeline):
    import cltess.formats

    def must_not_load(path):
        raise AssertionError("scene loaded before the output path was checked")

    monkeypatch.setattr(cltess.formats, "load_scene", must_not_load)
    code, _, err = run(capsys, "tessellate", tmp_path / "any.bpt", "--eps", "1e-3", "-o", tmp_path / "out.3ds")
    assert code == 2
    assert_clean_error(err, ".3ds", ".ply")
    assert list(tmp_path.iterdir()) == []


def test_output_in_missing_folder_exits_2(capsys, tmp_path, scene_file, fake_pipeline):
    code, _, err = run(capsys, "tessellate", scene_file, "--eps", "1e-3", "-o", tmp_path / "nowhere" / "out.ply")
    assert code == 2
    assert_clean_error(err, "does not exist")
    assert fake_pipeline.calls == []


def test_no_command_exits_2(capsys):
    code, _, err = run(capsys)
    assert code == 2
    assert_clean_error(err)


def test_help_exits_0(capsys):
    code, out, _ = run(capsys, "tessellate", "--help")
    assert code == 0
    assert "--max-factor" in out and "--pixels" in out


# --------------------------------------------------------------------------- bad scenes (cltess.formats)


def test_bad_scene_line_exits_2_naming_file_and_line(capsys, tmp_path, fake_pipeline):
    bad = flat_patch_bpt(tmp_path / "bad.bpt", bad_line=5)
    out_path = tmp_path / "out.ply"
    code, _, err = run(capsys, "tessellate", bad, "--eps", "1e-3", "-o", out_path)
    assert code == 2
    assert_clean_error(err, "bad.bpt", "line 5")
    assert not out_path.exists()
    assert fake_pipeline.calls == []


def test_truncated_scene_exits_2(capsys, tmp_path, fake_pipeline):
    truncated = tmp_path / "short.bpt"
    truncated.write_text("2\n3 3\n0 0 0\n")
    code, _, err = run(capsys, "tessellate", truncated, "--eps", "1e-3", "-o", tmp_path / "out.ply")
    assert code == 2
    assert_clean_error(err, "short.bpt")


def test_missing_scene_file_exits_2(capsys, tmp_path, fake_pipeline):
    code, _, err = run(capsys, "tessellate", tmp_path / "absent.bez", "--eps", "1e-3", "-o", tmp_path / "o.ply")
    assert code == 2
    assert_clean_error(err, "absent.bez")


def test_pixels_without_camera_exits_2(capsys, tmp_path, scene_file, fake_pipeline):
    out_path = tmp_path / "out.ply"
    code, _, err = run(capsys, "tessellate", scene_file, "--pixels", "0.5", "-o", out_path)
    assert code == 2
    assert_clean_error(err, "camera")
    assert not out_path.exists()
    assert fake_pipeline.calls == []


# --------------------------------------------------------------------------- tessellate (fake pipeline)


def test_tessellate_passes_options_and_prints_summary(capsys, tmp_path, scene_file, fake_pipeline):
    fake_pipeline.result = small_tessellation(stats_extra={"shared_edges": 7, "note": "not an int"})
    out_path = tmp_path / "mesh.ply"
    code, out, err = run(capsys, "tessellate", scene_file, "--eps", "2e-3", "--no-fd", "--max-factor", "16",
                         "--device", "pocl", "-o", out_path)
    assert code == 0, err
    assert err == ""
    (call,) = fake_pipeline.calls
    assert isinstance(call["scene"], Scene) and call["scene"].num_patches == 1
    assert call["eps"] == 2e-3 and call["pixels"] is None
    assert call["max_factor"] == 16 and call["forward_differencing"] is False
    assert isinstance(call["device"], cl.Device)
    for fragment in ("patches", "culled", "saturated", "vertices", "triangles", "shared edges", "7",
                     "factors 0.500", "indices 0.250", str(out_path)):
        assert fragment in out
    assert "not an int" not in out
    mesh = trimesh.load(out_path, process=False)
    assert mesh.faces.shape == (2, 3)


def test_defaults(capsys, tmp_path, scene_file, fake_pipeline):
    code, _, _ = run(capsys, "tessellate", scene_file, "--eps", "1e-3", "-o", tmp_path / "m.npz")
    assert code == 0
    (call,) = fake_pipeline.calls
    assert call["max_factor"] == 64 and call["forward_differencing"] is True
    assert call["pattern"] == "transition" and call["max_level"] == 6 and call["emit"] == "per_patch"
    assert (tmp_path / "m.npz").exists()


def test_saturated_patches_warn_even_when_quiet(capsys, tmp_path, scene_file, fake_pipeline):
    fake_pipeline.result = small_tessellation(saturated=3)
    code, out, err = run(capsys, "tessellate", scene_file, "--eps", "1e-3", "--quiet", "-o", tmp_path / "m.obj")
    assert code == 0
    assert out == ""
    assert "warning" in err and "3 patches" in err and "--max-factor" in err


@pytest.mark.parametrize("failure, code, fragment", [
    (ValueError("the scene has no patches"), 2, "no patches"),
    (cl.RuntimeError("clEnqueueNDRangeKernel failed: OUT_OF_RESOURCES"), 1, "OUT_OF_RESOURCES"),
    (RuntimeError("kernels/factors.cl failed to build"), 1, "failed to build"),
    (MemoryError("too many vertices"), 1, "too many vertices"),
    (OutputTooLarge("over the cap"), 2, "over the cap"),  # a cap the user chose
])
def test_pipeline_errors_map_to_exit_codes(capsys, tmp_path, scene_file, fake_pipeline, failure, code, fragment):
    fake_pipeline.result = failure
    out_path = tmp_path / "out.ply"
    result, _, err = run(capsys, "tessellate", scene_file, "--eps", "1e-3", "-o", out_path)
    assert result == code
    assert_clean_error(err, fragment)
    assert list(tmp_path.iterdir()) == [scene_file]


def test_unknown_device_exits_1_listing_devices(capsys, tmp_path, scene_file, fake_pipeline):
    code, _, err = run(capsys, "tessellate", scene_file, "--eps", "1e-3", "--device", "no-such-gpu",
                       "-o", tmp_path / "out.ply")
    assert code == 1
    assert_clean_error(err, "no-such-gpu", "available devices")
    assert fake_pipeline.calls == []


def test_a_scene_error_is_reported_before_a_device_error(capsys, tmp_path, fake_pipeline):
    """With both the scene and the device wrong, the scene's error is the one reported (exit 2)."""
    code, _, err = run(capsys, "tessellate", tmp_path / "missing.bez", "--eps", "1e-3", "--device", "no-such-gpu",
                       "-o", tmp_path / "out.ply")
    assert code == 2
    assert_clean_error(err, "missing.bez")
    assert "no-such-gpu" not in err
    assert list(tmp_path.iterdir()) == []


def test_a_scene_check_error_is_reported_before_a_device_error_and_no_thread_is_left(capsys, tmp_path, scene_file,
                                                                                     fake_pipeline):
    """OpenCL opens on a thread once the scene is read: a scene that reads but fails a later
    check (--pixels without a camera) is the error reported (exit 2), not the device's, and the
    thread has ended."""
    import threading

    code, _, err = run(capsys, "tessellate", scene_file, "--pixels", "0.5", "--device", "no-such-gpu",
                       "-o", tmp_path / "out.ply")
    assert code == 2
    assert_clean_error(err, "camera")
    assert "no-such-gpu" not in err
    assert not [t for t in threading.enumerate() if t.name == "cltess-opencl"]


def test_opencl_starts_after_the_scene_is_read(capsys, tmp_path, scene_file, fake_pipeline, monkeypatch):
    """The OpenCL thread starts only once the scene is read (the text parser's warning filters
    are global: io/text.py), and its tessellator is the one used."""
    import cltess.io

    events = []
    read = cltess.io.load_scene
    monkeypatch.setattr(cltess.io, "load_scene", lambda *a, **k: (read(*a, **k), events.append("read"))[0])
    opened = FakeTessellator.__init__
    monkeypatch.setattr(FakeTessellator, "__init__", lambda self, device=None: (
        events.append("opened"), opened(self, device))[1])
    monkeypatch.setattr(FakeTessellator, "compose", lambda self, scene, request: events.append(request), raising=False)
    code, _, err = run(capsys, "tessellate", scene_file, "--eps", "1e-3", "-o", tmp_path / "out.ply")
    assert code == 0, err
    assert events[:2] == ["read", "opened"] and len(events) == 3
    call = fake_pipeline.calls[0]
    assert call["device"] is not None
    # the programs built on the thread are those of the plan's request
    assert events[2].tolerance.eps == call["eps"] == 1e-3 and events[2].pattern == call["pattern"]


def test_a_failing_program_warm_up_leaves_the_error_to_the_plan(capsys, tmp_path, scene_file, fake_pipeline,
                                                                 monkeypatch):
    """cli._opened builds the plan's programs on the OpenCL thread; what fails there is met
    again, and reported, by the plan."""
    def compose(self, scene, request):
        raise RuntimeError("build failed")

    monkeypatch.setattr(FakeTessellator, "compose", compose, raising=False)
    code, _, err = run(capsys, "tessellate", scene_file, "--eps", "1e-3", "-o", tmp_path / "out.ply")
    assert code == 0, err
    assert len(fake_pipeline.calls) == 1
    fake_pipeline.result = RuntimeError("build failed")
    code, _, err = run(capsys, "tessellate", scene_file, "--eps", "1e-3", "-o", tmp_path / "out2.ply")
    assert code == 1
    assert_clean_error(err, "build failed")


def test_interrupt_during_export_leaves_no_file(capsys, tmp_path, scene_file, fake_pipeline, monkeypatch):
    def interrupted(fd):
        raise KeyboardInterrupt

    monkeypatch.setattr(os, "fsync", interrupted)
    out_path = tmp_path / "out.ply"
    code, _, err = run(capsys, "tessellate", scene_file, "--eps", "1e-3", "-o", out_path)
    assert code == 130
    assert "interrupted" in err
    assert list(tmp_path.iterdir()) == [scene_file]


# --------------------------------------------------------------------------- real pipeline, module entry


def test_tessellate_end_to_end(capsys, tmp_path, scene_file):
    """The real pipeline on one patch (needs cltess.pipeline and the kernels)."""
    out_path = tmp_path / "patch.ply"
    code, out, err = run(capsys, "tessellate", scene_file, "--eps", "1e-3", "-o", out_path)
    assert code == 0, err
    mesh = trimesh.load(out_path, process=False)
    assert len(mesh.faces) > 2
    summary = dict(line.split(None, 1) for line in out.splitlines())
    assert int(summary["triangles"]) == len(mesh.faces)
    assert int(summary["vertices"]) == len(mesh.vertices)
    assert summary["wrote"] == str(out_path)


@pytest.mark.parametrize("extension, emit", [(".ply", "per-patch"), (".npz", "per-patch"), (".ply", "by-level")])
def test_semi_uniform_end_to_end_with_levels_and_t_junctions(capsys, tmp_path, extension, emit):
    """--pattern semi-uniform: the summary's level histogram and T-junction
    count (0: the pattern snaps each edge to its own level), per patch and by level."""
    out_path = tmp_path / f"teapot{extension}"
    scene = Path(__file__).resolve().parents[1] / "scenes" / "teapot.bez"
    code, out, err = run(capsys, "tessellate", scene, "--eps", "1e-2", "--pattern", "semi-uniform",
                         "--max-level", "5", "--check-t-junctions", "--emit", emit, "-o", out_path)
    assert code == 0, err
    summary = dict(line.split(None, 1) for line in out.replace("t junctions", "t_junctions")
                   .replace("patch levels", "patch_levels").splitlines())
    assert summary["t_junctions"] == "0"
    levels = dict(item.split(": ") for item in summary["patch_levels"].split(", "))
    assert len(levels) > 1 and max(int(level) for level in levels) <= 5
    assert sum(int(count) for count in levels.values()) == int(summary["patches"].split()[0])


def test_emit_by_level_writes_the_per_patch_file(capsys, tmp_path):
    """--emit by-level gives the file --no-fd gives, byte for byte (welded and per patch)."""
    scene = Path(__file__).resolve().parents[1] / "scenes" / "teapot.bez"
    for weld in ("--weld", "--no-weld"):
        outputs = []
        for emit in (["--emit", "by-level"], ["--no-fd"]):
            outputs.append(tmp_path / f"{emit[-1]}{weld}.ply")
            code, _, err = run(capsys, "tessellate", scene, "--eps", "3e-3", "--pattern", "semi-uniform", weld,
                               *emit, "-q", "-o", outputs[-1])
            assert code == 0, err
        assert outputs[0].read_bytes() == outputs[1].read_bytes()


def test_python_dash_m_runs(tmp_path):
    result = subprocess.run([sys.executable, "-m", "cltess", "--version"], cwd=REPO,
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 0
    assert result.stdout.startswith("cltess ")


def test_console_script_points_at_run():
    import tomllib

    scripts = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]["scripts"]
    module, function = scripts["cltess"].split(":")
    assert (module, function) == ("cltess.cli", "run") and cli.main is main


@pytest.mark.parametrize("quick", ["1", "0"])
def test_quick_exit_keeps_the_output_the_summary_and_the_code(tmp_path, quick):
    """``python -m cltess`` (run(): os._exit after tessellate) prints the whole summary, leaves
    the complete file and no temporary one, and exits with main's code, as without it."""
    import subprocess

    env = dict(os.environ, CLTESS_QUICK_EXIT=quick)
    output = tmp_path / "teapot.ply"
    done = subprocess.run([sys.executable, "-m", "cltess", "tessellate", str(REPO / "scenes" / "teapot.bez"),
                           "--eps", "0.01", "--no-weld", "-o", str(output)], capture_output=True, text=True, env=env)
    assert done.returncode == 0, done.stderr
    assert "triangles" in done.stdout and str(output) in done.stdout
    assert [p.name for p in tmp_path.iterdir()] == ["teapot.ply"] and output.stat().st_size > 1000
    bad = subprocess.run([sys.executable, "-m", "cltess", "tessellate", str(tmp_path / "missing.bez"), "--eps",
                          "0.01", "-o", str(tmp_path / "x.ply")], capture_output=True, text=True, env=env)
    assert bad.returncode == 2 and "cltess: error:" in bad.stderr and "missing.bez" in bad.stderr
