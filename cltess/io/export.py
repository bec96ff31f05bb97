"""Write a :class:`~cltess.tessellation.Tessellation` (per-patch vertices) or a
:class:`~cltess.weld.WeldedMesh` (one indexed mesh) to disk, the format chosen by the
extension through ``WRITERS`` (one module per format: ``ply.py``, ``obj.py``, ``npz.py``,
``trimesh_formats.py``; every file written atomically, ``writing.py``).

PLY and OBJ are also streaming writers (:class:`PlyWriter`, :class:`ObjWriter`) that take the
totals up front (the PLY header needs them) and then any number of vertex and face blocks, so a
caller can write a mesh batch by batch without holding it whole::

    with PlyWriter("out.ply", num_vertices=V, num_faces=T) as writer:
        for batch in batches:
            writer.write_vertices(batch)          # anything with .positions, .normals, ...
            writer.write_faces(batch.triangles)   # (k, 3) global, 0-based vertex indices
"""
from __future__ import annotations

import os
from pathlib import Path

from ..tessellation import Tessellation
from . import npz, obj, ply, trimesh_formats
from .ply import PLY_FACE_DTYPE, PLY_VERTEX_DTYPE
from .writing import _face_array, _vertex_arrays

#: extension -> (writer of a Tessellation, writer of a WeldedMesh)
WRITERS = {
    ".ply": (ply.write_ply, ply.write_welded_ply),
    ".obj": (obj.write_obj, obj.write_welded_obj),
    ".npz": (npz.write_npz, npz.write_welded_npz),
    ".stl": (trimesh_formats.write_stl, trimesh_formats.write_stl),
    ".glb": (trimesh_formats.write_glb, trimesh_formats.write_glb),
}
SUPPORTED_EXTENSIONS: tuple[str, ...] = tuple(WRITERS)
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
    seconds = size / (WRITE_MIB_PER_SECOND[extension.lower()] * 2**20)
    if weld:
        from ..weld import T_JUNCTION_CHECK_LIMIT  # here: cltess.weld imports 10 ms of modules

        seconds += num_triangles * WELD_SECONDS_PER_TRIANGLE
        if num_triangles <= T_JUNCTION_CHECK_LIMIT:
            seconds += num_triangles * T_JUNCTION_SECONDS_PER_TRIANGLE
    return seconds


def check_extension(path: str | os.PathLike) -> str:
    """The lower-case extension of ``path`` if it is one :func:`export` writes, else ValueError."""
    extension = Path(path).suffix.lower()
    if extension not in WRITERS:
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
    per_patch, welded = WRITERS[extension]
    if not isinstance(tess, Tessellation):  # a WeldedMesh
        _face_array(tess.triangles, tess.num_vertices)
        welded(tess, path)
        return Path(path)
    _vertex_arrays(tess)
    _face_array(tess.triangles, tess.num_vertices)
    per_patch(tess, path)
    return Path(path)
