"""Former home of the triangle-mesh reader, kept as a re-export for one release: ``cltess.io.meshes``."""
from .io.meshes import MESH_EXTENSIONS, read_mesh, read_mesh_scene

__all__ = ["MESH_EXTENSIONS", "read_mesh", "read_mesh_scene"]
