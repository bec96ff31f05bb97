"""JSON scenes: ``{"objects": [{"file", "transform", "object_id"}], "camera": {...}}``; ``file`` is
relative to the JSON file's folder and is a patch file (``PATCH_FORMATS``) or a triangle mesh
(``cltess.io.meshes``); ``transform`` a row-major 4x4 applied to homogeneous control points
(``b' = M b``; affine for meshes).  Problems name the JSON key at fault."""
from __future__ import annotations

import json
import math
import os
from pathlib import Path

import numpy as np

from ..limits import float32_problem
from ..scene import DEFAULT_CREASE_ANGLE, Camera, Scene, SceneError
from . import bez, bpt
from .meshes import MESH_EXTENSIONS, read_mesh
from .text import INT32_MAX as _INT32_MAX  # noqa: N811
from .text import _read_text

PATCH_FORMATS = {module.EXTENSION: module for module in (bpt, bez)}  # object files with patches

def read_json_scene(path, crease_angle: float | None = DEFAULT_CREASE_ANGLE) -> Scene:
    """A JSON scene: its objects' patches (transformed) concatenated, with object ids and camera."""
    name = str(path)
    text = _read_text(path)
    try:
        doc = json.loads(text, object_pairs_hook=_no_duplicate_keys, parse_constant=_no_constants)
    except json.JSONDecodeError as exc:
        raise SceneError(f"{name}: line {exc.lineno}: not valid JSON: {exc.msg}") from None
    except _JsonProblem as exc:
        at = f" line {_line_of(text, exc.token)}:" if exc.token else ""
        raise SceneError(f"{name}:{at} {exc}") from None
    except ValueError as exc:  # e.g. an integer of more than sys.get_int_max_str_digits() digits
        raise SceneError(f"{name}: not usable JSON: {exc}") from None
    except RecursionError:  # arrays or objects nested thousands deep
        raise SceneError(f"{name}: not usable JSON: nested too deeply") from None

    where = _Where(name)
    _check_keys(doc, where, required={"objects"}, optional={"camera"})
    objects = doc["objects"]
    if not isinstance(objects, list) or not objects:
        raise where.error("objects", "must be a non-empty list of objects")

    folder = Path(path).parent
    cache: dict[Path, np.ndarray] = {}  # one parse per file within this load
    all_patches, all_ids, meshes = [], [], []
    instanced_bytes = 0  # what the instances will take once copied: checked before each copy
    for k, obj in enumerate(objects):
        key = f"objects[{k}]"
        _check_keys(obj, where, required={"file"}, optional={"transform", "object_id"}, key=key)
        file = obj["file"]
        if not isinstance(file, str) or not file:
            raise where.error(f"{key}.file", "must be a non-empty string (a path relative to the scene file)")
        ext = Path(file).suffix.lower()
        if ext not in tuple(PATCH_FORMATS) + MESH_EXTENSIONS:
            raise where.error(f"{key}.file", f"{file!r}: object files must be .bpt, .bez or a triangle mesh "
                              f"({', '.join(MESH_EXTENSIONS)}), not {ext or '(none)'!r}")
        object_id = obj.get("object_id", k)
        if not _is_int(object_id) or not 0 <= object_id <= _INT32_MAX:
            raise where.error(f"{key}.object_id", f"must be an integer in 0..{_INT32_MAX}, got {object_id!r}")
        file_path = folder / file
        try:
            resolved = file_path.resolve()
            if resolved not in cache:
                if ext in MESH_EXTENSIONS:
                    cache[resolved] = read_mesh(file_path, crease_angle=crease_angle)
                else:
                    cache[resolved] = PATCH_FORMATS[ext].read_patches(file_path)
        except SceneError as exc:
            raise where.error(f"{key}.file", str(exc)) from None
        except (OSError, RuntimeError, ValueError) as exc:  # a symlink loop, a NUL in the name
            raise where.error(f"{key}.file", f"{str(file_path)!r}: cannot read: {exc}") from None
        source = cache[resolved]
        instanced_bytes += source.patches.nbytes if isinstance(source, Scene) else (
            source.nbytes if isinstance(source, np.ndarray) else
            source.vertices.nbytes + source.faces.nbytes + 2 * source.vertices.nbytes)
        if instanced_bytes > _MAX_SCENE_BYTES:
            raise where.error(key, f"the objects up to here already take {instanced_bytes / 2**30:.1f} GiB "
                              f"once instanced, more than half of this machine's memory "
                              f"({_MAX_SCENE_BYTES / 2**30:.1f} GiB)")
        if ext in MESH_EXTENSIONS:
            matrix = _transform(obj["transform"], where, f"{key}.transform") if "transform" in obj else np.eye(4)
            try:
                meshes.append(cache[resolved].transformed(matrix, object_id))
            except ValueError as exc:
                raise where.error(f"{key}.transform", str(exc)) from None
            continue
        patches = cache[resolved]
        if "transform" in obj:
            matrix = _transform(obj["transform"], where, f"{key}.transform")
            with np.errstate(over="ignore", invalid="ignore"):  # reported just below
                patches = patches @ matrix.T  # b' = M b for every homogeneous control point
            _check_transformed(patches, where, f"{key}.transform")
            if np.linalg.det(matrix[:3, :3]) < 0:  # a mirror: reverse u so t_u x t_v points outwards again
                patches = patches[:, :, ::-1]
        all_patches.append(patches)
        all_ids.append(np.full(len(patches), object_id, np.int32))

    camera = _camera(doc["camera"], where) if "camera" in doc else None
    if not all_patches:
        all_patches, all_ids = [np.zeros((0, 4, 4, 4))], [np.zeros(0, np.int32)]
    return Scene(np.concatenate(all_patches), np.concatenate(all_ids), camera, name, meshes)


def _physical_memory() -> int:
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        return 16 * 2**30


_MAX_SCENE_BYTES = _physical_memory() // 2  # a JSON scene may instance objects up to this


class _JsonProblem(ValueError):
    """A problem the json module lets through; ``token``, if any, locates its line."""

    def __init__(self, message: str, token: str | None):
        super().__init__(message)
        self.token = token


def _no_duplicate_keys(pairs):
    seen = {}
    for key, value in pairs:
        if key in seen:
            raise _JsonProblem(f"duplicate key {key!r}", None)  # json gives no position
        seen[key] = value
    return seen


def _no_constants(token: str):
    raise _JsonProblem(f"non-finite number {token} (NaN/Infinity are not allowed)", token)


def _line_of(text: str, token: str) -> int:
    """The line of the first ``token`` (NaN / Infinity outside strings: good enough)."""
    at = text.find(token)
    return text.count("\n", 0, at) + 1 if at >= 0 else 1


class _Where:
    """Error messages naming the JSON file and the key path (``objects[2].transform``)."""

    def __init__(self, name: str):
        self.name = name

    def error(self, key: str, what: str) -> SceneError:
        return SceneError(f"{self.name}: {key}: {what}")


def _check_keys(obj, where: _Where, required: set, optional: set, key: str = "top level") -> None:
    if not isinstance(obj, dict):
        raise where.error(key, f"must be a JSON object, got {type(obj).__name__}")
    for name in obj:
        if name not in required | optional:
            allowed = ", ".join(sorted(required | optional))
            raise where.error(key if key != "top level" else name, f"unknown key {name!r} (allowed: {allowed})")
    for name in sorted(required):
        if name not in obj:
            raise where.error(key, f"missing required key {name!r}")


def _is_int(value) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def _is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _finite(value) -> float | None:
    """A JSON number as a finite float, or None (an integer too large for a float included)."""
    try:
        number = float(value)
    except OverflowError:
        return None
    return number if math.isfinite(number) else None


def _vector(value, where: _Where, key: str, size: int) -> np.ndarray:
    if not isinstance(value, list) or len(value) != size or not all(_is_number(x) for x in value):
        raise where.error(key, f"must be a list of {size} numbers, got {json.dumps(value)[:60]}")
    numbers = [_finite(x) for x in value]
    if None in numbers:
        raise where.error(key, f"values must be finite numbers, got {str(value[numbers.index(None)])[:40]}")
    return np.array(numbers, dtype=np.float64)


def _transform(value, where: _Where, key: str) -> np.ndarray:
    """A row-major 4x4 list -> (4, 4) float64; finite, upper 3x3 not singular."""
    if not isinstance(value, list) or len(value) != 4 or not all(isinstance(r, list) and len(r) == 4 for r in value):
        raise where.error(key, "must be a 4x4 matrix (a list of 4 rows of 4 numbers)")
    rows = [_vector(r, where, f"{key}[{i}]", 4) for i, r in enumerate(value)]
    matrix = np.array(rows)
    linear = matrix[:3, :3]
    scale = np.abs(linear).max()
    if scale == 0 or abs(np.linalg.det(linear / scale)) <= 1e-12:  # scaled: no overflow at 1e308
        raise where.error(key, "singular: the upper 3x3 has (nearly) zero determinant")
    return matrix


def _check_transformed(patches: np.ndarray, where: _Where, key: str) -> None:
    """patches: (P, 4, 4, 4) after a transform; finite, weights > 0."""
    finite = np.isfinite(patches).all(axis=(1, 2, 3))
    if not finite.all():
        raise where.error(key, f"patch {int(np.argmin(finite))}: not finite after the transform")
    positive = (patches[..., 3] > 0).all(axis=(1, 2))
    if not positive.all():
        p = int(np.argmin(positive))
        raise where.error(key, f"patch {p}: weight {float(patches[p, ..., 3].min())!r} <= 0 after the transform")
    problem = float32_problem(patches.reshape(-1, 4))
    if problem:
        r, what = problem
        raise where.error(key, f"patch {r // 16}: after the transform, {what}")


def _camera(value, where: _Where) -> Camera:
    key = "camera"
    fields = {"eye", "target", "up", "fov_y_deg", "width", "height", "near", "far"}
    _check_keys(value, where, required={"eye", "target"}, optional=fields - {"eye", "target"}, key=key)
    cam = Camera(eye=_vector(value["eye"], where, f"{key}.eye", 3), target=_vector(value["target"], where, f"{key}.target", 3))
    if "up" in value:
        cam.up = _vector(value["up"], where, f"{key}.up", 3)
    forward = cam.target - cam.eye
    if not np.linalg.norm(forward) > 0:
        raise where.error(f"{key}.target", "equals camera.eye")
    if not np.linalg.norm(np.cross(forward, cam.up)) > 1e-12 * np.linalg.norm(forward) * np.linalg.norm(cam.up):
        raise where.error(f"{key}.up", "is zero or parallel to the view direction")
    for name in ("width", "height"):
        if name in value:
            if not _is_int(value[name]) or not 0 < value[name] <= 1 << 16:
                raise where.error(f"{key}.{name}", f"must be an integer in 1..65536, got {value[name]!r}")
            setattr(cam, name, value[name])
    for name in ("fov_y_deg", "near", "far"):
        if name in value:
            if not _is_number(value[name]) or _finite(value[name]) is None:
                raise where.error(f"{key}.{name}", f"must be a finite number, got {value[name]!r}")
            setattr(cam, name, float(value[name]))
    if not 0 < cam.fov_y_deg < 180:
        raise where.error(f"{key}.fov_y_deg", f"must be in (0, 180), got {cam.fov_y_deg}")
    if not 0 < cam.near < cam.far:
        raise where.error(f"{key}.near", f"need 0 < near < far, got near={cam.near}, far={cam.far}")
    return cam
