"""NumPy ``.npz``: every array of a Tessellation (or of a welded mesh) plus ``stats_json``."""
from __future__ import annotations

import json
import os

import numpy as np

from ..tessellation import Tessellation
from .writing import atomic_write

#: The array fields of a Tessellation, as stored in an .npz export.
NPZ_ARRAYS = ("positions", "normals", "uv", "patch_ids", "object_ids", "triangles", "factors")
#: Stored when present: a strip pattern's strips (cltess.strips convention) and real factors.
NPZ_OPTIONAL_ARRAYS = ("strips", "real_factors")


def write_npz(tess: Tessellation, path: str | os.PathLike) -> None:
    """All arrays of ``tess`` under their field names, plus ``stats_json`` (stats, stage_ms)."""
    meta = {"stats": _jsonable(tess.stats), "stage_ms": _jsonable(tess.stage_ms)}
    arrays = {name: np.asarray(getattr(tess, name)) for name in NPZ_ARRAYS}
    arrays.update({name: np.asarray(getattr(tess, name)) for name in NPZ_OPTIONAL_ARRAYS
                   if getattr(tess, name, None) is not None})
    with atomic_write(path, "wb") as handle:
        np.savez(handle, **arrays, stats_json=np.array(json.dumps(meta)))


def load_npz(path: str | os.PathLike) -> Tessellation:
    """Read back a file written by :func:`write_npz`."""
    with np.load(path, allow_pickle=False) as data:
        arrays = {name: data[name] for name in NPZ_ARRAYS}
        arrays.update({name: data[name] for name in NPZ_OPTIONAL_ARRAYS if name in data})
        meta = json.loads(str(data["stats_json"])) if "stats_json" in data else {}
    return Tessellation(**arrays, stage_ms=meta.get("stage_ms", {}), stats=meta.get("stats", {}))


def _jsonable(mapping: dict) -> dict:
    """numpy scalars -> Python numbers, so json can write them."""
    return {str(k): (v.item() if isinstance(v, np.generic) else v) for k, v in mapping.items()}


WELDED_NPZ_ARRAYS = ("positions", "normals", "object_ids", "triangles", "patch_ids")


def write_welded_npz(mesh, path) -> None:
    """A WeldedMesh's arrays (and ``corner_uv`` with a seam) plus ``stats_json``."""
    arrays = {name: np.asarray(getattr(mesh, name)) for name in WELDED_NPZ_ARRAYS}
    if mesh.corner_uv is not None:
        arrays["corner_uv"] = mesh.corner_uv
    meta = {"stats": _jsonable(mesh.stats), "stage_ms": _jsonable(mesh.stage_ms)}
    with atomic_write(path, "wb") as handle:
        np.savez(handle, **arrays, stats_json=np.array(json.dumps(meta)))
