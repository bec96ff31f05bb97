"""Benchmark suite: the CudaTess paper's Tables 1 and 2 on any OpenCL device (issue 4).

Importable pieces:

* scene generators sized like the paper's, each with a camera (1024x768, 45 degree field of
  view) for a 0.5 px screen-space tolerance: :func:`tea_table`, :func:`bigguy_copies`
  (killeroo, herd), :func:`sphere_field` (spheres, close-up); PN meshes as ``trimesh``
  meshes with vertex normals: :func:`double_torus`, :func:`elephant`, :func:`star_field`,
  :func:`model_zoo`;
* :func:`numpy_evaluate` (Bézier) and :func:`pn_numpy_evaluate` (PN), the baseline: a plain,
  fully vectorised NumPy evaluation (einsum over Bernstein bases, float64) of positions and
  normals at exactly the pipeline's vertices (its uv and patch ids, so the same factors);
* :func:`write_bandwidth`, the memory-write baseline (a large ``numpy`` fill);
* :class:`AllocationTracker`, the peak device memory of a run (live bytes of every
  ``pyopencl.Buffer`` created while it is active);
* :func:`run_suite` and the table formatters behind ``cltess bench``.

Timing method, per scene: one warm-up run with forward differencing (FD) on and one with it
off (these also build the kernels), then ``repeat`` runs of each; every figure is the median
of those runs, and the spread is (max - min) / median.  Stage times are device milliseconds
from OpenCL profiling events (``Tessellation.stage_ms``); "end to end" is the pipeline's
``total_wall``: upload, the five stages, the two total read-backs and the read-back of every
output array.  The host adjacency (and the rest of a patch kind's host preparation) runs once
per scene and is cached on it (``Scene.prepared``), so the warm-up pays it and the timed runs
do not; it is timed alone beside them, and so is the NumPy baseline (median of ``repeat`` runs).
"""
from __future__ import annotations

import json
import math
import os
import platform
import statistics
import subprocess
import sys
import time
import weakref
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from . import reference
from .scene import Camera, Scene

REPO = Path(__file__).resolve().parent.parent
SCENES_DIR = REPO / "scenes"
DATA_ENV_VAR = "CLTESS_DATA"  # folder holding bigguy.bez (default ../shared/data)

PIXELS = 0.5
WIDTH, HEIGHT, FOV_Y = 1024, 768, 45.0

#: Bytes the pipeline writes per output vertex (position, normal: 3 floats; uv: 2 floats;
#: patch id, object id: 2 ints) and per triangle (3 uint32).
VERTEX_BYTES = (3 + 3 + 2) * 4 + 2 * 4
TRIANGLE_BYTES = 3 * 4

# --------------------------------------------------------------------------- the paper's figures

#: CudaTess (Schwarz & Stamminger 2009), Table 1, GeForce 8800 GTS, ms.  "offsets" is the
#: paper's scan stage: ours is crack_free + counts (counts kernel + pyopencl scan).
PAPER_BEZIER = {
    "tea_table": dict(title="Tea table", patches=332, tris=41_372,
                      factors=0.39, offsets=0.09, vertices=2.40, vertices_fd=1.40, indices=0.56),
    "killeroo": dict(title="Killeroo", patches=11_532, tris=100_930,
                     factors=0.82, offsets=0.16, vertices=3.32, vertices_fd=2.04, indices=0.61),
    "herd": dict(title="Killeroo herd", patches=92_256, tris=345_751,
                 factors=4.18, offsets=0.42, vertices=12.22, vertices_fd=7.38, indices=1.19),
    "spheres": dict(title="Spheres", patches=32_000, tris=402_000,
                    factors=1.62, offsets=0.20, vertices=4.54, vertices_fd=3.54, indices=0.96),
    "spheres_closeup": dict(title="Spheres close-up", patches=32_000, tris=272_301,
                            factors=1.04, offsets=0.19, vertices=5.54, vertices_fd=2.92, indices=0.77),
}
#: Table 2 (PN triangles), same GPU, ms.
PAPER_PN = {
    "double_torus": dict(title="Double torus", patches=1_536, tris=15_320,
                         factors=0.39, offsets=0.21, vertices=0.60, indices=0.48),
    "elephant": dict(title="Elephant", patches=21_540, tris=79_208,
                     factors=0.91, offsets=0.26, vertices=1.49, indices=0.68),
    "star_field": dict(title="Star field", patches=41_496, tris=1_050_688,
                       factors=1.41, offsets=0.33, vertices=6.81, indices=2.57),
    "star_field_closeup": dict(title="Star field close-up", patches=41_496, tris=379_982,
                               factors=0.75, offsets=0.30, vertices=2.84, indices=1.11),
    "model_zoo": dict(title="Model zoo", patches=80_578, tris=160_200,
                      factors=2.42, offsets=0.50, vertices=3.33, indices=0.93),
}
PAPER_DEVICE = "GeForce 8800 GTS (CudaTess paper)"

# --------------------------------------------------------------------------- geometry helpers


def framing_camera(lo, hi, direction, up=(0.0, 0.0, 1.0), margin: float = 1.0,
                   distance_scale: float = 1.0) -> Camera:
    """A 1024x768, 45 degree camera looking along ``direction`` at the box [lo, hi], far
    enough back that the box's bounding sphere (times ``margin``) fits the narrower field of
    view; ``distance_scale`` < 1 moves it closer (a close-up)."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    centre, radius = (lo + hi) / 2, np.linalg.norm(hi - lo) / 2 * margin
    direction = np.asarray(direction, float) / np.linalg.norm(direction)
    tan_y = math.tan(math.radians(FOV_Y) / 2)
    half = math.atan(min(tan_y, tan_y * WIDTH / HEIGHT))
    distance = radius / math.sin(half) * distance_scale
    eye = centre - direction * distance
    near = max(1e-3, 0.01 * distance)
    far = distance + 2 * radius
    return Camera(eye=eye, target=centre, up=np.asarray(up, float), fov_y_deg=FOV_Y,
                  width=WIDTH, height=HEIGHT, near=near, far=far)


def affine(rotation_z: float = 0.0, scale: float = 1.0, translate=(0.0, 0.0, 0.0),
           base: np.ndarray | None = None) -> np.ndarray:
    """Row-major 4x4: ``translate @ rot_z @ scale @ base`` (as the JSON scenes' transforms)."""
    c, s = math.cos(rotation_z), math.sin(rotation_z)
    m = np.array([[c * scale, -s * scale, 0, translate[0]], [s * scale, c * scale, 0, translate[1]],
                  [0, 0, scale, translate[2]], [0, 0, 0, 1.0]])
    return m @ base if base is not None else m


def random_rotation(rng: np.random.Generator) -> np.ndarray:
    """A uniformly random 3x3 rotation (QR of a Gaussian matrix, sign-fixed)."""
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q *= np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 0] = -q[:, 0]
    return q


def transform_patches(patches: np.ndarray, matrix: np.ndarray) -> np.ndarray:
    """Homogeneous control points ``b' = M b`` (so rational patches stay exact)."""
    return patches @ matrix.T


def _bounds(scene: Scene):
    points = scene.points.reshape(-1, 3)
    return points.min(axis=0), points.max(axis=0)


# --------------------------------------------------------------------------- Bézier scenes


def data_dir() -> Path:
    """Where bigguy.bez lives: ``$CLTESS_DATA``, else ``../shared/data`` or ``shared/data``."""
    if os.environ.get(DATA_ENV_VAR):
        return Path(os.environ[DATA_ENV_VAR])
    for candidate in (REPO.parent / "shared" / "data", REPO / "shared" / "data"):
        if (candidate / "bigguy.bez").exists():
            return candidate
    return REPO.parent / "shared" / "data"


def tea_table() -> Scene:
    """The bundled tea table (332 patches) with its own camera."""
    from .formats import load_scene

    return load_scene(SCENES_DIR / "tea_table.json")


_Y_UP_TO_Z_UP = np.array([[1.0, 0, 0, 0], [0, 0, -1, 0], [0, 1, 0, 0], [0, 0, 0, 1]])


def bigguy_copies(num_patches: int, columns: int | None = None, seed: int = 1,
                  view=(0.55, 1.0, -0.45), distance_scale: float = 1.0, jitter: bool = True) -> Scene:
    """``num_patches`` patches of bigguy.bez (3,570 each) standing on a grid: whole copies
    and, for the remainder, the first patches of one more copy.  Copies are turned about the
    vertical and scaled 0.8..1.2 (seeded); object ids count the copies.  bigguy is y-up,
    facing +z; it is turned z-up, facing -y, and the camera looks along ``view`` from
    ``distance_scale`` times the distance that just frames the copies."""
    from .formats import read_bez

    path = data_dir() / "bigguy.bez"
    if not path.exists():
        raise FileNotFoundError(f"{path}: bigguy.bez not found; set ${DATA_ENV_VAR} to its folder")
    model = read_bez(path).patches
    per = len(model)
    copies = -(-num_patches // per)
    columns = columns or max(1, math.ceil(math.sqrt(copies)))
    rng = np.random.default_rng(seed)
    chunks, ids = [], []
    for k in range(copies):
        row, col = divmod(k, columns)
        angle = rng.uniform(-0.6, 0.6) if jitter else 0.0
        scale = rng.uniform(0.8, 1.2) if jitter else 1.0
        matrix = affine(angle, scale, (7.0 * col, 7.0 * row, 3.0 * scale), _Y_UP_TO_Z_UP)
        take = min(per, num_patches - k * per)
        chunks.append(transform_patches(model[:take], matrix))
        ids.append(np.full(take, k, np.int32))
    scene = Scene(np.concatenate(chunks), np.concatenate(ids), name=f"bigguy x{num_patches / per:.2f}")
    scene.camera = framing_camera(*_bounds(scene), view, distance_scale=distance_scale)
    return scene


def sphere_field(count: int = 1000, closeup: bool = False, seed: int = 2,
                 radii=(0.1, 0.25), eye_at: float = 0.3) -> Scene:
    """``count`` exact spheres (scenes/sphere.bpt, 32 rational patches each) on a jittered
    cubic grid of spacing 3, each randomly rotated and scaled (radius in ``radii``).
    ``closeup`` puts the camera inside the grid (``eye_at`` of the way along the diagonal),
    looking along the diagonal, so that most patches are outside the view and culled."""
    from .formats import read_bpt

    sphere = read_bpt(SCENES_DIR / "sphere.bpt").patches
    side = max(1, round(count ** (1 / 3)))
    rng = np.random.default_rng(seed)
    chunks = []
    for k in range(count):
        i, j, l = k % side, (k // side) % side, k // (side * side)
        matrix = np.eye(4)
        matrix[:3, :3] = random_rotation(rng) * rng.uniform(*radii)
        matrix[:3, 3] = 3.0 * np.array([i, j, l]) + rng.uniform(-0.4, 0.4, 3)
        chunks.append(transform_patches(sphere, matrix))
    patches = np.concatenate(chunks)
    ids = np.repeat(np.arange(count, dtype=np.int32), len(sphere))
    scene = Scene(patches, ids, name=f"{count} spheres")
    lo, hi = _bounds(scene)
    if closeup:
        # inside the field near one corner, looking along the diagonal at a nearby sphere
        eye = lo + eye_at * (hi - lo)
        target = lo + 0.5 * (hi - lo)
        scene.camera = Camera(eye=eye, target=target, up=np.array([0.0, 0.0, 1.0]), fov_y_deg=FOV_Y,
                              width=WIDTH, height=HEIGHT, near=0.05, far=float(np.linalg.norm(hi - lo)))
    else:
        scene.camera = framing_camera(lo, hi, (0.6, 1.0, -0.5))
    return scene


# --------------------------------------------------------------------------- PN meshes


def vertex_normals(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Unit vertex normals: the sum of the area-weighted normals of the faces around each
    vertex (plain NumPy; trimesh's own falls back to a slow loop without scipy)."""
    corners = vertices[faces]
    face_normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    summed = np.zeros_like(vertices)
    for k in range(3):
        np.add.at(summed, faces[:, k], face_normals)
    length = np.linalg.norm(summed, axis=1, keepdims=True)
    return summed / np.where(length > 0, length, 1)


def _mesh(vertices, faces):
    """A trimesh mesh (not merged or reordered) with its vertex normals set."""
    import trimesh

    vertices, faces = np.asarray(vertices, float), np.asarray(faces, np.int64)
    return trimesh.Trimesh(vertices, faces, vertex_normals=vertex_normals(vertices, faces), process=False)


def _concatenate(meshes):
    """Meshes -> one mesh, vertices and faces in order (normals recomputed per vertex)."""
    vertices, faces, first = [], [], 0
    for mesh in meshes:
        vertices.append(np.asarray(mesh.vertices))
        faces.append(np.asarray(mesh.faces) + first)
        first += len(mesh.vertices)
    return _mesh(np.vstack(vertices), np.vstack(faces))


def double_torus():
    """Two tori of 24 x 16 sections (768 triangles each), side by side with their tubes
    overlapping where they meet: 1,536 triangles.  Not a boolean union (no boolean engine is
    installed): the two tubes interpenetrate, which PN triangles do not care about."""
    import trimesh

    parts = []
    for x in (-1.0, 1.0):
        torus = trimesh.creation.torus(major_radius=1.1, minor_radius=0.45, major_sections=24, minor_sections=16)
        torus.apply_translation((x * 1.35, 0.0, 0.0))
        parts.append(torus)
    return _concatenate(parts)


def elephant(seed: int = 3):
    """An elephant-sized mesh of 21,540 triangles: a bumpy ellipsoid body (icosphere level 5,
    20,480 triangles, displaced by a few low-frequency waves) and a trunk (torus of 53 x 10
    sections, 1,060 triangles)."""
    import trimesh

    rng = np.random.default_rng(seed)
    body = trimesh.creation.icosphere(subdivisions=5)
    v = body.vertices
    bumps = sum(0.06 * np.sin(rng.uniform(2, 5) * (v @ rng.normal(size=3)) + rng.uniform(0, 6))
                for _ in range(4))
    body.vertices = v * (1.0 + bumps)[:, None] * np.array([1.6, 1.0, 1.1])
    trunk = trimesh.creation.torus(major_radius=0.5, minor_radius=0.12, major_sections=53, minor_sections=10)
    trunk.apply_transform(trimesh.transformations.rotation_matrix(math.pi / 2, (1, 0, 0)))
    trunk.apply_translation((1.7, 0.0, -0.3))
    return _concatenate([body, trunk])


def _triakis_octahedron():
    """A spiky star: an octahedron with a pyramid on each face, 24 triangles, 14 vertices."""
    octa = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], float)
    apexes, faces = [], []
    for sx in (1, -1):
        for sy in (1, -1):
            for sz in (1, -1):
                a, b, c = (0 if sx > 0 else 1), (2 if sy > 0 else 3), (4 if sz > 0 else 5)
                if sx * sy * sz < 0:  # keep the face counter-clockwise seen from outside
                    b, c = c, b
                k = 6 + len(apexes)
                apexes.append(np.array([sx, sy, sz]) * 0.75)
                faces += [(a, b, k), (b, c, k), (c, a, k)]
    return _mesh(np.vstack([octa, apexes]), np.array(faces))


def star_field(count: int = 1729, seed: int = 4, extent: float = 40.0):
    """``count`` spiky stars (24 triangles each; 1,729 give 41,496) randomly rotated and
    scaled (0.3..1.0) in a cube of side ``extent``."""
    star = _triakis_octahedron()
    rng = np.random.default_rng(seed)
    vertices, faces = [], []
    for k in range(count):
        matrix = random_rotation(rng) * rng.uniform(0.3, 1.0)
        vertices.append(star.vertices @ matrix.T + rng.uniform(0, extent, 3))
        faces.append(star.faces + k * len(star.vertices))
    return _mesh(np.vstack(vertices), np.vstack(faces))


def model_zoo():
    """Several models side by side, 80,578 triangles: two elephants, two double tori, a
    bumpy blob (icosphere level 5) and a coiled snake (torus of 367 x 19 sections)."""
    import trimesh

    parts = []
    for k, mesh in enumerate([elephant(3), elephant(5), double_torus(), double_torus(), elephant(7)]):
        vertices, faces = np.array(mesh.vertices), np.array(mesh.faces)
        if k == 4:  # the blob: an elephant's body alone (the first 20,480 faces)
            vertices, faces = vertices[:10242], faces[:20480]
        parts.append(trimesh.Trimesh(vertices + (5.0 * k, 0.0, 0.0), faces, process=False))
    snake = trimesh.creation.torus(major_radius=2.0, minor_radius=0.15, major_sections=367, minor_sections=19)
    parts.append(trimesh.Trimesh(np.array(snake.vertices) + (12.0, 5.0, 0.0), snake.faces, process=False))
    return _concatenate(parts)


def mesh_camera(mesh, closeup: bool = False, distance_scale: float = 1.0, eye_at: float = 0.3) -> Camera:
    """The camera for a PN mesh: framing its bounds from ``distance_scale`` times the framing
    distance, or (close-up) inside them, ``eye_at`` of the way along the diagonal, looking
    along it."""
    lo, hi = mesh.bounds
    if closeup:
        return Camera(eye=lo + eye_at * (hi - lo), target=lo + (eye_at + 0.3) * (hi - lo),
                      up=np.array([0.0, 0.0, 1.0]), fov_y_deg=FOV_Y, width=WIDTH, height=HEIGHT,
                      near=0.05, far=float(np.linalg.norm(hi - lo)))
    return framing_camera(lo, hi, (0.6, 1.0, -0.5), distance_scale=distance_scale)


def pn_support() -> tuple[Callable | None, str]:
    """(make_scene(mesh, camera, name) -> scene the pipeline accepts, or None; why not).

    PN triangles are being added to the pipeline; this looks for a scene type that carries a
    triangle mesh.  Until one exists, PN scenes are skipped with the returned reason.
    """
    from . import scene as scene_module

    for name in ("PNScene", "MeshScene", "TriangleScene"):
        cls = getattr(scene_module, name, None)
        if cls is not None and hasattr(cls, "from_trimesh"):
            return (lambda mesh, camera, label: cls.from_trimesh(mesh, camera=camera, name=label)), ""
    if hasattr(Scene, "from_trimesh"):
        return (lambda mesh, camera, label: Scene.from_trimesh(mesh, camera=camera, name=label)), ""
    return None, "the pipeline does not take triangle meshes yet (no PN scene type in cltess.scene)"


# --------------------------------------------------------------------------- the suite


@dataclass
class BenchScene:
    key: str
    kind: str  # "bezier" or "pn"
    build: Callable
    note: str
    paper: dict = field(default_factory=dict)

    @property
    def title(self) -> str:
        return self.paper.get("title", self.key)


SUITE: dict[str, BenchScene] = {s.key: s for s in [
    BenchScene("tea_table", "bezier", tea_table,
               "scenes/tea_table.json (teapot, 6 cups, 6 spoons, table) and its camera",
               PAPER_BEZIER["tea_table"]),
    BenchScene("killeroo", "bezier", lambda: bigguy_copies(11_532, columns=4),
               "bigguy.bez x 3 + the first 822 patches of a 4th copy = 11,532 patches, one row",
               PAPER_BEZIER["killeroo"]),
    BenchScene("herd", "bezier", lambda: bigguy_copies(92_256, distance_scale=1.8),
               "bigguy.bez x 25 + 3,006 patches of a 26th = 92,256 patches on a 6 x 5 grid, "
               "seen from 1.8x the framing distance",
               PAPER_BEZIER["herd"]),
    BenchScene("spheres", "bezier", lambda: sphere_field(1000),
               "1,000 exact rational spheres (scenes/sphere.bpt, 32 patches), radius 0.1-0.25, "
               "randomly rotated, on a 10^3 grid of spacing 3",
               PAPER_BEZIER["spheres"]),
    BenchScene("spheres_closeup", "bezier", lambda: sphere_field(1000, closeup=True),
               "the same spheres, camera inside the grid (30% along the diagonal)", PAPER_BEZIER["spheres_closeup"]),
    BenchScene("double_torus", "pn", lambda: (double_torus(), {}),
               "two overlapping tori, 1,536 triangles", PAPER_PN["double_torus"]),
    BenchScene("elephant", "pn", lambda: (elephant(), {"distance_scale": 0.6}),
               "bumpy ellipsoid + torus trunk, 21,540 triangles; camera at 0.6x the framing distance", PAPER_PN["elephant"]),
    BenchScene("star_field", "pn", lambda: (star_field(), {}),
               "1,729 spiky stars of 24 triangles = 41,496", PAPER_PN["star_field"]),
    BenchScene("star_field_closeup", "pn", lambda: (star_field(), {"closeup": True, "eye_at": 0.6}),
               "the same stars, camera inside the field (60% along the diagonal)", PAPER_PN["star_field_closeup"]),
    BenchScene("model_zoo", "pn", lambda: (model_zoo(), {"distance_scale": 0.75}),
               "2 elephants, 2 double tori, a blob, a snake: 80,578 triangles; camera at 0.75x", PAPER_PN["model_zoo"]),
]}

GROUPS = {
    "all": list(SUITE),
    "bezier": [k for k, s in SUITE.items() if s.kind == "bezier"],
    "pn": [k for k, s in SUITE.items() if s.kind == "pn"],
    "small": ["tea_table", "double_torus"],
}


def resolve_scenes(names) -> list[str]:
    """Scene keys and group names (all, bezier, pn, small) -> scene keys in suite order."""
    names = list(names) or ["all"]
    wanted = set()
    for name in names:
        key = name.replace("-", "_").lower()
        if key in GROUPS:
            wanted.update(GROUPS[key])
        elif key in SUITE:
            wanted.add(key)
        else:
            raise ValueError(f"unknown bench scene {name!r}; choose from "
                             f"{', '.join(list(SUITE) + list(GROUPS))}")
    return [k for k in SUITE if k in wanted]


# --------------------------------------------------------------------------- baselines


def _bernstein(t: np.ndarray):
    s = 1 - t
    basis = np.stack([s * s * s, 3 * t * s * s, 3 * t * t * s, t * t * t], axis=-1)
    derivative = np.stack([-3 * s * s, 3 * s * s - 6 * t * s, 6 * t * s - 3 * t * t, 3 * t * t], axis=-1)
    return basis, derivative


def _evaluate_chunk(grid, u, v):
    """Homogeneous B, B_u, B_v (n, 4) of patches ``grid`` (n, 4, 4, 4) [n, j, i, c]."""
    bu, du = _bernstein(u)
    bv, dv = _bernstein(v)
    rows = np.einsum("ni,njic->njc", bu, grid)  # collapse u: (n, 4 v-points, 4)
    rows_u = np.einsum("ni,njic->njc", du, grid)
    return (np.einsum("nj,njc->nc", bv, rows), np.einsum("nj,njc->nc", bv, rows_u),
            np.einsum("nj,njc->nc", dv, rows))


def _normals(b, b_u, b_v):
    p = b[:, :3] / b[:, 3:]
    t_u = b_u[:, :3] - b_u[:, 3:] * p
    t_v = b_v[:, :3] - b_v[:, 3:] * p
    n = np.cross(t_u, t_v)
    scale = (t_u * t_u).sum(1) + (t_v * t_v).sum(1)
    ok = (n * n).sum(1) > (reference.NORMAL_DEGENERATE * scale) ** 2
    return p, n, ok


def numpy_evaluate(patches: np.ndarray, patch_ids: np.ndarray, uv: np.ndarray,
                   dtype=np.float64, chunk: int = 1 << 16):
    """Positions and unit normals (V, 3) of rational bicubic ``patches`` (P, 4, 4, 4)
    [p, j, i, (wx, wy, wz, w)] at vertex ``n``'s patch ``patch_ids[n]`` and ``uv[n]``.

    The baseline: plain NumPy, vectorised over vertices in chunks of ``chunk``, einsum over
    the Bernstein bases (u first, then v), in ``dtype``.  float64 by default: in float32 the
    normals next to a collapsed edge (a sphere's pole) come out wrong for a few vertices in
    a thousand, and float64 costs only about 30% more.  Where ``t_u x t_v``
    (nearly) vanishes, at a collapsed edge, the normal is the reference's
    (``cltess.reference.evaluate``: the limit from inside the patch).
    """
    grid_all = np.ascontiguousarray(patches, dtype=dtype)
    count = len(patch_ids)
    positions = np.empty((count, 3), dtype)
    normals = np.empty((count, 3), dtype)
    for start in range(0, count, chunk):
        stop = min(start + chunk, count)
        grid = grid_all[patch_ids[start:stop]]
        u = uv[start:stop, 0].astype(dtype)
        v = uv[start:stop, 1].astype(dtype)
        b, b_u, b_v = _evaluate_chunk(grid, u, v)
        p, n, ok = _normals(b, b_u, b_v)
        bad = np.flatnonzero(~ok)
        if len(bad):  # collapsed edges: the reference's rule (reference.evaluate), vectorised
            limit = reference.limit_normal(grid[bad], u[bad], v[bad], b[bad], b_u[bad], b_v[bad])
            stronger = (limit * limit).sum(1) > (n[bad] * n[bad]).sum(1)
            shift = dtype(reference.NORMAL_SHIFT)
            us, vs = u[bad] + shift * (dtype(0.5) - u[bad]), v[bad] + shift * (dtype(0.5) - v[bad])
            _, inside, _ = _normals(*_evaluate_chunk(grid[bad], us, vs))
            n[bad] = np.where(stronger[:, None], limit, inside)
        length = np.sqrt((n * n).sum(1, keepdims=True))
        positions[start:stop] = p
        normals[start:stop] = n / np.where(length > 0, length, 1)
    return positions, normals


def pn_controls(vertices: np.ndarray, normals: np.ndarray, faces: np.ndarray):
    """PN triangles of a mesh (docs/design.md section 3, Vlachos et al.): cubic control points
    (T, 10, 3) in the order b300 b030 b003 b210 b120 b021 b012 b102 b201 b111 and quadratic
    normal controls (T, 6, 3) n200 n020 n002 n110 n011 n101, from the vertex normals."""
    P, N = vertices[faces], normals[faces]  # (T, 3, 3): corner c of each triangle
    b = np.empty(faces.shape[:1] + (10, 3))
    n = np.empty(faces.shape[:1] + (6, 3))
    b[:, :3], n[:, :3] = P, N
    for e in range(3):  # edge e from corner e to corner e+1: b210/b120, b021/b012, b102/b201
        i, j = e, (e + 1) % 3
        w_ij = ((P[:, j] - P[:, i]) * N[:, i]).sum(-1, keepdims=True)
        w_ji = ((P[:, i] - P[:, j]) * N[:, j]).sum(-1, keepdims=True)
        b[:, 3 + 2 * e] = (2 * P[:, i] + P[:, j] - w_ij * N[:, i]) / 3
        b[:, 4 + 2 * e] = (2 * P[:, j] + P[:, i] - w_ji * N[:, j]) / 3
        d = P[:, j] - P[:, i]
        length2 = (d * d).sum(-1, keepdims=True)
        v_ij = 2 * (d * (N[:, i] + N[:, j])).sum(-1, keepdims=True) / np.where(length2 > 0, length2, 1)
        m = N[:, i] + N[:, j] - v_ij * d
        n[:, 3 + e] = m / np.maximum(np.linalg.norm(m, axis=-1, keepdims=True), 1e-300)
    mean_edge = b[:, 3:9].mean(axis=1)
    b[:, 9] = mean_edge + (mean_edge - P.mean(axis=1)) / 2
    return b, n


def pn_numpy_evaluate(vertices, normals, faces, patch_ids, uv, chunk: int = 1 << 16):
    """The PN baseline: positions and unit normals (V, 3) of the PN triangles of a mesh at
    vertex ``n``'s triangle ``patch_ids[n]`` and barycentric ``uv[n]`` (weights u, v, 1-u-v of
    corners 1, 2, 3); control points from :func:`pn_controls`, then einsum of the gathered
    controls with the cubic (and quadratic, for the normal field) Bernstein-triangle bases."""
    b, nc = pn_controls(np.asarray(vertices, float), np.asarray(normals, float), np.asarray(faces))
    count = len(patch_ids)
    positions, out_normals = np.empty((count, 3)), np.empty((count, 3))
    for start in range(0, count, chunk):
        stop = min(start + chunk, count)
        ids = patch_ids[start:stop]
        u, v = uv[start:stop, 0].astype(float), uv[start:stop, 1].astype(float)
        w = 1 - u - v
        cubic = np.stack([u ** 3, v ** 3, w ** 3, 3 * u * u * v, 3 * u * v * v, 3 * v * v * w,
                          3 * v * w * w, 3 * u * w * w, 3 * u * u * w, 6 * u * v * w], axis=-1)
        quadratic = np.stack([u * u, v * v, w * w, 2 * u * v, 2 * v * w, 2 * u * w], axis=-1)
        positions[start:stop] = np.einsum("nk,nkc->nc", cubic, b[ids])
        n = np.einsum("nk,nkc->nc", quadratic, nc[ids])
        out_normals[start:stop] = n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
    return positions, out_normals


def write_bandwidth(nbytes: int = 512 << 20, repeat: int = 5) -> float:
    """Bytes per second written by a single ``numpy`` fill of ``nbytes`` (best of ``repeat``,
    pages touched first)."""
    buffer = np.empty(nbytes, np.uint8)
    buffer.fill(0)
    best = math.inf
    for k in range(repeat):
        started = time.perf_counter()
        buffer.fill(k + 1)
        best = min(best, time.perf_counter() - started)
    return nbytes / best


class AllocationTracker:
    """Peak live bytes of ``pyopencl.Buffer`` objects while active (a context manager).

    ``pyopencl.Buffer`` is replaced by a subclass that counts each buffer's size when it is
    created and uncounts it when the Python object is freed; every buffer pyopencl.array,
    pyopencl.scan and the pipeline create goes through it.  It does not see memory the driver
    allocates on its own (kernel binaries, the scan's stack, PoCL's host copies).
    """

    def __init__(self):
        self.live = self.peak = self.total = self.count = 0

    def _free(self, size):
        self.live -= size

    def __enter__(self):
        import pyopencl as cl

        self._cl, self._original = cl, cl.Buffer
        tracker = self

        class TrackedBuffer(self._original):
            def __init__(buf, *args, **kwargs):
                super().__init__(*args, **kwargs)
                size = int(buf.size)
                tracker.live += size
                tracker.total += size
                tracker.count += 1
                tracker.peak = max(tracker.peak, tracker.live)
                weakref.finalize(buf, tracker._free, size)

        cl.Buffer = TrackedBuffer
        return self

    def __exit__(self, *exc):
        self._cl.Buffer = self._original
        return False


# --------------------------------------------------------------------------- running


def _median_spread(values):
    values = [float(v) for v in values]
    median = statistics.median(values)
    spread = (max(values) - min(values)) / median if median > 0 else 0.0
    return {"median": median, "min": min(values), "max": max(values), "spread": spread, "runs": values}


def _stages_summary(runs: list[dict]) -> dict:
    keys = [k for k in runs[0] if all(k in r for r in runs)]
    out = {k: _median_spread([r[k] for r in runs]) for k in keys}
    offsets = [r.get("crack_free", 0.0) + r.get("counts", 0.0) for r in runs]
    out["offsets"] = _median_spread(offsets)
    device = [sum(v for k, v in r.items() if k != "total_wall") for r in runs]
    out["device_total"] = _median_spread(device)
    return out


def machine_info() -> dict:
    """Host facts for the record: CPU model and count, OS, Python, numpy, pyopencl."""
    import pyopencl as cl

    model = platform.processor()
    try:
        text = subprocess.run(["lscpu"], capture_output=True, text=True, timeout=10).stdout
        for line in text.splitlines():
            if line.startswith("Model name:"):
                model = line.split(":", 1)[1].strip()
    except (OSError, subprocess.SubprocessError):
        pass
    return {"cpu": model, "cpus": os.cpu_count(), "os": platform.platform(),
            "python": platform.python_version(), "numpy": np.__version__, "pyopencl": cl.VERSION_TEXT,
            "hostname": platform.node(),
            "load_average": list(os.getloadavg()) if hasattr(os, "getloadavg") else None}


def device_info(device) -> dict:
    return {"name": device.name.strip(), "platform": device.platform.name.strip(),
            "platform_version": device.platform.version.strip(), "vendor": device.vendor.strip(),
            "version": device.version.strip(), "driver_version": device.driver_version.strip(),
            "compute_units": device.max_compute_units,
            "global_memory_gib": round(device.global_mem_size / 2**30, 2)}


class Progress:
    """Progress lines on a stream (stderr): updated in place on a terminal, one per step else."""

    def __init__(self, stream=None, enabled: bool = True):
        self.stream = stream or sys.stderr
        self.enabled = enabled
        self.tty = enabled and hasattr(self.stream, "isatty") and self.stream.isatty()
        self._width = 0

    def step(self, text: str) -> None:
        if not self.enabled:
            return
        if self.tty:
            self.stream.write("\r" + text.ljust(self._width))
            self._width = len(text)
        else:
            self.stream.write(text + "\n")
        self.stream.flush()

    def done(self, text: str) -> None:
        if not self.enabled:
            return
        if self.tty:
            self.stream.write("\r" + text.ljust(self._width) + "\n")
            self._width = 0
        else:
            self.stream.write(text + "\n")
        self.stream.flush()


def _host_adjacency(scene, kind: str):
    """The host-side adjacency work the pipeline does once per scene (then cached), to time
    it alone: Bézier ``adjacency.edge_groups``; PN the PN kind's host preparation (welding the
    mesh, grouping its edges, packing the upload), where the pipeline has one.  None if unknown."""
    if kind == "bezier":
        from .adjacency import edge_groups

        return lambda: edge_groups(scene.patches)
    from . import pipeline

    pn_kind = getattr(pipeline, "PNKind", None)
    if pn_kind is not None and hasattr(pn_kind, "prepare"):
        return lambda: pn_kind().prepare(scene)
    return None


def run_scene(tessellator, spec: BenchScene, repeat: int = 3, warmup: int = 1,
              progress: Progress | None = None, label: str = "", numpy_baseline: bool = True,
              make_pn=None) -> dict:
    """Generate one suite scene and time it; returns the scene's result record."""
    progress = progress or Progress(enabled=False)
    say = lambda text: progress.step(f"{label}{spec.key}: {text}")  # noqa: E731
    say("generating")
    started = time.perf_counter()
    built = spec.build()
    if spec.kind == "pn":
        mesh, view = built
        camera = mesh_camera(mesh, **view)
        scene = make_pn(mesh, camera, spec.key)
        base_count = len(mesh.faces)
    else:
        scene = built
        base_count = scene.num_patches
    generate_s = time.perf_counter() - started

    def once(fd: bool):
        return tessellator.tessellate(scene, pixels=PIXELS, forward_differencing=fd)

    record = {"key": spec.key, "title": spec.title, "kind": spec.kind, "note": spec.note,
              "paper": spec.paper, "generate_s": generate_s, "base_primitives": base_count,
              "repeat": repeat, "warmup": warmup}
    variants = [True, False]  # forward differencing on, then off (direct evaluation)
    runs = {True: [], False: []}
    last = None
    for fd in variants:
        tag = "FD" if fd else "direct"
        for k in range(warmup):
            say(f"warm-up {k + 1}/{warmup} ({tag})")
            if fd and k == 0:
                with AllocationTracker() as tracker:
                    result = once(fd)
                    del result
                record["peak_device_bytes"] = tracker.peak
                record["allocated_device_bytes"] = tracker.total
                record["device_buffers"] = tracker.count
            else:
                once(fd)
        for k in range(repeat):
            say(f"run {k + 1}/{repeat} ({tag})")
            result = once(fd)
            runs[fd].append(dict(result.stage_ms))
            if fd:
                last = result
    if "peak_device_bytes" not in record:  # no warm-up: measure on one more run
        with AllocationTracker() as tracker:
            once(True)
        record["peak_device_bytes"], record["allocated_device_bytes"] = tracker.peak, tracker.total
        record["device_buffers"] = tracker.count

    stats = dict(last.stats)
    stats["indices"] = 3 * int(stats["triangles"])
    record["stats"] = stats
    record["fd"] = _stages_summary(runs[True])
    if runs[False]:
        record["direct"] = _stages_summary(runs[False])
    e2e_s = record["fd"]["total_wall"]["median"] / 1e3
    device_s = record["fd"]["device_total"]["median"] / 1e3
    triangles = int(stats["triangles"])
    record["triangles_per_s"] = triangles / e2e_s if e2e_s > 0 else 0.0
    record["triangles_per_s_device"] = triangles / device_s if device_s > 0 else 0.0
    record["output_bytes"] = int(stats["vertices"]) * VERTEX_BYTES + triangles * TRIANGLE_BYTES
    record["output_bytes_per_s"] = record["output_bytes"] / e2e_s if e2e_s > 0 else 0.0

    adjacency = _host_adjacency(scene, spec.kind)
    if adjacency is not None:
        times = []
        for k in range(max(1, repeat)):
            say(f"host adjacency {k + 1}/{max(1, repeat)}")
            started = time.perf_counter()
            adjacency()
            times.append((time.perf_counter() - started) * 1e3)
        record["host_adjacency_ms"] = _median_spread(times)

    if numpy_baseline and last.num_vertices:
        if spec.kind == "bezier":
            evaluate = lambda: numpy_evaluate(scene.patches, last.patch_ids, last.uv)  # noqa: E731
            size = float(np.linalg.norm(np.subtract(*_bounds(scene))))
        else:  # a PN scene of one mesh: patch id = face index
            evaluate = lambda: pn_numpy_evaluate(mesh.vertices, mesh.vertex_normals, mesh.faces,  # noqa: E731
                                                 last.patch_ids, last.uv)
            size = float(np.linalg.norm(np.subtract(*mesh.bounds)))
        times = []
        for k in range(max(1, repeat)):
            say(f"NumPy baseline {k + 1}/{max(1, repeat)}")
            started = time.perf_counter()
            positions, normals = evaluate()
            times.append((time.perf_counter() - started) * 1e3)
        normal_gap = np.abs(normals - last.normals).max(axis=1)
        record["numpy"] = _median_spread(times)
        record["numpy"].update(
            dtype="float64", vertices=int(last.num_vertices),
            max_position_error_rel=float(np.abs(positions - last.positions).max() / size),
            normals_off_by_0_1=int(np.count_nonzero(normal_gap > 0.1)),
            normals_off_by_1=int(np.count_nonzero(normal_gap > 1.0)))
    progress.done(f"{label}{spec.key}: {triangles:,} triangles, {e2e_s * 1e3:.1f} ms end to end, "
                  f"{record['triangles_per_s'] / 1e6:.2f} Mtri/s")
    return record


def run_suite(names=(), device=None, repeat: int = 3, warmup: int = 1, progress: Progress | None = None,
              numpy_baseline: bool = True, bandwidth_bytes: int = 512 << 20, command: str | None = None) -> dict:
    """Run the named scenes (keys or groups; default all) on one device; returns the record
    that ``--json`` writes and the table formatters read."""
    from .pipeline import Tessellator

    progress = progress or Progress()
    keys = resolve_scenes(names)
    tessellator = Tessellator(device=device)
    progress.step(f"measuring memory-write bandwidth ({bandwidth_bytes >> 20} MiB numpy fill)")
    bandwidth = write_bandwidth(bandwidth_bytes)
    progress.done(f"memory-write bandwidth: {bandwidth / 1e9:.2f} GB/s (single numpy fill)")
    make_pn, pn_reason = pn_support()
    record = {"device": device_info(tessellator.device), "machine": machine_info(),
              "write_bandwidth_bytes_per_s": bandwidth, "pixels": PIXELS, "viewport": [WIDTH, HEIGHT],
              "repeat": repeat, "warmup": warmup, "command": command or " ".join(sys.argv),
              "date": time.strftime("%Y-%m-%d %H:%M:%S %z"), "scenes": [], "skipped": []}
    for n, key in enumerate(keys, 1):
        spec = SUITE[key]
        label = f"[{n}/{len(keys)}] "
        if spec.kind == "pn" and make_pn is None:
            progress.done(f"{label}{key}: skipped: {pn_reason}")
            record["skipped"].append({"key": key, "reason": pn_reason})
            continue
        result = run_scene(tessellator, spec, repeat, warmup, progress, label, numpy_baseline, make_pn)
        result["bandwidth_fraction"] = result["output_bytes_per_s"] / bandwidth
        record["scenes"].append(result)
    if hasattr(os, "getloadavg"):  # other work on the machine during the run shows here
        record["load_average_after"] = list(os.getloadavg())
    return record


# --------------------------------------------------------------------------- tables


def _ms(x: float) -> str:
    return f"{x:.3f}" if x < 10 else f"{x:.1f}" if x < 1000 else f"{x:,.0f}"


def _stage_cell(ours: float, paper: float | None) -> str:
    if paper is None:
        return _ms(ours)
    return f"{_ms(ours)} ({paper:g}, {ours / paper:.2f}x)"


def format_tables(record: dict) -> str:
    """The suite's tables as Markdown: per kind, scene statistics and the stage break-down
    with the paper's 8800 GTS figure and our ratio (ours / paper) beside each stage."""
    dev = record["device"]
    bandwidth = record["write_bandwidth_bytes_per_s"]
    lines = [f"Device: {dev['name']} ({dev['platform']}, {dev['platform_version']}; driver "
             f"{dev['driver_version']}; {dev['compute_units']} compute units). Host: "
             f"{record['machine']['cpu']}, {record['machine']['cpus']} CPUs. "
             f"{record['pixels']} px, {record['viewport'][0]}x{record['viewport'][1]}; median of "
             f"{record['repeat']} runs after {record['warmup']} warm-up. Memory-write bandwidth "
             f"(numpy fill): {bandwidth / 1e9:.2f} GB/s.", ""]
    for kind, title in (("bezier", "Table 1: Bézier scenes"), ("pn", "Table 2: PN-triangle scenes")):
        scenes = [s for s in record["scenes"] if s["kind"] == kind]
        skipped = [s for s in record.get("skipped", []) if SUITE.get(s["key"]) and SUITE[s["key"]].kind == kind]
        if not scenes and not skipped:
            continue
        lines.append(f"### {title}")
        lines.append("")
        if scenes:
            unit = "patches" if kind == "bezier" else "base tris"
            lines += [f"| scene | {unit} (paper) | culled | vertices | tris (paper) | indices | "
                      "end to end ms [min-max] | host adjacency ms (timed alone) | Mtri/s e2e | Mtri/s device | "
                      "peak MiB | NumPy eval ms | NumPy / our vertices stage | % of write BW |",
                      "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
            for s in scenes:
                st, p, e2e = s["stats"], s["paper"], s["fd"]["total_wall"]
                numpy_ms = s.get("numpy", {}).get("median")
                vertices_ms = s.get("direct", s["fd"])["vertices"]["median"] if "vertices" in s["fd"] else None
                ratio = f"{numpy_ms / vertices_ms:.0f}x" if numpy_ms and vertices_ms else "-"
                lines.append(
                    f"| {s['title']} | {s['base_primitives']:,} ({p.get('patches', 0):,}) | {st['culled']:,} | "
                    f"{st['vertices']:,} | {st['triangles']:,} ({p.get('tris', 0):,}) | {st['indices']:,} | "
                    f"{_ms(e2e['median'])} [{_ms(e2e['min'])}-{_ms(e2e['max'])}] | "
                    f"{_ms(s['host_adjacency_ms']['median']) if 'host_adjacency_ms' in s else '-'} | "
                    f"{s['triangles_per_s'] / 1e6:.2f} | {s['triangles_per_s_device'] / 1e6:.2f} | "
                    f"{s['peak_device_bytes'] / 2**20:.1f} | {_ms(numpy_ms) if numpy_ms else '-'} | {ratio} | "
                    f"{100 * s['bandwidth_fraction']:.2f} |")
            lines.append("")
            if kind == "bezier":
                lines += ["| scene (device ms; paper ms, ours/paper) | factors | offsets | vertices | "
                          "vertices FD | indices | sum FD | spread of sum |",
                          "|---|---|---|---|---|---|---|---|"]
            else:  # the paper gives one PN vertices figure: it stands beside ours with FD
                lines += ["| scene (device ms; paper ms, ours/paper) | factors | offsets | vertices | "
                          "vertices FD | indices | sum FD | spread of sum |", "|---|---|---|---|---|---|---|---|"]
            for s in scenes:
                fd, direct, p = s["fd"], s.get("direct"), s["paper"]
                cell = lambda run, k, pk=None: (_stage_cell(run[k]["median"], p.get(pk or k))  # noqa: E731
                                                if run and k in run else "-")
                spread = fd["device_total"]["spread"]
                if kind == "bezier":
                    row = [cell(fd, "factors"), cell(fd, "offsets"), cell(direct, "vertices"),
                           cell(fd, "vertices", "vertices_fd"), cell(fd, "indices")]
                else:
                    row = [cell(fd, "factors"), cell(fd, "offsets"), cell(direct, "vertices", "-"),
                           cell(fd, "vertices"), cell(fd, "indices")]
                lines.append(f"| {s['title']} | " + " | ".join(row) +
                             f" | {_ms(fd['device_total']['median'])} | {100 * spread:.0f}% |")
            lines.append("")
        for s in skipped:
            lines.append(f"- {SUITE[s['key']].title}: skipped: {s['reason']}")
        if skipped:
            lines.append("")
    return "\n".join(lines)


def write_json(record: dict, path) -> None:
    Path(path).write_text(json.dumps(record, indent=1, default=float) + "\n")
