"""The scene data model: what every reader produces and every pipeline stage consumes.

A scene is a batch of rational bicubic Bézier patches in homogeneous form plus an optional
camera.  Patch layout (DESIGN.md section 2, issue 2): ``patches[p, j, i] = (w*x, w*y, w*z, w)``,
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

from dataclasses import dataclass, field

import numpy as np


class SceneError(ValueError):
    """Bad input: the message names the file and the line, patch or field at fault."""


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
    """A pinhole camera for screen-space tolerances (DESIGN.md section 7)."""

    eye: np.ndarray
    target: np.ndarray
    up: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    fov_y_deg: float = 45.0
    width: int = 1024
    height: int = 768
    near: float = 0.01
    far: float = 1.0e4

    def view_matrix(self) -> np.ndarray:
        """World -> camera (4, 4); the camera looks down its -z axis, right-handed."""
        forward = np.asarray(self.target, float) - np.asarray(self.eye, float)
        forward /= np.linalg.norm(forward)
        right = np.cross(forward, np.asarray(self.up, float))
        right /= np.linalg.norm(right)
        true_up = np.cross(right, forward)
        view = np.eye(4)
        view[0, :3], view[1, :3], view[2, :3] = right, true_up, -forward
        view[:3, 3] = -view[:3, :3] @ np.asarray(self.eye, float)
        return view

    def pixel_size_at_unit_depth(self) -> float:
        """World length of one pixel at depth 1: ``2 tan(fov_y / 2) / height``."""
        return 2.0 * np.tan(np.radians(self.fov_y_deg) / 2.0) / self.height


@dataclass
class Scene:
    """Rational bicubic Bézier patches ready for the pipeline.

    patches:    (P, 4, 4, 4) float64, homogeneous ``(w*x, w*y, w*z, w)``, ``[p, j, i]``.
    object_ids: (P,) int32, the object each patch came from.
    camera:     optional camera for ``pixels`` tolerances.
    name:       where the scene came from (for messages).
    """

    patches: np.ndarray
    object_ids: np.ndarray
    camera: Camera | None = None
    name: str = "<scene>"

    def __post_init__(self) -> None:
        self.patches = np.ascontiguousarray(self.patches, dtype=np.float64)
        self.object_ids = np.ascontiguousarray(self.object_ids, dtype=np.int32)
        if self.patches.ndim != 4 or self.patches.shape[1:] != (4, 4, 4):
            raise SceneError(f"{self.name}: patches must have shape (P, 4, 4, 4), got {self.patches.shape}")
        if self.object_ids.shape != (len(self.patches),):
            raise SceneError(f"{self.name}: need one object id per patch")

    @property
    def num_patches(self) -> int:
        return len(self.patches)

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
