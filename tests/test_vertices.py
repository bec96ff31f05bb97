"""Stage 4 (kernels/vertices.cl, Tessellator.stage_vertices) against reference.tessellate."""
import numpy as np
import pyopencl as cl
import pyopencl.array as cl_array
import pytest

from cltess import reference
from cltess.tessellation import VERTEX_RECORD
from support import as_float32, random_patches
from support.factors import random_factors, random_triangle_factors

FD_POSITION_TOLERANCE = 2e-5  # relative to the patch size, forward differencing vs direct


def device_vertices(tessellator, patches, factors, forward_differencing):
    q = tessellator.queue
    count = len(patches)
    data = cl_array.to_device(q, patches.reshape(count, 16, 4).astype(np.float32))
    final = cl_array.to_device(q, factors)
    objects = cl_array.to_device(q, (np.arange(count) * 7 % 5).astype(np.int32))
    vertex_offsets, _, _ = tessellator.stage_counts(final)
    total = int(vertex_offsets[count].get())
    out, _ = tessellator.stage_vertices(data, final, vertex_offsets, objects, (0, total), (0, count),
                                       forward_differencing)
    return {k: a.get() for k, a in out.items()}


@pytest.mark.parametrize("forward_differencing", [False, True], ids=["direct", "fd"])
def test_vertices_match_reference_on_random_rational_patches(tessellator, rng, forward_differencing):
    patches = random_patches(rng, 300, spread=1.0)
    factors = random_factors(rng, 300, high=40)
    got = device_vertices(tessellator, patches, factors, forward_differencing)
    expected = reference.tessellate(as_float32(patches), factors, (np.arange(300) * 7 % 5))
    assert np.array_equal(got["patch_ids"], expected["patch_ids"])
    assert np.array_equal(got["object_ids"], expected["object_ids"])
    assert np.abs(got["uv"] - expected["uv"]).max() < 1e-6
    scale = np.abs(patches[..., :3] / patches[..., 3:]).max()
    tolerance = (2e-6 if not forward_differencing else FD_POSITION_TOLERANCE) * scale
    assert np.abs(got["positions"] - expected["positions"]).max() < tolerance
    # Normals: unit, and the same direction (cosine) except at rare near-degenerate points.
    assert np.allclose(np.linalg.norm(got["normals"], axis=1), 1, atol=1e-5)
    cosine = (got["normals"] * expected["normals"]).sum(1)
    assert np.quantile(cosine, 0.999) > 1 - 1e-6 and cosine.min() > 0.99


def test_forward_differencing_agrees_with_direct_evaluation(tessellator, rng):
    """The stated tolerance of FD: max position difference / patch size below 2e-5 at factor 64."""
    patches = random_patches(rng, 200, spread=1.0)
    factors = np.full((200, 4), 64, np.int32)
    fd = device_vertices(tessellator, patches, factors, True)
    direct = device_vertices(tessellator, patches, factors, False)
    scale = np.abs(patches[..., :3] / patches[..., 3:]).max()
    difference = np.abs(fd["positions"] - direct["positions"]).max() / scale
    print(f"forward differencing vs direct at factor 64: {difference:.2e} of the patch size")
    assert difference < FD_POSITION_TOLERANCE
    assert np.array_equal(fd["uv"], direct["uv"])


def test_boundary_points_are_symmetric_and_corners_exact(tessellator, rng):
    """A patch and its mirror (u -> 1 - u) walk edge 0 in opposite directions: the points on it
    must come out bitwise equal, corners included (docs/design.md section 4)."""
    patch = random_patches(rng, 1, spread=1.0)[0]
    mirrored = patch[:, ::-1]
    for f in (1, 2, 3, 7, 8, 33, 64):
        out = device_vertices(tessellator, np.stack([patch, mirrored]), np.full((2, 4), f, np.int32), True)
        ring = out["positions"].reshape(2, -1, 3)[:, :4 * f]
        assert np.array_equal(ring[0, :f + 1], ring[1, :f + 1][::-1]), f
        corners = patch[[0, 0, 3, 3], [0, 3, 3, 0]].astype(np.float32)
        assert np.allclose(ring[0, [0, f, 2 * f, 3 * f]], corners[:, :3] / corners[:, 3:], rtol=1e-6, atol=0)


# --- PN triangles (pn_vertices against reference.pn_tessellate) --------------------------------

PN_FD_POSITION_TOLERANCE = 2e-6  # relative to the triangle's size, forward differencing vs direct


def device_pn_vertices(tessellator, triangles, factors, forward_differencing):
    from cltess.pipeline import PN

    q = tessellator.queue
    count = len(triangles)
    controls, _, _, _ = tessellator.stage_pn_factors(cl_array.to_device(q, triangles), 1.0, None, None, 64)
    final = cl_array.to_device(q, factors)
    objects = cl_array.to_device(q, (np.arange(count) * 7 % 5).astype(np.int32))
    vertex_offsets, _, _ = tessellator.stage_counts(final, kind=PN)
    total = int(vertex_offsets[count].get())
    out, _ = tessellator.stage_vertices(controls, final, vertex_offsets, objects, (0, total), (0, count),
                                       forward_differencing, kind=PN)
    return {k: a.get() for k, a in out.items()}, controls.get()


@pytest.mark.parametrize("forward_differencing", [False, True], ids=["direct", "fd"])
def test_pn_vertices_match_reference_on_random_triangles(tessellator, rng, forward_differencing):
    from support import random_pn_triangles

    triangles = random_pn_triangles(rng, 300, spread=1.0)
    factors = random_triangle_factors(rng, 300, high=40)
    got, controls = device_pn_vertices(tessellator, triangles, factors, forward_differencing)
    expected = reference.pn_tessellate(controls.astype(np.float64), factors, np.arange(300) * 7 % 5)
    assert np.array_equal(got["patch_ids"], expected["patch_ids"])
    assert np.array_equal(got["object_ids"], expected["object_ids"])
    assert np.abs(got["uv"] - expected["uv"]).max() < 1e-6
    scale = np.abs(triangles[:, :3, :3]).max()
    assert np.abs(got["positions"] - expected["positions"]).max() < 2e-6 * scale
    assert np.allclose(np.linalg.norm(got["normals"], axis=1), 1, atol=1e-5)
    cosine = (got["normals"] * expected["normals"]).sum(1)
    assert np.quantile(cosine, 0.999) > 1 - 1e-6 and cosine.min() > 0.99


def test_pn_forward_differencing_agrees_with_direct_evaluation(tessellator, rng):
    """The stated tolerance of FD on PN triangles at factor 64."""
    from support import random_pn_triangles

    triangles = random_pn_triangles(rng, 200, spread=1.0)
    factors = np.zeros((200, 4), np.int32)
    factors[:, :3] = 64
    fd, _ = device_pn_vertices(tessellator, triangles, factors, True)
    direct, _ = device_pn_vertices(tessellator, triangles, factors, False)
    size = np.ptp(triangles[:, :3, :3], axis=1).max()
    difference = np.abs(fd["positions"] - direct["positions"]).max() / size
    print(f"PN forward differencing vs direct at factor 64: {difference:.2e} of the triangle size")
    assert difference < PN_FD_POSITION_TOLERANCE
    assert (fd["normals"] * direct["normals"]).sum(1).min() > 1 - 1e-5
    assert np.array_equal(fd["uv"], direct["uv"])


def test_pn_boundary_points_are_bitwise_shared_and_corners_exact(tessellator, rng):
    """Two triangles sharing the edge P1-P2, the second meeting it from the other end and as its
    edge 1 (corners rotated): the points on it come out bitwise equal (docs/design.md section 4)."""
    from support import random_pn_triangles

    a = random_pn_triangles(rng, 1, spread=1.0)[0]
    b = random_pn_triangles(rng, 1, spread=1.0)[0]
    # b's corners (X, P2, P1): its edge 1 runs P2 -> P1 with the same end normals.
    b[1, :3], b[2, :3] = a[1, :3], a[0, :3]
    b[4, :3], b[5, :3] = a[4, :3], a[3, :3]
    b[8, :3], b[9, :3] = a[7, :3], a[6, :3]  # edge 1 end normals: at P2, at P1
    for f in (1, 2, 3, 7, 8, 33, 64):
        factors = np.array([[f, 5, 9, 0], [3, f, 6, 0]], np.int32)
        out, _ = device_pn_vertices(tessellator, np.stack([a, b]), factors, True)
        first_b = int((out["patch_ids"] == 0).sum())
        edge_a = out["positions"][:f + 1]  # ring of a: edge 0 points 0..f (f = corner P2)
        edge_b = out["positions"][first_b + 3:first_b + 3 + f + 1]  # ring of b: edge 1 starts at 3
        assert np.array_equal(edge_a, edge_b[::-1]), f
        assert np.array_equal(edge_a[[0, f]], a[[0, 1], :3])


# --- eight points at a time (kernels/common.h CLTESS_LANES) -----------------------------------

def lanes_vertices(tessellator, patches, factors, lanes: int):
    """Stage 4's per-patch kernel (stages/vertices.cl, forward differencing) built with
    -D CLTESS_LANES=lanes, on the patches: its vertex arrays."""
    from cltess.backends.opencl.programs import composition, correctly_rounded_division, program_text
    from cltess.kinds import BEZIER

    ctx, q = tessellator.context, tessellator.queue
    headers, defines = composition("vertices", kind=BEZIER, pattern=BEZIER.pattern)
    source, options = program_text("vertices", headers, {**defines, "CLTESS_LANES": lanes})
    program = cl.Program(ctx, source).build(options=options + correctly_rounded_division(ctx.devices[0]))
    count = len(patches)
    final = cl_array.to_device(q, factors)
    vertex_offsets, _, _ = tessellator.stage_counts(final)
    total = int(vertex_offsets[count].get())
    out = {name: cl_array.zeros(q, (total, *shape), dtype) for name, dtype, shape in VERTEX_RECORD}
    program.vertices(q, (-(-count // 64) * 64,), (64,),
                     cl_array.to_device(q, patches.reshape(count, 16, 4).astype(np.float32)).data, final.data,
                     vertex_offsets.data, cl_array.to_device(q, np.arange(count, dtype=np.int32) % 5).data,
                     np.uint32(0), np.uint32(count), np.uint32(0), np.uint64(0), np.int32(1), np.uint64(total),
                     *(a.data for a in out.values()))
    return {name: a.get() for name, a in out.items()}


def folded_patch() -> np.ndarray:
    """A flat patch folded along u = 1/2: x's controls along u are 0, 1, 0, 1, so B_u.x is 3 (1 -
    4 u (1 - u)), zero there, and t_u x t_v vanishes along that line (surface_normal's fall-backs
    for some lanes of a row and not others)."""
    u, v = np.meshgrid([0.0, 1.0, 0.0, 1.0], np.arange(4) / 3.0, indexing="xy")
    return np.stack([u, v, 0.1 * u * v, np.ones_like(u)], -1)


@pytest.mark.parametrize("runtime", ["Portable Computing Language", "Intel(R) OpenCL"], ids=["pocl", "intel"])
def test_lanes_are_the_points_one_by_one(rng, runtime):
    """Stage 4's interior rows and ring edges KIND_LANES points at once (stages/rows.h,
    kinds/bezier.h: on by default on PoCL for x86-64 and on Intel's CPU runtime) write bitwise
    what one point at a time writes, at every row and edge length around the lanes (7 points: no
    lanes; 8: one set; 9 .. 15: the last set overlaps the one before; 16 .. 63; transition
    patterns' edges of other lengths), and KIND_LANES rows at once where a patch has that many of
    at least 9 points (put_row_block: 8 .. 62 rows, the last block overlapping the one before),
    with the lanes that take surface_normal's fall-backs: a patch folded so that t_u x t_v
    vanishes along a line across its rows (some lanes of a row, not the others) and one along a
    row (some rows of a block, not the others), a patch flat on a line (every lane), patches
    with a collapsed edge, and squared normals below
    FLT_MIN (coordinates of 1e-10) or infinite (1e10) where t_u x t_v does not vanish against the
    tangents: length's scaled branches.  The lanes compute the builtins in the forms of the
    runtimes where they are the default (common.h), so this runs on those two."""
    from cltess.pipeline import Tessellator
    try:
        engine = Tessellator(runtime)
    except Exception as error:  # noqa: BLE001  (not installed here)
        pytest.skip(f"no {runtime} device: {error}")
    if runtime.startswith("Portable") and "x86_64" not in engine.device.version:
        pytest.skip("PoCL's lanes are its forms on x86-64")
    patches = [random_patches(rng, 120, spread=1.0)]
    patches.append(np.stack([folded_patch()] * 8))
    patches.append(np.stack([folded_patch().transpose(1, 0, 2)] * 8))  # folded along v = 1/2
    patches.append(np.stack([folded_patch() * [1.0, 0.0, 0.0, 1.0]] * 2))  # on the line y = z = 0
    collapsed = random_patches(rng, 6, spread=1.0)
    collapsed[:, 0] = collapsed[:, 0, :1]  # edge 0 (v = 0) one point, as the teapot's lid
    patches.append(collapsed)
    for scale in (1e-10, 1e10):
        scaled = random_patches(rng, 6, spread=1.0)
        scaled[..., :3] *= scale
        patches.append(scaled)
    patches = np.concatenate(patches)
    count = len(patches)
    factors = random_factors(rng, count, high=64)
    whole = rng.random(count) < 0.5  # uniform rows of every length from 1 to 63 points
    factors[whole] = (np.arange(count) % 64 + 1)[whole, None]
    factors[-26:] = 16
    factors[128:136] = np.array([10, 12, 16, 20, 24, 32, 40, 64])[:, None]  # the row v = 1/2 in one block or two
    with_lanes = lanes_vertices(engine, patches, factors, 1)
    one_by_one = lanes_vertices(engine, patches, factors, 0)
    for name in with_lanes:
        differ = with_lanes[name].view(np.uint32) != one_by_one[name].view(np.uint32)
        assert not differ.any(), f"{name}: {differ.any(axis=-1).sum() if differ.ndim > 1 else differ.sum()} differ"
    normals = with_lanes["normals"]
    assert (np.abs(normals - [0.0, 0.0, 1.0]).max(axis=1) == 0).sum() > 100  # the flat patches' +z
