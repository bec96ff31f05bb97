"""Scene files -> :class:`~cltess.scene.Scene`, one reader per format (trimesh style): a format
module under ``cltess/io/`` and its line in ``READERS``.

``.bpt`` (``io/bpt.py``), ``.bez`` (``io/bez.py``), ``.json`` (``io/json_scene.py``), and triangle
meshes as PN triangles (``io/meshes.py``: ``.obj``, ``.ply``, ``.stl``, ``.off``, ``.glb``,
``.gltf``, through trimesh).  Every problem raises :class:`SceneError` naming the file and the
1-based line, the 0-based patch (as in ``patch_ids``) or the JSON key at fault.  Header counts
are checked against the lines actually present before anything is allocated from them.
"""
from __future__ import annotations

from pathlib import Path

from ..scene import DEFAULT_CREASE_ANGLE, Scene, SceneError
from .bez import read_bez
from .bpt import read_bpt
from .json_scene import read_json_scene
from .meshes import MESH_EXTENSIONS, read_mesh_scene

# extension -> (reader, whether it takes crease_angle)
READERS = {".bpt": (read_bpt, False), ".bez": (read_bez, False), ".json": (read_json_scene, True),
           **{ext: (read_mesh_scene, True) for ext in MESH_EXTENSIONS}}


def load_scene(path, crease_angle: float | None = DEFAULT_CREASE_ANGLE) -> Scene:
    """Read a ``.bpt``, ``.bez``, ``.json`` or mesh scene; ``Scene.name`` is ``path`` as given.
    crease_angle: degrees, for meshes without normals in the file (``TriangleMesh``): sharper
    edges stay creases; None: every edge smooth."""
    ext = Path(path).suffix.lower()
    if ext not in READERS:
        raise SceneError(f"{path}: unknown scene extension {ext or '(none)'!r}; expected .bpt, .bez, .json "
                         f"or a triangle mesh ({', '.join(MESH_EXTENSIONS)})")
    reader, creases = READERS[ext]
    return reader(path, crease_angle=crease_angle) if creases else reader(path)
