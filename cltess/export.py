"""The writers' former home, kept as re-exports for one release: they are ``cltess.io``
(``io/export.py`` and its registry ``WRITERS``; one module per format)."""
from .io.export import (MESH_FORMATS, SUPPORTED_EXTENSIONS, WRITERS, check_extension, estimate_output_bytes,
                        estimate_write_seconds, export)
from .io.npz import load_npz, write_npz, write_welded_npz
from .io.obj import ObjWriter, write_welded_obj
from .io.ply import (PLY_FACE_DTYPE, PLY_VERTEX_DTYPE, PlyWriter, ply_face_records, ply_header, ply_vertex_records,
                     write_welded_ply)
from .io.trimesh_formats import to_trimesh
from .io.writing import VertexBlock, atomic_write

__all__ = ["MESH_FORMATS", "PLY_FACE_DTYPE", "PLY_VERTEX_DTYPE", "SUPPORTED_EXTENSIONS", "WRITERS", "ObjWriter",
           "PlyWriter", "VertexBlock", "atomic_write", "check_extension", "estimate_output_bytes",
           "estimate_write_seconds", "export", "load_npz", "ply_face_records", "ply_header", "ply_vertex_records",
           "to_trimesh", "write_npz", "write_welded_npz", "write_welded_obj", "write_welded_ply"]
