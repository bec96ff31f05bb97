"""Orientation (cltess/orient.py): patches face one way across shared edges, and outwards."""
from pathlib import Path

import numpy as np
import pytest
import trimesh

from cltess import load_scene
from cltess.adjacency import edge_groups
from cltess.cli import main
from cltess.orient import orient_scene
from cltess.scene import Scene, TriangleMesh
from support import closed_torus_grid, icosphere

SCENES = Path(__file__).resolve().parent.parent / "scenes"


def reversed_u(scene: Scene, which: np.ndarray) -> Scene:
    patches = scene.patches.copy()
    patches[which] = patches[which][:, :, ::-1]
    return Scene(patches, scene.object_ids, scene.camera, scene.name)


def welded(tessellator, scene, eps=0.05):
    mesh = tessellator.tessellate(scene, eps=eps, max_factor=256).welded(check_t_junctions=False)
    return mesh, mesh.to_trimesh()


def test_randomly_reversed_closed_grids_come_back_consistent_and_outward(tessellator, rng):
    for _ in range(3):
        scene = closed_torus_grid(rng, int(rng.integers(3, 10)), int(rng.integers(3, 8)), noise=0.1)
        which = rng.random(scene.num_patches) < 0.4
        messy = reversed_u(scene, which)
        assert edge_groups(messy.patches).reversed_pairs > 0
        fixed, report = orient_scene(messy)
        assert report.components == 1 and report.conflicts == 0
        assert edge_groups(fixed.patches).reversed_pairs == 0
        _, loaded = welded(tessellator, fixed)
        assert loaded.is_watertight and loaded.is_winding_consistent and loaded.volume > 0
        # it reversed exactly the patches that disagree with the outward-facing original
        _, original = welded(tessellator, scene)
        outward = original.volume > 0
        assert report.flipped == int((which if outward else ~which).sum())


def test_inward_sphere_is_turned_outwards(tessellator):
    sphere = load_scene(SCENES / "sphere.bpt")
    inward = reversed_u(sphere, np.ones(sphere.num_patches, bool))
    fixed, report = orient_scene(inward)
    assert report.flipped == sphere.num_patches
    assert np.array_equal(fixed.patches, sphere.patches)
    _, loaded = welded(tessellator, fixed, eps=1e-2)
    assert loaded.is_watertight and loaded.is_winding_consistent and loaded.volume > 4


def test_orienting_is_idempotent_and_leaves_good_scenes_alone():
    for name in ("sphere.bpt", "teapot.bez", "table.bpt"):
        scene = load_scene(SCENES / name)
        same, report = orient_scene(scene)
        assert same is scene and report.flipped == 0
    cup, _ = orient_scene(load_scene(SCENES / "teacup.bez"))
    again, report = orient_scene(cup)
    assert again is cup and report.flipped == 0


@pytest.mark.parametrize("name, patches", [("teacup.bez", 26), ("teaspoon.bez", 16)])
def test_teaset_is_turned_right_side_out(tessellator, name, patches):
    """The teacup and teaspoon data face inwards (scenes/README.md): every patch is reversed."""
    fixed, report = orient_scene(load_scene(SCENES / name))
    assert report.flipped == patches
    mesh, loaded = welded(tessellator, fixed, eps=1e-2)
    assert loaded.is_winding_consistent and mesh.stats["welded_misoriented_edges"] == 0
    # outwards: the normals point away from the centre on the whole
    centre = loaded.vertices.mean(axis=0)
    assert (np.einsum("ij,ij->i", loaded.face_normals, loaded.triangles_center - centre) * loaded.area_faces).sum() > 0


def test_tea_table_cups_and_spoons_are_reversed(tessellator):
    scene = load_scene(SCENES / "tea_table.json")
    fixed, report = orient_scene(scene)
    cups_and_spoons = np.isin(scene.object_ids, [i for i in np.unique(scene.object_ids)
                                                 if (scene.object_ids == i).sum() in (26, 16)])
    assert report.flipped == int(cups_and_spoons.sum()) > 0
    assert report.conflicts == 0


def test_mesh_with_reversed_faces_is_reoriented(tessellator, rng):
    sphere = icosphere(2)
    faces = np.array(sphere.faces)
    which = rng.random(len(faces)) < 0.3
    faces[which] = faces[which][:, ::-1]
    scene = Scene.from_meshes([TriangleMesh(sphere.vertices, faces, name="messy")])
    fixed, report = orient_scene(scene)
    assert report.flipped == int(which.sum())
    _, loaded = welded(tessellator, fixed, eps=1e-2)
    assert loaded.is_watertight and loaded.is_winding_consistent and loaded.volume > 3.5


def test_mesh_with_file_normals_is_left_alone():
    sphere = icosphere(1)
    faces = np.array(sphere.faces)
    faces[:5] = faces[:5, ::-1]
    scene = Scene.from_meshes([TriangleMesh(sphere.vertices, faces, np.array(sphere.vertex_normals))])
    same, report = orient_scene(scene)
    assert same is scene and report.flipped == 0


def test_cli_orients_by_default_and_reports_it(capsys, tmp_path):
    code = main(["tessellate", str(SCENES / "teacup.bez"), "--eps", "0.01", "-o", str(tmp_path / "cup.ply")])
    out = capsys.readouterr().out
    assert code == 0
    assert "flipped patches  " in out and out.split("flipped patches")[1].split()[0] == "26"
    code = main(["tessellate", str(SCENES / "teacup.bez"), "--eps", "0.01", "--no-orient", "-o",
                 str(tmp_path / "raw.ply")])
    out = capsys.readouterr().out
    assert code == 0 and "flipped" not in out
    oriented, raw = (trimesh.load(tmp_path / f"{n}.ply", process=False) for n in ("cup", "raw"))
    # the vector area (sum of n dA) depends only on the boundary: reversed, it changes sign
    vector_area = [(m.face_normals * m.area_faces[:, None]).sum(axis=0) for m in (oriented, raw)]
    assert np.allclose(vector_area[0], -vector_area[1], atol=1e-3 * np.abs(vector_area[1]).max())


def test_cli_orient_option_refuses_a_value(capsys, tmp_path):
    code = main(["tessellate", str(SCENES / "teacup.bez"), "--eps", "0.01", "--orient=no", "-o",
                 str(tmp_path / "cup.ply")])
    assert code == 2 and "--orient" in capsys.readouterr().err
    assert not any(tmp_path.iterdir())


def test_a_large_scenes_orientation_and_edge_groups_come_back_from_the_cache(tmp_path, rng, monkeypatch):
    """io.scene_cache.derived: the second scene with the same patches gets the same flips,
    report and edge groups (every field, dtype included) from the cache, without deciding
    again; other patches are another key."""
    import dataclasses

    import cltess.orient as orient
    from cltess.crack.adjacency import EdgeGroups, scene_edge_groups
    from cltess.io import scene_cache

    monkeypatch.setenv("CLTESS_SCENE_CACHE", str(tmp_path))
    monkeypatch.setattr(scene_cache, "MIN_BYTES", 0)
    teapot = load_scene(SCENES / "teapot.bez")
    messy = reversed_u(teapot, rng.random(teapot.num_patches) < 0.5)
    first, report = orient_scene(messy)
    assert report.flipped and list(tmp_path.glob("*-orientation-*.npz"))
    calls = []
    monkeypatch.setattr(orient, "orientation_flips", lambda *a: calls.append(a))
    again, report_again = orient_scene(reversed_u(messy, np.zeros(messy.num_patches, bool)))
    assert not calls and report_again == report and np.array_equal(again.patches, first.patches)
    cached = scene_edge_groups(Scene(messy.patches, messy.object_ids))
    fresh = edge_groups(messy.patches)
    for field in dataclasses.fields(EdgeGroups):
        a, b = getattr(cached, field.name), getattr(fresh, field.name)
        assert type(a) is type(b) and np.asarray(a).dtype == np.asarray(b).dtype and np.array_equal(a, b), field.name
    with pytest.raises(TypeError):  # not in the cache: orientation_flips (the spy) is asked
        orient_scene(reversed_u(teapot, np.zeros(teapot.num_patches, bool)))
    assert calls


@pytest.mark.parametrize("count", [1, 2, 3, 4, 9, 64, 65, 130])
def test_volume_sums_a_few_patches_at_a_time_are_those_of_all_at_once(rng, monkeypatch, count):
    """orient._patch_sums in steps (any step of 4 or more) against the sums over all patches
    at once, bitwise (NumPy's reference: the formula of _signed_volumes' docstring)."""
    from cltess import orient

    points, grid = orient._bezier_samples(rng.normal(size=(count, 4, 4, 4)) + [0, 0, 0, 3])
    a, b, d = (points[:, :, grid[:, k]] for k in range(3))
    b_x_d = orient._cross(b, d)
    whole = [(a * b_x_d).sum(axis=(0, 2)), (orient._cross(a, b) + b_x_d + orient._cross(d, a)).sum(axis=2),
             (a + b + d).sum(axis=2)]
    for step in (4, 5, 7, 64):
        monkeypatch.setattr(orient, "VOLUME_PATCHES_PER_STEP", step)
        assert [s.tobytes() for s in orient._patch_sums(points, grid)] == [s.tobytes() for s in whole]
