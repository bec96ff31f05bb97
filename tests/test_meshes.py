"""Triangle meshes as PN triangles: reading them (cltess.io.meshes, cltess.io), their checks and
repairs (cltess.scene.TriangleMesh), adjacency and sharp edges (cltess.adjacency), scenes
mixing Bézier patches and meshes, and the command line on a mesh."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import trimesh

from cltess import reference
from cltess.adjacency import mesh_edge_groups, pn_edge_normals
from cltess.cli import main
from cltess.io import load_scene
from cltess.pipeline import PN
from cltess.scene import Scene, SceneError, TriangleMesh, vertex_normals
from support import flat_shaded, icosphere, split_some_vertices, torus, weld_exact

SCENES = Path(__file__).resolve().parent.parent / "scenes"


def write_obj(path: Path, vertices, faces, normals=None) -> Path:
    lines = [f"v {x!r} {y!r} {z!r}" for x, y, z in np.asarray(vertices, float).tolist()]
    if normals is not None:
        lines += [f"vn {x!r} {y!r} {z!r}" for x, y, z in np.asarray(normals, float).tolist()]
        lines += [f"f {a + 1}//{a + 1} {b + 1}//{b + 1} {c + 1}//{c + 1}" for a, b, c in np.asarray(faces).tolist()]
    else:
        lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in np.asarray(faces).tolist()]
    path.write_text("\n".join(lines) + "\n")
    return path


# --- reading ----------------------------------------------------------------------------------

def test_obj_normals_are_used_as_given(tmp_path, tessellator):
    """Normals from the file (here tilted away from anything trimesh would compute) reach the
    PN patches unchanged: the tessellation's corner normals are exactly them."""
    mesh = icosphere(1)
    tilted = mesh.vertices + np.array([0.3, 0.0, 0.0])
    tilted /= np.linalg.norm(tilted, axis=1, keepdims=True)
    scene = load_scene(write_obj(tmp_path / "ball.obj", mesh.vertices, mesh.faces, tilted))
    (read,) = scene.meshes
    assert read.normals_from_file and read.repaired_normals == 0
    order = np.argsort(np.lexsort(read.vertices.T))  # trimesh may renumber vertices
    expected = tilted[np.argsort(np.lexsort(mesh.vertices.T))]
    assert np.allclose(read.normals[order], expected, atol=1e-12)
    tess = tessellator.tessellate(scene, eps=1e-2)
    corners = tess.uv.max(axis=1) == 1  # (1, 0) and (0, 1): corners P1, P2
    at = read.faces[tess.patch_ids[corners], np.where(tess.uv[corners, 0] == 1, 0, 1)]
    assert np.allclose(tess.normals[corners], read.normals[at], atol=1e-6)


def test_meshes_without_normals_get_angle_weighted_ones(tmp_path):
    mesh = torus()
    scene = load_scene(write_obj(tmp_path / "torus.obj", mesh.vertices, mesh.faces))
    (read,) = scene.meshes
    assert not read.normals_from_file
    assert np.allclose(read.normals, vertex_normals(read.vertices, read.faces))
    # The same as trimesh's weighting on a mesh without split vertices.
    expected = trimesh.geometry.weighted_vertex_normals(len(read.vertices), read.faces,
                                                        trimesh.Trimesh(read.vertices, read.faces).face_normals,
                                                        trimesh.triangles.angles(read.vertices[read.faces]),
                                                        use_loop=True)
    assert np.allclose(read.normals, expected, atol=1e-9)


@pytest.mark.parametrize("ext, has_normals", [(".ply", True), (".stl", False), (".off", False), (".glb", True)])
def test_every_mesh_format_reads_and_tessellates_closed(tmp_path, tessellator, ext, has_normals):
    """STL stores a triangle soup: welding by position still closes it."""
    mesh = icosphere(2)
    source = trimesh.Trimesh(mesh.vertices, mesh.faces, vertex_normals=mesh.vertex_normals, process=False)
    path = tmp_path / f"ball{ext}"
    source.export(path)
    scene = load_scene(path)
    (read,) = scene.meshes
    assert read.normals_from_file == has_normals and read.num_faces == len(mesh.faces)
    tess = tessellator.tessellate(scene, eps=3e-3)
    assert tess.stats["sharp_edges"] == 0 and tess.stats["boundary_edges"] == 0
    assert weld_exact(tess.positions, tess.triangles).is_watertight


def test_gltf_nodes_are_placed_by_their_transforms(tmp_path):
    mesh = icosphere(1)
    part = trimesh.Trimesh(mesh.vertices, mesh.faces, vertex_normals=mesh.vertex_normals, process=False)
    gltf = trimesh.Scene()
    matrix = np.diag([2.0, 1.0, 1.0, 1.0])
    matrix[:3, 3] = (5, 0, 0)
    gltf.add_geometry(part, transform=matrix)
    gltf.add_geometry(part)
    gltf.export(tmp_path / "two.glb")
    (read,) = load_scene(tmp_path / "two.glb").meshes
    assert read.num_faces == 2 * len(mesh.faces) and read.normals_from_file
    moved = read.vertices[:, 0] > 2.5
    assert moved.sum() == len(mesh.vertices)
    # A normal of the stretched sphere: the inverse transpose, (x / 4, y, z) direction at (2x + 5, y, z).
    p = (read.vertices[moved] - [5, 0, 0]) / [2, 1, 1]
    expected = p * [0.5, 1, 1]
    expected /= np.linalg.norm(expected, axis=1, keepdims=True)
    assert np.allclose(read.normals[moved], expected, atol=1e-5)


def test_json_scene_mixes_bezier_objects_and_meshes(tmp_path, tessellator):
    """Each object keeps its id; patch ids number Bézier patches first, then mesh faces."""
    mesh = icosphere(1)
    write_obj(tmp_path / "ball.obj", mesh.vertices, mesh.faces)
    (tmp_path / "teapot.bez").write_text((SCENES / "teapot.bez").read_text())
    doc = {"objects": [
        {"file": "ball.obj", "object_id": 7, "transform": [[1, 0, 0, 4], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]},
        {"file": "teapot.bez", "object_id": 3},
        {"file": "ball.obj", "object_id": 9}]}
    (tmp_path / "mix.json").write_text(json.dumps(doc))
    scene = load_scene(tmp_path / "mix.json")
    assert scene.num_bezier == 32 and scene.num_triangles == 160 and scene.num_patches == 192
    assert [m.object_id for m in scene.meshes] == [7, 9]
    assert scene.mesh_first_patch(0) == 32 and scene.mesh_first_patch(1) == 112
    assert np.allclose(scene.meshes[0].vertices, scene.meshes[1].vertices + [4, 0, 0])
    tess = tessellator.tessellate(scene, eps=1e-2)
    owner = {3: (0, 32), 7: (32, 112), 9: (112, 192)}
    for object_id, (first, last) in owner.items():
        mine = tess.object_ids == object_id
        assert mine.any() and ((tess.patch_ids[mine] >= first) & (tess.patch_ids[mine] < last)).all()
    assert tess.stats["pn_triangles"] == 160 and tess.factors.shape == (192, 4)
    assert (tess.factors[32:, 3] == 0).all() and (tess.factors[32:, :3] > 0).all()


def test_mixed_scene_equals_its_parts_and_batches_concatenate(tessellator):
    """The Bézier part and the mesh part of one scene come out as they do alone; batches that
    cut across the two kinds concatenate to the single pass."""
    teapot = load_scene(SCENES / "teapot.bez")
    ball = TriangleMesh(icosphere(2).vertices, icosphere(2).faces, object_id=5, name="ball")
    mixed = Scene(teapot.patches, teapot.object_ids, meshes=[ball], name="mixed")
    whole = tessellator.tessellate(mixed, eps=5e-3)
    alone = [tessellator.tessellate(teapot, eps=5e-3), tessellator.tessellate(Scene.from_meshes([ball]), eps=5e-3)]
    split = alone[0].num_vertices
    assert np.array_equal(whole.positions, np.concatenate([a.positions for a in alone]))
    assert np.array_equal(whole.triangles, np.concatenate([alone[0].triangles, alone[1].triangles + split]))
    assert np.array_equal(whole.patch_ids[split:], alone[1].patch_ids + teapot.num_patches)
    assert np.array_equal(whole.factors, np.concatenate([a.factors for a in alone]))
    plan, batches = tessellator.tessellate_in_batches(mixed, max_output_bytes=whole.num_vertices * 6, eps=5e-3)
    batches = list(batches)
    assert len(batches) >= 4 and any(b.stats["first_patch"] < 32 < b.stats["last_patch"] for b in batches)
    for name in ("positions", "normals", "uv", "patch_ids", "object_ids", "triangles", "factors"):
        assert np.array_equal(np.concatenate([getattr(b, name) for b in batches]), getattr(whole, name)), name


def test_all_factors_one_give_back_the_input_triangles(tessellator):
    """At a tolerance no triangle needs refining, each comes back as itself: its corners, in
    order, with (u, v) = (1, 0), (0, 1), (0, 0) and its vertex normals."""
    mesh = torus()
    scene = Scene.from_trimesh(mesh, name="torus")
    tess = tessellator.tessellate(scene, eps=10.0)
    assert (tess.factors[:, :3] == 1).all() and tess.num_triangles == len(mesh.faces)
    (read,) = scene.meshes
    assert np.array_equal(tess.positions, read.vertices[read.faces].reshape(-1, 3).astype(np.float32))
    assert np.array_equal(tess.triangles, np.arange(3 * len(mesh.faces)).reshape(-1, 3))
    assert np.array_equal(tess.uv, np.tile([[1, 0], [0, 1], [0, 0]], (len(mesh.faces), 1)).astype(np.float32))
    assert np.allclose(tess.normals, read.normals[read.faces].reshape(-1, 3), atol=1e-6)
    assert np.array_equal(tess.patch_ids, np.repeat(np.arange(len(mesh.faces)), 3))


def test_counts_agree_with_emitted_data(tessellator, rng):
    mesh = split_some_vertices(rng, torus(), 0.2)
    tess = tessellator.tessellate(Scene.from_trimesh(mesh), eps=1e-3)
    vertex_counts, index_counts = reference.counts(tess.factors, kind="pn")
    assert np.array_equal(np.bincount(tess.patch_ids, minlength=len(mesh.faces)), vertex_counts)
    owner = tess.patch_ids[tess.triangles]
    assert (owner == owner[:, :1]).all()
    assert (np.bincount(owner[:, 0], minlength=len(mesh.faces)) * 3 == index_counts).all()
    assert np.isfinite(tess.positions).all() and np.isfinite(tess.normals).all()


# --- adjacency and sharp edges ------------------------------------------------------------------

def corner_arrays(mesh: TriangleMesh):
    return mesh.vertices[mesh.faces].astype(np.float32), mesh.normals[mesh.faces].astype(np.float32)


def test_mesh_edge_groups_count_open_shared_and_nonmanifold_edges(tessellator):
    # Three triangles on one edge (0, 1), one more beside: 1 non-manifold, 1 shared, open rest.
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [1, 1, 0]], float)
    faces = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4], [1, 5, 2]])
    normals = vertices + [0.2, 0.3, 0.4]  # curved patches, one normal per vertex: no sharp edge
    mesh = TriangleMesh(vertices, faces, normals)
    groups, sharp = mesh_edge_groups(*corner_arrays(mesh))
    assert (groups.nonmanifold, groups.shared, groups.boundary) == (1, 1, 7)
    assert not sharp.any()
    g = groups.group_of
    assert g[0] == g[3] == g[6] and groups.group_sizes[g[0]] == 3
    assert groups.flipped[3] and not groups.flipped[0]
    # Tessellated: the three triangles on the non-manifold edge sample it at one factor, at
    # bitwise the same points.
    tess = tessellator.tessellate(Scene.from_meshes([mesh]), eps=1e-3)
    assert tess.stats["nonmanifold_edges"] == 1 and tess.stats["boundary_edges"] == 7
    f = tess.factors
    assert f[0, 0] == f[1, 0] == f[2, 0] > 1
    starts = np.concatenate([[0], np.cumsum(np.bincount(tess.patch_ids))])
    edge = [tess.positions[starts[t]:starts[t] + f[0, 0] + 1] for t in range(3)]
    assert np.array_equal(edge[0], edge[1][::-1]) and np.array_equal(edge[0], edge[2])


def test_split_vertices_weld_and_only_differing_normals_are_sharp():
    mesh = torus()
    soup = flat_shaded(mesh)
    faces_normals = TriangleMesh(soup.vertices, soup.faces, soup.vertex_normals)  # per-face normals
    corners, normals = corner_arrays(faces_normals)
    groups, sharp = mesh_edge_groups(corners, normals)
    assert groups.shared == len(mesh.edges_unique) and groups.boundary == 0
    # Sharp exactly where the two faces' normals differ (the torus's quads are two coplanar halves).
    first = groups.members[groups.group_start[:-1]][groups.group_of]
    other = groups.members[groups.group_start[1:] - 1][groups.group_of]
    expected = (normals[first // 3, 0] != normals[other // 3, 0]).any(axis=1)
    assert np.array_equal(sharp, expected) and 0.4 < sharp.mean() < 0.9
    smooth = TriangleMesh(soup.vertices, soup.faces)  # normals computed over welded positions
    assert not mesh_edge_groups(*corner_arrays(smooth))[1].any()


def test_sharp_edge_normals_by_mode(rng):
    mesh = split_some_vertices(rng, icosphere(1), 0.4)
    read = TriangleMesh(mesh.vertices, mesh.faces, mesh.vertex_normals)
    corners, normals = corner_arrays(read)
    groups, sharp = mesh_edge_groups(corners, normals)
    assert 0 < sharp.sum() < len(sharp)
    keep = pn_edge_normals(normals, groups, sharp, "keep").reshape(-1, 2, 3)
    straight = pn_edge_normals(normals, groups, sharp, "straight").reshape(-1, 2, 3)
    average = pn_edge_normals(normals, groups, sharp, "average").reshape(-1, 2, 3)
    assert np.array_equal(keep[~sharp], straight[~sharp]) and np.array_equal(keep[~sharp], average[~sharp])
    assert (straight[sharp] == 0).all()
    assert np.allclose(np.linalg.norm(average[sharp], axis=2), 1, atol=1e-6)
    # Both sides of each sharp edge hold the same end normals, in their own direction.
    for g in np.unique(groups.group_of[sharp]):
        a, b = groups.members[groups.group_start[g]:groups.group_start[g + 1]]
        ends_b = average[b] if groups.flipped[a] == groups.flipped[b] else average[b][::-1]
        assert np.array_equal(average[a], ends_b)
    with pytest.raises(ValueError, match="sharp_edges"):
        pn_edge_normals(normals, groups, sharp, "round")


# --- bad input ------------------------------------------------------------------------------

@pytest.mark.parametrize("text, fragments", [
    ("v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n", ["bad.obj", "vertex 1", "not finite"]),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\n", ["bad.obj", "no faces"]),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n", ["bad.obj", "cannot read it as a mesh"]),
    ("# nothing\n", ["bad.obj", "no faces"]),
])
def test_bad_obj_files_are_clear_errors(tmp_path, text, fragments):
    path = tmp_path / "bad.obj"
    path.write_text(text)
    with pytest.raises(SceneError) as error:
        load_scene(path)
    for fragment in fragments:
        assert fragment in str(error.value)


def test_face_indices_past_the_vertices_are_named(tmp_path):
    header = ("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
              "element face 2\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n")
    for face, fragment in (("3 0 1 5", "face 1: vertex index 5 out of range 0..2"),
                           ("3 0 -1 2", "face 1: vertex index -1 out of range")):
        (tmp_path / "bad.ply").write_text(header + "3 0 1 2\n" + face + "\n")
        with pytest.raises(SceneError, match=fragment):
            load_scene(tmp_path / "bad.ply")
    with pytest.raises(SceneError, match="no faces"):
        TriangleMesh(np.zeros((3, 3)), np.zeros((0, 3), int), name="empty")
    with pytest.raises(SceneError, match="missing.obj: file not found"):
        load_scene(tmp_path / "missing.obj")


def test_zero_and_nan_normals_are_repaired_and_counted(tmp_path, tessellator):
    mesh = icosphere(1)
    normals = np.array(mesh.vertex_normals)
    normals[[0, 5]] = 0.0
    normals[7] = np.nan
    normals[9] *= 3.0  # not unit: scaled, not counted
    path = tmp_path / "ball.ply"
    trimesh.Trimesh(mesh.vertices, mesh.faces, vertex_normals=normals, process=False).export(path)
    (read,) = load_scene(path).meshes
    assert read.repaired_normals == 3
    assert np.allclose(np.linalg.norm(read.normals, axis=1), 1)
    computed = vertex_normals(read.vertices, read.faces)
    assert np.allclose(read.normals[[0, 5, 7]], computed[[0, 5, 7]])
    tess = tessellator.tessellate(Scene.from_meshes([read]), eps=1e-3)
    assert tess.stats["repaired_normals"] == 3 and np.isfinite(tess.normals).all()
    assert weld_exact(tess.positions, tess.triangles).is_watertight


def test_folded_triangles_are_dropped_and_the_surface_stays_closed(tessellator):
    """Two corners moved together: the two triangles on that edge fold to zero area, their other
    two edges coinciding.  They get no output (counted), their neighbours meet directly."""
    mesh = icosphere(2)
    vertices = np.array(mesh.vertices)
    a, b = mesh.edges_unique[0]
    vertices[b] = vertices[a]
    scene = Scene.from_meshes([TriangleMesh(vertices, mesh.faces, name="collapsed")])
    tess = tessellator.tessellate(scene, eps=1e-3)
    assert tess.stats["degenerate_triangles"] == 2 and tess.stats["folded_triangles"] == 2
    assert tess.stats["nonmanifold_edges"] == 0 and tess.stats["boundary_edges"] == 0
    folded = np.flatnonzero((mesh.faces == a).any(1) & (mesh.faces == b).any(1))
    assert (tess.factors[folded] == 0).all() and not np.isin(tess.patch_ids, folded).any()
    assert np.isfinite(tess.positions).all() and np.isfinite(tess.normals).all()
    assert weld_exact(tess.positions, tess.triangles).is_watertight


def test_sliver_triangles_are_kept_and_close_the_surface(tessellator):
    """A zero-area sliver (a, m, b) with m the midpoint of edge a-b, its neighbour split at m:
    its PN patch is what joins the two sides, so it stays."""
    mesh = icosphere(2)
    faces = [list(f) for f in mesh.faces]
    a, b = (int(x) for x in mesh.edges_unique[0])
    (other,) = [k for k, f in enumerate(faces) if any(f[i] == b and f[(i + 1) % 3] == a for i in range(3))]
    d = next(v for v in faces[other] if v not in (a, b))
    m = len(mesh.vertices)
    vertices = np.vstack([mesh.vertices, (mesh.vertices[a] + mesh.vertices[b]) / 2])
    faces[other] = [b, m, d]
    faces += [[m, a, d], [b, a, m]]
    scene = Scene.from_meshes([TriangleMesh(vertices, np.array(faces), name="sliver")])
    tess = tessellator.tessellate(scene, eps=1e-3)
    assert tess.stats["degenerate_triangles"] == 1 and tess.stats["folded_triangles"] == 0
    assert (tess.patch_ids == len(faces) - 1).any()
    assert np.isfinite(tess.positions).all() and np.isfinite(tess.normals).all()
    assert weld_exact(tess.positions, tess.triangles).is_watertight


def test_non_affine_transforms_of_meshes_are_refused(tmp_path):
    mesh = icosphere(0)
    write_obj(tmp_path / "ball.obj", mesh.vertices, mesh.faces)
    doc = {"objects": [{"file": "ball.obj", "transform": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 1, 1]]}]}
    (tmp_path / "s.json").write_text(json.dumps(doc))
    with pytest.raises(SceneError, match=r"objects\[0\]\.transform.*affine"):
        load_scene(tmp_path / "s.json")


def test_pipeline_refuses_an_unknown_sharp_edge_choice(tessellator):
    with pytest.raises(ValueError, match="sharp_edges"):
        tessellator.tessellate(Scene.from_trimesh(icosphere(0)), eps=1e-2, sharp_edges="round")


# --- the command line ------------------------------------------------------------------------

def test_cli_tessellates_an_obj_and_reports_its_edges(capsys, tmp_path):
    mesh = torus()
    path = write_obj(tmp_path / "torus.obj", mesh.vertices, mesh.faces)
    out_path = tmp_path / "torus.ply"
    code = main(["tessellate", str(path), "--eps", "1e-3", "-o", str(out_path)])
    out, err = capsys.readouterr()
    assert code == 0, err
    summary = dict(line.split(None, 1) if "  " not in line else line.split("  ", 1) for line in out.splitlines())
    summary = {k.strip(): v.strip() for k, v in summary.items()}
    assert summary["sharp edges"] == "0" and summary["boundary edges"] == "0"
    assert summary["nonmanifold edges"] == "0" and summary["pn triangles"] == str(len(mesh.faces))
    written = trimesh.load(out_path, process=False)
    assert len(written.faces) == int(summary["triangles"])
    assert weld_exact(np.asarray(written.vertices, np.float32), written.faces).is_watertight


def test_cli_sharp_edges_option(capsys, tmp_path, rng):
    split = split_some_vertices(rng, icosphere(1), 0.4)
    path = tmp_path / "split.ply"
    split.export(path)
    code = main(["tessellate", str(path), "--eps", "1e-3", "--sharp-edges", "keep", "-q", "-o", str(tmp_path / "o.ply")])
    out, err = capsys.readouterr()
    assert code == 0 and out == ""
    assert "warning" in err and "sharp mesh edges" in err and "may crack" in err
    code = main(["tessellate", str(path), "--eps", "1e-3", "--sharp-edges", "round", "-o", str(tmp_path / "o.ply")])
    assert code == 2 and "invalid choice" in capsys.readouterr().err
