"""Camera paths (``--camera-path FILE.json``): the cameras of a sequence of frames, for the
per-frame patterns (silhouette refinement, SD-2 level functions, ESC with ``--pixels``).

A file is either a list of cameras, ``{"cameras": [...]}``, or an orbit,
``{"orbit": {"target": [x, y, z], "radius": r, "elevation_deg": 20, "frames": 36,
"start_deg": 0, "sweep_deg": 360, "up": [0, 0, 1], "fov_y_deg": 45, "width": 1024,
"height": 768}}``; every camera takes the keys of a JSON scene's ``"camera"``.  Problems name
the file and the key at fault (``path.json: cameras[3].eye: ...``)."""
from __future__ import annotations

import json
import math

import numpy as np

from ..scene import Camera, SceneError
from .json_scene import _camera, _check_keys, _is_int, _is_number, _vector, _Where
from .text import _read_text

#: Most frames a path may hold (each frame is a whole tessellation).
MAX_FRAMES = 100_000


def orbit(target, radius: float, frames: int, elevation_deg: float = 20.0, start_deg: float = 0.0,
          sweep_deg: float = 360.0, up=(0.0, 0.0, 1.0), **camera) -> list[Camera]:
    """``frames`` cameras on a circle of ``radius`` about ``target`` (z up), looking at it,
    ``elevation_deg`` above its horizontal plane, from ``start_deg`` over ``sweep_deg``
    (a full turn does not repeat its first camera)."""
    target = np.asarray(target, float)
    step = math.radians(sweep_deg) / (frames if abs(sweep_deg) >= 360.0 else max(frames - 1, 1))
    lift = math.radians(elevation_deg)
    cameras = []
    for k in range(frames):
        angle = math.radians(start_deg) + k * step
        offset = radius * np.array([math.cos(lift) * math.cos(angle), math.cos(lift) * math.sin(angle),
                                    math.sin(lift)])
        cameras.append(Camera(eye=target + offset, target=target.copy(), up=np.asarray(up, float), **camera))
    return cameras


def read_camera_path(path) -> list[Camera]:
    """The cameras of a camera-path file (module docstring), at least one."""
    name = str(path)
    text = _read_text(path)
    try:
        doc = json.loads(text)
    except json.JSONDecodeError as exc:
        raise SceneError(f"{name}: line {exc.lineno}: not valid JSON: {exc.msg}") from None
    except (ValueError, RecursionError) as exc:
        raise SceneError(f"{name}: not usable JSON: {exc}") from None
    where = _Where(name)
    if isinstance(doc, dict) and "orbit" in doc:
        _check_keys(doc, where, required={"orbit"}, optional=set())
        return _orbit(doc["orbit"], where)
    if isinstance(doc, dict):
        _check_keys(doc, where, required={"cameras"}, optional=set())
        doc, key = doc["cameras"], "cameras"
    else:
        key = "cameras"
    if not isinstance(doc, list) or not doc:
        raise where.error(key, "must be a non-empty list of cameras")
    if len(doc) > MAX_FRAMES:
        raise where.error(key, f"{len(doc)} cameras, more than {MAX_FRAMES}")
    return [_camera(value, _Prefixed(name, f"{key}[{k}]")) for k, value in enumerate(doc)]


class _Prefixed(_Where):
    """Errors of one camera of the list: ``cameras[3].eye`` instead of ``camera.eye``."""

    def __init__(self, name: str, prefix: str):
        super().__init__(name)
        self.prefix = prefix

    def error(self, key: str, what: str) -> SceneError:
        return super().error(self.prefix + key.removeprefix("camera"), what)


def _orbit(value, where: _Where) -> list[Camera]:
    key = "orbit"
    numbers = {"radius", "elevation_deg", "start_deg", "sweep_deg", "fov_y_deg", "near", "far"}
    _check_keys(value, where, required={"target", "radius", "frames"},
                optional=numbers | {"up", "width", "height"}, key=key)
    target = _vector(value["target"], where, f"{key}.target", 3)
    options = {}
    for name in numbers & set(value):
        if not _is_number(value[name]) or not math.isfinite(value[name]):
            raise where.error(f"{key}.{name}", f"must be a finite number, got {value[name]!r}")
        options[name] = float(value[name])
    if not options["radius"] > 0:
        raise where.error(f"{key}.radius", f"must be > 0, got {options['radius']}")
    frames = value["frames"]
    if not _is_int(frames) or not 1 <= frames <= MAX_FRAMES:
        raise where.error(f"{key}.frames", f"must be an integer in 1..{MAX_FRAMES}, got {frames!r}")
    for name in ("width", "height"):
        if name in value:
            if not _is_int(value[name]) or not 0 < value[name] <= 1 << 16:
                raise where.error(f"{key}.{name}", f"must be an integer in 1..65536, got {value[name]!r}")
            options[name] = value[name]
    if "up" in value:
        options["up"] = _vector(value["up"], where, f"{key}.up", 3)
    if not 0 < options.get("fov_y_deg", 45.0) < 180:
        raise where.error(f"{key}.fov_y_deg", f"must be in (0, 180), got {options['fov_y_deg']}")
    if not 0 < options.get("near", 0.01) < options.get("far", 1.0e4):
        raise where.error(f"{key}.near", "need 0 < near < far")
    if abs(math.cos(math.radians(options.get("elevation_deg", 20.0)))) < 1e-9:
        raise where.error(f"{key}.elevation_deg", "looks straight along up: the view direction is undefined")
    radius = options.pop("radius")
    return orbit(target, radius, frames, **options)
