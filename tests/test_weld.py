"""Welded output (cltess/weld.py): one indexed mesh per object, exact, watertight where the
surface is closed; its writers and the command line's --weld / --uv."""
from pathlib import Path

import numpy as np
import pytest
import trimesh

from cltess import export, load_scene
from cltess.cli import main
from cltess.tessellation import Tessellation
from cltess.weld import edge_counts, weld
from support import closed_torus_grid

SCENES = Path(__file__).resolve().parent.parent / "scenes"


def two_patches() -> Tessellation:
    """Two patches of one square, each with its own copies of the shared diagonal (0,0)-(1,1)
    (one at -0.0), plus a triangle that collapses onto the diagonal when welded."""
    positions = np.float32([[0, 0, 0], [1, 0, 0], [1, 1, 0],      # patch 0
                            [-0.0, 0, 0], [1, 1, 0], [0, 1, 0],   # patch 1
                            [0, 0, 0], [1, 1, 0], [1, 1, 0]])     # patch 1: degenerate
    normals = np.float32([[0, 0, 1]] * 3 + [[0, 0.6, 0.8]] * 3 + [[0, 0, 1]] * 3)
    uv = np.float32([[0, 0], [1, 0], [1, 1], [0, 0], [1, 0], [0, 1], [0, 0], [0.5, 0.5], [1, 1]])
    return Tessellation(positions, normals, uv, np.int32([0, 0, 0, 1, 1, 1, 1, 1, 1]), np.zeros(9, np.int32),
                        np.uint32([[0, 1, 2], [3, 4, 5], [6, 7, 8]]), np.ones((2, 4), np.int32),
                        stats={"patches": 2})


def test_weld_merges_bitwise_equal_positions_and_drops_collapsed_triangles():
    mesh = two_patches().welded()
    assert mesh.num_vertices == 4 and mesh.num_triangles == 2
    assert mesh.stats["dropped_triangles"] == 1 and mesh.stats["patch_vertices"] == 9
    assert mesh.stats["welded_boundary_edges"] == 4 and mesh.stats["welded_nonmanifold_edges"] == 0
    assert mesh.stats["welded_misoriented_edges"] == 0 and mesh.stats["welded_t_junctions"] == 0
    assert mesh.patch_ids.tolist() == [0, 1]
    assert mesh.corner_uv is None
    # the shared corner's normal: the normalised sum of its four copies' normals
    shared = np.flatnonzero((mesh.positions == [1, 1, 0]).all(axis=1))[0]
    expected = np.float64([0, 0.6, 3.8]) / np.linalg.norm([0, 0.6, 3.8])
    assert np.allclose(mesh.normals[shared], expected, atol=1e-6)
    assert np.allclose(np.linalg.norm(mesh.normals, axis=1), 1, atol=1e-6)


def test_weld_keeps_objects_apart_and_uv_as_a_seam():
    tess = two_patches()
    tess.object_ids = np.int32([0, 0, 0, 1, 1, 1, 1, 1, 1])
    mesh = weld(tess, uv="seam")
    assert mesh.num_vertices == 6 and mesh.num_triangles == 2  # objects 0 and 1 share no vertex
    assert mesh.corner_uv.shape == (2, 3, 2)
    assert mesh.corner_uv[1].tolist() == [[0, 0], [1, 0], [0, 1]]
    with pytest.raises(ValueError, match="uv must be"):
        weld(tess, uv="keep")


def test_edge_counts_see_boundary_nonmanifold_and_misoriented_edges():
    assert edge_counts(np.array([[0, 1, 2], [1, 0, 3]])) == \
        {"boundary_edges": 4, "nonmanifold_edges": 0, "misoriented_edges": 0}
    assert edge_counts(np.array([[0, 1, 2], [0, 1, 3]]))["misoriented_edges"] == 1
    assert edge_counts(np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]]))["nonmanifold_edges"] == 1


def edge_counts_by_counting(triangles) -> dict:
    """edge_counts the obvious way: each undirected edge's uses and their directions, counted."""
    uses, directions = {}, {}
    for a, b, c in np.asarray(triangles).tolist():
        for start, end in ((a, b), (b, c), (c, a)):
            key = (min(start, end), max(start, end))
            uses[key] = uses.get(key, 0) + 1
            directions.setdefault(key, []).append(start < end)
    return {"boundary_edges": sum(n == 1 for n in uses.values()),
            "nonmanifold_edges": sum(n > 2 for n in uses.values()),
            "misoriented_edges": sum(n == 2 and directions[key][0] == directions[key][1] for key, n in uses.items())}


def test_edge_counts_equal_counting_on_random_meshes():
    """Small vertex counts make shared, non-manifold, misoriented and degenerate edges common."""
    rng = np.random.default_rng(12)
    for _ in range(500):
        triangles = rng.integers(0, int(rng.integers(3, 12)), size=(int(rng.integers(1, 40)), 3))
        assert edge_counts(triangles) == edge_counts_by_counting(triangles)
    sphere = np.array(trimesh.creation.icosphere(2).faces)  # closed; some faces turned over
    turned = rng.random(len(sphere)) < 0.05
    sphere[turned] = sphere[turned][:, ::-1]
    counts = edge_counts(sphere)
    assert counts == edge_counts_by_counting(sphere) and counts["boundary_edges"] == 0 < counts["misoriented_edges"]


def check_closed(mesh):
    loaded = mesh.to_trimesh()
    assert loaded.is_watertight and loaded.is_winding_consistent
    assert mesh.stats["welded_boundary_edges"] == 0 and mesh.stats["welded_nonmanifold_edges"] == 0
    assert mesh.stats["welded_misoriented_edges"] == 0 and mesh.stats["welded_t_junctions"] == 0
    return loaded


@pytest.mark.parametrize("eps", [1e-2, 1e-3])
def test_welded_sphere_is_watertight_and_outward(tessellator, eps):
    tess = tessellator.tessellate(load_scene(SCENES / "sphere.bpt"), eps=eps)
    mesh = tess.welded()
    assert mesh.stats["dropped_triangles"] == 0  # the poles' collapsed edges emit no triangle (issue 9)
    loaded = check_closed(mesh)
    assert abs(loaded.volume - 4 / 3 * np.pi) < 4 * np.pi * eps


def test_welded_closed_grids_are_watertight_and_outward_once_oriented(tessellator, rng):
    from cltess.orient import orient_scene

    for _ in range(3):
        scene = closed_torus_grid(rng, int(rng.integers(3, 12)), int(rng.integers(3, 9)), noise=0.1)
        scene, _ = orient_scene(scene)
        mesh = tessellator.tessellate(scene, eps=0.05, max_factor=256).welded()
        loaded = check_closed(mesh)
        assert loaded.euler_number == 0
        assert loaded.volume > 0


@pytest.mark.parametrize("suffix", [".ply", ".obj", ".stl", ".glb"])
def test_welded_files_load_watertight_in_trimesh(tessellator, tmp_path, suffix):
    mesh = tessellator.tessellate(load_scene(SCENES / "sphere.bpt"), eps=1e-2).welded()
    export(mesh, tmp_path / f"s{suffix}")
    loaded = trimesh.load(tmp_path / f"s{suffix}", force="mesh")
    assert len(loaded.faces) == mesh.num_triangles
    assert loaded.is_watertight and loaded.is_winding_consistent and loaded.volume > 4
    if suffix in (".ply", ".obj"):  # every float32 position reads back exactly
        assert np.array_equal(np.unique(np.asarray(loaded.vertices, np.float32), axis=0),
                              np.unique(mesh.positions, axis=0))


def test_seam_uv_written_per_corner(tessellator, tmp_path):
    mesh = tessellator.tessellate(load_scene(SCENES / "teacup.bez"), eps=1e-2).welded(uv="seam")
    export(mesh, tmp_path / "cup.obj")
    text = (tmp_path / "cup.obj").read_text()
    assert text.count("\nvt ") == 3 * mesh.num_triangles and text.count("\nv ") == mesh.num_vertices
    export(mesh, tmp_path / "cup.ply")
    header = (tmp_path / "cup.ply").read_bytes().split(b"end_header")[0]
    assert b"property list uchar float texcoord" in header
    with pytest.raises(ValueError, match="seam"):
        export(mesh, tmp_path / "cup.stl")


def test_to_trimesh_is_welded_unless_asked(tessellator):
    tess = tessellator.tessellate(load_scene(SCENES / "sphere.bpt"), eps=1e-2)
    assert tess.to_trimesh().is_watertight
    raw = tess.to_trimesh(weld=False)
    assert len(raw.vertices) == tess.num_vertices and not raw.is_watertight


# --------------------------------------------------------------------------- command line


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def test_cli_welds_mesh_formats_by_default(capsys, tmp_path):
    code, out, err = run(capsys, "tessellate", SCENES / "sphere.bpt", "--eps", "0.01", "-o", tmp_path / "s.ply")
    assert code == 0, err
    loaded = trimesh.load(tmp_path / "s.ply", process=False)
    assert loaded.is_watertight and loaded.volume > 0
    summary = dict(line.split(None, 1) for line in out.splitlines() if not line.startswith(("stage", "scene")))
    assert int(summary["vertices"]) == len(loaded.vertices)
    for fragment in ("welded boundary edges", "welded t junctions", "dropped triangles", "patch vertices"):
        assert fragment in out


def test_cli_no_weld_and_npz_keep_patch_vertices(capsys, tmp_path):
    code, out, err = run(capsys, "tessellate", SCENES / "sphere.bpt", "--eps", "0.01", "--no-weld",
                         "-o", tmp_path / "s.ply")
    assert code == 0, err
    assert not trimesh.load(tmp_path / "s.ply", process=False).is_watertight
    assert "welded" not in out
    code, _, err = run(capsys, "tessellate", SCENES / "sphere.bpt", "--eps", "0.01", "-o", tmp_path / "s.npz")
    assert code == 0, err
    assert "uv" in np.load(tmp_path / "s.npz")
    code, _, err = run(capsys, "tessellate", SCENES / "sphere.bpt", "--eps", "0.01", "--weld", "--uv", "seam",
                       "-o", tmp_path / "w.npz")
    assert code == 0, err
    assert "corner_uv" in np.load(tmp_path / "w.npz")


@pytest.mark.parametrize("arguments, fragment", [
    (["--uv", "seam", "-o", "x.stl"], "seam"),
    (["--uv", "seam", "--no-weld", "-o", "x.ply"], "seam"),
    (["--uv", "sideways", "-o", "x.ply"], "invalid choice"),
    (["--weld=yes", "-o", "x.ply"], "--weld"),
])
def test_cli_bad_weld_options_exit_2(capsys, tmp_path, arguments, fragment):
    arguments = [str(tmp_path / a) if a.startswith("x.") else a for a in arguments]
    code, _, err = run(capsys, "tessellate", SCENES / "sphere.bpt", "--eps", "0.01", *arguments)
    assert code == 2 and fragment in err and "Traceback" not in err
    assert not any(tmp_path.iterdir())


def test_cli_welded_output_must_fit_in_memory(capsys, tmp_path):
    code, _, err = run(capsys, "tessellate", SCENES / "teapot.bez", "--eps", "0.001", "--max-memory", "1M",
                       "-o", tmp_path / "t.ply")
    assert code == 2 and "--no-weld" in err
    code, _, err = run(capsys, "tessellate", SCENES / "teapot.bez", "--eps", "0.001", "--max-memory", "1M",
                       "--no-weld", "-q", "-o", tmp_path / "t.ply")
    assert code == 0, err
