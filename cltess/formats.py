"""The scene readers' former home, kept as re-exports for one release: they are ``cltess.io``
(one module per format: ``io/bpt.py``, ``io/bez.py``, ``io/json_scene.py``, ``io/meshes.py``)."""
from .io import load_scene, read_bez, read_bpt, read_json_scene, write_bez, write_bpt

__all__ = ["load_scene", "read_bpt", "read_bez", "read_json_scene", "write_bpt", "write_bez"]
