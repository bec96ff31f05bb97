"""Scene files -> :class:`~cltess.scene.Scene` (patch layout: docs/design.md section 2).

Three formats, chosen by extension (``load_scene``):

``.bpt``   first line the patch count; per patch a line ``3 3`` (degrees in u and v) and 16
           lines ``x y z`` or ``x y z w`` (Cartesian point and weight), rows ``j = 0..3`` of
           four points ``i = 0..3``.  All 16 lines of one patch have the same arity.
``.bez``   indexed (Newell's files, /work/shared/data): the patch count; one line per patch of
           16 comma-separated 1-based vertex indices (same row order); the vertex count; one
           ``x,y,z`` (or ``x,y,z,w``) line per vertex.
``.json``  a scene: ``{"objects": [{"file", "transform", "object_id"}], "camera": {...}}``;
           ``file`` is relative to the JSON file's folder, ``transform`` a row-major 4x4
           applied to homogeneous control points (``b' = M b``).  An object file may also be
           a triangle mesh (below); its transform must be affine.

Triangle meshes (PN triangles): ``.obj``, ``.ply``, ``.stl``, ``.off``, ``.glb``, ``.gltf``,
read through trimesh (``cltess.meshes``).

Every problem raises :class:`SceneError` naming the file and the 1-based line, the 0-based
patch (as in ``patch_ids``) or the JSON key at fault.  Header counts are checked against the
lines actually present before anything is allocated from them.  Blank lines are skipped
(line numbers still count them).  The writers ``write_bpt`` / ``write_bez`` use ``repr``
floats, so the Cartesian points and weights read back bitwise equal.
"""
from __future__ import annotations

import json
import math
import os
import re
from pathlib import Path

import numpy as np

from .limits import float32_problem
from .meshes import MESH_EXTENSIONS, read_mesh, read_mesh_scene
from .scene import DEFAULT_CREASE_ANGLE, Camera, Scene, SceneError, check_scene_file

__all__ = ["load_scene", "read_bpt", "read_bez", "read_json_scene", "write_bpt", "write_bez"]

# Characters a numeric block may hold; anything else sends the block to the slow
# line-by-line diagnosis (numpy would accept "1_0", "nan" or non-ASCII digits).
_FLOAT_BLOCK_BAD = re.compile(r"[^0-9eE.+\-,\s]")
_INDEX_BLOCK_BAD = re.compile(r"[^0-9+\-,\s]")
# re.ASCII: \d alone would take any Unicode digit ("\uff11"), which float() and int() accept too.
_FLOAT_TOKEN = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?", re.ASCII)
_NONFINITE_TOKEN = re.compile(r"[+-]?(?:nan|inf|infinity)", re.IGNORECASE | re.ASCII)
_INT_TOKEN = re.compile(r"[+-]?\d+", re.ASCII)

_BPT_LINES_PER_PATCH = 17  # "3 3" + 16 points
_INT32_MAX = 2**31 - 1


def load_scene(path, crease_angle: float | None = DEFAULT_CREASE_ANGLE) -> Scene:
    """Read a ``.bpt``, ``.bez``, ``.json`` or mesh scene; ``Scene.name`` is ``path`` as given.
    crease_angle: degrees, for meshes without normals in the file (``TriangleMesh``): sharper
    edges stay creases; None: every edge smooth."""
    ext = Path(path).suffix.lower()
    reader = _READERS.get(ext)
    if reader is None:
        raise SceneError(f"{path}: unknown scene extension {ext or '(none)'!r}; expected .bpt, .bez, .json "
                         f"or a triangle mesh ({', '.join(MESH_EXTENSIONS)})")
    if ext == ".json" or ext in MESH_EXTENSIONS:
        return reader(path, crease_angle=crease_angle)
    return reader(path)


def read_bpt(path) -> Scene:
    """A ``.bpt`` file as a single-object scene (object id 0)."""
    patches = _parse_bpt(_Lines.read(path))
    return Scene(patches, np.zeros(len(patches), np.int32), None, str(path))


def read_bez(path) -> Scene:
    """An indexed ``.bez`` file as a single-object scene (object id 0)."""
    patches = _parse_bez(_Lines.read(path))
    return Scene(patches, np.zeros(len(patches), np.int32), None, str(path))


# --------------------------------------------------------------------------- text helpers


class _Lines:
    """The non-blank lines of a text file with their 1-based line numbers."""

    def __init__(self, name: str, text: str):
        self.name = name
        raw = text.replace("\r\n", "\n").replace("\r", "\n").split("\n")  # lines as editors count them (not at \f, \x1c, ...)
        self.numbers = [k for k, line in enumerate(raw, 1) if line and not line.isspace()]
        self.texts = [raw[k - 1] for k in self.numbers]

    @staticmethod
    def read(path) -> "_Lines":
        return _Lines(str(path), _read_text(path))

    def __len__(self) -> int:
        return len(self.texts)

    def error(self, k: int, what: str) -> SceneError:
        """An error at non-blank line ``k`` (0-based position in ``texts``)."""
        return SceneError(f"{self.name}: line {self.numbers[k]}: {what}")

    def count(self, k: int, what: str, per_item: int, after: int) -> int:
        """Parse the count on line ``k``: a positive integer whose ``per_item`` lines each,
        plus ``after`` more lines, fit in the lines that follow (checked before any allocation)."""
        tokens = self.texts[k].split()
        if len(tokens) != 1 or not _INT_TOKEN.fullmatch(tokens[0]):
            raise self.error(k, f"expected the {what} count (one integer), got {self.texts[k].strip()[:60]!r}")
        n = _clamped_int(tokens[0])
        if n <= 0:
            raise self.error(k, f"{what} count is {n}; need at least one")
        left = len(self) - k - 1
        if n > (left - after) // per_item:
            raise self.error(
                k,
                f"{what} count {n} needs {n * per_item + after} more lines but only {left} follow "
                f"(file truncated, or the count is wrong)",
            )
        return n

    def no_trailing(self, k: int, what: str) -> None:
        if k < len(self):
            raise self.error(k, f"unexpected content after the last {what}: {self.texts[k].strip()[:60]!r}")


def _read_text(path) -> str:
    check_scene_file(path)
    try:
        data = Path(path).read_bytes()
    except FileNotFoundError:
        raise SceneError(f"{path}: file not found") from None
    except OSError as exc:
        raise SceneError(f"{path}: cannot read: {exc.strerror or exc}") from None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        raise SceneError(f"{path}: line {line}: not UTF-8 text (byte {exc.start})") from None
    text = text.removeprefix("\ufeff")  # a byte-order mark, as some Windows editors write
    if not text.strip():
        raise SceneError(f"{path}: empty file")
    return text


def _clamped_int(token: str) -> int:
    """An ASCII integer token (``_INT_TOKEN``) as an int clamped to +-2**62, without converting
    thousands of digits (which Python refuses above sys.get_int_max_str_digits())."""
    token = token.strip()
    digits = token.lstrip("+-").lstrip("0")
    if len(digits) > 18:
        return -(2**62) if token.startswith("-") else 2**62
    return int(token)


def _token_problem(token: str) -> str | None:
    """Why ``token`` is not a finite float, or None if it is one."""
    token = token.strip()
    if _FLOAT_TOKEN.fullmatch(token):
        return None if math.isfinite(float(token)) else f"number {token!r} overflows to infinity"
    if _NONFINITE_TOKEN.fullmatch(token):
        return f"non-finite value {token!r}"
    return f"not a number: {token[:40]!r}" if token else "empty value"


def _floats(lines: _Lines, ks, rows: list[list[str]]) -> np.ndarray:
    """Rows of numeric tokens (``rows[r]`` from line position ``ks[r]``, equal lengths) ->
    finite float64 (R, C).  Fast path: one numpy conversion; on any doubt, find the first bad
    line for the message."""
    block = "\n".join(lines.texts[k] for k in ks)
    if not _FLOAT_BLOCK_BAD.search(block):
        try:
            values = np.array(rows, dtype=np.float64)
        except ValueError:
            pass
        else:
            if np.isfinite(values).all():
                return values
    for k, row in zip(ks, rows):
        for token in row:
            problem = _token_problem(token)
            if problem:
                raise lines.error(k, problem)
    # every token is an ASCII float numpy did not take (e.g. whitespace it does not strip)
    return np.array([[float(token) for token in row] for row in rows], dtype=np.float64)


def _homogeneous(xyzw: np.ndarray) -> np.ndarray:
    """(..., 4) Cartesian ``(x, y, z, w)`` -> homogeneous ``(w x, w y, w z, w)`` (docs/design.md section 2)."""
    return np.concatenate([xyzw[..., :3] * xyzw[..., 3:], xyzw[..., 3:]], axis=-1)


# --------------------------------------------------------------------------- .bpt


def _parse_bpt(lines: _Lines) -> np.ndarray:
    """``.bpt`` text -> (P, 4, 4, 4) homogeneous patches."""
    num = lines.count(0, "patch", _BPT_LINES_PER_PATCH, 0)
    for p in range(num):  # degree lines: "3 3" only (bicubic)
        k = 1 + p * _BPT_LINES_PER_PATCH
        tokens = lines.texts[k].split()
        if tokens != ["3", "3"]:
            hint = " (a point line: does the previous patch have 16 points?)" if len(tokens) in (3, 4) else ""
            raise lines.error(
                k, f"patch {p}: wrong degree {lines.texts[k].strip()[:40]!r}; only bicubic '3 3' is supported{hint}"
            )
    point_ks = [1 + p * _BPT_LINES_PER_PATCH + 1 + q for p in range(num) for q in range(16)]
    rows = [lines.texts[k].split() for k in point_ks]
    arity = np.array([len(r) for r in rows]).reshape(num, 16)
    for p in np.flatnonzero((arity != arity[:, :1]).any(axis=1) | ((arity[:, 0] != 3) & (arity[:, 0] != 4))):
        q = int(np.argmax(arity[p] != arity[p, 0])) if arity[p, 0] in (3, 4) else 0
        k = point_ks[p * 16 + q]
        raise lines.error(
            k,
            f"patch {p}: expected 'x y z' or 'x y z w' with the same arity on all 16 lines "
            f"(first line of the patch has {arity[p, 0]} values, this one {arity[p, q]})",
        )
    rows = [r if len(r) == 4 else r + ["1"] for r in rows]  # x y z -> weight 1
    values = _floats(lines, point_ks, rows)
    weights = values[:, 3]
    bad = np.flatnonzero(weights <= 0)
    if len(bad):
        r = int(bad[0])
        raise lines.error(point_ks[r], f"patch {r // 16}: weight {float(weights[r])!r} <= 0 (weights must be positive)")
    lines.no_trailing(1 + num * _BPT_LINES_PER_PATCH, "patch")
    homogeneous = _homogeneous(values)
    problem = float32_problem(homogeneous)
    if problem:
        r, what = problem
        raise lines.error(point_ks[r], f"patch {r // 16}: {what}")
    return homogeneous.reshape(num, 4, 4, 4)


# --------------------------------------------------------------------------- .bez


def _parse_bez(lines: _Lines) -> np.ndarray:
    """Indexed ``.bez`` text -> (P, 4, 4, 4) homogeneous patches."""
    num = lines.count(0, "patch", 1, 2)  # + vertex count line + at least one vertex
    rows = [lines.texts[k].split(",") for k in range(1, 1 + num)]
    for r, row in enumerate(rows):
        if len(row) != 16:
            raise lines.error(
                1 + r,
                f"patch {r}: expected 16 comma-separated vertex indices, got {len(row)} "
                f"(file truncated, or the patch count {num} is wrong?)",
            )
    num_vertices = lines.count(1 + num, "vertex", 1, 0)
    indices = _indices(lines, 1, rows, num_vertices)

    first = 2 + num
    vrows = [lines.texts[k].split(",") for k in range(first, first + num_vertices)]
    arity = len(vrows[0])
    for r, row in enumerate(vrows):
        if len(row) != arity or arity not in (3, 4):
            raise lines.error(
                first + r,
                f"vertex {r + 1}: expected 'x,y,z' or 'x,y,z,w' (same arity on every vertex line), got {len(row)} values",
            )
    values = _floats(lines, range(first, first + num_vertices), vrows)
    if arity == 3:
        values = np.concatenate([values, np.ones((num_vertices, 1))], axis=1)
    elif (values[:, 3] <= 0).any():
        r = int(np.argmax(values[:, 3] <= 0))
        raise lines.error(first + r, f"vertex {r + 1}: weight {float(values[r, 3])!r} <= 0 (weights must be positive)")
    lines.no_trailing(first + num_vertices, "vertex")
    homogeneous = _homogeneous(values)
    problem = float32_problem(homogeneous)
    if problem:
        r, what = problem
        raise lines.error(first + r, f"vertex {r + 1}: {what}")
    return homogeneous[indices - 1].reshape(num, 4, 4, 4)


def _indices(lines: _Lines, first: int, rows: list[list[str]], num_vertices: int) -> np.ndarray:
    """Rows of 16 index tokens -> (R, 16) int64 in 1..num_vertices."""
    block = "\n".join(lines.texts[first : first + len(rows)])
    values = None
    if not _INDEX_BLOCK_BAD.search(block):
        try:
            values = np.array(rows, dtype=np.int64)
        except (ValueError, OverflowError):
            values = None
    if values is None:
        for r, row in enumerate(rows):
            for token in row:
                t = token.strip()
                if _INT_TOKEN.fullmatch(t):
                    continue
                kind = "non-integer vertex index" if _FLOAT_TOKEN.fullmatch(t) else "not a vertex index"
                raise lines.error(first + r, f"patch {r}: {kind}: {t[:40]!r}")
        # every token is an integer: numpy overflowed on a huge one
        values = np.array([[_clamped_int(t) for t in row] for row in rows], dtype=np.int64)
    bad = (values < 1) | (values > num_vertices)
    if bad.any():
        r, c = np.argwhere(bad)[0]
        raise lines.error(
            first + int(r),
            f"patch {r}: vertex index {rows[r][c].strip()[:40]} out of range 1..{num_vertices}",
        )
    return values


# --------------------------------------------------------------------------- .json


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
        if ext not in (".bpt", ".bez") + MESH_EXTENSIONS:
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
                    lines = _Lines.read(file_path)
                    cache[resolved] = _parse_bpt(lines) if ext == ".bpt" else _parse_bez(lines)
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


# --------------------------------------------------------------------------- writers


def _cartesian_rows(patches: np.ndarray) -> np.ndarray:
    """(..., 4) homogeneous -> (..., 4) Cartesian ``(x, y, z, w)``, -0.0 written as 0.0."""
    w = patches[..., 3:]
    return np.concatenate([patches[..., :3] / w, w], axis=-1) + 0.0


def write_bpt(path, patches: np.ndarray) -> None:
    """Write (P, 4, 4, 4) homogeneous patches as ``.bpt``: ``x y z`` for a patch whose weights
    are all 1, else ``x y z w``; ``repr`` floats, so reading back gives ``w * (b.xyz / w)``."""
    patches = np.asarray(patches, dtype=np.float64)
    out = [f"{len(patches)}"]
    for patch in _cartesian_rows(patches):
        rational = not (patch[..., 3] == 1).all()
        out.append("3 3")
        for x, y, z, w in patch.reshape(16, 4).tolist():
            out.append(f"{x!r} {y!r} {z!r} {w!r}" if rational else f"{x!r} {y!r} {z!r}")
    Path(path).write_text("\n".join(out) + "\n")


def write_bez(path, patches: np.ndarray) -> None:
    """Write (P, 4, 4, 4) homogeneous patches as indexed ``.bez``; exactly equal control points
    share one vertex (numbered by first use); weights written only if some weight != 1."""
    patches = np.asarray(patches, dtype=np.float64)
    points = _cartesian_rows(patches).reshape(-1, 4)
    _, first, inverse = np.unique(points, axis=0, return_index=True, return_inverse=True)
    order = np.argsort(first)  # vertices in order of first use
    number = np.empty(len(order), np.int64)
    number[order] = np.arange(1, len(order) + 1)
    indices = number[inverse.reshape(-1)].reshape(len(patches), 16)
    vertices = points[first[order]]
    rational = not (vertices[:, 3] == 1).all()
    out = [f"{len(patches)}"]
    out += [",".join(map(str, row)) for row in indices.tolist()]
    out.append(f"{len(vertices)}")
    for x, y, z, w in vertices.tolist():
        out.append(f"{x!r},{y!r},{z!r},{w!r}" if rational else f"{x!r},{y!r},{z!r}")
    Path(path).write_text("\n".join(out) + "\n")


_READERS = {".bpt": read_bpt, ".bez": read_bez, ".json": read_json_scene,
            **{ext: read_mesh_scene for ext in MESH_EXTENSIONS}}
