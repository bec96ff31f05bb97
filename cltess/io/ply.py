"""Binary little-endian PLY: per-patch output streamed in blocks (``PlyWriter``; vertex
``float x y z nx ny nz u v``, ``int patch object``; face ``list uchar uint vertex_indices``) and
one welded mesh (``write_welded_ply``)."""
from __future__ import annotations

import sys

import numpy as np

from ..tessellation import VERTEX_RECORD, Tessellation
from .direct import BlockFile
from .writing import _StreamingWriter, _vertex_arrays, atomic_write

#: The PLY property names of each field of the vertex record (cltess.tessellation.VERTEX_RECORD).
PLY_COLUMNS = {"positions": ("x", "y", "z"), "normals": ("nx", "ny", "nz"), "uv": ("u", "v"),
               "patch_ids": ("patch",), "object_ids": ("object",)}
#: One PLY vertex record, the vertex record little-endian: 8 float32 then 2 int32 (40 bytes).
PLY_VERTEX_DTYPE = np.dtype([(column, np.dtype(dtype).newbyteorder("<"))
                             for name, dtype, _ in VERTEX_RECORD for column in PLY_COLUMNS[name]])
_PLY_TYPES = {"f4": "float", "i4": "int"}
#: One PLY face record: ``list uchar uint`` with a constant count of 3 (13 bytes, no padding).
PLY_FACE_DTYPE = np.dtype([("count", "u1"), ("vertex_indices", "<u4", (3,))])


def ply_header(num_vertices: int, num_faces: int) -> bytes:
    """The header of a cltess PLY file with these totals."""
    lines = [
        "ply",
        "format binary_little_endian 1.0",
        "comment written by cltess",
        f"element vertex {num_vertices}",
        *(f"property {_PLY_TYPES[PLY_VERTEX_DTYPE[name].str[1:]]} {name}" for name in PLY_VERTEX_DTYPE.names),
        f"element face {num_faces}",
        "property list uchar uint vertex_indices",
        "end_header",
    ]
    return ("\n".join(lines) + "\n").encode("ascii")


#: Records built and written per step: small enough to stay in cache and to reuse one buffer
#: (a fresh 400 MB array costs its page faults; measured 3x slower than a reused 10 MB one).
CHUNK_RECORDS = 1 << 18


def ply_vertex_records(block, out: np.ndarray | None = None) -> np.ndarray:
    """The PLY vertex records (PLY_VERTEX_DTYPE) of a block with positions, normals, uv,
    patch_ids, object_ids (into ``out[:k]`` when given)."""
    return _vertex_records(_vertex_arrays(block), 0, len(block.positions), out)


def _vertex_records(arrays, first: int, last: int, out: np.ndarray | None = None) -> np.ndarray:
    """Records of vertices first..last-1: each field copied as one opaque item per record
    (``_bytes_at``; the record is 8 float32 and 2 int32, all little-endian on this host)."""
    count = last - first
    records = np.empty(count, PLY_VERTEX_DTYPE) if out is None else out[:count]
    if sys.byteorder != "little":  # the fields one by one, swapped to little-endian
        for name, _, shape in VERTEX_RECORD:
            values = getattr(arrays, name)[first:last]
            for k, column in enumerate(PLY_COLUMNS[name]):
                records[column] = values[:, k] if shape else values
        return records
    if not count:
        return records
    offset = 0
    for name, _, shape in VERTEX_RECORD:
        values = getattr(arrays, name)[first:last]
        width = values.itemsize * int(np.prod(shape))
        _bytes_at(records, offset, width)[...] = values.view(f"V{width}").reshape(count)
        offset += width
    return records


def _bytes_at(records: np.ndarray, offset: int, width: int) -> np.ndarray:
    """(k,) view of bytes offset..offset+width-1 of each record as one opaque (void) item: a
    field copied in whole per record (measured 3-6x faster than column by column)."""
    return np.ndarray(len(records), f"V{width}", records, offset, (records.itemsize,))


def ply_face_records(triangles, out: np.ndarray | None = None) -> np.ndarray:
    """The PLY face records (PLY_FACE_DTYPE) of (k, 3) vertex indices (into ``out[:k]``)."""
    faces = np.ascontiguousarray(triangles, dtype=np.uint32)
    records = np.empty(len(faces), PLY_FACE_DTYPE) if out is None else out[:len(faces)]
    if sys.byteorder != "little":
        records["count"], records["vertex_indices"] = 3, faces
        return records
    if not len(faces):
        return records
    records.view(np.uint8).reshape(len(faces), PLY_FACE_DTYPE.itemsize)[:, 0] = 3
    _bytes_at(records, 1, 12)[...] = faces.view("V12").reshape(len(faces))
    return records


class PlyWriter(_StreamingWriter):
    """Binary little-endian PLY, written in blocks.

    Vertex element: ``float x y z nx ny nz u v``, ``int patch object``.
    Face element: ``list uchar uint vertex_indices``.
    The totals fix where everything goes: the header, then the vertex records, then the face
    records, each a region of the file (``io.direct.BlockFile``) filled in the order its blocks
    arrive, so face blocks may come before the last vertex block.  The records are built in
    place in the regions' aligned staging buffers and written by direct I/O where the file
    system allows it (bypassing the page cache; ``CLTESS_DIRECT_IO=off`` turns it off).
    """

    def header(self) -> bytes:
        return ply_header(self.num_vertices, self.num_faces)

    def _write_header(self) -> None:
        header = self.header()
        vertex_bytes = self.num_vertices * PLY_VERTEX_DTYPE.itemsize
        face_bytes = self.num_faces * PLY_FACE_DTYPE.itemsize
        self._blocks = BlockFile(self._file.fileno(), len(header) + vertex_bytes + face_bytes)
        self._blocks.region(0, len(header)).write(header)
        self._vertex_region = self._blocks.region(len(header), vertex_bytes)
        self._face_region = self._blocks.region(len(header) + vertex_bytes, face_bytes)

    def write_vertices(self, block) -> None:
        """Append vertices: ``block`` has positions (k,3), normals (k,3), uv (k,2), patch_ids, object_ids (k,)."""
        arrays = self._take_vertices(block)
        step = min(CHUNK_RECORDS, self._vertex_region.capacity // PLY_VERTEX_DTYPE.itemsize)
        for first in range(0, len(arrays.positions), step):
            last = min(first + step, len(arrays.positions))
            nbytes = (last - first) * PLY_VERTEX_DTYPE.itemsize
            _vertex_records(arrays, first, last, self._vertex_region.reserve(nbytes).view(PLY_VERTEX_DTYPE))
            self._vertex_region.commit(nbytes)

    def write_faces(self, triangles) -> None:
        """Append faces: (k, 3) global, 0-based vertex indices."""
        faces = self._take_faces(triangles)
        step = min(CHUNK_RECORDS, self._face_region.capacity // PLY_FACE_DTYPE.itemsize)
        for first in range(0, len(faces), step):
            chunk = faces[first:first + step]
            nbytes = len(chunk) * PLY_FACE_DTYPE.itemsize
            ply_face_records(chunk, self._face_region.reserve(nbytes).view(PLY_FACE_DTYPE))
            self._face_region.commit(nbytes)

    def _finish(self) -> None:
        self._check_totals()
        self._blocks.finish()
        self._blocks.close()

    def _abort(self, error: BaseException) -> None:
        blocks = getattr(self, "_blocks", None)
        if blocks is not None:
            blocks.close()
        super()._abort(error)


def write_ply(tess: Tessellation, path) -> None:
    with PlyWriter(path, tess.num_vertices, tess.num_triangles) as writer:
        writer.write_vertices(tess)
        writer.write_faces(tess.triangles)


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
