"""The scene data model: what every reader produces and every pipeline stage consumes.

A scene is a batch of rational bicubic Bézier patches in homogeneous form, any number of
triangle meshes (tessellated as PN triangles, docs/design.md section 3) and an optional camera.

Patch numbering (``Tessellation.patch_ids``): the scene's Bézier patches first, in the order of
``Scene.patches`` (0..P-1), then the triangles of ``Scene.meshes``, mesh after mesh, each in
face order: face ``f`` of mesh ``m`` is patch ``Scene.mesh_first_patch(m) + f``.  For a scene of
one mesh (a mesh file), the patch id is the face index.  Every vertex also carries its object
id, so (object id, patch id - first patch of that object's mesh) names the face.

Bézier patch layout (docs/design.md section 2, issue 2): ``patches[p, j, i] = (w*x, w*y, w*z, w)``,
``i`` along u, ``j`` along v, both 0..3; the 16 points of a patch in file order are rows
``j = 0..3`` of four points ``i = 0..3``.

Patch edges are numbered counter-clockwise around the (u, v) domain; edge ``e`` is sampled by
its factor ``factors[p, e]``:

====  ========  =====================================  =========
edge  curve     boundary control points, in order      factor of
====  ========  =====================================  =========
0     v = 0     patches[p, 0, 0..3]                    u (m)
1     u = 1     patches[p, 0..3, 3]                    v (n)
2     v = 1     patches[p, 3, 3..0]                    u (m)
3     u = 0     patches[p, 3..0, 0]                    v (n)
====  ========  =====================================  =========
"""
from __future__ import annotations

import copy
import math
import os
import stat
from dataclasses import dataclass, field

import numpy as np

from .limits import float32_problem


class SceneError(ValueError):
    """Bad input: the message names the file and the line, patch or field at fault."""


def check_scene_file(path, what: str = "scene file") -> None:
    """SceneError unless ``path`` is a regular file: not found, a directory, or a device, FIFO
    or socket (/dev/zero would be read without end, a FIFO would block until a writer comes).
    os.stat neither blocks nor reads; a symlink loop is named as such."""
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        raise SceneError(f"{path}: file not found") from None
    except (OSError, ValueError) as exc:  # ELOOP, EACCES, a NUL byte in the name
        raise SceneError(f"{path}: cannot read: {getattr(exc, 'strerror', None) or exc}") from None
    if stat.S_ISDIR(mode):
        raise SceneError(f"{path}: is a directory, not a {what}")
    if not stat.S_ISREG(mode):
        kind = "a FIFO" if stat.S_ISFIFO(mode) else "a socket" if stat.S_ISSOCK(mode) else "a device"
        raise SceneError(f"{path}: is {kind}, not a regular file; give a {what}")


def device_patches(patches: np.ndarray) -> np.ndarray:
    """(P, 4, 4, 4) homogeneous float64 -> (P, 16, 4) float32, what the device evaluates.

    A patch whose 16 Cartesian control points round to one float32 point is collapsed to a
    point: it becomes that point 16 times with weight 1.  The surface is the same point, and
    its factors are 1 (two triangles), where float32 rounding of unequal weights far from the
    origin would otherwise look like curvature and saturate it (issue 9, item 7)."""
    source = patches.reshape(-1, 16, 4)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        points = (source[..., :3] / source[..., 3:]).astype(np.float32)
    collapsed = (points == points[:, :1]).all(axis=(1, 2))
    source32 = source.astype(np.float32)
    with np.errstate(over="ignore", invalid="ignore"):
        source32[:, CORNERS] = exact_corners(source32[:, CORNERS], points[:, CORNERS])
    if collapsed.any():
        source32[collapsed, :, :3] = points[collapsed, :1]
        source32[collapsed, :, 3] = 1.0
    return source32


#: The corner control points of a patch's 16: (u, v) = (0, 0), (1, 0), (0, 1), (1, 1).
CORNERS = [0, 3, 12, 15]


def exact_corners(homogeneous: np.ndarray, points: np.ndarray, reach: int = 3) -> np.ndarray:
    """Homogeneous float32 control points ``(h, w)`` whose projection ``h / w`` (correctly
    rounded float32 division, as the device does it: programs.py builds with
    -cl-fp32-correctly-rounded-divide-sqrt) is exactly ``points``, their float32 Cartesian
    positions.

    Issue 9 item 2: the corners that meet at a sphere's pole are one point with different
    weights; ``fl(w p) / w`` rounds differently for each weight (far from the origin), and the
    pole came out as 2-4 positions.  h is moved by up to ``reach`` units in the last place; where
    that cannot hit p (``fl(h / w)`` steps over it), w is moved by up to 16 units as well (the
    surface moves by about 1e-6 of the patch's size, far below any tolerance float32 can meet).
    The result depends on (h, w, p) alone, so a corner shared by several patches stays bitwise
    shared.  Points with no exact projection within reach keep their values (measured: 0.7% of
    random points with weights in [0.7, 1.5]; none of the sphere's poles, tests/test_poles.py).
    """
    out = homogeneous.reshape(-1, 4).copy()
    points = points.reshape(-1, 3)
    todo = np.flatnonzero(~(out[:, :3] / out[:, 3:] == points).all(axis=1))
    for weight_step in [0] + [s for k in range(1, 17) for s in (k, -k)]:
        if not len(todo):
            break
        weights, target = _ulps(out[todo, 3:], weight_step), points[todo]
        start = (weights * target).astype(np.float32)
        best, found = start.copy(), start / weights == target
        for step in [s for k in range(1, reach + 1) for s in (k, -k)]:
            candidate = _ulps(start, step)
            hit = ~found & (candidate / weights == target)
            best[hit], found = candidate[hit], found | hit
        fixed = found.all(axis=1)
        out[todo[fixed], :3], out[todo[fixed], 3:] = best[fixed], weights[fixed]
        todo = todo[~fixed]
    return out.reshape(homogeneous.shape)


def _ulps(values: np.ndarray, steps: int) -> np.ndarray:
    """float32 values moved by ``steps`` units in the last place (negative: down)."""
    direction = np.float32(np.inf if steps > 0 else -np.inf)
    for _ in range(abs(steps)):
        values = np.nextafter(values, direction)
    return values


def boundary_curves(patches: np.ndarray) -> np.ndarray:
    """The four boundary curves of each patch, counter-clockwise (table above).

    patches: (P, 4, 4, 4) homogeneous control points.  Returns (P, 4, 4, 4):
    ``[p, e, k]`` is the k-th control point of edge e, walking counter-clockwise.
    """
    return np.stack(
        [
            patches[:, 0, :, :],  # v = 0, u rising
            patches[:, :, 3, :],  # u = 1, v rising
            patches[:, 3, ::-1, :],  # v = 1, u falling
            patches[:, ::-1, 0, :],  # u = 0, v falling
        ],
        axis=1,
    )


@dataclass
class Camera:
    """A pinhole camera for screen-space tolerances (docs/design.md section 7)."""

    eye: np.ndarray
    target: np.ndarray
    up: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    fov_y_deg: float = 45.0
    width: int = 1024
    height: int = 768
    near: float = 0.01
    far: float = 1.0e4

    def view_matrix(self, dtype=np.float64) -> np.ndarray:
        """World -> camera (4, 4) float64, or rounded to ``dtype`` (stage 1's float32); the
        camera looks down its -z axis, right-handed.

        Once per frame, so on Python floats but for the three NumPy (BLAS) products: the same
        IEEE operations as ``np.cross``, ``np.linalg.norm`` (sqrt of the vector's dot with
        itself) and ``-rotation @ eye`` on the float64 matrix, bitwise the same matrix
        (tests/test_session.py), at a fraction of their call overhead (a NumPy call costs
        1-4 µs on this VM's CPUs: bench/RESULTS.md, "Issue 15: a frame's host cost, session 8")."""
        eye = np.asarray(self.eye, float)
        forward = np.asarray(self.target, float) - eye
        f0, f1, f2 = (forward / math.sqrt(forward.dot(forward))).tolist()
        w0, w1, w2 = np.asarray(self.up, float).tolist()
        right = np.array([f1 * w2 - f2 * w1, f2 * w0 - f0 * w2, f0 * w1 - f1 * w0])  # forward x up
        r0, r1, r2 = (right / math.sqrt(right.dot(right))).tolist()
        u0, u1, u2 = r1 * f2 - r2 * f1, r2 * f0 - r0 * f2, r0 * f1 - r1 * f0  # the true up: right x forward
        # -rotation @ eye, the negation (exact) made on the Python floats
        t0, t1, t2 = (np.array([[-r0, -r1, -r2], [-u0, -u1, -u2], [f0, f1, f2]]) @ eye).tolist()
        return np.array([[r0, r1, r2, t0], [u0, u1, u2, t1], [-f0, -f1, -f2, t2], [0.0, 0.0, 0.0, 1.0]], dtype)

    def pixel_size_at_unit_depth(self) -> float:
        """World length of one pixel at depth 1: ``2 tan(fov_y / 2) / height``."""
        return pixel_size_at_unit_depth(self.fov_y_deg, self.height)


def pixel_size_at_unit_depth(fov_y_deg: float, height: int) -> float:
    """World length of one pixel at depth 1 of a camera with this field of view and image
    height: ``2 tan(fov_y / 2) / height``."""
    return 2.0 * np.tan(np.radians(fov_y_deg) / 2.0) / height


def vertex_normals(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(V, 3) unit vertex normals as trimesh computes them (face normals weighted by the corner
    angles), but summed over all vertices at the same float32 position, so that a mesh whose
    vertices are split along UV seams still gets one normal per point.  Zero where a point
    touches only degenerate triangles."""
    vertices = np.asarray(vertices, np.float64)
    faces = np.asarray(faces, np.int64)
    welded = weld_positions(vertices)
    corners = vertices[faces]  # (F, 3, 3)
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    normal = _unit_rows(normal)
    angles = np.zeros(faces.shape)
    for c in range(3):
        a = _unit_rows(corners[:, (c + 1) % 3] - corners[:, c])
        b = _unit_rows(corners[:, (c + 2) % 3] - corners[:, c])
        angles[:, c] = np.arccos(np.clip((a * b).sum(1), -1.0, 1.0))
    total = np.zeros((welded.max() + 1, 3))
    np.add.at(total, welded[faces].reshape(-1), (normal[:, None, :] * angles[..., None]).reshape(-1, 3))
    return _unit_rows(total)[welded]


#: Edges whose faces' normals differ by more than this many degrees stay sharp when a mesh file
#: has no normals.  Between Blender's auto-smooth 30 and 3ds Max's 45: a 12-sided cylinder or
#: torus (30 degrees between facets), the coarse meshes PN triangles are for, stays round; a
#: 45-degree chamfer and a cube's edges stay sharp.
DEFAULT_CREASE_ANGLE = 40.0


def creased_normals(vertices: np.ndarray, faces: np.ndarray, crease_angle: float) -> np.ndarray:
    """(F, 3, 3) normal per face corner: the angle-weighted face normals (as
    :func:`vertex_normals`) of the faces around the corner's welded position whose normal is
    within ``crease_angle`` degrees of the corner's own face's (three.js ``toCreasedNormals``).
    Corners on one smooth region get bitwise the same normal (the same sum in the same order);
    across an edge sharper than the angle they differ, and the PN pipeline keeps it a crease."""
    vertices = np.asarray(vertices, np.float64)
    faces = np.asarray(faces, np.int64)
    corners = vertices[faces]
    normal = _unit_rows(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]))
    angles = np.zeros(faces.shape)
    for c in range(3):
        a = _unit_rows(corners[:, (c + 1) % 3] - corners[:, c])
        b = _unit_rows(corners[:, (c + 2) % 3] - corners[:, c])
        angles[:, c] = np.arccos(np.clip((a * b).sum(1), -1.0, 1.0))
    # every pair (corner k, corner l) at one welded position: sum(s^2) pairs over the positions
    at = weld_positions(vertices)[faces].reshape(-1)
    order = np.argsort(at, kind="stable")
    sizes = np.bincount(at)
    starts = np.concatenate([[0], np.cumsum(sizes)])[at[order]]
    count = sizes[at[order]]
    k = np.repeat(order, count)
    l = order[np.repeat(starts, count) + np.arange(len(k)) - np.repeat(np.cumsum(count) - count, count)]
    face_k, face_l = k // 3, l // 3
    cos_limit = np.cos(np.radians(min(max(float(crease_angle), 0.0), 180.0)))
    smooth = (normal[face_k] * normal[face_l]).sum(axis=1) >= cos_limit - 1e-12
    smooth |= (face_k == face_l) | ~normal[face_k].any(axis=1)  # a sliver's corner takes every side
    k, l = k[smooth], l[smooth]
    weighted = normal[l // 3] * angles.reshape(-1)[l][:, None]
    total = np.stack([np.bincount(k, weighted[:, axis], minlength=3 * len(faces)) for axis in range(3)], axis=1)
    return _unit_rows(total).reshape(-1, 3, 3)


def weld_positions(vertices: np.ndarray) -> np.ndarray:
    """(V,) id per vertex, equal for vertices at bitwise the same float32 position (the device's
    view of them; -0.0 = 0.0): the welding PN adjacency uses."""
    keys = np.ascontiguousarray(np.asarray(vertices, np.float32) + np.float32(0.0))
    _, welded = np.unique(keys.view(np.dtype((np.void, 12))).ravel(), return_inverse=True)
    return welded.ravel()


def _unit_rows(a: np.ndarray) -> np.ndarray:
    length = np.linalg.norm(a, axis=1, keepdims=True)
    return np.where(length > 0, a / np.where(length > 0, length, 1.0), 0.0)


@dataclass
class TriangleMesh:
    """A triangle mesh with vertex normals, tessellated as PN triangles (docs/design.md section 3).

    Checked and repaired on construction; every problem raises :class:`SceneError` naming the
    mesh and the vertex or face (0-based, as the file's loader numbered them):

    vertices:  (V, 3) float64, finite.
    faces:     (F, 3) int64 vertex indices in 0..V-1, at least one face.
    normals:   (V, 3) float64 vertex normals.  Given (from the file): used as they are, only
               scaled to unit length; those that are not finite or of zero length are replaced
               by the computed normal (counted in ``repaired_normals``).  None: computed
               (:func:`vertex_normals`: angle-weighted, over the welded positions).
    object_id: the object id of every vertex of its tessellation.
    name:      for messages.
    crease_angle: degrees, or None.  Only where ``normals`` is None: edges whose faces' normals
               differ by more than this get a normal per side (:func:`creased_normals`; the
               vertices there are split, faces keep their order), so the PN surface keeps them
               as creases; None: one averaged normal per position (every edge smooth).

    ``degenerate_triangles`` counts faces of (near) zero area.  They are kept: a PN triangle
    over a sliver is still a well-defined patch between its neighbours' curves, and dropping it
    would open a hole.  The exception are *folded* ones, two corners at one point: their other
    two edges are one edge, so the pipeline gives them no output and lets their neighbours meet
    directly (``reference.pn_folded``; counted as ``folded_triangles`` in the stats).
    """

    vertices: np.ndarray
    faces: np.ndarray
    normals: np.ndarray | None = None
    object_id: int = 0
    name: str = "<mesh>"
    crease_angle: float | None = None
    normals_from_file: bool = field(init=False, default=False)
    repaired_normals: int = field(init=False, default=0)
    degenerate_triangles: int = field(init=False, default=0)

    def __post_init__(self) -> None:
        name = self.name
        vertices = np.asarray(self.vertices, dtype=np.float64)
        if vertices.ndim != 2 or vertices.shape[1] != 3:
            raise SceneError(f"{name}: vertices must have shape (V, 3), got {vertices.shape}")
        bad = ~np.isfinite(vertices).all(axis=1)
        if bad.any():
            v = int(np.argmax(bad))
            raise SceneError(f"{name}: vertex {v}: position {vertices[v].tolist()} is not finite")
        problem = float32_problem(vertices)
        if problem:
            raise SceneError(f"{name}: vertex {problem[0]}: {problem[1]}")
        faces = np.asarray(self.faces)
        if faces.size == 0:
            raise SceneError(f"{name}: the mesh has no faces (PN triangles need triangles)")
        if faces.ndim != 2 or faces.shape[1] != 3:
            raise SceneError(f"{name}: faces must be triangles, shape (F, 3), got {faces.shape}")
        if not np.issubdtype(faces.dtype, np.integer):
            if not (np.isfinite(faces).all() and (faces == np.round(faces)).all()):
                raise SceneError(f"{name}: face vertex indices must be integers")
        faces = faces.astype(np.int64)
        out = (faces < 0) | (faces >= len(vertices))
        if out.any():
            f, c = (int(x) for x in np.argwhere(out)[0])
            raise SceneError(f"{name}: face {f}: vertex index {int(faces[f, c])} out of range "
                             f"0..{len(vertices) - 1}")
        self.vertices, self.faces = vertices.copy(), faces.copy()  # owned: made read-only below
        if self.object_id is None or not 0 <= int(self.object_id) <= 2**31 - 1:
            raise SceneError(f"{name}: object id {self.object_id!r} is not in 0..2**31-1")
        self.object_id = int(self.object_id)

        corners = vertices[faces]
        area2 = np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1)
        longest2 = np.max([((corners[:, (c + 1) % 3] - corners[:, c]) ** 2).sum(1) for c in range(3)], axis=0)
        self.degenerate_triangles = int((area2 <= 1e-12 * longest2).sum())

        computed = None
        self.normals_from_file = self.normals is not None
        if self.normals is None and self.crease_angle is not None:
            if not 0 <= float(self.crease_angle) <= 180:
                raise SceneError(f"{name}: crease angle must be in 0..180 degrees, got {self.crease_angle!r}")
            # a vertex per distinct (position, corner normal); faces keep their order
            corner_normals = creased_normals(vertices, faces, self.crease_angle).reshape(-1, 3)
            keys = np.hstack([vertices[faces].reshape(-1, 3), corner_normals])
            _, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
            vertices, faces = vertices[faces].reshape(-1, 3)[first], inverse.reshape(-1, 3).astype(np.int64)
            self.vertices, self.faces = vertices.copy(), faces.copy()
            normals = corner_normals[first]
        elif self.normals is None:
            normals = computed = vertex_normals(vertices, faces)
        else:
            normals = np.array(self.normals, dtype=np.float64)
            if normals.shape != vertices.shape:
                raise SceneError(f"{name}: normals must have shape {vertices.shape} (one per vertex), "
                                 f"got {normals.shape}")
            length = np.linalg.norm(np.where(np.isfinite(normals), normals, 0.0), axis=1)
            bad = ~np.isfinite(normals).all(axis=1) | ~(length > 0)
            normals[~bad] /= length[~bad, None]
            if bad.any():
                computed = vertex_normals(vertices, faces)
                normals[bad] = computed[bad]
            self.repaired_normals = int(bad.sum())
        self.normals = normals
        _read_only(self.vertices, self.faces, self.normals)

    @property
    def num_faces(self) -> int:
        return len(self.faces)

    def transformed(self, matrix: np.ndarray, object_id: int | None = None) -> "TriangleMesh":
        """A copy moved by an affine row-major 4x4 ``matrix`` (last row 0 0 0 1; ValueError else):
        positions ``M p``, normals by the inverse transpose of its 3x3, unit length again; a
        mirroring matrix (negative determinant) also reverses each face's winding."""
        matrix = np.asarray(matrix, np.float64)
        if not np.array_equal(matrix[3], [0.0, 0.0, 0.0, 1.0]):
            raise ValueError("a mesh takes only affine transforms (last row 0 0 0 1)")
        out = copy.copy(self)
        with np.errstate(over="ignore", invalid="ignore"):
            out.vertices = self.vertices @ matrix[:3, :3].T + matrix[:3, 3]
            out.normals = _unit_rows(self.normals @ np.linalg.inv(matrix[:3, :3]))
        bad = ~np.isfinite(out.vertices).all(axis=1)
        if bad.any():
            raise ValueError(f"vertex {int(np.argmax(bad))}: not finite after the transform")
        problem = float32_problem(out.vertices)
        if problem:
            raise ValueError(f"vertex {problem[0]}: after the transform, {problem[1]}")
        if np.linalg.det(matrix[:3, :3]) < 0:  # a mirror: keep the winding with the normals
            out.faces = self.faces[:, ::-1].copy()
        if object_id is not None:
            out.object_id = int(object_id)
        return out

    @staticmethod
    def from_trimesh(mesh, object_id: int = 0, name: str | None = None) -> "TriangleMesh":
        """From a ``trimesh.Trimesh``: its vertex normals only where it holds some already (read
        from the file, or given to its constructor), never ones trimesh would compute on access."""
        cache = getattr(mesh, "_cache", None)
        normals = np.asarray(mesh.vertex_normals) if cache is not None and "vertex_normals" in cache else None
        return TriangleMesh(np.asarray(mesh.vertices), np.asarray(mesh.faces), normals, object_id,
                            name or str(getattr(mesh, "metadata", {}).get("file_name", "<trimesh>")))


def _read_only(*arrays: np.ndarray) -> None:
    for array in arrays:
        array.setflags(write=False)


@dataclass
class Scene:
    """Rational bicubic Bézier patches and triangle meshes ready for the pipeline.

    patches:    (P, 4, 4, 4) float64, homogeneous ``(w*x, w*y, w*z, w)``, ``[p, j, i]``.
    object_ids: (P,) int32, the object each patch came from.
    camera:     optional camera for ``pixels`` tolerances.
    name:       where the scene came from (for messages).
    meshes:     triangle meshes (PN triangles), each with its own object id.

    Patches are numbered Bézier first, then mesh faces (module docstring).
    """

    patches: np.ndarray
    object_ids: np.ndarray
    camera: Camera | None = None
    name: str = "<scene>"
    meshes: list = field(default_factory=list)

    def __post_init__(self) -> None:
        # Owned, read-only copies: what the pipeline derives from them (adjacency, uploads) is
        # cached per scene (``prepared``), so they must not change under it.
        self.patches = np.array(self.patches, dtype=np.float64, order="C")
        self.object_ids = np.array(self.object_ids, dtype=np.int32, order="C")
        if self.patches.size == 0 and self.patches.shape[1:] != (4, 4, 4):
            self.patches = self.patches.reshape(0, 4, 4, 4)
        if self.patches.ndim != 4 or self.patches.shape[1:] != (4, 4, 4):
            raise SceneError(f"{self.name}: patches must have shape (P, 4, 4, 4), got {self.patches.shape}")
        if self.object_ids.shape != (len(self.patches),):
            raise SceneError(f"{self.name}: need one object id per patch")
        if not np.isfinite(self.patches).all():
            raise SceneError(f"{self.name}: patch {int(np.argmin(np.isfinite(self.patches).all(axis=(1, 2, 3))))}: "
                             "control points must be finite")
        problem = float32_problem(self.patches.reshape(-1, 4))
        if problem:
            raise SceneError(f"{self.name}: patch {problem[0] // 16}: {problem[1]}")
        self.meshes = tuple(self.meshes)
        if not all(isinstance(mesh, TriangleMesh) for mesh in self.meshes):
            raise SceneError(f"{self.name}: meshes must be TriangleMesh objects")
        _read_only(self.patches, self.object_ids)
        self._prepared: dict = {}

    def prepared(self, key, make):
        """``make()``, computed once per key while the scene's arrays stay the same objects.

        The pipeline keeps each patch kind's host input here (adjacency, float32 copies), so
        tessellating a scene again (another tolerance, a camera move) skips that work.  The
        arrays are read-only; assigning new ones starts afresh.
        """
        identity = (id(self.patches), id(self.object_ids),
                    tuple((id(m.vertices), id(m.faces), id(m.normals), m.object_id) for m in self.meshes))
        cached = self._prepared.get(key)
        if cached is None or cached[0] != identity:
            cached = self._prepared[key] = (identity, make())
        return cached[1]

    @property
    def num_patches(self) -> int:
        """All patches: Bézier patches and mesh triangles."""
        return len(self.patches) + self.num_triangles

    @property
    def num_bezier(self) -> int:
        return len(self.patches)

    @property
    def num_triangles(self) -> int:
        """Triangles over all meshes (the PN patches)."""
        return sum(mesh.num_faces for mesh in self.meshes)

    def mesh_first_patch(self, m: int) -> int:
        """Patch id of face 0 of mesh m."""
        return len(self.patches) + sum(mesh.num_faces for mesh in self.meshes[:m])

    @staticmethod
    def from_meshes(meshes, camera: Camera | None = None, name: str = "<scene>") -> "Scene":
        """A scene of triangle meshes only."""
        return Scene(np.zeros((0, 4, 4, 4)), np.zeros(0, np.int32), camera, name, list(meshes))

    @staticmethod
    def from_trimesh(mesh, camera: Camera | None = None, name: str = "<trimesh>", object_id: int = 0) -> "Scene":
        """A scene of one ``trimesh.Trimesh`` (see TriangleMesh.from_trimesh for its normals)."""
        return Scene.from_meshes([TriangleMesh.from_trimesh(mesh, object_id, name)], camera, name)

    def bounding_box(self) -> tuple[np.ndarray, np.ndarray]:
        """(lo (3,), hi (3,)) of every Bézier control point and mesh vertex: it holds the
        surfaces (convex hull property; PN triangles stay near their vertices)."""
        points = [self.points.reshape(-1, 3)] + [np.asarray(m.vertices) for m in self.meshes]
        points = np.concatenate(points) if points else np.zeros((0, 3))
        if not len(points):
            return np.zeros(3), np.zeros(3)
        return points.min(axis=0), points.max(axis=0)

    @property
    def diagonal(self) -> float:
        """Length of the bounding box's diagonal (what ``--eps 0.1%`` is a fraction of)."""
        lo, hi = self.bounding_box()
        return float(np.linalg.norm(hi - lo))

    @property
    def weights(self) -> np.ndarray:
        """(P, 4, 4) weights ``w[p, j, i]``."""
        return self.patches[..., 3]

    @property
    def points(self) -> np.ndarray:
        """(P, 4, 4, 3) Cartesian control points ``P[p, j, i]``."""
        return self.patches[..., :3] / self.patches[..., 3:]

    @staticmethod
    def from_points(points, weights=None, object_ids=None, camera=None, name="<scene>") -> "Scene":
        """Build from Cartesian points (P, 4, 4, 3) and optional weights (P, 4, 4)."""
        points = np.asarray(points, dtype=np.float64)
        weights = np.ones(points.shape[:3]) if weights is None else np.asarray(weights, dtype=np.float64)
        patches = np.concatenate([points * weights[..., None], weights[..., None]], axis=-1)
        if object_ids is None:
            object_ids = np.zeros(len(points), dtype=np.int32)
        return Scene(patches, object_ids, camera, name)
