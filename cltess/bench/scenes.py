"""The benchmark scenes, sized like the CudaTess paper's, each with a camera (1024x768, 45 degree
field of view) for a 0.5 px screen-space tolerance: Bézier scenes as cltess Scenes, PN meshes as
trimesh meshes with vertex normals."""
from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from ..scene import Camera, Scene


REPO = Path(__file__).resolve().parents[2]


SCENES_DIR = REPO / "scenes"


DATA_ENV_VAR = "CLTESS_DATA"  # folder holding bigguy.bez (default scenes/)


PIXELS = 0.5


WIDTH, HEIGHT, FOV_Y = 1024, 768, 45.0


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


def data_dir() -> Path:
    """Where bigguy.bez lives: ``$CLTESS_DATA``, else the repository's ``scenes/``."""
    if os.environ.get(DATA_ENV_VAR):
        return Path(os.environ[DATA_ENV_VAR])
    return SCENES_DIR


def tea_table() -> Scene:
    """The bundled tea table (332 patches) with its own camera."""
    from ..formats import load_scene

    return load_scene(SCENES_DIR / "tea_table.json")


_Y_UP_TO_Z_UP = np.array([[1.0, 0, 0, 0], [0, 0, -1, 0], [0, 1, 0, 0], [0, 0, 0, 1]])


def bigguy_copies(num_patches: int, columns: int | None = None, seed: int = 1,
                  view=(0.55, 1.0, -0.45), distance_scale: float = 1.0, jitter: bool = True) -> Scene:
    """``num_patches`` patches of bigguy.bez (3,570 each) standing on a grid: whole copies
    and, for the remainder, the first patches of one more copy.  Copies are turned about the
    vertical and scaled 0.8..1.2 (seeded); object ids count the copies.  bigguy is y-up,
    facing +z; it is turned z-up, facing -y, and the camera looks along ``view`` from
    ``distance_scale`` times the distance that just frames the copies."""
    from ..formats import read_bez

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
    from ..formats import read_bpt

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


def bumpy_torus(faces: int, seed: int):
    """A trimesh torus of about ``faces`` triangles (major sections twice the minor, radii 2 and
    0.7), its tube radius modulated by smooth seeded bumps, with vertex normals: the mesh of the
    size sweeps of bench/semi_uniform.py and bench/silhouette.py."""
    import trimesh

    minor = max(3, round(math.sqrt(faces / 4)))
    mesh = trimesh.creation.torus(major_radius=2.0, minor_radius=0.7, major_sections=2 * minor,
                                  minor_sections=minor)
    rng = np.random.default_rng(seed)
    vertices = np.array(mesh.vertices)
    ring = vertices * [1, 1, 0]
    ring = 2.0 * ring / np.linalg.norm(ring, axis=1, keepdims=True)
    tube = vertices - ring
    angle = np.arctan2(vertices[:, 1], vertices[:, 0])
    height = np.arctan2(vertices[:, 2], np.linalg.norm(vertices[:, :2], axis=1) - 2.0)
    bumps = 1 + 0.25 * np.sin(3 * angle + rng.uniform(0, 6)) * np.cos(2 * height + rng.uniform(0, 6))
    vertices = ring + tube * bumps[:, None]
    faces = np.asarray(mesh.faces)
    return trimesh.Trimesh(vertices, faces, vertex_normals=vertex_normals(vertices, faces), process=False)


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
