"""What a user meets on the command line (issue 16): the version, -o refused when it is an
input, --eps as a fraction of the scene, the output-size estimate and --max-output, and the
saturation warning before anything is written."""
import json
import os
import re
from pathlib import Path

import numpy as np
import pytest
import trimesh

import cltess
from cltess.cli import main
from cltess.io.export import estimate_output_bytes
from cltess.io import load_scene

SCENES = Path(__file__).resolve().parent.parent / "scenes"


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def test_version_comes_from_the_package_metadata():
    from importlib import metadata

    assert cltess.__version__ == metadata.version("cltess")
    assert re.fullmatch(r"\d+\.\d+.*", cltess.__version__)


# --------------------------------------------------------------------------- -o is not an input


def test_output_equal_to_the_scene_is_refused(capsys, tmp_path):
    scene = tmp_path / "ball.stl"
    trimesh.creation.icosphere(1).export(scene)
    before = scene.read_bytes()
    code, _, err = run(capsys, "tessellate", scene, "--eps", "0.01", "-o", scene)
    assert code == 2 and "is an input" in err
    link = tmp_path / "link.stl"
    link.symlink_to(scene)
    code, _, err = run(capsys, "tessellate", scene, "--eps", "0.01", "-o", link)
    assert code == 2 and "is an input" in err
    assert scene.read_bytes() == before


def test_output_equal_to_an_object_of_a_json_scene_is_refused(capsys, tmp_path):
    trimesh.creation.icosphere(1).export(tmp_path / "ball.ply")
    (tmp_path / "s.json").write_text(json.dumps({"objects": [{"file": "ball.ply"}]}))
    before = (tmp_path / "ball.ply").read_bytes()
    code, _, err = run(capsys, "tessellate", tmp_path / "s.json", "--eps", "0.01", "-o", tmp_path / "ball.ply")
    assert code == 2 and "is an input" in err and "ball.ply" in err
    assert (tmp_path / "ball.ply").read_bytes() == before
    code, _, err = run(capsys, "tessellate", tmp_path / "s.json", "--eps", "0.01", "-q", "-o", tmp_path / "out.ply")
    assert code == 0, err


# --------------------------------------------------------------------------- --eps 0.1%


def test_eps_as_a_percentage_of_the_diagonal(capsys, tmp_path):
    diagonal = load_scene(SCENES / "teapot.bez").diagonal
    assert 5 < diagonal < 10
    code, out, err = run(capsys, "tessellate", SCENES / "teapot.bez", "--eps", "0.1%", "-o", tmp_path / "a.ply")
    assert code == 0, err
    assert f"eps {diagonal / 1000:.6g} = 0.1% of the diagonal {diagonal:.6g}" in out
    code, out_abs, err = run(capsys, "tessellate", SCENES / "teapot.bez", "--eps", f"{diagonal / 1000!r}",
                             "-o", tmp_path / "b.ply")
    assert code == 0, err
    assert (tmp_path / "a.ply").read_bytes() == (tmp_path / "b.ply").read_bytes()


@pytest.mark.parametrize("value, fragment", [("0%", "> 0"), ("-1%", "> 0"), ("100%", "below 100%"),
                                             ("abc%", "not a number"), ("%", "not a number"),
                                             ("1e-60%", "float32")])
def test_bad_percentages_exit_2(capsys, tmp_path, value, fragment):
    code, _, err = run(capsys, "tessellate", SCENES / "teapot.bez", f"--eps={value}", "-o", tmp_path / "a.ply")
    assert code == 2 and fragment in err and "Traceback" not in err
    assert not any(tmp_path.iterdir())


# --------------------------------------------------------------------------- output size


def test_estimates_bound_the_real_file_sizes(tessellator, tmp_path):
    from cltess import export

    tess = tessellator.tessellate(load_scene(SCENES / "teapot.bez"), eps=0.01)
    welded = tess.welded()
    for suffix in (".ply", ".obj", ".npz", ".stl", ".glb"):
        export(tess, tmp_path / f"raw{suffix}")
        export(welded, tmp_path / f"welded{suffix}")
        raw_estimate = estimate_output_bytes(suffix, tess.num_vertices, tess.num_triangles)
        welded_estimate = estimate_output_bytes(suffix, tess.num_vertices, tess.num_triangles, weld=True)
        raw_size, welded_size = ((tmp_path / f"{n}{suffix}").stat().st_size for n in ("raw", "welded"))
        assert 0.6 * raw_size < raw_estimate < 1.5 * raw_size, suffix
        assert 0.6 * welded_size < welded_estimate < 1.5 * welded_size, suffix


def test_max_output_refuses_before_writing_and_says_how_to_proceed(capsys, tmp_path):
    out_path = tmp_path / "t.ply"
    code, _, err = run(capsys, "tessellate", SCENES / "teapot.bez", "--eps", "0.001", "--max-output", "100K",
                       "-o", out_path)
    assert code == 2
    assert "would be about" in err and "MiB" in err and "--max-output" in err and "diagonal" in err
    assert not any(tmp_path.iterdir())
    code, _, err = run(capsys, "tessellate", SCENES / "teapot.bez", "--eps", "0.001", "--max-output", "none",
                       "-q", "-o", out_path)
    assert code == 0, err


@pytest.mark.parametrize("value", ["lots", "-5M", "1X"])
def test_bad_max_output_exits_2(capsys, tmp_path, value):
    code, _, err = run(capsys, "tessellate", SCENES / "teapot.bez", "--eps", "0.01", f"--max-output={value}",
                       "-o", tmp_path / "t.ply")
    assert code == 2 and "--max-output" in err
    assert not any(tmp_path.iterdir())


def test_saturation_warning_comes_before_anything_is_written(capsys, tmp_path):
    """With a --max-output that refuses, the warning is still there: it is printed after the
    plan, before the file."""
    code, _, err = run(capsys, "tessellate", SCENES / "teapot.bez", "--eps", "0.0001", "--max-factor", "4",
                       "--max-output", "1K", "-o", tmp_path / "t.ply")
    assert code == 2
    assert err.index("warning") < err.index("error") and "--max-factor 4" in err
    assert not any(tmp_path.iterdir())


def test_large_outputs_are_announced_before_writing(capsys, tmp_path, monkeypatch):
    monkeypatch.setattr("cltess.cli.NOTE_OUTPUT_SIZE", 1000)
    code, out, err = run(capsys, "tessellate", SCENES / "teapot.bez", "--eps", "0.01", "-o", tmp_path / "t.ply")
    assert code == 0 and "writing about" in err and "before welding" in err and "to write)" in err
    code, out, err = run(capsys, "tessellate", SCENES / "teapot.bez", "--eps", "0.01", "-q", "-o", tmp_path / "u.ply")
    assert code == 0 and err == "" and out == ""


# --------------------------------------------------------------------------- progress bar


class Terminal:
    """A stderr that says it is a terminal and keeps what is written."""

    def __init__(self):
        self.text = ""

    def write(self, text):
        self.text += text

    def flush(self):
        pass

    def isatty(self):
        return True


def test_progress_bar_on_a_terminal_only_and_not_when_quiet(capsys, tmp_path, monkeypatch):
    import sys

    monkeypatch.setattr("cltess.cli.PROGRESS_DELAY", 0.0)  # show it even for a short run
    terminal = Terminal()
    monkeypatch.setattr(sys, "stderr", terminal)
    code = main(["tessellate", str(SCENES / "teapot.bez"), "--eps", "0.005", "--no-weld", "--max-memory", "256K",
                 "-o", str(tmp_path / "t.ply")])
    assert code == 0
    assert "batches" in terminal.text and "%|" in terminal.text and "/32" in terminal.text
    terminal.text = ""
    code = main(["tessellate", str(SCENES / "teapot.bez"), "--eps", "0.005", "-q", "-o", str(tmp_path / "u.ply")])
    assert code == 0 and terminal.text == ""
    monkeypatch.undo()
    monkeypatch.setattr("cltess.cli.PROGRESS_DELAY", 0.0)
    code, _, err = run(capsys, "tessellate", SCENES / "teapot.bez", "--eps", "0.005", "-o", tmp_path / "v.ply")
    assert code == 0 and "%|" not in err  # pytest's captured stderr is not a terminal
