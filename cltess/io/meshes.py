"""Triangle-mesh files -> :class:`~cltess.scene.TriangleMesh`, through trimesh (PN triangles,
docs/design.md section 3).

Any format trimesh reads, chosen by extension: ``.obj``, ``.ply``, ``.stl``, ``.off``,
``.glb``/``.gltf`` (all of a glTF scene's meshes, placed by their node transforms, as one mesh).
Nothing is merged, reordered or recomputed (``process=False``): faces keep trimesh's order
(polygons come triangulated), and vertex normals are the file's when it has them (OBJ ``vn``,
PLY ``nx ny nz``, glTF ``NORMAL``); STL and OFF have none, so they are computed
(:func:`cltess.scene.vertex_normals`).  Problems raise :class:`SceneError` naming the file.
"""
from __future__ import annotations

import logging
from pathlib import Path

import numpy as np

from ..scene import DEFAULT_CREASE_ANGLE, Scene, SceneError, TriangleMesh, check_scene_file

__all__ = ["MESH_EXTENSIONS", "read_mesh", "read_mesh_scene"]

MESH_EXTENSIONS = (".obj", ".ply", ".stl", ".off", ".glb", ".gltf")


def read_mesh_scene(path, crease_angle: float | None = DEFAULT_CREASE_ANGLE) -> Scene:
    """A mesh file as a scene of one mesh (object id 0); patch ids are its face indices."""
    return Scene.from_meshes([read_mesh(path, crease_angle=crease_angle)], name=str(path))


def read_mesh(path, object_id: int = 0, crease_angle: float | None = DEFAULT_CREASE_ANGLE) -> TriangleMesh:
    """One mesh file as a TriangleMesh (checked and repaired: see TriangleMesh).  Where the file
    has no normals, edges sharper than ``crease_angle`` degrees stay creases (None: all smooth)."""
    import trimesh

    name = str(path)
    file = Path(path)
    check_scene_file(name, "mesh file")
    if file.suffix.lower() == ".stl":
        _check_binary_stl(file, name)
    # trimesh logs, and without scipy prints tracebacks for, fallbacks it takes: keep it quiet.
    quiet = logging.getLogger("trimesh")
    level, quiet.level = quiet.level, logging.CRITICAL
    try:
        loaded = trimesh.load(file, process=False)
    except Exception as exc:  # noqa: BLE001 - the loaders raise anything on bad input
        raise SceneError(f"{name}: cannot read it as a mesh: {type(exc).__name__}: {exc}") from None
    finally:
        quiet.level = level
    if isinstance(loaded, trimesh.Scene):
        vertices, faces, normals = _scene_arrays(loaded)
    elif isinstance(loaded, trimesh.Trimesh):
        vertices, faces = np.asarray(loaded.vertices), np.asarray(loaded.faces)
        normals = np.asarray(loaded.vertex_normals) if _has_normals(loaded) else None
    else:
        raise SceneError(f"{name}: the mesh has no faces (read as a {type(loaded).__name__})")
    return TriangleMesh(vertices, faces, normals, object_id, name, crease_angle)


def _check_binary_stl(file: Path, name: str) -> None:
    """A binary STL is an 80-byte header, a triangle count, 50 bytes per triangle.  When the
    count does not fit the size and the file is not ASCII ("solid ..."), say so here: trimesh
    would fall back to its ASCII reader and fail with an unrelated message."""
    size = file.stat().st_size
    with file.open("rb") as handle:
        head = handle.read(84)
    if head.lstrip().lower().startswith(b"solid") or len(head) < 84:
        return  # ASCII (or too short for binary): trimesh reports what is wrong
    count = int.from_bytes(head[80:84], "little")
    if 84 + 50 * count != size:
        raise SceneError(f"{name}: binary STL header says {count} triangles ({84 + 50 * count} bytes), "
                         f"but the file has {size} bytes: truncated or not an STL file")


def _has_normals(mesh) -> bool:
    """Whether the mesh holds vertex normals already (from the file), not ones trimesh would
    compute when asked."""
    cache = getattr(mesh, "_cache", None)
    return cache is not None and "vertex_normals" in cache


def _scene_arrays(scene):
    """Every Trimesh instance of a trimesh Scene, transformed by its node, as one mesh's
    (vertices, faces, normals or None when some instance has none)."""
    import trimesh

    vertices, faces, normals, first = [], [], [], 0
    for node in scene.graph.nodes_geometry:
        transform, geometry = scene.graph[node]
        mesh = scene.geometry.get(geometry)
        if not isinstance(mesh, trimesh.Trimesh) or not len(mesh.faces):
            continue
        transform = np.asarray(transform, float)
        vertices.append(np.asarray(mesh.vertices) @ transform[:3, :3].T + transform[:3, 3])
        faces.append(np.asarray(mesh.faces) + first)
        normals.append(np.asarray(mesh.vertex_normals) @ np.linalg.inv(transform[:3, :3])
                       if _has_normals(mesh) else None)
        first += len(mesh.vertices)
    if not faces:
        return np.zeros((0, 3)), np.zeros((0, 3), np.int64), None
    return np.vstack(vertices), np.vstack(faces), \
        (np.vstack(normals) if all(n is not None for n in normals) else None)
