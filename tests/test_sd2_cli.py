"""SD-2 on the command line and in Request: --pattern sd2, --level-function, the camera a level
function needs, NPZ keeping strips and real factors, bad level options refused."""
import json

import numpy as np
import pytest
import trimesh

from cltess.cli import main
from cltess.io.npz import load_npz
from cltess.request import Request
from cltess.criteria import ObjectSpace
from cltess.scene import Camera
from cltess.strips import expand_strips


@pytest.fixture
def mesh_file(tmp_path):
    path = tmp_path / "ico.ply"
    trimesh.creation.icosphere(1).export(path)
    return path


def test_pattern_sd2_writes_strips_to_npz(tmp_path, mesh_file):
    out = tmp_path / "out.npz"
    assert main(["tessellate", str(mesh_file), "-o", str(out), "--eps", "1e-3", "--pattern", "sd2", "-q"]) == 0
    tess = load_npz(out)
    assert tess.strips is not None and tess.real_factors is not None
    assert np.array_equal(expand_strips(tess.strips), tess.triangles)
    assert tess.stats["level_function"] == "bound"


def test_level_function_from_a_json_scenes_camera(tmp_path, mesh_file):
    scene = tmp_path / "scene.json"
    scene.write_text(json.dumps({"objects": [{"file": str(mesh_file)}],
                                 "camera": {"eye": [3, 1, 0.5], "target": [0, 0, 0]}}))
    out = tmp_path / "out.npz"
    code = main(["tessellate", str(scene), "-o", str(out), "--eps", "1e-3", "--level-function", "silhouette",
                 "--level-factors", "2", "6", "--silhouette-band", "0", "-q"])
    assert code == 0
    real = load_npz(out).real_factors[:, :3]
    assert set(np.unique(real)) == {2.0, 6.0}  # band 0: the paper's classes
    code = main(["tessellate", str(scene), "-o", str(out), "--eps", "1e-3", "--level-function", "silhouette",
                 "--level-factors", "2", "6", "-q"])
    real = load_npz(out).real_factors[:, :3]
    assert code == 0 and real.min() >= 2.0 and real.max() == 6.0 and len(np.unique(real)) > 2  # the ramp


def test_level_function_without_camera_is_a_clear_error(tmp_path, mesh_file, capsys):
    code = main(["tessellate", str(mesh_file), "-o", str(tmp_path / "x.npz"), "--eps", "1e-3",
                 "--level-function", "depth"])
    assert code != 0 and "needs a camera" in capsys.readouterr().err
    assert not (tmp_path / "x.npz").exists()


@pytest.mark.parametrize("options, fragment", [
    (dict(level_function="height"), "level_function must be one of"),
    (dict(level_function="depth", pattern="transition"), "needs pattern 'sd2'"),
    (dict(level_function="depth", level_factors=(3, 2)), "level_factors"),
    (dict(level_function="depth", level_factors=(1, 100)), "level_factors"),
    (dict(level_function="depth", level_factors=(0.5, 2)), "level_factors"),
    (dict(depth_map="cubic"), "depth_map"),
    (dict(depth_range=(2, 1)), "depth_range"),
    (dict(camera="front"), "camera"),
    (dict(silhouette_band=-0.1), "silhouette_band"),
    (dict(silhouette_band="wide"), "silhouette_band"),
])
def test_bad_level_options_are_refused(options, fragment):
    with pytest.raises(ValueError, match=fragment):
        Request(ObjectSpace(1e-3), **options)


def test_a_level_function_selects_sd2_for_triangles_only():
    from cltess.kinds import BEZIER, PN

    request = Request(ObjectSpace(1e-3), level_function="depth", camera=Camera(np.ones(3), np.zeros(3)))
    assert request.pattern_for(PN).name == "sd2" and request.pattern_for(BEZIER).name == "quad_transition"
    assert Request(ObjectSpace(1e-3), max_factor=4).level_factors  # the default (1, 7) is not checked unused
