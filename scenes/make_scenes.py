"""Write the generated scenes into scenes/ (deterministic; run from the repo root):

    python scenes/make_scenes.py

sphere.bpt      an exact unit sphere: 32 rational bicubic patches (docs/design.md section 2)
torus.bpt       an exact torus (radii 3 and 1): 16 rational bicubic patches, one per pair of quarter circles
table.bpt       a flat 8 x 6 grid of bicubic patches, the tea table's top
teapots.json    16 teapot instances on a 4 x 4 grid, with a camera
tea_table.json  the teapot, six cups with saucers and six spoons on the table (332 patches)
"""
from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))
from cltess.io import write_bpt  # noqa: E402

# --------------------------------------------------------------------------- exact sphere


def elevate_to_cubic(net: np.ndarray, axis: int) -> np.ndarray:
    """Degree-elevate a quadratic net to cubic along ``axis`` (homogeneous points):
    ``c0 = b0, c1 = (b0 + 2 b1) / 3, c2 = (2 b1 + b2) / 3, c3 = b2``."""
    b0, b1, b2 = np.moveaxis(net, axis, 0)
    return np.moveaxis(np.stack([b0, (b0 + 2 * b1) / 3, (2 * b1 + b2) / 3, b2]), 0, axis)


def split_half(net: np.ndarray, axis: int) -> tuple[np.ndarray, np.ndarray]:
    """De Casteljau at t = 1/2 along ``axis`` (homogeneous points).  ``(a + b) * 0.5`` is
    symmetric in a and b, so a reversed curve splits into bitwise the same halves."""
    p0, p1, p2, p3 = np.moveaxis(net, axis, 0)
    a, b, c = (p0 + p1) * 0.5, (p1 + p2) * 0.5, (p2 + p3) * 0.5
    d, e = (a + b) * 0.5, (b + c) * 0.5
    f = (d + e) * 0.5
    return np.moveaxis(np.stack([p0, a, d, f]), 0, axis), np.moveaxis(np.stack([f, e, c, p3]), 0, axis)


def sphere_patches() -> np.ndarray:
    """(32, 4, 4, 4) homogeneous patches of the exact unit sphere, outward normals.

    One octant (x, y, z >= 0) is the tensor product of two quarter-circle arcs, rational
    quadratics with weights 1, sqrt(2)/2, 1: the parallel (cos u, sin u) along i and the
    meridian (r, z) = (cos v, sin v) along j, so ``b_ij = (C_i.x M_j.r, C_i.y M_j.r,
    C_i.w M_j.z, C_i.w M_j.w)``.  It is elevated to bicubic and split into 4; the other 7
    octants are exact signed permutations of it, so shared control points are bitwise equal.
    """
    s = math.sqrt(2.0) / 2.0
    arc = np.array([[1.0, 0.0, 1.0], [s, s, s], [0.0, 1.0, 1.0]])  # homogeneous (x w, y w, w)
    circle, meridian = arc, arc  # (cos, sin, w) along u; (r, z, w) along v
    net = np.empty((3, 3, 4))  # [j, i, xyzw]
    for j in range(3):
        for i in range(3):
            r, z, wv = meridian[j]
            cx, cy, wu = circle[i]
            net[j, i] = (cx * r, cy * r, wu * z, wu * wv)
    net = elevate_to_cubic(elevate_to_cubic(net, axis=1), axis=0)  # u (i) then v (j)

    octant = []
    for half_u in split_half(net, axis=1):
        octant.extend(split_half(half_u, axis=0))
    octant = np.array(octant)  # (4, 4, 4, 4): [patch, j, i, xyzw]

    patches = []
    for lower in (False, True):
        for quarter in range(4):  # rotate by quarter * 90 degrees about z: exact swaps/negations
            q = octant.copy()
            for _ in range(quarter):
                x, y = q[..., 0].copy(), q[..., 1].copy()
                q[..., 0], q[..., 1] = -y, x
            if lower:  # mirror z (det -1), then reverse u so the normals still point outward
                q[..., 2] = -q[..., 2]
                q = q[:, :, ::-1]
            patches.append(q)
    return np.concatenate(patches) + 0.0  # + 0.0 turns -0.0 into 0.0


QUARTER_TURNS = [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)]  # (cos, sin) of k * 90 degrees, exact


def quarter_arc(centre: tuple[float, float], radius: float, k: int) -> np.ndarray:
    """(3, 3) homogeneous (x w, y w, w) rational quadratic of the circle's quarter from k * 90 to
    (k + 1) * 90 degrees: ends weight 1, the corner (the two end tangents' meeting point) weight
    sqrt(2)/2.  Every number is a sum of exact ones, so the end of arc k is bitwise the start of
    arc k + 1."""
    (c0, s0), (c1, s1) = QUARTER_TURNS[k % 4], QUARTER_TURNS[(k + 1) % 4]
    cx, cy = centre
    w = math.sqrt(2.0) / 2.0
    points = [(cx + radius * c0, cy + radius * s0, 1.0), (cx + radius * (c0 + c1), cy + radius * (s0 + s1), w),
              (cx + radius * c1, cy + radius * s1, 1.0)]
    return np.array([(x * wk, y * wk, wk) for x, y, wk in points]) + 0.0


def torus_patches(major: float = 3.0, minor: float = 1.0) -> np.ndarray:
    """(16, 4, 4, 4) homogeneous patches of the exact torus ((R + r cos v) cos u, (R + r cos v) sin u,
    r sin v), outward normals.  Patch (a, b) is the tensor product of quarter a of the unit circle
    (C, along i = u) and quarter b of the tube's circle about (R, 0) in the (rho, z) plane (M, along
    j = v): ``b_ij = (C_i.x M_j.rho, C_i.y M_j.rho, C_i.w M_j.z, C_i.w M_j.w)``, elevated to
    bicubic.  Shared boundary rows are products of bitwise equal numbers: bitwise equal."""
    patches = []
    for b in range(4):
        meridian = quarter_arc((major, 0.0), minor, b)
        for a in range(4):
            circle = quarter_arc((0.0, 0.0), 1.0, a)
            net = np.empty((3, 3, 4))  # [j, i, xyzw]
            for j in range(3):
                for i in range(3):
                    rho, z, wv = meridian[j]
                    cx, cy, wu = circle[i]
                    net[j, i] = (cx * rho, cy * rho, wu * z, wu * wv)
            patches.append(elevate_to_cubic(elevate_to_cubic(net, axis=1), axis=0))
    return np.array(patches) + 0.0


def evaluate(patches: np.ndarray, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Positions (P, K, 3) of rational patches (P, 4, 4, 4) at parameters u, v: (K,)."""
    def bernstein(t):
        t = np.asarray(t, float)[:, None]
        k = np.arange(4)
        return np.array([1, 3, 3, 1]) * t**k * (1 - t) ** (3 - k)  # (K, 4)

    bu, bv = bernstein(u), bernstein(v)
    hom = np.einsum("kj,ki,pjic->pkc", bv, bu, patches)
    return hom[..., :3] / hom[..., 3:]


# --------------------------------------------------------------------------- table


def grid_patches(x0: float, x1: float, y0: float, y1: float, nx: int, ny: int, z: float = 0.0) -> np.ndarray:
    """(nx * ny, 4, 4, 4) flat bilinear-as-bicubic patches tiling [x0, x1] x [y0, y1] at height z,
    u along +x, v along +y (normal +z).  Control points come from one shared coordinate
    grid, so neighbours share their boundary points bitwise."""
    xs = np.linspace(x0, x1, 3 * nx + 1)
    ys = np.linspace(y0, y1, 3 * ny + 1)
    patches = np.zeros((ny, nx, 4, 4, 4))
    for b in range(ny):
        for a in range(nx):
            X, Y = np.meshgrid(xs[3 * a : 3 * a + 4], ys[3 * b : 3 * b + 4])  # [j, i]
            patches[b, a, ..., 0], patches[b, a, ..., 1] = X, Y
    patches[..., 2] = z
    patches[..., 3] = 1.0
    return patches.reshape(-1, 4, 4, 4)


# --------------------------------------------------------------------------- transforms


def _cos_sin(degrees: float) -> tuple[float, float]:
    if degrees % 90 == 0:  # exact for quarter turns
        return [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)][int(degrees // 90) % 4]
    return math.cos(math.radians(degrees)), math.sin(math.radians(degrees))


def translate(x: float, y: float, z: float) -> np.ndarray:
    m = np.eye(4)
    m[:3, 3] = (x, y, z)
    return m


def rotate_z(degrees: float) -> np.ndarray:
    c, s = _cos_sin(degrees)
    m = np.eye(4)
    m[:2, :2] = [[c, -s], [s, c]]
    return m


def rotate_x(degrees: float) -> np.ndarray:
    c, s = _cos_sin(degrees)
    m = np.eye(4)
    m[1:3, 1:3] = [[c, -s], [s, c]]
    return m


def scale(k: float) -> np.ndarray:
    return np.diag([k, k, k, 1.0])


def compose(*matrices: np.ndarray) -> np.ndarray:
    """compose(A, B, C) = A @ B @ C: C applies first."""
    out = np.eye(4)
    for m in matrices:
        out = out @ m
    return out + 0.0


def obj(file: str, transform: np.ndarray | None = None, object_id: int | None = None) -> dict:
    entry = {"file": file}
    if transform is not None:
        entry["transform"] = [[float(x) for x in row] for row in transform]
    if object_id is not None:
        entry["object_id"] = object_id
    return entry


def dump_scene(path: Path, objects: list[dict], camera: dict) -> None:
    """JSON with one line per object and per matrix row (repr floats: exact round trip)."""
    lines = ['{', '  "objects": [']
    for k, entry in enumerate(objects):
        parts = [f'"file": {json.dumps(entry["file"])}']
        if "transform" in entry:
            rows = ",\n      ".join(json.dumps(row) for row in entry["transform"])
            parts.append(f'"transform": [\n      {rows}]')
        if "object_id" in entry:
            parts.append(f'"object_id": {entry["object_id"]}')
        lines.append("    {" + ", ".join(parts) + "}" + ("," if k + 1 < len(objects) else ""))
    lines.append("  ],")
    lines.append(f'  "camera": {json.dumps(camera)}')
    lines.append("}")
    text = "\n".join(lines) + "\n"
    json.loads(text)  # stays valid JSON
    path.write_text(text)


# --------------------------------------------------------------------------- scenes


def teapots_scene() -> tuple[list[dict], dict]:
    """16 teapots on a 4 x 4 grid (10 apart), turned and scaled; object ids 11..44 (row, col)."""
    objects = []
    scales = [1.0, 0.8, 1.2, 0.9]
    for row in range(4):
        for col in range(4):
            k = 4 * row + col
            transform = compose(
                translate(10.0 * col - 15.0, 10.0 * row - 15.0, 0.0),
                rotate_z(30.0 * k),
                scale(scales[(row + col) % 4]),
            )
            objects.append(obj("teapot.bez", transform, 10 * (row + 1) + col + 1))
    camera = {"eye": [0.0, -40.0, 30.0], "target": [0.0, 1.5, 0.0], "up": [0.0, 0.0, 1.0],
              "fov_y_deg": 45.0, "width": 1024, "height": 768, "near": 0.1, "far": 1000.0}
    return objects, camera


TABLE = dict(x0=-9.0, x1=9.0, y0=-6.0, y1=6.0, nx=8, ny=6)
LIFT = 0.005  # objects float a hair above the table top (no coplanar faces)


def tea_table_scene() -> tuple[list[dict], dict]:
    """Table (id 0), teapot (id 1), six cups with saucers (ids 2..7), six spoons (ids 8..13).

    teapot.bez is z-up; teacup.bez is y-up (a cup on a saucer, handle towards -x) and is
    stood up by a +90 degree turn about x; teaspoon.bez lies along y (bowl tip at y = -1)."""
    objects = [obj("table.bpt", None, 0), obj("teapot.bez", translate(0.0, 0.0, LIFT), 1)]
    cup_scale, spoon_scale = 1.2, 2.0
    spoon_lift = LIFT + 0.107143 * spoon_scale  # the spoon's lowest point is z = -0.107143
    settings = [(x, side) for side in (-1, 1) for x in (-6.0, 0.0, 6.0)]  # near side y < 0
    for k, (x, side) in enumerate(settings):
        y = 4.2 * side
        # handle and spoon on the diner's right: +x on the near side, -x on the far side
        turn = 180.0 if side < 0 else 0.0
        objects.append(obj("teacup.bez", compose(translate(x, y, LIFT), rotate_z(turn), rotate_x(90.0), scale(cup_scale)), 2 + k))
    for k, (x, side) in enumerate(settings):
        y = 4.2 * side
        spoon = compose(translate(x - 1.7 * side, y - 0.8 * side, spoon_lift), rotate_z(0.0 if side < 0 else 180.0), scale(spoon_scale))
        objects.append(obj("teaspoon.bez", spoon, 8 + k))
    camera = {"eye": [0.0, -21.0, 14.0], "target": [0.0, 0.0, 0.8], "up": [0.0, 0.0, 1.0],
              "fov_y_deg": 45.0, "width": 1024, "height": 768, "near": 0.1, "far": 1000.0}
    return objects, camera


def write_sample_mesh(path: Path) -> None:
    """A coarse 12-sided cylinder (radius 1, height 2, 48 triangles) as binary STL, the sample
    triangle mesh: no normals in the file, 30 degrees between side facets (smooth under the
    default --crease-angle 40), 90 degrees at the rims (kept sharp)."""
    import trimesh

    trimesh.creation.cylinder(radius=1.0, height=2.0, sections=12).export(path)


def main() -> None:
    write_sample_mesh(HERE / "cylinder.stl")
    write_bpt(HERE / "sphere.bpt", sphere_patches())
    write_bpt(HERE / "torus.bpt", torus_patches())
    write_bpt(HERE / "table.bpt", grid_patches(**TABLE))
    dump_scene(HERE / "teapots.json", *teapots_scene())
    dump_scene(HERE / "tea_table.json", *tea_table_scene())
    for name in ("cylinder.stl", "sphere.bpt", "torus.bpt", "table.bpt", "teapots.json", "tea_table.json"):
        print(f"wrote scenes/{name}")


if __name__ == "__main__":
    main()
