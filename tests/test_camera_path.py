"""Camera paths (cltess/io/camera_path.py): lists and orbits, errors naming file and key."""
import json

import numpy as np
import pytest

from cltess.io.camera_path import orbit, read_camera_path
from cltess.scene import SceneError


def write(tmp_path, doc):
    path = tmp_path / "path.json"
    path.write_text(json.dumps(doc))
    return path


def test_a_list_of_cameras(tmp_path):
    cams = read_camera_path(write(tmp_path, [{"eye": [5, 0, 0], "target": [0, 0, 0]},
                                             {"eye": [0, 5, 0], "target": [0, 0, 0], "width": 640}]))
    assert len(cams) == 2 and cams[1].width == 640
    assert np.array_equal(cams[0].eye, [5, 0, 0])
    assert len(read_camera_path(write(tmp_path, {"cameras": [{"eye": [1, 2, 3], "target": [0, 0, 0]}]}))) == 1


def test_an_orbit_circles_its_target_at_its_radius(tmp_path):
    cams = read_camera_path(write(tmp_path, {"orbit": {"target": [1, 2, 3], "radius": 10, "frames": 12,
                                                       "elevation_deg": 30}}))
    assert len(cams) == 12
    eyes = np.array([c.eye for c in cams])
    assert np.allclose(np.linalg.norm(eyes - [1, 2, 3], axis=1), 10)
    assert np.allclose(eyes[:, 2] - 3, 10 * np.sin(np.radians(30)))
    assert not np.allclose(eyes[0], eyes[-1])  # a full turn does not repeat its first camera
    steps = np.linalg.norm(np.diff(eyes, axis=0), axis=1)
    assert np.allclose(steps, steps[0])


def test_a_partial_sweep_ends_on_its_last_angle():
    cams = orbit([0, 0, 0], 2.0, 3, elevation_deg=0, sweep_deg=90)
    assert np.allclose(cams[-1].eye, [0, 2, 0])


@pytest.mark.parametrize("doc, where", [
    ([{"eye": [0, 0, 0], "target": [0, 0, 0]}], "cameras[0].target"),
    ([{"eye": [1, 0, 0], "target": [0, 0, 0]}, {"eye": [1, 0], "target": [0, 0, 0]}], "cameras[1].eye"),
    ({"orbit": {"target": [0, 0, 0], "radius": -1, "frames": 3}}, "orbit.radius"),
    ({"orbit": {"target": [0, 0, 0], "radius": 1, "frames": 0}}, "orbit.frames"),
    ({"orbit": {"target": [0, 0, 0], "radius": 1, "frames": 2, "elevation_deg": 90}}, "orbit.elevation_deg"),
    ([], "cameras"),
    ({"views": []}, "views"),
])
def test_bad_paths_name_the_file_and_key(tmp_path, doc, where):
    path = write(tmp_path, doc)
    with pytest.raises(SceneError) as caught:
        read_camera_path(path)
    assert str(path) in str(caught.value) and where in str(caught.value)
