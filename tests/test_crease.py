"""Crease angle (cltess.scene.creased_normals): a mesh file without normals keeps its sharp
edges; the cube stays a cube, the cylinder a cylinder."""
import math

import numpy as np
import pytest
import trimesh

from cltess.cli import main
from cltess.io import load_scene
from cltess.scene import TriangleMesh, creased_normals, vertex_normals

EPS = 1e-3


@pytest.fixture(scope="module")
def solids(tmp_path_factory):
    folder = tmp_path_factory.mktemp("solids")
    trimesh.creation.box((1, 1, 1)).export(folder / "cube.stl")
    trimesh.creation.cylinder(radius=0.5, height=1.0, sections=24).export(folder / "cylinder.stl")
    return folder


def plane_distances(scene, tess):
    """Each output vertex's distance to the plane of the input triangle (patch) it came from."""
    mesh = scene.meshes[0]
    corners = mesh.vertices[mesh.faces]
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    face = tess.patch_ids
    return np.abs(((tess.positions - corners[face, 0]) * normal[face]).sum(axis=1)), normal[face]


def test_cube_from_stl_stays_a_cube(tessellator, solids):
    scene = load_scene(solids / "cube.stl")
    tess = tessellator.tessellate(scene, eps=EPS)
    distance, _ = plane_distances(scene, tess)
    assert distance.max() <= EPS
    assert tess.stats["sharp_edges"] == 12
    loaded = tess.to_trimesh()
    assert loaded.is_watertight and np.allclose(loaded.extents, 1, atol=EPS)
    assert abs(loaded.volume - 1) < 6 * EPS


def test_smoothing_every_edge_makes_the_blob_the_crease_angle_prevents(tessellator, solids):
    scene = load_scene(solids / "cube.stl", crease_angle=None)
    extents = tessellator.tessellate(scene, eps=EPS).to_trimesh().extents
    assert extents.min() > 1.2  # the 1.33-unit blob of issue 16


def test_cylinder_from_stl_stays_a_cylinder(tessellator, solids):
    scene = load_scene(solids / "cylinder.stl")
    tess = tessellator.tessellate(scene, eps=EPS)
    distance, normal = plane_distances(scene, tess)
    caps = np.abs(normal[:, 2]) > 0.99
    assert caps.any() and distance[caps].max() <= EPS  # flat caps
    radius = np.linalg.norm(tess.positions[:, :2], axis=1)
    sides = ~caps
    assert radius.max() <= 0.5 + EPS and radius[sides].min() >= 0.5 * math.cos(math.pi / 24) - EPS
    assert np.abs(tess.positions[:, 2]).max() <= 0.5 + EPS  # the caps do not bulge
    # the sides are smooth between their facets: PN curves bow outwards towards the circle
    assert radius[sides].mean() > 0.5 * math.cos(math.pi / 24) + 1e-3
    assert tess.to_trimesh().is_watertight


def test_creased_normals_split_only_sharp_edges():
    # two squares folded by 90 degrees along x = 0, plus a flat extension of the first
    vertices = np.array([[0, 0, 0], [0, 1, 0], [-1, 0, 0], [-1, 1, 0], [0, 0, 1], [0, 1, 1],
                         [-2, 0, 0], [-2, 1, 0]], float)
    faces = np.array([[0, 1, 3], [0, 3, 2], [0, 4, 5], [0, 5, 1], [2, 3, 7], [2, 7, 6]])
    corner = creased_normals(vertices, faces, 30)
    assert np.allclose(corner[:2].reshape(-1, 3), [0, 0, 1]) and np.allclose(corner[4:].reshape(-1, 3), [0, 0, 1])
    assert np.allclose(np.abs(corner[2:4].reshape(-1, 3)), [1, 0, 0])
    # corners of one smooth region at one point are bitwise equal (so PN edges there stay smooth)
    assert np.array_equal(corner[1, 1], corner[4, 0])  # vertex 3 on faces 1 and 4
    # 180 degrees: every edge smooth, as vertex_normals
    assert np.allclose(creased_normals(vertices, faces, 180), vertex_normals(vertices, faces)[faces])


def test_crease_angle_splits_vertices_but_keeps_faces_and_file_normals_win():
    box = trimesh.creation.box((1, 1, 1))
    creased = TriangleMesh(box.vertices, box.faces, crease_angle=30)
    assert len(creased.vertices) == 24 and len(creased.faces) == len(box.faces)
    assert np.array_equal(creased.vertices[creased.faces], np.asarray(box.vertices)[box.faces])
    given = TriangleMesh(box.vertices, box.faces, np.asarray(box.vertex_normals), crease_angle=30)
    assert len(given.vertices) == 8
    with pytest.raises(ValueError, match="crease angle"):
        TriangleMesh(box.vertices, box.faces, crease_angle=200)


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def test_cli_crease_angle(capsys, tmp_path, solids):
    code, out, err = run(capsys, "tessellate", solids / "cube.stl", "--eps", EPS, "-o", tmp_path / "cube.ply")
    assert code == 0, err
    assert np.allclose(trimesh.load(tmp_path / "cube.ply").extents, 1, atol=EPS)
    assert "sharp edges      12" in out or out.split("sharp edges")[1].split()[0] == "12"
    code, out, err = run(capsys, "tessellate", solids / "cube.stl", "--eps", EPS, "--crease-angle", "180",
                         "-o", tmp_path / "blob.ply")
    assert code == 0, err
    assert trimesh.load(tmp_path / "blob.ply").extents.min() > 1.2


@pytest.mark.parametrize("value", ["-1", "181", "nan", "sharp", ""])
def test_cli_bad_crease_angle_exits_2(capsys, tmp_path, solids, value):
    code, _, err = run(capsys, "tessellate", solids / "cube.stl", "--eps", EPS, "--crease-angle", value,
                       "-o", tmp_path / "cube.ply")
    assert code == 2 and "--crease-angle" in err and "Traceback" not in err
    assert not any(tmp_path.iterdir())
