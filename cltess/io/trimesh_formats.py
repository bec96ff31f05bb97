"""STL (binary) and GLB through trimesh's writers, and ``to_trimesh``."""
from __future__ import annotations

import os

import numpy as np

from .writing import atomic_write

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


def write_stl(mesh, path) -> None:
    _write_with_trimesh(mesh, path, "stl")


def write_glb(mesh, path) -> None:
    _write_with_trimesh(mesh, path, "glb")
