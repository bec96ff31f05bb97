"""Pictures of a tessellation without a display: a small z-buffer rasteriser in NumPy and a PNG
writer (zlib), so ``cltess render`` and ``--preview`` need nothing beyond the core install.

Triangles are added in any number of blocks (a streamed run adds each batch), shaded by their
vertex normals interpolated across them (or flat): front faces (counter-clockwise on screen, the side the
surface faces) in a light grey-blue, or coloured by edge factor; back faces in red, so an
inside-out surface shows at a glance.  Rendered at twice the size and averaged 2 x 2 (anti-aliasing).

Rasterising (vectorised over candidate pixels): each triangle's screen bounding box gives its
candidate pixel centres; the edge functions (Pineda 1988) say which lie inside; 1/depth,
which is affine in screen space, is interpolated and the nearest kept per pixel.
"""
from __future__ import annotations

import struct
import zlib
from dataclasses import dataclass

import numpy as np

from .io.writing import atomic_write

__all__ = ["Rasteriser", "View", "factor_colours", "render", "view_for", "write_png"]

SUPERSAMPLE = 2
#: Candidate pixels handled at once (memory: about 100 bytes each).
CANDIDATES_PER_BLOCK = 2_000_000
BACKGROUND = np.array([1.0, 1.0, 1.0])
FRONT = np.array([0.72, 0.78, 0.86])
BACK = np.array([0.85, 0.25, 0.2])
# A perceptually ordered ramp (viridis' end points and three between), for factor colours.
RAMP = np.array([[0.267, 0.005, 0.329], [0.231, 0.322, 0.545], [0.129, 0.569, 0.553],
                 [0.369, 0.788, 0.384], [0.993, 0.906, 0.144]])


@dataclass
class View:
    """A pinhole camera: world -> camera ``matrix`` (4x4, looking down -z), vertical field of
    view, image size in pixels."""

    matrix: np.ndarray
    fov_y_deg: float
    width: int
    height: int


def view_for(scene, width: int = 800, height: int | None = None, use_camera: bool = True) -> View:
    """The scene's camera if it has one (its aspect; ``width`` sets the size), else a view from
    the front-right and above (z up) that frames the scene's bounding box."""
    from .scene import Camera

    camera = scene.camera if use_camera else None
    if camera is not None:
        height = height or max(1, round(width * camera.height / camera.width))
        return View(camera.view_matrix(), camera.fov_y_deg, width, height)
    height = height or max(1, round(width * 3 / 4))
    lo, hi = scene.bounding_box()
    centre, radius = (lo + hi) / 2, max(float(np.linalg.norm(hi - lo)) / 2, 1e-30)
    fov = 30.0
    fit = min(np.tan(np.radians(fov) / 2), np.tan(np.radians(fov) / 2) * width / height)
    direction = np.array([0.55, -1.0, 0.6]) / np.linalg.norm([0.55, -1.0, 0.6])
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    distance = radius / fit  # the bounding sphere fits; then move in until the box's corners do
    for _ in range(4):
        matrix = Camera(eye=centre + direction * distance, target=centre).view_matrix()
        camera = corners @ matrix[:3, :3].T + matrix[:3, 3]
        depth = np.maximum(-camera[:, 2], 1e-9 * radius)
        spread = max(np.abs(camera[:, 0] / depth).max() / (np.tan(np.radians(fov) / 2) * width / height),
                     np.abs(camera[:, 1] / depth).max() / np.tan(np.radians(fov) / 2))
        distance = max(distance * spread * 1.1, radius * 1.2)
    eye = centre + direction * distance
    return View(Camera(eye=eye, target=centre).view_matrix(), fov, width, height)


def factor_colours(factors: np.ndarray, patch_of_triangle: np.ndarray, largest: float) -> np.ndarray:
    """(T, 3) colours: each triangle's patch's largest edge factor on the ramp, log2 scale from
    1 to ``largest``."""
    level = np.log2(np.maximum(factors.max(axis=1)[patch_of_triangle], 1)) / max(np.log2(max(largest, 2)), 1)
    position = np.clip(level, 0, 1) * (len(RAMP) - 1)
    low = np.minimum(position.astype(int), len(RAMP) - 2)
    t = (position - low)[:, None]
    return RAMP[low] * (1 - t) + RAMP[low + 1] * t


class Rasteriser:
    """Accumulates triangles into a z-buffer; ``image()`` shades it."""

    def __init__(self, view: View):
        self.view = view
        self.width, self.height = view.width * SUPERSAMPLE, view.height * SUPERSAMPLE
        self.inverse_depth = np.zeros(self.width * self.height)  # 0: nothing (infinitely far)
        self.colour = np.tile(BACKGROUND, (self.width * self.height, 1))
        self.triangles = 0

    def add(self, positions: np.ndarray, triangles: np.ndarray, colours: np.ndarray | None = None,
            normals: np.ndarray | None = None) -> None:
        """Draw triangles (T, 3) indexing positions (V, 3); colours (T, 3) in 0..1 for the front
        faces (default a light grey-blue); normals (V, 3): shade smoothly with them, interpolated
        across each triangle (default: flat, each triangle's own normal)."""
        positions = np.asarray(positions, np.float64)
        triangles = np.asarray(triangles, np.int64).reshape(-1, 3)
        corners = positions[triangles]  # (T, 3, 3)
        if not len(corners):
            return
        matrix = self.view.matrix
        camera = corners @ matrix[:3, :3].T + matrix[:3, 3]
        depth = -camera[..., 2]
        visible = (depth > 1e-9).all(axis=1)  # no clipping: triangles across the eye plane are left out
        scale = self.height / (2 * np.tan(np.radians(self.view.fov_y_deg) / 2))
        with np.errstate(divide="ignore", invalid="ignore"):
            x = self.width / 2 + scale * camera[..., 0] / depth
            y = self.height / 2 - scale * camera[..., 1] / depth
        face = _unit(np.cross(camera[:, 1] - camera[:, 0], camera[:, 2] - camera[:, 0]))
        view_ray = _unit(-camera.mean(axis=1))
        front = (face * view_ray).sum(axis=1) > 0
        if normals is None:
            corner_normals = np.repeat(face[:, None], 3, axis=1)
        else:
            corner_normals = np.asarray(normals, np.float64)[triangles] @ matrix[:3, :3].T
        # shade the side that is seen: back faces with their normals turned towards the eye
        corner_normals = np.where(front[:, None, None], corner_normals, -corner_normals)
        base = np.tile(FRONT, (len(corners), 1)) if colours is None else np.asarray(colours, np.float64)
        base = np.where(front[:, None], base, BACK)
        self._draw(x[visible], y[visible], 1 / depth[visible], base[visible], corner_normals[visible],
                   view_ray[visible])
        self.triangles += int(visible.sum())

    def _draw(self, x, y, inverse_depth, *shading) -> None:
        x0 = np.clip(np.floor(x.min(axis=1) - 0.5), 0, self.width).astype(np.int64)
        x1 = np.clip(np.ceil(x.max(axis=1) - 0.5), -1, self.width - 1).astype(np.int64)
        y0 = np.clip(np.floor(y.min(axis=1) - 0.5), 0, self.height).astype(np.int64)
        y1 = np.clip(np.ceil(y.max(axis=1) - 0.5), -1, self.height - 1).astype(np.int64)
        columns, rows = np.maximum(x1 - x0 + 1, 0), np.maximum(y1 - y0 + 1, 0)
        counts = columns * rows
        ends = np.cumsum(counts)
        start = 0
        while start < len(counts):
            # triangles start..stop-1 give about CANDIDATES_PER_BLOCK candidates (at least one triangle)
            base = ends[start - 1] if start else 0
            stop = max(int(np.searchsorted(ends, base + CANDIDATES_PER_BLOCK, side="right")), start + 1)
            self._block(slice(start, stop), x, y, inverse_depth, shading, x0, y0, columns, counts)
            start = stop

    def _block(self, block, x, y, inverse_depth, shading, x0, y0, columns, counts) -> None:
        count = counts[block]
        triangle = np.repeat(np.arange(block.start, block.stop), count)
        if not len(triangle):
            return
        k = np.arange(len(triangle)) - np.repeat(np.cumsum(count) - count, count)
        px = x0[triangle] + k % columns[triangle]
        py = y0[triangle] + k // columns[triangle]
        cx, cy = px + 0.5, py + 0.5
        xs, ys = x[triangle], y[triangle]
        # edge functions: w_i = signed area of (corner i+1, corner i+2, pixel centre)
        w = np.stack([(xs[:, (i + 2) % 3] - xs[:, (i + 1) % 3]) * (cy - ys[:, (i + 1) % 3])
                      - (ys[:, (i + 2) % 3] - ys[:, (i + 1) % 3]) * (cx - xs[:, (i + 1) % 3])
                      for i in range(3)], axis=1)
        area = w.sum(axis=1)
        w = w * np.sign(area)[:, None]
        inside = (w >= 0).all(axis=1) & (area != 0)
        if not inside.any():
            return
        w, triangle, area = w[inside], triangle[inside], np.abs(area[inside])
        pixel = py[inside] * self.width + px[inside]
        depth = (w * inverse_depth[triangle]).sum(axis=1) / area
        np.maximum.at(self.inverse_depth, pixel, depth)
        won = depth >= self.inverse_depth[pixel]
        base, corner_normals, view_ray = shading
        triangle, weights = triangle[won], w[won] / area[won, None]
        normal = _unit(np.einsum("nk,nkc->nc", weights, corner_normals[triangle]))
        self.colour[pixel[won]] = np.clip(base[triangle] * _light(normal, view_ray[triangle])[:, None], 0, 1)

    def image(self) -> np.ndarray:
        """(height, width, 3) uint8, the supersampled buffer averaged down."""
        s = SUPERSAMPLE
        colour = self.colour.reshape(self.view.height, s, self.view.width, s, 3).mean(axis=(1, 3))
        return np.round(colour * 255).astype(np.uint8)


KEY_LIGHT = np.array([-0.4, 0.6, 0.7]) / np.linalg.norm([-0.4, 0.6, 0.7])


def _light(normal: np.ndarray, view_ray: np.ndarray) -> np.ndarray:
    """Lambert in camera space: ambient, a headlight and a key light from the upper left."""
    return 0.25 + 0.5 * np.abs((normal * view_ray).sum(axis=1)) + 0.3 * np.clip(normal @ KEY_LIGHT, 0, 1)


def _unit(a: np.ndarray) -> np.ndarray:
    length = np.linalg.norm(a, axis=-1, keepdims=True)
    return np.where(length > 0, a / np.where(length > 0, length, 1), 0)


def render(mesh, view: View, colours: np.ndarray | None = None, smooth: bool = True) -> np.ndarray:
    """(height, width, 3) uint8 image of a Tessellation or WeldedMesh (anything with positions,
    normals and triangles); smooth: shade with the vertex normals, else flat."""
    rasteriser = Rasteriser(view)
    rasteriser.add(mesh.positions, mesh.triangles, colours, mesh.normals if smooth else None)
    return rasteriser.image()


def write_png(path, image: np.ndarray) -> None:
    """An 8-bit RGB PNG (no filter, zlib level 9), written atomically."""
    image = np.ascontiguousarray(image, np.uint8)
    height, width, _ = image.shape
    raw = np.concatenate([np.zeros((height, 1), np.uint8), image.reshape(height, -1)], axis=1).tobytes()

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    data = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))
    with atomic_write(path, "wb") as handle:
        handle.write(data)
