"""cltess tessellate --camera-path / --silhouette (issue 12): one mesh or one summary per frame."""
import json

import numpy as np
import pytest
import trimesh

from cltess.cli import main
from cltess.io import load_scene
from cltess.io.npz import load_npz


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("frames")
    trimesh.creation.icosphere(2).export(folder / "sphere.ply")
    (folder / "orbit.json").write_text(json.dumps({"orbit": {"target": [0, 0, 0], "radius": 3.0, "frames": 3}}))
    return folder


def test_one_watertight_mesh_per_frame(files, capsys):
    out = files / "out_{frame:02d}.ply"
    assert main(["tessellate", str(files / "sphere.ply"), "--eps", "1", "--no-bound", "--silhouette", "3",
                 "--camera-path", str(files / "orbit.json"), "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "prepared once" in printed and printed.count("frame ") == 3
    for frame in range(3):
        mesh = trimesh.load(files / f"out_{frame:02d}.ply", process=False)
        assert mesh.is_watertight and len(mesh.faces) > 320


def test_a_summary_per_frame(files):
    out = files / "frames.json"
    assert main(["tessellate", str(files / "sphere.ply"), "--eps", "0.5%", "--silhouette", "--phi", "20",
                 "--camera-path", str(files / "orbit.json"), "-o", str(out), "-q"]) == 0
    frames = json.loads(out.read_text())["frames"]
    assert [f["frame"] for f in frames] == [0, 1, 2]
    assert all(f["triangles"] > 320 and f["silhouette_edges"] > 0 for f in frames)


def test_per_patch_npz_frames_hold_the_lod(files):
    out = files / "lod_{frame}.npz"
    assert main(["tessellate", str(files / "sphere.ply"), "--eps", "1", "--no-bound", "--silhouette", "2",
                 "--no-blend", "--camera-path", str(files / "orbit.json"), "-o", str(out), "--no-weld", "-q"]) == 0
    with np.load(files / "lod_1.npz") as data:
        lod, positions = data["lod"], data["positions"]
    assert len(lod) == len(positions) and 0 <= lod.min() and lod.max() == 2
    assert load_npz(files / "lod_1.npz").num_triangles > 0


def test_pixels_per_frame(files):
    out = files / "px_{frame}.ply"
    assert main(["tessellate", str(files / "sphere.ply"), "--pixels", "2", "--camera-path",
                 str(files / "orbit.json"), "-o", str(out), "-q"]) == 0
    assert all((files / f"px_{k}.ply").exists() for k in range(3))


def test_pixel_frames_are_each_cameras_one_shot_tessellation(files):
    """--pixels frames come from a two-set Session, frame k+1 computed while frame k is written:
    each is bitwise the one-shot tessellation for its camera."""
    from cltess.criteria.tolerance import ScreenSpace
    from cltess.io.camera_path import read_camera_path
    from cltess.pipeline import Tessellator
    from cltess.request import Request

    out = files / "bits_{frame}.npz"
    assert main(["tessellate", str(files / "sphere.ply"), "--pixels", "2", "--camera-path",
                 str(files / "orbit.json"), "-o", str(out), "--no-weld", "-q"]) == 0
    scene, tessellator = load_scene(files / "sphere.ply"), Tessellator()
    for k, camera in enumerate(read_camera_path(files / "orbit.json")):
        expected = tessellator.tessellate(scene, Request(ScreenSpace(2.0, camera)))
        got = load_npz(files / f"bits_{k}.npz")
        for field in ("positions", "normals", "uv", "patch_ids", "object_ids", "triangles"):
            assert np.array_equal(getattr(got, field), getattr(expected, field)), (k, field)


@pytest.mark.parametrize("argv, message", [
    (["--eps", "1%", "--camera-path", "{orbit}", "-o", "{dir}/a_{{frame}}.ply"], "needs a per-frame criterion"),
    (["--eps", "1%", "--silhouette", "--camera-path", "{orbit}", "-o", "{dir}/a.ply"], "need {frame}"),
    (["--pixels", "1", "--silhouette", "--camera-path", "{orbit}", "-o", "{dir}/a_{{frame}}.ply"], "not --pixels"),
    (["--eps", "1%", "--no-blend", "--camera-path", "{orbit}", "-o", "{dir}/a_{{frame}}.ply"], "for --silhouette"),
    (["--eps", "1%", "--silhouette", "-o", "{dir}/a.ply"], "needs a camera"),
    (["--eps", "1%", "--silhouette", "--phi", "95", "--camera-path", "{orbit}", "-o", "{dir}/a_{{frame}}.ply"],
     "(0, 90)"),
    (["--eps", "1%", "--silhouette", "--camera-path", "{dir}/missing.json", "-o", "{dir}/a_{{frame}}.ply"],
     "not found"),
])
def test_bad_combinations_are_usage_errors(files, capsys, argv, message):
    argv = [a.format(orbit=files / "orbit.json", dir=files) for a in argv]
    assert main(["tessellate", str(files / "sphere.ply"), *argv]) == 2
    assert message in capsys.readouterr().err
    assert not list(files.glob("a*.ply"))


def test_the_scene_camera_without_a_path(files, tmp_path):
    scene = tmp_path / "scene.json"
    scene.write_text(json.dumps({"objects": [{"file": str(files / "sphere.ply")}],
                                 "camera": {"eye": [0, -3, 1], "target": [0, 0, 0]}}))
    out = tmp_path / "one.ply"
    assert main(["tessellate", str(scene), "--eps", "0.2%", "--silhouette", "2", "-o", str(out), "-q"]) == 0
    assert trimesh.load(out, process=False).is_watertight
    assert load_scene(scene).camera is not None
