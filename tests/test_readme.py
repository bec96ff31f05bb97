"""The README for users: its pictures exist and are made by the script, its numbers are the
scenes', its quick start runs as shown, the developer set-up lines stay as CI runs them."""
import re
from pathlib import Path

import pytest

from cltess.cli import main
from cltess.io import load_scene
from support import load_script

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text()


def test_every_picture_exists_and_is_made_by_the_script():
    linked = set(re.findall(r"\]\((docs/pictures/[^)]+\.png)\)", README))
    assert linked and all((ROOT / link).is_file() for link in linked)
    module = load_script(ROOT / "docs" / "make_pictures.py", "make_pictures")
    made = {f"docs/pictures/{name}" for name, _ in module.PICTURES}
    assert linked <= made
    assert {f"docs/pictures/{p.name}" for p in (ROOT / "docs" / "pictures").glob("*.png")} == made
    assert all((ROOT / m).stat().st_size < 100_000 for m in made)  # small enough for the repository


def test_developer_setup_lines_are_the_ones_ci_runs():
    block = README.split("## Set-up and tests", 1)[1].split("```sh\n", 1)[1].split("```", 1)[0]
    assert block == 'python3 -m venv .venv && . .venv/bin/activate && pip install -e ".[test]"\npython -m pytest -q\n'
    assert README.index("## Install") < README.index("## Quick start") < README.index("## Set-up and tests")
    assert "## Troubleshooting" in README
    assert 'pip install .  ' in README  # installing for use pulls no test extras


def test_license_is_mit():
    text = (ROOT / "LICENSE").read_text()
    assert text.startswith("MIT License") and "cltess developers" in text


@pytest.mark.parametrize("name", ["teapot.bez", "teacup.bez", "teaspoon.bez", "sphere.bpt", "cylinder.stl",
                                  "tea_table.json", "teapots.json"])
def test_scene_size_table_matches_the_scenes(name):
    row = next(line for line in README.splitlines() if line.startswith(f"| `{name}`"))
    diagonal = float(row.split("|")[3])
    assert f"{load_scene(ROOT / 'scenes' / name).diagonal:.3g}" == f"{diagonal:.3g}"


def test_quick_start_prints_what_the_readme_shows(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(ROOT)
    code = main(["tessellate", "scenes/teapot.bez", "--eps", "0.1%", "-o", str(tmp_path / "teapot.ply"),
                 "--preview", str(tmp_path / "teapot.png")])
    out = capsys.readouterr().out
    assert code == 0
    shown = README.split("## Quick start", 1)[1].split("```\n", 2)[1].split("```", 1)[0]
    for line in shown.splitlines():
        label = re.split(r"\s{2,}", line)[0]
        if label in ("stage ms", "wrote", "scene"):
            continue
        assert line in out, line  # every count as shown
