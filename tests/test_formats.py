"""Scene readers and writers (cltess/io/) and the generated scenes (scenes/make_scenes.py)."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from cltess.io import bez, bpt
from cltess.io import load_scene, write_bez, write_bpt
from cltess.scene import SceneError
from support import DATA, SCENES, load_make_scenes

make_scenes = load_make_scenes()


# ----------------------------------------------------------------------------- shipped files


@pytest.mark.parametrize(
    "name, count",
    [("teapot.bez", 32), ("teapot.bpt", 32), ("teacup.bez", 26), ("teaspoon.bez", 16), ("sphere.bpt", 32), ("torus.bpt", 16),
     ("table.bpt", 48)],
)
def test_shipped_files(name, count):
    path = str(SCENES / name)
    scene = load_scene(path)
    assert scene.name == path
    assert scene.patches.shape == (count, 4, 4, 4) and scene.patches.dtype == np.float64
    assert np.array_equal(scene.object_ids, np.zeros(count, np.int32))
    assert np.isfinite(scene.patches).all() and (scene.weights > 0).all()
    assert scene.camera is None


def test_shipped_files_are_the_shared_data():
    for name in ("teapot.bez", "teapot.bpt", "teacup.bez", "teaspoon.bez", "bigguy.bez"):
        if (DATA / name).exists():
            assert (SCENES / name).read_bytes() == (DATA / name).read_bytes()


def test_teapot_bpt_equals_bez():
    bpt = load_scene(SCENES / "teapot.bpt").patches
    bez = load_scene(SCENES / "teapot.bez").patches
    assert np.array_equal(bpt, bez)
    # file order: the first point line is patches[0, 0, 0], the fourth [0, 0, 3], the fifth [0, 1, 0]
    assert bpt[0, 0, 0].tolist() == [1.4, 0.0, 2.4, 1.0]
    assert bpt[0, 0, 3].tolist() == [0.0, -1.4, 2.4, 1.0]
    assert bpt[0, 1, 0].tolist() == [1.3375, 0.0, 2.53125, 1.0]


def test_bigguy_loads():
    scene = load_scene(SCENES / "bigguy.bez")
    assert scene.num_patches == 3570
    assert scene.patches[0, 0, 0].tolist() == [-0.294095001667, -0.598564997381, -0.671400683916, 1.0]


def test_unknown_extension_and_missing_file(tmp_path):
    path = tmp_path / "model.xyz"
    path.write_text("v 0 0 0\n")
    with pytest.raises(SceneError, match=r"model\.xyz.*'\.xyz'"):
        load_scene(path)
    with pytest.raises(SceneError, match=r"no_such\.bpt: file not found"):
        load_scene(tmp_path / "no_such.bpt")
    (tmp_path / "dir.bez").mkdir()
    with pytest.raises(SceneError, match=r"dir\.bez"):
        load_scene(tmp_path / "dir.bez")


def test_blank_lines_and_crlf_are_fine(tmp_path):
    text = (SCENES / "teapot.bpt").read_text()
    path = tmp_path / "spaced.bpt"
    path.write_text("\n" + text.replace("\n3 3\n", "\n\n3 3\n").replace("\n", "\r\n") + "\n\n")
    assert np.array_equal(load_scene(path).patches, load_scene(SCENES / "teapot.bpt").patches)


# ----------------------------------------------------------------------------- rational input


def test_rational_bpt_and_bez(tmp_path):
    bpt = tmp_path / "r.bpt"
    lines = ["1", "3 3"] + [f"{i} {j} 0 {1 + i + j}" for j in range(4) for i in range(4)]
    bpt.write_text("\n".join(lines) + "\n")
    patches = load_scene(bpt).patches
    i, j = 2, 1
    assert patches[0, j, i].tolist() == [i * (1 + i + j), j * (1 + i + j), 0.0, 1 + i + j]

    bez = tmp_path / "r.bez"
    bez.write_text("1\n" + ",".join(str(k) for k in range(1, 17)) + "\n16\n"
                   + "".join(f"{i},{j},1,{0.5 + i}\n" for j in range(4) for i in range(4)))
    patches = load_scene(bez).patches
    assert patches[0, 3, 1].tolist() == [1 * 1.5, 3 * 1.5, 1.5, 1.5]


# ----------------------------------------------------------------------------- round trips


def test_round_trip_teapot(tmp_path):
    teapot = load_scene(SCENES / "teapot.bez").patches
    write_bpt(tmp_path / "t.bpt", teapot)
    write_bez(tmp_path / "t.bez", teapot)
    assert np.array_equal(load_scene(tmp_path / "t.bpt").patches, teapot)
    assert np.array_equal(load_scene(tmp_path / "t.bez").patches, teapot)
    # polynomial patches are written without weights; equal points share one vertex
    assert (tmp_path / "t.bpt").read_text().splitlines()[2].count(" ") == 2
    assert int((tmp_path / "t.bez").read_text().splitlines()[33]) <= 306


finite = st.floats(-1e6, 1e6, allow_nan=False, allow_infinity=False)
positive = st.floats(1e-3, 1e3, allow_nan=False, allow_infinity=False)


@settings(max_examples=40, deadline=None)
@given(
    points=arrays(np.float64, (3, 4, 4, 3), elements=finite),
    weights=arrays(np.float64, (3, 4, 4), elements=positive),
    share=st.booleans(),
)
def test_round_trip_rational(tmp_path_factory, points, weights, share):
    """Written Cartesian points and weights read back bitwise: patches == w * (b.xyz / w)."""
    if share:  # give the writers some equal points to share
        points[1, 0], weights[1, 0] = points[0, 3], weights[0, 3]
    patches = np.concatenate([points * weights[..., None], weights[..., None]], axis=-1)
    w = patches[..., 3:]
    expected = np.concatenate([w * (patches[..., :3] / w), w], axis=-1)
    folder = tmp_path_factory.mktemp("rt")
    for name, writer in (("r.bpt", write_bpt), ("r.bez", write_bez)):
        writer(folder / name, patches)
        got = load_scene(folder / name).patches
        assert np.array_equal(got, expected + 0.0), name


# ----------------------------------------------------------------------------- errors


def expect_error(tmp_path, name: str, text, *fragments: str) -> str:
    """Load ``text`` (str or bytes) from ``tmp_path / name``; the SceneError must name the file
    and contain every fragment.  Returns the message."""
    path = tmp_path / name
    if isinstance(text, bytes):
        path.write_bytes(text)
    else:
        path.write_text(text)
    with pytest.raises(SceneError) as info:
        load_scene(path)
    message = str(info.value)
    assert str(path) in message, message
    for fragment in fragments:
        assert fragment in message, f"{fragment!r} not in {message!r}"
    return message


def bpt_text(patches: int = 2, weights: bool = False) -> list[str]:
    lines = [str(patches)]
    for p in range(patches):
        lines.append("3 3")
        lines += [f"{i}.5 {j} {p}" + (" 1.5" if weights else "") for j in range(4) for i in range(4)]
    return lines


def edit(lines: list[str], line_number: int, text: str) -> str:
    lines = list(lines)
    lines[line_number - 1] = text
    return "\n".join(lines) + "\n"


BPT_ERRORS = [
    # (1-based line, replacement, expected fragments)
    (5, "1.0 nan 2.0", ["line 5", "non-finite", "nan"]),
    (5, "1.0 inf 2.0", ["line 5", "non-finite"]),
    (5, "1.0 -Infinity 2.0", ["line 5", "non-finite"]),
    (5, "1e400 0 0", ["line 5", "overflows"]),
    (5, "1.0 abc 2.0", ["line 5", "not a number", "abc"]),
    (5, "1.0 1_0 2.0", ["line 5", "not a number"]),
    (5, "1.0,2.0,3.0", ["line 5", "patch 0"]),
    (5, "1.0 2.0", ["line 5", "patch 0", "arity"]),
    (5, "1.0 2.0 3.0 4.0", ["line 5", "patch 0", "arity"]),
    (2, "2 2", ["line 2", "patch 0", "wrong degree"]),
    (19, "3 2", ["line 19", "patch 1", "wrong degree"]),
    (19, "3", ["line 19", "patch 1", "wrong degree"]),
    (1, "3", ["line 1", "patch count 3", "truncated"]),
    (1, "-2", ["line 1", "-2"]),
    (1, "0", ["line 1", "patch count is 0"]),
    (1, "99999999999999999999", ["line 1", "truncated"]),
    (1, "two", ["line 1", "patch count"]),
    (1, "1", ["line 19", "unexpected content"]),
]


@pytest.mark.parametrize("line, text, fragments", BPT_ERRORS)
def test_bpt_errors(tmp_path, line, text, fragments):
    expect_error(tmp_path, "bad.bpt", edit(bpt_text(), line, text), *fragments)


@pytest.mark.parametrize(
    "line, text, fragments",
    [
        (20, "1 2 3 0", ["line 20", "patch 1", "weight 0.0 <= 0"]),
        (35, "1 2 3 -1e-3", ["line 35", "patch 1", "weight -0.001 <= 0"]),
        (20, "1 2 3 nan", ["line 20", "non-finite"]),
        (21, "1 2 3", ["line 21", "patch 1", "arity"]),
    ],
)
def test_bpt_weight_errors(tmp_path, line, text, fragments):
    expect_error(tmp_path, "bad.bpt", edit(bpt_text(weights=True), line, text), *fragments)


def test_bpt_truncated_inside_a_patch(tmp_path):
    expect_error(tmp_path, "short.bpt", "\n".join(bpt_text()[:-3]) + "\n", "line 1", "truncated")


def test_bpt_patch_with_15_points(tmp_path):
    lines = bpt_text(3)
    del lines[5]  # patch 0 loses a point: the next degree line is out of step
    message = expect_error(tmp_path, "bad.bpt", "\n".join(lines + ["0 0 0"]) + "\n", "line 19", "patch 1", "wrong degree")
    assert "previous patch" in message


def bez_text() -> list[str]:
    """Two patches over 20 vertices (patch 1 shares patch 0's right column)."""
    first = list(range(1, 17))
    second = [4, 17, 18, 19, 8, 20, 17, 18, 12, 19, 20, 17, 16, 18, 19, 20]
    vertices = [f"{k}.0,{k % 4}.25,-{k}" for k in range(20)]
    return ["2", ",".join(map(str, first)), ",".join(map(str, second)), "20"] + vertices


BEZ_ERRORS = [
    (2, "1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,21", ["line 2", "patch 0", "21 out of range 1..20"]),
    (3, "0,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16", ["line 3", "patch 1", "0 out of range"]),
    (3, "-1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16", ["line 3", "patch 1", "out of range"]),
    (2, "1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,99999999999999999999999", ["line 2", "out of range"]),
    (2, "1,2,3.5,4,5,6,7,8,9,10,11,12,13,14,15,16", ["line 2", "patch 0", "non-integer", "3.5"]),
    (2, "1,2,x,4,5,6,7,8,9,10,11,12,13,14,15,16", ["line 2", "patch 0", "not a vertex index"]),
    (2, "1,2,,4,5,6,7,8,9,10,11,12,13,14,15,16", ["line 2", "patch 0", "not a vertex index"]),
    (2, "1,2,3,4,5,6,7,8,9,10,11,12,13,14,15", ["line 2", "patch 0", "16", "got 15"]),
    (2, "1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16", ["line 2", "patch 0", "got 1"]),
    (1, "3", ["line 4", "patch 2", "got 1"]),  # the vertex count line read as a patch
    (1, "30", ["line 1", "patch count 30", "truncated"]),
    (1, "0", ["line 1", "patch count is 0"]),
    (1, "-5", ["line 1", "-5"]),
    (1, "123456789012345678901234567890", ["line 1", "truncated"]),
    (4, "21", ["line 4", "vertex count 21", "truncated"]),
    (4, "19", ["line 3", "patch 1", "20 out of range 1..19"]),
    (4, "0", ["line 4", "vertex count is 0"]),
    (4, "twenty", ["line 4", "vertex count"]),
    (7, "1.0,NaN,2.0", ["line 7", "non-finite"]),
    (7, "1.0,2.0,inf", ["line 7", "non-finite"]),
    (7, "1.0,2.0,junk", ["line 7", "not a number"]),
    (7, "1.0,2.0", ["line 7", "vertex 3", "got 2"]),
    (7, "1.0,2.0,3.0,1.0", ["line 7", "vertex 3", "got 4"]),
]


@pytest.mark.parametrize("line, text, fragments", BEZ_ERRORS)
def test_bez_errors(tmp_path, line, text, fragments):
    expect_error(tmp_path, "bad.bez", edit(bez_text(), line, text), *fragments)


def test_bez_weight_errors(tmp_path):
    lines = [line + ",2.0" if k >= 4 else line for k, line in enumerate(bez_text())]
    assert load_scene_text(tmp_path, "ok.bez", "\n".join(lines)).patches[0, 0, 0, 3] == 2.0
    expect_error(tmp_path, "bad.bez", edit(lines, 9, "1,2,3,0"), "line 9", "vertex 5", "weight 0.0 <= 0")
    expect_error(tmp_path, "bad.bez", edit(lines, 10, "1,2,3,-2"), "line 10", "weight -2.0 <= 0")


def load_scene_text(tmp_path, name, text):
    (tmp_path / name).write_text(text)
    return load_scene(tmp_path / name)


def test_bez_trailing_content(tmp_path):
    expect_error(tmp_path, "long.bez", "\n".join(bez_text() + ["1.0,2.0,3.0"]) + "\n", "line 25", "unexpected content")


def test_bez_truncated_vertices(tmp_path):
    expect_error(tmp_path, "short.bez", "\n".join(bez_text()[:-4]) + "\n", "line 4", "vertex count 20", "truncated")


@pytest.mark.parametrize("name", ["empty.bpt", "empty.bez", "empty.json"])
def test_empty_files(tmp_path, name):
    expect_error(tmp_path, name, "", "empty file")
    expect_error(tmp_path, name, "\n  \n\t\n", "empty file")


def test_binary_file(tmp_path):
    expect_error(tmp_path, "binary.bez", b"2\n\xff\xfe\x00garbage", "line 2", "not UTF-8")


def test_header_never_allocates(tmp_path, monkeypatch):
    """A huge count is refused from the line count alone, before any array is built."""
    calls = []
    for reader in (bpt, bez):
        monkeypatch.setattr(reader, "_floats", lambda *a: calls.append(a))
    expect_error(tmp_path, "huge.bpt", "1000000000000\n3 3\n1 2 3\n", "line 1", "truncated")
    expect_error(tmp_path, "huge.bez", "1000000000000\n1,2\n", "line 1", "truncated")
    assert calls == []


# ----------------------------------------------------------------------------- JSON scenes


def write_json(tmp_path, doc, name="scene.json") -> Path:
    for model in ("teapot.bez", "teaspoon.bez"):
        target = tmp_path / model
        if not target.exists():
            target.write_bytes((SCENES / model).read_bytes())
    path = tmp_path / name
    path.write_text(doc if isinstance(doc, str) else json.dumps(doc))
    return path


def test_json_transform_ids_and_camera(tmp_path):
    matrix = [[0.0, -2.0, 0.0, 1.0], [2.0, 0.0, 0.0, 2.0], [0.0, 0.0, 2.0, 3.0], [0.0, 0.0, 0.0, 1.0]]
    doc = {
        "objects": [
            {"file": "teapot.bez"},
            {"file": "teapot.bez", "transform": matrix, "object_id": 7},
            {"file": "teaspoon.bez"},
        ],
        "camera": {"eye": [0, -10, 5], "target": [0, 0, 1], "fov_y_deg": 30, "width": 640, "height": 480, "near": 0.5, "far": 100},
    }
    scene = load_scene(write_json(tmp_path, doc))
    teapot = load_scene(SCENES / "teapot.bez").patches
    spoon = load_scene(SCENES / "teaspoon.bez").patches
    assert scene.num_patches == 32 + 32 + 16
    assert np.array_equal(scene.object_ids, np.repeat(np.int32([0, 7, 2]), [32, 32, 16]))
    assert np.array_equal(scene.patches[:32], teapot)
    assert np.allclose(scene.patches[32:64], teapot @ np.array(matrix).T)  # b' = M b
    p = scene.points[32, 0, 0]
    assert np.allclose(p, [1 - 2 * 0.0, 2 + 2 * 1.4, 3 + 2 * 2.4])  # (1.4, 0, 2.4) turned, scaled, moved
    assert np.array_equal(scene.patches[64:], spoon)
    cam = scene.camera
    assert cam.eye.tolist() == [0, -10, 5] and cam.up.tolist() == [0, 0, 1]
    assert (cam.fov_y_deg, cam.width, cam.height, cam.near, cam.far) == (30, 640, 480, 0.5, 100)


def test_json_parses_each_file_once(tmp_path, monkeypatch):
    calls = []
    original = bez.read_patches
    monkeypatch.setattr(bez, "read_patches", lambda path: calls.append(str(path)) or original(path))
    doc = {"objects": [{"file": "teapot.bez"}, {"file": "./teapot.bez"}, {"file": "../" + tmp_path.name + "/teapot.bez"}]}
    scene = load_scene(write_json(tmp_path, doc))
    assert scene.num_patches == 96 and len(calls) == 1


def test_json_relative_to_its_folder(tmp_path):
    sub = tmp_path / "sub"
    sub.mkdir()
    (tmp_path / "teapot.bez").write_bytes((SCENES / "teapot.bez").read_bytes())
    (sub / "s.json").write_text(json.dumps({"objects": [{"file": "../teapot.bez"}]}))
    assert load_scene(sub / "s.json").num_patches == 32


SINGULAR = [[1, 0, 0, 0], [0, 1, 0, 0], [1, 1, 0, 0], [0, 0, 0, 1]]
FLIPPING = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, -1]]
PROJECTIVE = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, -1, 2]]  # w' = 2 - z: <= 0 above z = 2
TEAPOT = {"file": "teapot.bez"}

JSON_ERRORS = [
    ("{\"objects\": [", ["line 1", "not valid JSON"]),
    ("{\n\"objects\": []\n,}", ["line 3", "not valid JSON"]),
    ("[1, 2]", ["top level", "JSON object"]),
    ({"objects": [TEAPOT], "lights": []}, ["lights", "unknown key"]),
    ({}, ["missing required key 'objects'"]),
    ({"objects": []}, ["objects", "non-empty list"]),
    ({"objects": {"file": "teapot.bez"}}, ["objects", "non-empty list"]),
    ({"objects": [{"file": "teapot.bez", "color": "red"}]}, ["objects[0]", "unknown key 'color'"]),
    ({"objects": [TEAPOT, {"transform": SINGULAR}]}, ["objects[1]", "missing required key 'file'"]),
    ({"objects": [{"file": 3}]}, ["objects[0].file", "string"]),
    ({"objects": [TEAPOT, {"file": "nothere.bez"}]}, ["objects[1].file", "nothere.bez: file not found"]),
    ({"objects": [{"file": "teapot.obj"}]}, ["objects[0].file", ".obj"]),
    ({"objects": [{"file": "other.json"}]}, ["objects[0].file", ".json"]),
    ({"objects": [{"file": "teapot.bez", "transform": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]}]}, ["objects[0].transform", "4x4"]),
    ({"objects": [{"file": "teapot.bez", "transform": [[1, 0, 0, 0]] * 3 + [[0, 0, 0, "1"]]}]}, ["objects[0].transform[3]", "numbers"]),
    ({"objects": [{"file": "teapot.bez", "transform": [[1, 0, 0, 0]] * 3 + [[0, 0, 0, True]]}]}, ["objects[0].transform[3]", "numbers"]),
    ('{"objects": [{"file": "teapot.bez", "transform": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1e999]]}]}', ["objects[0].transform[3]", "finite"]),
    ('{"objects": [{"file": "teapot.bez",\n "transform": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,NaN]]}]}', ["line 2", "NaN"]),
    ({"objects": [{"file": "teapot.bez", "transform": SINGULAR}]}, ["objects[0].transform", "singular"]),
    ({"objects": [{"file": "teapot.bez", "transform": [[1e-300, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]}]}, ["objects[0].transform", "singular"]),
    ({"objects": [TEAPOT, {"file": "teapot.bez", "transform": FLIPPING}]}, ["objects[1].transform", "patch 0", "<= 0 after the transform"]),
    ({"objects": [{"file": "teapot.bez", "transform": PROJECTIVE}]}, ["objects[0].transform", "patch 0", "<= 0 after the transform"]),
    ({"objects": [{"file": "teapot.bez", "object_id": -1}]}, ["objects[0].object_id", "integer"]),
    ({"objects": [{"file": "teapot.bez", "object_id": 1.5}]}, ["objects[0].object_id", "integer"]),
    ({"objects": [{"file": "teapot.bez", "object_id": True}]}, ["objects[0].object_id", "integer"]),
    ({"objects": [{"file": "teapot.bez", "object_id": 2**31}]}, ["objects[0].object_id", "integer"]),
    ({"objects": [TEAPOT], "camera": {"eye": [0, 0, 5]}}, ["camera", "missing required key 'target'"]),
    ({"objects": [TEAPOT], "camera": {"eye": [0, 0, 5], "target": [0, 0, 0], "zoom": 2}}, ["camera", "unknown key 'zoom'"]),
    ({"objects": [TEAPOT], "camera": {"eye": [0, 0], "target": [0, 0, 0]}}, ["camera.eye", "3 numbers"]),
    ({"objects": [TEAPOT], "camera": {"eye": [0, 0, 5], "target": [0, 0, 5]}}, ["camera.target", "equals camera.eye"]),
    ({"objects": [TEAPOT], "camera": {"eye": [0, 0, 5], "target": [0, 0, 0]}}, ["camera.up", "parallel"]),
    ({"objects": [TEAPOT], "camera": {"eye": [0, -5, 0], "target": [0, 0, 0], "width": 0}}, ["camera.width", "integer"]),
    ({"objects": [TEAPOT], "camera": {"eye": [0, -5, 0], "target": [0, 0, 0], "height": 7.5}}, ["camera.height", "integer"]),
    ({"objects": [TEAPOT], "camera": {"eye": [0, -5, 0], "target": [0, 0, 0], "fov_y_deg": 180}}, ["camera.fov_y_deg"]),
    ({"objects": [TEAPOT], "camera": {"eye": [0, -5, 0], "target": [0, 0, 0], "fov_y_deg": "wide"}}, ["camera.fov_y_deg", "number"]),
    ({"objects": [TEAPOT], "camera": {"eye": [0, -5, 0], "target": [0, 0, 0], "near": 10, "far": 1}}, ["camera.near", "near < far"]),
    ({"objects": [TEAPOT], "camera": [0, 0, 5]}, ["camera", "JSON object"]),
    ('{"objects": [{"file": "teapot.bez"}],\n "objects": []}', ["duplicate key 'objects'"]),
    ({"objects": [{"file": "teapot.bez", "object_id": 1}], "camera": {"eye": [0, 0, 5], "target": [0, 0, 0], "up": [0, 1, 0], "up ": 1}},
     ["camera", "unknown key 'up '"]),
]


@pytest.mark.parametrize("doc, fragments", JSON_ERRORS)
def test_json_errors(tmp_path, doc, fragments):
    write_json(tmp_path, "{}")
    expect_error(tmp_path, "scene.json", doc if isinstance(doc, str) else json.dumps(doc), *fragments)


def test_json_reports_errors_inside_object_files(tmp_path):
    (tmp_path / "bad.bez").write_text(edit(bez_text(), 7, "1.0,2.0,nan"))
    message = expect_error(tmp_path, "scene.json", json.dumps({"objects": [{"file": "bad.bez"}]}), "objects[0].file", "line 7")
    assert str(tmp_path / "bad.bez") in message


def test_json_tiny_uniform_scale_is_not_singular(tmp_path):
    small = [[1e-6, 0, 0, 0], [0, 1e-6, 0, 0], [0, 0, 1e-6, 0], [0, 0, 0, 1]]
    scene = load_scene(write_json(tmp_path, {"objects": [{"file": "teapot.bez", "transform": small}]}))
    assert np.allclose(scene.points.max(axis=(0, 1, 2)), [3.525e-6, 2e-6, 3.15e-6])


# ----------------------------------------------------------------------------- generated scenes


def test_make_scenes_is_deterministic(tmp_path):
    """The committed files are what the generator writes."""
    write_bpt(tmp_path / "sphere.bpt", make_scenes.sphere_patches())
    write_bpt(tmp_path / "torus.bpt", make_scenes.torus_patches())
    write_bpt(tmp_path / "table.bpt", make_scenes.grid_patches(**make_scenes.TABLE))
    make_scenes.dump_scene(tmp_path / "teapots.json", *make_scenes.teapots_scene())
    make_scenes.dump_scene(tmp_path / "tea_table.json", *make_scenes.tea_table_scene())
    for name in ("sphere.bpt", "torus.bpt", "table.bpt", "teapots.json", "tea_table.json"):
        assert (tmp_path / name).read_bytes() == (SCENES / name).read_bytes(), name


def test_sphere_is_exact():
    generated = make_scenes.sphere_patches()
    scene = load_scene(SCENES / "sphere.bpt")
    # the file holds Cartesian points and weights, repr-exact
    w = generated[..., 3:]
    assert np.array_equal(scene.points, generated[..., :3] / w + 0.0)
    assert np.array_equal(scene.weights, generated[..., 3])
    assert np.array_equal(scene.patches, np.concatenate([w * (generated[..., :3] / w), w], -1) + 0.0)
    assert not np.signbit(scene.patches[scene.patches == 0]).any()  # no -0.0 in the file
    rng = np.random.default_rng(7)
    u, v = rng.random(64), rng.random(64)
    u[:4], v[:4] = [0, 1, 0, 1], [0, 0, 1, 1]
    for patches in (generated, scene.patches):
        radius = np.linalg.norm(make_scenes.evaluate(patches, u, v), axis=-1)
        assert np.abs(radius - 1).max() < 1e-12
    # outward normals: t_u x t_v points away from the centre
    h = 1e-6
    mid_u, mid_v = rng.uniform(0.1, 0.9, 16), rng.uniform(0.1, 0.9, 16)
    t_u = make_scenes.evaluate(scene.patches, mid_u + h, mid_v) - make_scenes.evaluate(scene.patches, mid_u - h, mid_v)
    t_v = make_scenes.evaluate(scene.patches, mid_u, mid_v + h) - make_scenes.evaluate(scene.patches, mid_u, mid_v - h)
    position = make_scenes.evaluate(scene.patches, mid_u, mid_v)
    assert (np.einsum("pkc,pkc->pk", np.cross(t_u, t_v), position) > 0).all()


def test_torus_is_exact():
    """((R + r cos v) cos u, (R + r cos v) sin u, r sin v) with R = 3, r = 1: every point at
    distance 1 from the core circle, normals outward (away from it)."""
    scene = load_scene(SCENES / "torus.bpt")
    rng = np.random.default_rng(8)
    u, v = rng.random(64), rng.random(64)
    u[:4], v[:4] = [0, 1, 0, 1], [0, 0, 1, 1]
    for patches in (make_scenes.torus_patches(), scene.patches):
        x = make_scenes.evaluate(patches, u, v)
        core = 3 * x[..., :2] / np.linalg.norm(x[..., :2], axis=-1, keepdims=True)
        assert np.abs(np.linalg.norm(x - np.concatenate([core, 0 * x[..., 2:]], -1), axis=-1) - 1).max() < 1e-12
    h = 1e-6
    mid_u, mid_v = rng.uniform(0.1, 0.9, 16), rng.uniform(0.1, 0.9, 16)
    t_u = make_scenes.evaluate(scene.patches, mid_u + h, mid_v) - make_scenes.evaluate(scene.patches, mid_u - h, mid_v)
    t_v = make_scenes.evaluate(scene.patches, mid_u, mid_v + h) - make_scenes.evaluate(scene.patches, mid_u, mid_v - h)
    x = make_scenes.evaluate(scene.patches, mid_u, mid_v)
    outward = x - np.concatenate([3 * x[..., :2] / np.linalg.norm(x[..., :2], axis=-1, keepdims=True), 0 * x[..., 2:]], -1)
    assert (np.einsum("pkc,pkc->pk", np.cross(t_u, t_v), outward) > 0).all()


def _in_view(scene) -> bool:
    """All control points inside the camera frustum (so, by the convex hull property, all surfaces)."""
    cam = scene.camera
    view = cam.view_matrix()
    pts = scene.points.reshape(-1, 3) @ view[:3, :3].T + view[:3, 3]
    depth = -pts[:, 2]
    half_h = np.tan(np.radians(cam.fov_y_deg) / 2)
    half_w = half_h * cam.width / cam.height
    return bool(
        (depth > cam.near).all() and (depth < cam.far).all()
        and (np.abs(pts[:, 0]) < half_w * depth).all() and (np.abs(pts[:, 1]) < half_h * depth).all()
    )


def test_teapots_scene():
    scene = load_scene(SCENES / "teapots.json")
    assert scene.num_patches == 16 * 32
    ids = scene.object_ids.reshape(16, 32)
    assert (ids == ids[:, :1]).all() and len(set(ids[:, 0].tolist())) == 16
    assert _in_view(scene)
    lows = scene.points.reshape(16, -1, 3).min(axis=1)
    highs = scene.points.reshape(16, -1, 3).max(axis=1)
    for a in range(16):  # no two teapots overlap
        for b in range(a + 1, 16):
            assert (highs[a, :2] < lows[b, :2]).any() or (highs[b, :2] < lows[a, :2]).any()


def test_tea_table_scene():
    scene = load_scene(SCENES / "tea_table.json")
    assert scene.num_patches == 332  # table 48, teapot 32, 6 cups 26, 6 spoons 16
    assert np.bincount(scene.object_ids).tolist() == [48, 32] + [26] * 6 + [16] * 6
    assert _in_view(scene)
    table = scene.points[scene.object_ids == 0]
    assert (table[..., 2] == 0).all()
    boxes = []
    for k in range(1, 14):
        pts = scene.points[scene.object_ids == k].reshape(-1, 3)
        low, high = pts.min(axis=0), pts.max(axis=0)
        assert low[2] > 0  # above the table top
        assert (low[:2] > table.min(axis=(0, 1, 2))[:2]).all() and (high[:2] < table.max(axis=(0, 1, 2))[:2]).all()
        boxes.append((low, high))
    for a in range(len(boxes)):  # nothing overlaps
        for b in range(a + 1, len(boxes)):
            (la, ha), (lb, hb) = boxes[a], boxes[b]
            assert (ha[:2] < lb[:2]).any() or (hb[:2] < la[:2]).any(), (a + 1, b + 1)


def test_a_mirroring_transform_keeps_patches_facing_outwards(tmp_path):
    """x -> -x turns the sphere inside out unless u is reversed: normals must still point out."""
    import json

    from cltess.reference import evaluate

    sphere = Path(__file__).resolve().parent.parent / "scenes" / "sphere.bpt"
    (tmp_path / "sphere.bpt").write_bytes(sphere.read_bytes())
    mirror = [[-1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]
    (tmp_path / "s.json").write_text(json.dumps({"objects": [{"file": "sphere.bpt", "transform": mirror}]}))
    scene = load_scene(tmp_path / "s.json")
    for patch in scene.patches:
        position, normal = evaluate(patch, [0.3, 0.6], [0.4, 0.7])
        assert ((position * normal).sum(axis=1) > 0.99).all()


def test_a_mirroring_transform_reverses_mesh_winding():
    import trimesh

    from cltess.scene import TriangleMesh

    mesh = TriangleMesh.from_trimesh(trimesh.creation.icosphere(1))
    mirrored = mesh.transformed(np.diag([-1.0, 1.0, 1.0, 1.0]))
    corners = mirrored.vertices[mirrored.faces]
    face_normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    assert ((face_normals * corners.mean(axis=1)).sum(axis=1) > 0).all()
