"""Files in and out, one module per format behind a registry (trimesh style).

Scenes in: ``load_scene`` and ``READERS`` (``scenes.py``), with ``bpt.py``, ``bez.py``,
``json_scene.py`` and ``meshes.py``; the shared text helpers are ``text.py``.
Meshes out: ``export`` and ``WRITERS`` (``export.py``), with ``ply.py``, ``obj.py``, ``npz.py`` and
``trimesh_formats.py`` (STL, GLB); atomic writes and the streaming writer base are ``writing.py``.
To add a format: a module here and its line in ``READERS`` or ``WRITERS``.
"""
from .bez import read_bez, write_bez
from .export import MESH_FORMATS, SUPPORTED_EXTENSIONS, WRITERS, check_extension, export
from .bpt import read_bpt, write_bpt
from .json_scene import read_json_scene
from .meshes import MESH_EXTENSIONS, read_mesh, read_mesh_scene
from .scenes import READERS, load_scene

__all__ = ["MESH_EXTENSIONS", "MESH_FORMATS", "READERS", "SUPPORTED_EXTENSIONS", "WRITERS", "check_extension",
           "export", "load_scene", "read_bez", "read_bpt", "read_json_scene", "read_mesh",
           "read_mesh_scene", "write_bez", "write_bpt"]
