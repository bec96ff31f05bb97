"""Write a :class:`~cltess.tessellation.Tessellation` (per-patch vertices) or a
:class:`~cltess.weld.WeldedMesh` (one indexed mesh) to disk: PLY, OBJ, STL, GLB or NPZ.

Every file is written atomically (:func:`atomic_write`): into a temporary file next to the
target, fsync'd, then renamed onto the target; on any failure, Ctrl-C included, the
temporary is removed and an existing target is left untouched.

PLY and OBJ are written by streaming writers (:class:`PlyWriter`, :class:`ObjWriter`) that
take the totals up front (the PLY header needs them) and then any number of vertex and face
blocks, so a caller can write a mesh batch by batch without holding it whole::

    with PlyWriter("out.ply", num_vertices=V, num_faces=T) as writer:
        for batch in batches:
            writer.write_vertices(batch)          # anything with .positions, .normals, ...
            writer.write_faces(batch.triangles)   # (k, 3) global, 0-based vertex indices

:func:`export` does exactly that with one block of each.
"""
from __future__ import annotations

import contextlib
import json
import os
import shutil
import tempfile
from pathlib import Path
from typing import IO, Iterator, NamedTuple

import numpy as np

from cltess.tessellation import Tessellation

__all__ = [
    "MESH_FORMATS",
    "SUPPORTED_EXTENSIONS",
    "ObjWriter",
    "PlyWriter",
    "VertexBlock",
    "atomic_write",
    "check_extension",
    "export",
    "load_npz",
    "to_trimesh",
    "write_welded_obj",
    "write_welded_ply",
    "write_npz",
]

#: One PLY vertex record: 8 little-endian float32 then 2 int32 (40 bytes, no padding).
PLY_VERTEX_DTYPE = np.dtype(
    [("x", "<f4"), ("y", "<f4"), ("z", "<f4"),
     ("nx", "<f4"), ("ny", "<f4"), ("nz", "<f4"),
     ("u", "<f4"), ("v", "<f4"),
     ("patch", "<i4"), ("object", "<i4")]
)
#: One PLY face record: ``list uchar uint`` with a constant count of 3 (13 bytes, no padding).
PLY_FACE_DTYPE = np.dtype([("count", "u1"), ("vertex_indices", "<u4", (3,))])

#: Rows per formatted OBJ text block: bounds the memory of the text built at once.
OBJ_BLOCK_ROWS = 1 << 17


class VertexBlock(NamedTuple):
    """A run of vertices for the streaming writers (the vertex fields of a Tessellation).

    positions (k, 3), normals (k, 3), uv (k, 2): float32; patch_ids (k,), object_ids (k,): int32.
    """

    positions: np.ndarray
    normals: np.ndarray
    uv: np.ndarray
    patch_ids: np.ndarray
    object_ids: np.ndarray


# --------------------------------------------------------------------------- atomic writes


def _current_umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


@contextlib.contextmanager
def atomic_write(path: str | os.PathLike, mode: str = "wb", **open_kwargs) -> Iterator[IO]:
    """Open a temporary file next to ``path``; on success fsync it and rename it onto ``path``.

    If the body raises anything (KeyboardInterrupt included) the temporary file is removed,
    the exception propagates, and whatever was at ``path`` before is unchanged.
    ``mode`` is ``"wb"`` or ``"w"`` (``open_kwargs`` such as ``encoding`` go to ``open``).
    """
    if "w" not in mode:
        raise ValueError(f"atomic_write needs a write mode, got {mode!r}")
    target = Path(path)
    try:
        fd, temp_name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
    except OSError as error:
        raise _naming(error, target) from error
    handle = None
    try:
        if hasattr(os, "fchmod"):  # mkstemp makes it 0600; give it what a plain open() would
            os.fchmod(fd, 0o666 & ~_current_umask())
        handle = open(fd, mode, **open_kwargs)
        with handle:
            yield handle
            handle.flush()
            os.fsync(handle.fileno())
        os.replace(temp_name, target)
    except BaseException as error:
        if handle is None:
            os.close(fd)  # open() never took the descriptor over
        with contextlib.suppress(FileNotFoundError):
            os.unlink(temp_name)
        if isinstance(error, OSError) and error.filename in (None, temp_name):
            raise _naming(error, target) from error
        raise


def _naming(error: OSError, target: Path) -> OSError:
    """The same error (class, errno) naming the output file rather than the temporary one or
    none (a full disk, a read-only file system)."""
    return type(error)(error.errno, f"cannot write: {error.strerror or error}", os.fspath(target))


# --------------------------------------------------------------------------- checks


def _as_array(values, dtype, shape_tail: tuple, name: str) -> np.ndarray:
    array = np.asarray(values)
    if array.ndim != 1 + len(shape_tail) or array.shape[1:] != shape_tail:
        raise ValueError(f"{name} must have shape (n, {', '.join(map(str, shape_tail))})"
                         if shape_tail else f"{name} must have shape (n,)")
    return np.ascontiguousarray(array, dtype=dtype)


def _vertex_arrays(block) -> VertexBlock:
    """The five vertex arrays of ``block`` (any object with those attributes), checked."""
    arrays = VertexBlock(
        _as_array(block.positions, np.float32, (3,), "positions"),
        _as_array(block.normals, np.float32, (3,), "normals"),
        _as_array(block.uv, np.float32, (2,), "uv"),
        _as_array(block.patch_ids, np.int32, (), "patch_ids"),
        _as_array(block.object_ids, np.int32, (), "object_ids"),
    )
    lengths = {len(a) for a in arrays}
    if len(lengths) != 1:
        raise ValueError(f"vertex arrays differ in length: {[len(a) for a in arrays]}")
    return arrays


def _face_array(triangles, num_vertices: int) -> np.ndarray:
    """(k, 3) uint32 triangles, checked against the declared vertex total."""
    triangles = np.asarray(triangles)
    if triangles.ndim != 2 or triangles.shape[1] != 3:
        raise ValueError(f"triangles must have shape (n, 3), got {triangles.shape}")
    if len(triangles):
        low, high = int(triangles.min()), int(triangles.max())
        if low < 0 or high >= num_vertices:
            raise ValueError(f"triangle indices span [{low}, {high}], outside [0, {num_vertices})")
    return np.ascontiguousarray(triangles, dtype=np.uint32)


class _StreamingWriter:
    """Shared bookkeeping: declared totals, counts written so far, the atomic target file."""

    def __init__(self, path: str | os.PathLike, num_vertices: int, num_faces: int):
        if num_vertices < 0 or num_faces < 0:
            raise ValueError("vertex and face totals must be non-negative")
        self.path = Path(path)
        self.num_vertices = int(num_vertices)
        self.num_faces = int(num_faces)
        self.vertices_written = 0
        self.faces_written = 0
        self._atomic = atomic_write(self.path, "wb")
        self._file: IO | None = None
        self._face_spool: IO | None = None

    def __enter__(self):
        self._file = self._atomic.__enter__()
        try:
            self._write_header()
        except BaseException as error:
            self._abort(error)
            raise
        return self

    def __exit__(self, exc_type, exc, tb) -> bool:
        if exc_type is None:
            try:
                self._finish()
            except BaseException as error:
                self._abort(error)
                raise
            self._atomic.__exit__(None, None, None)
        else:
            self._abort(exc)
        return False

    def _abort(self, error: BaseException) -> None:
        """Remove the temporary files; the caller re-raises ``error``."""
        self._close_spool()
        self._atomic.__exit__(type(error), error, error.__traceback__)

    def _put_faces(self, data: bytes) -> None:
        """Face records go after every vertex: straight into the file once all vertices are
        written, else to an anonymous spool appended at the end.  So the file does not depend
        on how the mesh was cut into blocks."""
        if self.vertices_written == self.num_vertices and self._face_spool is None:
            self._file.write(data)
            return
        if self._face_spool is None:
            self._face_spool = tempfile.TemporaryFile(dir=self.path.parent)
        self._face_spool.write(data)

    def _close_spool(self) -> None:
        if self._face_spool is not None:
            self._face_spool.close()
            self._face_spool = None

    def _take_vertices(self, block) -> VertexBlock:
        arrays = _vertex_arrays(block)
        if self.vertices_written + len(arrays.positions) > self.num_vertices:
            raise ValueError(f"more vertices than the {self.num_vertices} declared")
        self.vertices_written += len(arrays.positions)
        return arrays

    def _take_faces(self, triangles) -> np.ndarray:
        faces = _face_array(triangles, self.num_vertices)
        if self.faces_written + len(faces) > self.num_faces:
            raise ValueError(f"more faces than the {self.num_faces} declared")
        self.faces_written += len(faces)
        return faces

    def _check_totals(self) -> None:
        if (self.vertices_written, self.faces_written) != (self.num_vertices, self.num_faces):
            raise ValueError(
                f"{self.path}: wrote {self.vertices_written} vertices and {self.faces_written} faces, "
                f"declared {self.num_vertices} and {self.num_faces}"
            )

    def _write_header(self) -> None:
        raise NotImplementedError

    def _finish(self) -> None:
        self._check_totals()
        if self._face_spool is not None:
            self._face_spool.seek(0)
            shutil.copyfileobj(self._face_spool, self._file, 1 << 24)
            self._close_spool()


# --------------------------------------------------------------------------- PLY


def ply_header(num_vertices: int, num_faces: int) -> bytes:
    """The header of a cltess PLY file with these totals."""
    lines = [
        "ply",
        "format binary_little_endian 1.0",
        "comment written by cltess",
        f"element vertex {num_vertices}",
        *(f"property float {name}" for name in ("x", "y", "z", "nx", "ny", "nz", "u", "v")),
        "property int patch",
        "property int object",
        f"element face {num_faces}",
        "property list uchar uint vertex_indices",
        "end_header",
    ]
    return ("\n".join(lines) + "\n").encode("ascii")


def ply_vertex_records(block) -> np.ndarray:
    """The PLY vertex records (PLY_VERTEX_DTYPE) of a block with positions, normals, uv,
    patch_ids, object_ids."""
    arrays = _vertex_arrays(block)
    records = np.empty(len(arrays.positions), PLY_VERTEX_DTYPE)
    for column, name in enumerate("xyz"):
        records[name] = arrays.positions[:, column]
    for column, name in enumerate(("nx", "ny", "nz")):
        records[name] = arrays.normals[:, column]
    records["u"], records["v"] = arrays.uv[:, 0], arrays.uv[:, 1]
    records["patch"], records["object"] = arrays.patch_ids, arrays.object_ids
    return records


def ply_face_records(triangles) -> np.ndarray:
    """The PLY face records (PLY_FACE_DTYPE) of (k, 3) vertex indices."""
    faces = np.ascontiguousarray(triangles, dtype=np.uint32)
    records = np.empty(len(faces), PLY_FACE_DTYPE)
    records["count"] = 3
    records["vertex_indices"] = faces
    return records


class PlyWriter(_StreamingWriter):
    """Binary little-endian PLY, written in blocks.

    Vertex element: ``float x y z nx ny nz u v``, ``int patch object``.
    Face element: ``list uchar uint vertex_indices``.
    Face blocks that arrive before the last vertex block are spooled to an anonymous
    temporary file and appended after the vertices when the writer closes.
    """

    def header(self) -> bytes:
        return ply_header(self.num_vertices, self.num_faces)

    def _write_header(self) -> None:
        self._file.write(self.header())

    def write_vertices(self, block) -> None:
        """Append vertices: ``block`` has positions (k,3), normals (k,3), uv (k,2), patch_ids, object_ids (k,)."""
        self._file.write(ply_vertex_records(self._take_vertices(block)).view(np.uint8))

    def write_faces(self, triangles) -> None:
        """Append faces: (k, 3) global, 0-based vertex indices."""
        self._put_faces(ply_face_records(self._take_faces(triangles)).tobytes())


# --------------------------------------------------------------------------- OBJ


def _format_rows(template: str, values: np.ndarray) -> str:
    """Format each row of ``values`` (n, k) with ``template`` (k fields), one string per block."""
    flat = values.ravel().tolist()
    return (template * len(values)) % tuple(flat)


class ObjWriter(_StreamingWriter):
    """Wavefront OBJ, written in blocks: per vertex a ``v``, a ``vt`` and a ``vn`` line, then
    ``f a/a/a b/b/b c/c/c`` per face (1-based, position/uv/normal share the index).

    Floats are written with 9 significant digits, so float32 values read back exactly.  Faces
    may only refer to vertices written before them (checked); like PLY's, face blocks that
    arrive before the last vertex block are spooled and appended after the vertices, so a
    mesh written in any blocks gives the same bytes.
    """

    def _write_header(self) -> None:
        self._file.write(
            "# written by cltess\n"
            f"# {self.num_vertices} vertices, {self.num_faces} triangles\n"
            "# per vertex: v (position), vt (patch u v), vn (normal); faces: f v/vt/vn, 1-based\n"
            .encode("ascii"))

    def write_vertices(self, block) -> None:
        """Append vertices: ``block`` has positions (k,3), normals (k,3), uv (k,2) (ids are not written)."""
        arrays = self._take_vertices(block)
        rows = np.hstack([arrays.positions, arrays.uv, arrays.normals])
        for start in range(0, len(rows), OBJ_BLOCK_ROWS):
            text = _format_rows("v %.9g %.9g %.9g\nvt %.9g %.9g\nvn %.9g %.9g %.9g\n",
                                rows[start:start + OBJ_BLOCK_ROWS])
            self._file.write(text.encode("ascii"))

    def write_faces(self, triangles) -> None:
        """Append faces: (k, 3) global, 0-based vertex indices of vertices already written."""
        faces = self._take_faces(triangles)
        if len(faces) and int(faces.max()) >= self.vertices_written:
            raise ValueError("OBJ faces may only refer to vertices already written")
        line = "f {0}/{0}/{0} {1}/{1}/{1} {2}/{2}/{2}\n".format
        for start in range(0, len(faces), OBJ_BLOCK_ROWS):
            one_based = faces[start:start + OBJ_BLOCK_ROWS].astype(np.int64) + 1
            self._put_faces("".join(map(line, *one_based.T.tolist())).encode("ascii"))


# --------------------------------------------------------------------------- NPZ

#: The array fields of a Tessellation, as stored in an .npz export.
NPZ_ARRAYS = ("positions", "normals", "uv", "patch_ids", "object_ids", "triangles", "factors")


def write_npz(tess: Tessellation, path: str | os.PathLike) -> None:
    """All arrays of ``tess`` under their field names, plus ``stats_json`` (stats, stage_ms)."""
    meta = {"stats": _jsonable(tess.stats), "stage_ms": _jsonable(tess.stage_ms)}
    arrays = {name: np.asarray(getattr(tess, name)) for name in NPZ_ARRAYS}
    with atomic_write(path, "wb") as handle:
        np.savez(handle, **arrays, stats_json=np.array(json.dumps(meta)))


def load_npz(path: str | os.PathLike) -> Tessellation:
    """Read back a file written by :func:`write_npz`."""
    with np.load(path, allow_pickle=False) as data:
        arrays = {name: data[name] for name in NPZ_ARRAYS}
        meta = json.loads(str(data["stats_json"])) if "stats_json" in data else {}
    return Tessellation(**arrays, stage_ms=meta.get("stage_ms", {}), stats=meta.get("stats", {}))


def _jsonable(mapping: dict) -> dict:
    """numpy scalars -> Python numbers, so json can write them."""
    return {str(k): (v.item() if isinstance(v, np.generic) else v) for k, v in mapping.items()}


# --------------------------------------------------------------------------- welded meshes


def write_welded_ply(mesh, path) -> None:
    """Binary PLY of a WeldedMesh: vertex ``float x y z nx ny nz``, ``int object``; face
    ``list uchar uint vertex_indices``, ``int patch`` and, with a uv seam, ``list uchar float
    texcoord`` (u0 v0 u1 v1 u2 v2: per-wedge texture coordinates, as MeshLab reads them)."""
    vertex = np.dtype([*((name, "<f4") for name in ("x", "y", "z", "nx", "ny", "nz")), ("object", "<i4")])
    fields = [("count", "u1"), ("vertex_indices", "<u4", (3,)), ("patch", "<i4")]
    if mesh.corner_uv is not None:
        fields += [("uv_count", "u1"), ("texcoord", "<f4", (6,))]
    face = np.dtype(fields)
    header = ["ply", "format binary_little_endian 1.0", "comment written by cltess (welded)",
              f"element vertex {mesh.num_vertices}",
              *(f"property float {name}" for name in ("x", "y", "z", "nx", "ny", "nz")), "property int object",
              f"element face {mesh.num_triangles}", "property list uchar uint vertex_indices", "property int patch"]
    if mesh.corner_uv is not None:
        header.append("property list uchar float texcoord")
    vertices = np.empty(mesh.num_vertices, vertex)
    for column, name in enumerate(("x", "y", "z")):
        vertices[name] = mesh.positions[:, column]
        vertices["n" + name] = mesh.normals[:, column]
    vertices["object"] = mesh.object_ids
    faces = np.empty(mesh.num_triangles, face)
    faces["count"], faces["vertex_indices"], faces["patch"] = 3, mesh.triangles, mesh.patch_ids
    if mesh.corner_uv is not None:
        faces["uv_count"], faces["texcoord"] = 6, mesh.corner_uv.reshape(-1, 6)
    with atomic_write(path, "wb") as handle:
        handle.write(("\n".join(header) + "\nend_header\n").encode("ascii"))
        handle.write(vertices.tobytes())
        handle.write(faces.tobytes())


def write_welded_obj(mesh, path) -> None:
    """OBJ of a WeldedMesh: ``v`` and ``vn`` per vertex, with a uv seam a ``vt`` per triangle
    corner, then ``f a//a ...`` (or ``f a/t/a ...``), 1-based, floats to 9 significant digits."""
    with atomic_write(path, "wb") as handle:
        handle.write(f"# written by cltess (welded)\n# {mesh.num_vertices} vertices, {mesh.num_triangles} "
                     "triangles\n".encode("ascii"))
        rows = np.hstack([mesh.positions, mesh.normals])
        for start in range(0, len(rows), OBJ_BLOCK_ROWS):
            handle.write(_format_rows("v %.9g %.9g %.9g\nvn %.9g %.9g %.9g\n",
                                      rows[start:start + OBJ_BLOCK_ROWS]).encode("ascii"))
        if mesh.corner_uv is not None:
            uv = mesh.corner_uv.reshape(-1, 2)
            for start in range(0, len(uv), OBJ_BLOCK_ROWS):
                handle.write(_format_rows("vt %.9g %.9g\n", uv[start:start + OBJ_BLOCK_ROWS]).encode("ascii"))
        faces = mesh.triangles.astype(np.int64) + 1
        for start in range(0, len(faces), OBJ_BLOCK_ROWS):
            block = faces[start:start + OBJ_BLOCK_ROWS]
            if mesh.corner_uv is None:
                text = _format_rows("f %d//%d %d//%d %d//%d\n", np.repeat(block, 2, axis=1))
            else:
                corner = 3 * (start + np.arange(len(block)))[:, None] + np.arange(1, 4)
                text = _format_rows("f %d/%d/%d %d/%d/%d %d/%d/%d\n",
                                    np.stack([block, corner, block], axis=2).reshape(-1, 9))
            handle.write(text.encode("ascii"))


def _write_with_trimesh(mesh, path, file_type: str) -> None:
    """STL (binary) or GLB through trimesh's writers, atomically."""
    if getattr(mesh, "corner_uv", None) is not None:
        raise ValueError(f"{os.fspath(path)}: a uv seam can be written to .ply or .obj only")
    data = to_trimesh(mesh).export(file_type=file_type)
    with atomic_write(path, "wb") as handle:
        handle.write(data)


def to_trimesh(mesh):
    """A Tessellation (per-patch vertices, as they are) or WeldedMesh as a ``trimesh.Trimesh``
    (not processed), with its vertex normals."""
    import trimesh

    return trimesh.Trimesh(np.asarray(mesh.positions), np.asarray(mesh.triangles),
                           vertex_normals=np.asarray(mesh.normals), process=False)


WELDED_NPZ_ARRAYS = ("positions", "normals", "object_ids", "triangles", "patch_ids")


def write_welded_npz(mesh, path) -> None:
    """A WeldedMesh's arrays (and ``corner_uv`` with a seam) plus ``stats_json``."""
    arrays = {name: np.asarray(getattr(mesh, name)) for name in WELDED_NPZ_ARRAYS}
    if mesh.corner_uv is not None:
        arrays["corner_uv"] = mesh.corner_uv
    meta = {"stats": _jsonable(mesh.stats), "stage_ms": _jsonable(mesh.stage_ms)}
    with atomic_write(path, "wb") as handle:
        np.savez(handle, **arrays, stats_json=np.array(json.dumps(meta)))


# --------------------------------------------------------------------------- dispatch


def _write_ply(tess: Tessellation, path) -> None:
    with PlyWriter(path, tess.num_vertices, tess.num_triangles) as writer:
        writer.write_vertices(tess)
        writer.write_faces(tess.triangles)


def _write_obj(tess: Tessellation, path) -> None:
    with ObjWriter(path, tess.num_vertices, tess.num_triangles) as writer:
        writer.write_vertices(tess)
        writer.write_faces(tess.triangles)


_WRITERS = {".ply": _write_ply, ".obj": _write_obj, ".npz": write_npz,
            ".stl": lambda tess, path: _write_with_trimesh(tess, path, "stl"),
            ".glb": lambda tess, path: _write_with_trimesh(tess, path, "glb")}
_WELDED_WRITERS = {".ply": write_welded_ply, ".obj": write_welded_obj, ".npz": write_welded_npz,
                   ".stl": _WRITERS[".stl"], ".glb": _WRITERS[".glb"]}
SUPPORTED_EXTENSIONS: tuple[str, ...] = tuple(_WRITERS)
#: Formats for people's mesh tools: welded by default on the command line.
MESH_FORMATS = (".ply", ".obj", ".stl", ".glb")


def estimate_output_bytes(extension: str, num_vertices: int, num_triangles: int, weld: bool = False,
                          seam: bool = False) -> int:
    """About how many bytes a file of this mesh takes, from the plan's exact totals before
    anything is made.  Binary formats: exact per-patch, an upper bound welded (welding only
    merges vertices, its count is known after); OBJ: about 33 bytes per float and 7 per index.
    Headers are a few hundred bytes."""
    v, t = int(num_vertices), int(num_triangles)
    per = {  # (bytes per vertex, bytes per triangle)
        ".ply": (28, 17 + (25 if seam else 0)) if weld else (PLY_VERTEX_DTYPE.itemsize, PLY_FACE_DTYPE.itemsize),
        ".obj": (70, 45 + (3 * 25 + 12 if seam else 0)) if weld else (100, 60),
        ".stl": (0, 50),
        ".glb": (24, 12),
        ".npz": (28, 16 + (24 if seam else 0)) if weld else (40, 12),
    }[extension.lower()]
    return 512 + v * per[0] + t * per[1]


#: Writing speed by format, MiB/s, measured on 2 busy AMD EPYC cores (a 640k-triangle teapot):
#: binary PLY and NPZ about 600, STL and GLB (through trimesh) about 90, OBJ (text) about 50.
WRITE_MIB_PER_SECOND = {".ply": 600, ".npz": 600, ".stl": 90, ".glb": 90, ".obj": 50}
#: Welding, about 2 s, and the T-junction check, about 6 s, per million triangles (same machine).
WELD_SECONDS_PER_TRIANGLE, T_JUNCTION_SECONDS_PER_TRIANGLE = 2e-6, 6e-6


def estimate_write_seconds(extension: str, size: int, num_triangles: int = 0, weld: bool = False) -> float:
    """About how long writing ``size`` bytes in this format takes (welding included), from the
    speeds measured above: an order of magnitude, not a promise."""
    from .weld import T_JUNCTION_CHECK_LIMIT

    seconds = size / (WRITE_MIB_PER_SECOND[extension.lower()] * 2**20)
    if weld:
        seconds += num_triangles * WELD_SECONDS_PER_TRIANGLE
        if num_triangles <= T_JUNCTION_CHECK_LIMIT:
            seconds += num_triangles * T_JUNCTION_SECONDS_PER_TRIANGLE
    return seconds


def check_extension(path: str | os.PathLike) -> str:
    """The lower-case extension of ``path`` if it is one :func:`export` writes, else ValueError."""
    extension = Path(path).suffix.lower()
    if extension not in _WRITERS:
        shown = f"extension {extension!r}" if extension else "no extension"
        raise ValueError(f"{os.fspath(path)}: cannot export to {shown}; "
                         f"supported: {', '.join(SUPPORTED_EXTENSIONS)}")
    return extension


def export(tess, path: str | os.PathLike) -> Path:
    """Write ``tess`` (a Tessellation, or a WeldedMesh from ``tess.welded()``) to ``path`` as
    PLY, OBJ, STL, GLB or NPZ, chosen by the extension; returns the path.

    Raises ValueError for an unknown extension or inconsistent arrays before writing anything.
    """
    extension = check_extension(path)
    if not isinstance(tess, Tessellation):  # a WeldedMesh
        _face_array(tess.triangles, tess.num_vertices)
        _WELDED_WRITERS[extension](tess, path)
        return Path(path)
    _vertex_arrays(tess)
    _face_array(tess.triangles, tess.num_vertices)
    _WRITERS[extension](tess, path)
    return Path(path)
