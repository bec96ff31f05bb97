"""Wavefront OBJ: per-patch output streamed in blocks (``ObjWriter``) and one welded mesh
(``write_welded_obj``); floats to 9 significant digits, so float32 values read back exactly."""
from __future__ import annotations

import numpy as np

from ..tessellation import Tessellation
from .writing import _StreamingWriter, atomic_write

#: Rows per formatted OBJ text block: bounds the memory of the text built at once.
OBJ_BLOCK_ROWS = 1 << 17


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


def write_obj(tess: Tessellation, path) -> None:
    with ObjWriter(path, tess.num_vertices, tess.num_triangles) as writer:
        writer.write_vertices(tess)
        writer.write_faces(tess.triangles)


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
