"""Exports: PLY / OBJ / NPZ contents read back exactly, streaming, atomic writes."""
from __future__ import annotations

import importlib
import os

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from cltess.io.export import check_extension, export
from cltess.io.npz import load_npz
from cltess.io.obj import ObjWriter
from cltess.io.ply import PLY_FACE_DTYPE, PLY_VERTEX_DTYPE, PlyWriter
from cltess.io.writing import VertexBlock, atomic_write
from cltess.tessellation import Tessellation

export_module = importlib.import_module("cltess.io.writing")  # where atomic_write lives


def grid_tessellation(nu: int = 5, nv: int = 4, seed: int = 0) -> Tessellation:
    """A bumpy (nu x nv)-vertex grid: two triangles per cell, every vertex referenced.

    Values are awkward float32s (thirds, tiny, large, negative) so that text formats are tested
    for exact round trips."""
    rng = np.random.default_rng(seed)
    u, v = np.meshgrid(np.linspace(0, 1, nu, dtype=np.float32), np.linspace(0, 1, nv, dtype=np.float32))
    uv = np.stack([u.ravel(), v.ravel()], axis=1).astype(np.float32)
    count = len(uv)
    positions = np.column_stack([
        uv[:, 0] * np.float32(1 / 3) - 1e3,
        uv[:, 1] * np.float32(7e-5),
        rng.standard_normal(count) * 123.456,
    ]).astype(np.float32)
    normals = rng.standard_normal((count, 3))
    normals = (normals / np.linalg.norm(normals, axis=1, keepdims=True)).astype(np.float32)
    cells = [(j * nu + i, j * nu + i + 1, (j + 1) * nu + i, (j + 1) * nu + i + 1)
             for j in range(nv - 1) for i in range(nu - 1)]
    triangles = np.array([t for a, b, c, d in cells for t in ((a, b, c), (b, d, c))], dtype=np.uint32)
    patch_ids = (np.arange(count) // 7).astype(np.int32)
    object_ids = (np.arange(count) % 3 + 40).astype(np.int32)
    factors = np.arange(4 * (patch_ids.max() + 1), dtype=np.int32).reshape(-1, 4)
    return Tessellation(positions, normals, uv, patch_ids, object_ids, triangles, factors,
                        stage_ms={"factors": 0.25, "indices": 1.5},
                        stats={"patches": int(patch_ids.max() + 1), "culled": 0, "saturated": np.int64(1)})


def read_ply(path) -> tuple[list[str], np.ndarray, np.ndarray]:
    """Our own PLY reader for what PlyWriter writes: header lines, vertex and face records."""
    data = open(path, "rb").read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii").splitlines()
    num_vertices = int(next(line.split()[2] for line in header if line.startswith("element vertex")))
    num_faces = int(next(line.split()[2] for line in header if line.startswith("element face")))
    vertices = np.frombuffer(data, PLY_VERTEX_DTYPE, count=num_vertices, offset=end)
    face_offset = end + num_vertices * PLY_VERTEX_DTYPE.itemsize
    faces = np.frombuffer(data, PLY_FACE_DTYPE, count=num_faces, offset=face_offset)
    assert face_offset + num_faces * PLY_FACE_DTYPE.itemsize == len(data), "trailing bytes"
    return header, vertices, faces


def read_obj(path) -> dict[str, np.ndarray]:
    """Our own OBJ reader: v / vt / vn as float32 arrays, f as (T, 3, 3) 1-based indices."""
    rows: dict[str, list] = {"v": [], "vt": [], "vn": [], "f": []}
    for line in open(path):
        if line.startswith("#") or not line.strip():
            continue
        key, *values = line.split()
        if key == "f":
            rows["f"].append([[int(x) for x in corner.split("/")] for corner in values])
        else:
            rows[key].append([np.float32(x) for x in values])
    return {"f": np.array(rows["f"], dtype=np.int64).reshape(-1, 3, 3),
            **{k: np.array(rows[k], dtype=np.float32) for k in ("v", "vt", "vn")}}


def bits(array: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(array, dtype=np.float32).view(np.uint32)


@pytest.fixture
def tess() -> Tessellation:
    return grid_tessellation()


# --------------------------------------------------------------------------- PLY


def test_ply_body_is_exact(tess, tmp_path):
    path = export(tess, tmp_path / "mesh.ply")
    header, vertices, faces = read_ply(path)
    assert header[:2] == ["ply", "format binary_little_endian 1.0"]
    assert f"element vertex {tess.num_vertices}" in header
    assert f"element face {tess.num_triangles}" in header
    assert "property int patch" in header and "property int object" in header
    assert "property list uchar uint vertex_indices" in header
    np.testing.assert_array_equal(bits(np.column_stack([vertices["x"], vertices["y"], vertices["z"]])),
                                  bits(tess.positions))
    np.testing.assert_array_equal(bits(np.column_stack([vertices["nx"], vertices["ny"], vertices["nz"]])),
                                  bits(tess.normals))
    np.testing.assert_array_equal(bits(np.column_stack([vertices["u"], vertices["v"]])), bits(tess.uv))
    np.testing.assert_array_equal(vertices["patch"], tess.patch_ids)
    np.testing.assert_array_equal(vertices["object"], tess.object_ids)
    assert (faces["count"] == 3).all()
    np.testing.assert_array_equal(faces["vertex_indices"], tess.triangles)


def test_ply_reads_back_with_trimesh(tess, tmp_path):
    path = export(tess, tmp_path / "mesh.ply")
    mesh = trimesh.load(path, process=False)
    np.testing.assert_array_equal(mesh.vertices, tess.positions.astype(np.float64))
    np.testing.assert_array_equal(mesh.faces, tess.triangles)
    np.testing.assert_array_equal(mesh.vertex_normals, tess.normals.astype(np.float64))
    raw = mesh.metadata["_ply_raw"]["vertex"]["data"]
    np.testing.assert_array_equal(raw["patch"], tess.patch_ids)
    np.testing.assert_array_equal(raw["object"], tess.object_ids)
    np.testing.assert_array_equal(raw["u"], tess.uv[:, 0])
    np.testing.assert_array_equal(raw["v"], tess.uv[:, 1])


def test_ply_of_empty_mesh(tmp_path):
    empty = Tessellation(np.zeros((0, 3), np.float32), np.zeros((0, 3), np.float32), np.zeros((0, 2), np.float32),
                         np.zeros(0, np.int32), np.zeros(0, np.int32), np.zeros((0, 3), np.uint32),
                         np.zeros((2, 4), np.int32))
    header, vertices, faces = read_ply(export(empty, tmp_path / "empty.ply"))
    assert "element vertex 0" in header and "element face 0" in header
    assert len(vertices) == len(faces) == 0


@settings(max_examples=25, deadline=None)
@given(hnp.arrays(np.float32, st.tuples(st.integers(3, 40), st.just(8)),
                  elements=st.floats(width=32, allow_nan=False)))
def test_ply_float_fields_bitwise_for_any_values(tmp_path_factory, values):
    count = len(values)
    tess = Tessellation(values[:, :3], values[:, 3:6], values[:, 6:8], np.arange(count, dtype=np.int32),
                        -np.arange(count, dtype=np.int32), np.array([[0, 1, 2]] * count, np.uint32),
                        np.zeros((1, 4), np.int32))
    path = export(tess, tmp_path_factory.mktemp("ply") / "any.ply")
    _, vertices, _ = read_ply(path)
    names = ("x", "y", "z", "nx", "ny", "nz", "u", "v")
    np.testing.assert_array_equal(bits(np.column_stack([vertices[n] for n in names])), bits(values))


def test_ply_of_a_million_triangles(tmp_path):
    """A 1M-triangle PLY has exactly its header and records (its speed: bench/tessellate_30k.py)."""
    count = 1_000_000
    rng = np.random.default_rng(1)
    big = Tessellation(rng.random((count // 2, 3), np.float32), rng.random((count // 2, 3), np.float32),
                       rng.random((count // 2, 2), np.float32), np.zeros(count // 2, np.int32),
                       np.zeros(count // 2, np.int32), rng.integers(0, count // 2, (count, 3)).astype(np.uint32),
                       np.zeros((1, 4), np.int32))
    path = export(big, tmp_path / "big.ply")
    header_bytes = len(PlyWriter(path, count // 2, count).header())
    assert os.path.getsize(path) == header_bytes + (count // 2) * 40 + count * 13


# --------------------------------------------------------------------------- OBJ


def test_obj_round_trips_exactly(tess, tmp_path):
    path = export(tess, tmp_path / "mesh.obj")
    text = path.read_text()
    assert text.startswith("# written by cltess")
    obj = read_obj(path)
    np.testing.assert_array_equal(bits(obj["v"]), bits(tess.positions))
    np.testing.assert_array_equal(bits(obj["vt"]), bits(tess.uv))
    np.testing.assert_array_equal(bits(obj["vn"]), bits(tess.normals))
    one_based = tess.triangles.astype(np.int64) + 1
    np.testing.assert_array_equal(obj["f"], np.repeat(one_based[:, :, None], 3, axis=2))


def test_obj_reads_back_with_trimesh(tess, tmp_path):
    mesh = trimesh.load(export(tess, tmp_path / "mesh.obj"), process=False)
    np.testing.assert_array_equal(mesh.vertices.astype(np.float32), tess.positions)
    np.testing.assert_array_equal(mesh.faces, tess.triangles)
    np.testing.assert_allclose(mesh.vertex_normals, tess.normals, atol=1e-6)
    np.testing.assert_array_equal(mesh.visual.uv.astype(np.float32), tess.uv)


def test_obj_faces_must_follow_their_vertices(tess, tmp_path):
    target = tmp_path / "early.obj"
    with pytest.raises(ValueError, match="already written"):
        with ObjWriter(target, tess.num_vertices, tess.num_triangles) as writer:
            writer.write_faces(tess.triangles)
    assert list(tmp_path.iterdir()) == []


# --------------------------------------------------------------------------- NPZ


def test_npz_holds_every_array(tess, tmp_path):
    path = export(tess, tmp_path / "mesh.npz")
    with np.load(path) as data:
        for name in ("positions", "normals", "uv", "patch_ids", "object_ids", "triangles", "factors"):
            np.testing.assert_array_equal(data[name], getattr(tess, name))
            assert data[name].dtype == getattr(tess, name).dtype
    back = load_npz(path)
    np.testing.assert_array_equal(back.triangles, tess.triangles)
    assert back.stage_ms == tess.stage_ms
    assert back.stats == {"patches": 3, "culled": 0, "saturated": 1}


# --------------------------------------------------------------------------- streaming


def blocks_of(tess: Tessellation, size: int):
    """Vertex blocks and the faces whose vertices all lie in blocks so far (a batch's worth)."""
    for start in range(0, tess.num_vertices, size):
        stop = start + size
        block = VertexBlock(tess.positions[start:stop], tess.normals[start:stop], tess.uv[start:stop],
                            tess.patch_ids[start:stop], tess.object_ids[start:stop])
        top = tess.triangles.max(axis=1)
        faces = tess.triangles[(top >= start) & (top < stop)]
        yield block, faces


def faces_by_last_vertex(tess: Tessellation) -> Tessellation:
    """The same mesh with its triangles ordered by their largest vertex index."""
    order = np.argsort(tess.triangles.max(axis=1), kind="stable")
    return Tessellation(tess.positions, tess.normals, tess.uv, tess.patch_ids, tess.object_ids,
                        tess.triangles[order], tess.factors)


@pytest.mark.parametrize("block_size", [1, 3, 7, 1000])
def test_streamed_ply_batches_equal_one_shot_export(tess, tmp_path, block_size):
    tess = faces_by_last_vertex(tess)
    streamed = tmp_path / "streamed.ply"
    with PlyWriter(streamed, tess.num_vertices, tess.num_triangles) as writer:
        for block, faces in blocks_of(tess, block_size):  # faces arrive before the last vertices
            writer.write_vertices(block)
            writer.write_faces(faces)
    whole = export(tess, tmp_path / "whole.ply")
    assert streamed.read_bytes() == whole.read_bytes()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["streamed.ply", "whole.ply"]


@pytest.mark.parametrize("block_size", [1, 7, 1000])
def test_streamed_obj_batches_read_back(tess, tmp_path, block_size):
    tess = faces_by_last_vertex(tess)
    streamed = tmp_path / "streamed.obj"
    with ObjWriter(streamed, tess.num_vertices, tess.num_triangles) as writer:
        for block, faces in blocks_of(tess, block_size):
            writer.write_vertices(block)
            writer.write_faces(faces)
    assert streamed.read_bytes() == export(tess, tmp_path / "whole.obj").read_bytes()
    (tmp_path / "whole.obj").unlink()
    obj = read_obj(streamed)
    np.testing.assert_array_equal(bits(obj["v"]), bits(tess.positions))
    np.testing.assert_array_equal(bits(obj["vn"]), bits(tess.normals))
    np.testing.assert_array_equal(obj["f"][:, :, 0] - 1, tess.triangles)
    assert [p.name for p in tmp_path.iterdir()] == ["streamed.obj"]


def test_streaming_checks_declared_totals(tess, tmp_path):
    target = tmp_path / "short.ply"
    with pytest.raises(ValueError, match="declared"):
        with PlyWriter(target, tess.num_vertices + 1, tess.num_triangles) as writer:
            writer.write_vertices(tess)
            writer.write_faces(tess.triangles)
    with pytest.raises(ValueError, match="more faces"):
        with PlyWriter(target, tess.num_vertices, 1) as writer:
            writer.write_faces(tess.triangles)
    assert list(tmp_path.iterdir()) == []


# --------------------------------------------------------------------------- errors, atomicity


@pytest.mark.parametrize("name", ["mesh.3ds", "mesh", "mesh.ply.gz"])
def test_unknown_extension_writes_nothing(tess, tmp_path, name):
    with pytest.raises(ValueError) as error:
        export(tess, tmp_path / name)
    message = str(error.value)
    assert ".ply" in message and ".obj" in message and ".npz" in message
    assert (".stl" in message) if name.endswith(".stl") else True
    assert list(tmp_path.iterdir()) == []


def test_extension_is_case_insensitive(tess, tmp_path):
    assert check_extension("MESH.PLY") == ".ply"
    read_ply(export(tess, tmp_path / "MESH.PLY"))


def test_bad_triangle_index_writes_nothing(tess, tmp_path):
    tess.triangles[0, 0] = tess.num_vertices
    with pytest.raises(ValueError, match="outside"):
        export(tess, tmp_path / "bad.ply")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("extension", [".ply", ".obj", ".npz"])
@pytest.mark.parametrize("failure", [OSError("disk full"), KeyboardInterrupt()])
def test_failed_write_leaves_no_file_and_keeps_existing_target(tess, tmp_path, monkeypatch, extension, failure):
    fresh = tmp_path / f"fresh{extension}"
    existing = tmp_path / f"existing{extension}"
    existing.write_bytes(b"previous contents")

    def broken_fsync(fd):
        raise failure

    monkeypatch.setattr(export_module.os, "fsync", broken_fsync)  # after all bytes are written
    for target in (fresh, existing):
        with pytest.raises(type(failure)):
            export(tess, target)
    assert not fresh.exists()
    assert existing.read_bytes() == b"previous contents"
    assert sorted(p.name for p in tmp_path.iterdir()) == [existing.name]


@pytest.mark.parametrize("failure", [RuntimeError("boom"), KeyboardInterrupt()])
def test_failure_mid_stream_leaves_no_file(tess, tmp_path, monkeypatch, failure):
    existing = tmp_path / "mesh.ply"
    existing.write_bytes(b"old")
    original = PlyWriter.write_faces

    def fail_after_some_faces(self, triangles):
        original(self, triangles[:2])
        raise failure

    monkeypatch.setattr(PlyWriter, "write_faces", fail_after_some_faces)
    with pytest.raises(type(failure)):
        export(tess, existing)
    assert existing.read_bytes() == b"old"
    assert [p.name for p in tmp_path.iterdir()] == ["mesh.ply"]


def test_package_level_export_is_the_function(tess, tmp_path):
    """README: ``from cltess import load_scene, Tessellator, export``; the submodule
    cltess.export must not shadow the function once it has been imported."""
    import cltess

    importlib.import_module("cltess.export")
    from cltess import export as exported

    assert exported is export
    exported(tess, tmp_path / "mesh.ply")


def test_atomic_write_replaces_only_on_success(tmp_path):
    target = tmp_path / "file.txt"
    with atomic_write(target, "w") as handle:
        handle.write("one")
    assert target.read_text() == "one"
    umask = os.umask(0)
    os.umask(umask)
    assert target.stat().st_mode & 0o777 == 0o666 & ~umask
    with pytest.raises(ZeroDivisionError):
        with atomic_write(target, "w") as handle:
            handle.write("two")
            1 / 0
    assert target.read_text() == "one"
    assert [p.name for p in tmp_path.iterdir()] == ["file.txt"]


def test_atomic_write_into_missing_folder_fails_cleanly(tmp_path):
    with pytest.raises(FileNotFoundError):
        with atomic_write(tmp_path / "missing" / "file.ply") as handle:
            handle.write(b"x")
    assert list(tmp_path.iterdir()) == []
