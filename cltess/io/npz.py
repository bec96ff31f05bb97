"""NumPy ``.npz``: every array of a Tessellation (or of a welded mesh) plus ``stats_json``."""
from __future__ import annotations

import json
import os
import shutil
import tempfile
import zipfile

import numpy as np

from ..strips import STRIP_RESTART
from ..tessellation import Tessellation
from .writing import _StreamingWriter, atomic_write

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


class NpzWriter(_StreamingWriter):
    """An .npz written batch by batch (cltess.stream), the same arrays as :func:`write_npz` of the
    whole: each array's batches are spooled to an anonymous temporary file next to the output, and
    on close copied, in order and in chunks, into the zip's members (stored, as ``np.savez`` writes
    them, each with its .npy header).  A strip pattern's strips join the batches' strips with one
    STRIP_RESTART between non-empty ones (each batch drops its last marker, as the whole does), so
    they equal the single pass's; factors and real factors concatenate per patch."""

    def __init__(self, path: str | os.PathLike, num_vertices: int, num_faces: int):
        super().__init__(path, num_vertices, num_faces)
        self._spools: dict = {}  # name -> [file, dtype, shape tail, rows]
        self._meta: dict = {"stats": {}, "stage_ms": {}}

    def _write_header(self) -> None:
        pass  # the zip is assembled on close

    def _spool(self, name: str, values) -> None:
        array = np.ascontiguousarray(values)
        entry = self._spools.get(name)
        if entry is None:
            entry = self._spools[name] = [tempfile.TemporaryFile(dir=self.path.parent), array.dtype, array.shape[1:], 0]
        elif (array.dtype, array.shape[1:]) != (entry[1], entry[2]):
            raise ValueError(f"{self.path}: batch {name} is {array.dtype} {array.shape[1:]}, "
                             f"earlier batches {entry[1]} {entry[2]}")
        entry[0].write(array.tobytes())
        entry[3] += len(array)

    def write_vertices(self, block) -> None:
        """Append vertices: ``block`` has positions (k,3), normals (k,3), uv (k,2), patch_ids, object_ids (k,)."""
        arrays = self._take_vertices(block)
        for name, array in zip(("positions", "normals", "uv", "patch_ids", "object_ids"), arrays):
            self._spool(name, array)

    def write_faces(self, triangles) -> None:
        """Append faces: (k, 3) global, 0-based vertex indices."""
        self._spool("triangles", self._take_faces(triangles))

    def write_batch(self, batch: Tessellation) -> None:
        """A batch's vertices, faces, per-patch factors (and real factors) and strips."""
        self.write_vertices(batch)
        self.write_faces(batch.triangles)
        self._spool("factors", np.asarray(batch.factors))
        if batch.real_factors is not None:
            self._spool("real_factors", np.asarray(batch.real_factors))
        if batch.strips is not None:
            strips = np.asarray(batch.strips, np.uint32)
            if len(strips) and self._spools.get("strips", [None, None, None, 0])[3]:
                self._spool("strips", np.array([STRIP_RESTART], np.uint32))
            self._spool("strips", strips)

    def set_meta(self, stats: dict, stage_ms: dict) -> None:
        """What ``stats_json`` holds (as write_npz: the stats and the stage times)."""
        self._meta = {"stats": _jsonable(stats), "stage_ms": _jsonable(stage_ms)}

    def _finish(self) -> None:
        self._check_totals()
        order = [*NPZ_ARRAYS, *(name for name in NPZ_OPTIONAL_ARRAYS if name in self._spools)]
        with zipfile.ZipFile(self._file, "w", compression=zipfile.ZIP_STORED, allowZip64=True) as archive:
            for name in order:
                spool, dtype, tail, rows = self._spools.get(name) or (None, np.dtype(np.float32), (0,), 0)
                header = np.lib.format.header_data_from_array_1_0(np.empty((0, *tail), dtype))
                header["shape"] = (rows, *tail)
                with archive.open(name + ".npy", "w", force_zip64=True) as member:
                    np.lib.format.write_array_header_1_0(member, header)
                    if spool is not None:
                        spool.seek(0)
                        shutil.copyfileobj(spool, member, 1 << 24)
            with archive.open("stats_json.npy", "w", force_zip64=True) as member:
                np.lib.format.write_array(member, np.array(json.dumps(self._meta)))
        self._close_spool()

    def _close_spool(self) -> None:
        super()._close_spool()
        for entry in self._spools.values():
            entry[0].close()
        self._spools = {}


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
