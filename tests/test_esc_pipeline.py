"""ESC through the pipeline (--pattern esc): stage 1 masks, the OR crack pass, the device against
the NumPy mirror, watertightness, monotonicity in eps and the measured error (docs/esc.md)."""
from pathlib import Path

import numpy as np

from cltess.backends.numpy import NumpyBackend
from cltess.bound import worst_bound_ratio
from cltess.checks import t_junctions
from cltess.crack.adjacency import edge_groups
from cltess.criteria.tolerance import ObjectSpace
from cltess.esc.masks import candidate_tested, esc_stage, patch_levels, patch_steps
from cltess.criteria.zheng_sederberg import zs_factors
from cltess.io import load_scene
from cltess.patterns import esc
from cltess.request import Request
from cltess.scene import Camera
from conftest import BOUND_RATIOS
from support import closed_torus_grid, weld_exact

SCENES = Path(__file__).resolve().parent.parent / "scenes"


def test_device_equals_the_mirror_on_the_teacup(tessellator):
    scene = load_scene(SCENES / "teacup.bez")
    for eps in (1e-3, 1e-2, 3e-2, 1.0):
        request = Request.of(eps=eps, pattern="esc")
        device, host = tessellator.tessellate(scene, request), NumpyBackend().tessellate(scene, request)
        assert np.array_equal(device.factors, host.factors)
        assert np.array_equal(device.triangles, host.triangles)
        assert np.abs(device.uv - host.uv).max() < 1e-6
        assert np.abs(device.positions - host.positions).max() < 1e-5 * np.abs(host.positions).max()
    assert len(tessellator.tessellate(scene, eps=1e-6, pattern="esc").triangles) == 288 * scene.num_patches
    assert len(tessellator.tessellate(scene, eps=1e3, pattern="esc").triangles) <= 18 * scene.num_patches


def test_max_level_selects_the_candidate_lattice(tessellator):
    scene = load_scene(SCENES / "teacup.bez")
    for level in (0, 1, 2, 3):
        tess = tessellator.tessellate(scene, eps=1e-6, pattern="esc", max_level=level)
        assert len(tess.triangles) == 18 * (level + 1) ** 2 * scene.num_patches
    capped = tessellator.tessellate(scene, eps=1e-6, pattern="esc", max_level=6)
    assert len(capped.triangles) == 288 * scene.num_patches  # records hold L <= 3


def test_boundary_masks_agree_before_the_or(rng):
    """Both patches at a shared edge store bitwise the same canonical boundary bits (object space),
    so the OR only matters where tolerances differ; flipped sides store REVERSED."""
    scene = closed_torus_grid(rng, 6, 4, noise=0.2)
    groups = edge_groups(scene.patches)
    for eps in (1e-3, 1e-2, 5e-2):
        records, _ = esc_stage(scene.patches, ObjectSpace(eps), 3)
        flat = records.reshape(-1)
        for g in range(groups.num_groups):
            members = groups.members[groups.group_start[g]:groups.group_start[g + 1]]
            if len(members) == 2:
                a, b = flat[members]
                assert a & esc.BOUNDARY_BITS == b & esc.BOUNDARY_BITS
                assert bool(a & esc.REVERSED) == bool(groups.flipped[members[0]])
                assert bool(b & esc.REVERSED) == bool(groups.flipped[members[1]])


def closed_scenes(rng):
    yield "torus_grid", closed_torus_grid(rng, 8, 5, noise=0.15)
    yield "sphere", load_scene(SCENES / "sphere.bpt")
    yield "torus", load_scene(SCENES / "torus.bpt")


def assert_closed(tess):
    mesh = weld_exact(tess.positions, tess.triangles)
    assert mesh.is_watertight
    assert mesh.is_winding_consistent
    assert len(t_junctions(tess.positions, tess.triangles)) == 0


def test_closed_scenes_are_watertight_for_random_eps(tessellator, rng):
    for name, scene in closed_scenes(rng):
        for eps in 10.0 ** rng.uniform(-4, -1, 3):
            tess = tessellator.tessellate(scene, eps=float(eps), pattern="esc")
            assert_closed(tess)
            BOUND_RATIOS[f"esc {name} eps={eps:.2g}"] = worst_bound_ratio(scene, tess, eps=float(eps),
                                                                           max_triangles=4000)


def test_screen_space_tolerances_differ_and_the_or_closes_them(tessellator, rng):
    """Pixels: every patch its own eps, so the two sides test a shared edge against different
    thresholds; the OR pass makes them agree."""
    scene = closed_torus_grid(rng, 8, 5, noise=0.15)
    scene.camera = Camera(eye=np.array([0.0, -7.0, 3.0]), target=np.zeros(3), fov_y_deg=60, width=800, height=600)
    for pixels in (0.5, 2.0, 8.0):
        request = Request.of(pixels=pixels, pattern="esc")
        plan = NumpyBackend().plan(scene, request)
        records, _ = esc_stage(scene.patches, request.tolerance_for(scene), 3)
        assert not np.array_equal(np.abs(plan.factors), records)  # the OR changed something
        tess = tessellator.tessellate(scene, request)
        assert tess.stats["culled"] == 0
        assert_closed(tess)


def test_smaller_eps_never_removes_a_candidate(tessellator, rng):
    scene = closed_torus_grid(rng, 6, 4, noise=0.2)
    previous_masks, previous_count = None, None
    for eps in sorted(10.0 ** rng.uniform(-4, 0, 8), reverse=True):
        tess = tessellator.tessellate(scene, eps=float(eps), pattern="esc")
        masks = np.stack([esc.unpack(np.abs(f))[1] for f in tess.factors])
        if previous_masks is not None:
            assert ((masks & previous_masks) == previous_masks).all()
            assert len(tess.triangles) >= previous_count
        previous_masks, previous_count = masks, len(tess.triangles)


def test_strips_of_the_records_expand_to_the_triangles():
    from cltess.strips import expand_strips
    tess = NumpyBackend().plan(load_scene(SCENES / "teapot.bez"), Request.of(eps=1e-2, pattern="esc"))
    for f in tess.factors[16:32]:  # the lid and the bottom: collapsed edges
        _, triangles = esc.layout(f)
        strips = esc.strips(f)
        expanded = expand_strips(strips, drop_degenerate=True)
        assert sorted(map(tuple, np.sort(expanded, 1))) == sorted(map(tuple, np.sort(triangles, 1)))


def test_collapsed_edges_leave_no_triangle_on_them(tessellator):
    """The teapot's lid and bottom have collapsed edges (poles): ESC leaves out the triangles with
    a side on them, as the other patterns do, and the device agrees with the mirror."""
    scene = load_scene(SCENES / "teapot.bez")
    request = Request.of(eps=1e-2, pattern="esc")
    device, host = tessellator.tessellate(scene, request), NumpyBackend().tessellate(scene, request)
    assert edge_groups(scene.patches).collapsed_edges.sum() == 8
    assert np.array_equal(device.triangles, host.triangles)
    mesh = weld_exact(device.positions, device.triangles)
    assert len(mesh.faces) == len(device.triangles)  # no triangle collapsed onto a pole
    assert mesh.is_winding_consistent


def candidate_distances(patch, level):
    """(33, L) float64 |V_B - V_S| of every candidate (canonical directions), as masks.py tests them."""
    from cltess.esc.masks import curve_points, edge_reversed
    from cltess.scene import boundary_curves
    from cltess.surfaces.bezier import evaluate
    n, m = level + 1, 3 * (level + 1)
    out = np.zeros((33, level))
    k = np.arange(n + 1)
    for c, (start, end) in enumerate(esc.COARSE_EDGES):
        points = evaluate(patch, (n * start[0] + k * (end[0] - start[0])) / m,
                          (n * start[1] + k * (end[1] - start[1])) / m)[0]
        chord = points[0] * (n - k[1:-1, None]) / n + points[-1] * k[1:-1, None] / n
        out[c] = np.linalg.norm(points[1:-1] - chord, axis=1)
    for e in range(4):  # boundary edges from the curve, in its canonical direction
        controls = boundary_curves(patch[None])[0, e]
        if edge_reversed(controls.astype(np.float32)):
            controls = controls[::-1]
        points = curve_points(controls, np.arange(m + 1) / m)
        ccw = []
        for s in range(3):
            seg = points[s * n:s * n + n + 1]
            chord = seg[0] * (n - k[1:-1, None]) / n + seg[-1] * k[1:-1, None] / n
            ccw.append(np.linalg.norm(seg[1:-1] - chord, axis=1))
        # canonical segment s is the patch edge's segment s, or 2 - s reversed
        flip = edge_reversed(boundary_curves(patch[None])[0, e].astype(np.float32))
        for s, c in enumerate(esc.PATCH_EDGE_COARSE[e]):
            d = ccw[2 - s][::-1] if flip else ccw[s]  # counter-clockwise order along the edge
            out[c] = d[::-1] if esc.PATCH_EDGE_AGAINST[e] else d
    return out


def test_stage_1_on_random_patches_equals_the_mirror_but_at_the_threshold(tessellator, rng):
    """Device stage 1 (float32, NBM inside) against the float64 mirror on random rational patches:
    every record equal, except candidate bits whose distance is within 1e-4 of the patch size of
    eps (where float32 may round either way)."""
    from cltess.scene import Scene
    from support import random_patches
    patches = random_patches(rng, 150, spread=1.0).astype(np.float32).astype(np.float64)
    scene = Scene(patches, np.zeros(len(patches), np.int32), name="random")
    for eps in (3e-3, 3e-2):
        request = Request.of(eps=eps, pattern="esc")
        device = tessellator.plan(scene, request).factors.get()
        host = NumpyBackend().plan(scene, request).factors
        differ = np.flatnonzero((device != host).any(axis=1))
        assert len(differ) < 0.05 * len(patches)
        levels = host_levels(scene, request)
        for p in range(10):  # the distances below are the ones the mirror tested (its own level's)
            tested = sum(1 << (k - 1) for k in (1, 2, 3) if candidate_tested(k, levels[p] + 1, 3))
            bits = ((candidate_distances(patches[p], 3) > eps) * (1 << np.arange(3))).sum(axis=1)
            assert np.array_equal(bits & tested, esc.unpack(np.abs(host[p]))[1])
        for p in differ:
            _, got = esc.unpack(np.abs(device[p]))
            _, expected = esc.unpack(np.abs(host[p]))
            distances = candidate_distances(patches[p], 3)
            size = np.abs(patches[p, ..., :3] / patches[p, ..., 3:]).max()
            for c, k in zip(*np.nonzero(((got ^ expected)[:, None] >> np.arange(3)) & 1)):
                assert abs(distances[c, k] - eps) < 1e-4 * size, (p, c, k, distances[c, k], eps)


# --- per-patch levels (docs/esc.md decision 5) -------------------------------------------------

def host_levels(scene, request):
    """(P,) the levels L_p the mirror gives the scene's patches (from the float64 bound)."""
    patches = np.asarray(scene.patches, np.float64).reshape(-1, 4, 4, 4)
    points = (patches[..., :3] / patches[..., 3:]).reshape(len(patches), -1, 3)
    eps, culled = request.tolerance_for(scene).reference(points.min(axis=1), points.max(axis=1))
    return patch_levels(zs_factors(patches, eps, culled, request.max_factor)[0], request.max_level)


def test_patch_levels_lie_on_the_lattice_and_grow_with_the_bound():
    """L_p + 1 divides L + 1 (its candidates are the lattice's), 3 (L_p + 1) segments meet the
    factor where the lattice allows, and the tested candidates only grow with the factor."""
    assert [patch_steps(f, 3) - 1 for f in (0, 1, 3, 4, 6, 7, 12, 13, 64)] == [0, 0, 0, 1, 1, 3, 3, 3, 3]
    assert [patch_steps(f, 2) - 1 for f in (1, 3, 4, 9, 10)] == [0, 0, 2, 2, 2]
    for level in range(4):
        n, previous = level + 1, set()
        for factor in range(0, 3 * n + 5):
            steps = patch_steps(factor, level)
            assert n % steps == 0 and (3 * steps >= factor or steps == n)
            tested = {k for k in range(1, n) if candidate_tested(k, steps, level)}
            assert previous <= tested and len(tested) == steps - 1
            previous = tested
        assert previous == set(range(1, n))


def test_per_patch_levels_device_equals_the_mirror_and_test_a_subset(tessellator):
    """Eps where the teacup's patches get different levels: device records and triangles equal
    the mirror's; each patch's masks are a subset of the all-L-3 test's, only on its level's
    candidates."""
    scene = load_scene(SCENES / "teacup.bez")
    for eps in (0.0142, 0.05):
        request = Request.of(eps=eps, pattern="esc")
        levels = host_levels(scene, request)
        assert len(set(levels.tolist())) >= 2, levels
        device, host = tessellator.tessellate(scene, request), NumpyBackend().tessellate(scene, request)
        assert np.array_equal(device.factors, host.factors)
        assert np.array_equal(device.triangles, host.triangles)
        own, _ = esc_stage(scene.patches, request.tolerance_for(scene), 3)
        full, _ = esc_stage(scene.patches, request.tolerance_for(scene), 3, levels=np.full(scene.num_patches, 3))
        for p in range(scene.num_patches):
            mine, everything = esc.unpack(own[p])[1], esc.unpack(full[p])[1]
            tested = sum(1 << (k - 1) for k in (1, 2, 3) if candidate_tested(k, levels[p] + 1, 3))
            assert np.array_equal(mine, everything & tested)


def test_one_level_variant_equals_the_mirror_and_inserts_a_superset(tessellator, monkeypatch):
    """esc.ESC_ONE_LEVEL (bench/esc.py's baseline: every patch at L): device == mirror, and its
    masks contain the per-patch levels' masks."""
    from cltess.patterns import PATTERNS
    monkeypatch.setitem(PATTERNS, "esc_one_level", esc.ESC_ONE_LEVEL)
    scene = load_scene(SCENES / "teacup.bez")
    for eps in (0.0142, 0.05):
        one = Request.of(eps=eps, pattern="esc_one_level")
        device, host = tessellator.tessellate(scene, one), NumpyBackend().tessellate(scene, one)
        assert np.array_equal(device.factors, host.factors)
        assert np.array_equal(device.triangles, host.triangles)
        per_patch = tessellator.tessellate(scene, eps=eps, pattern="esc").factors
        for a, b in zip(per_patch, device.factors):
            mine, everything = esc.unpack(np.abs(a))[1], esc.unpack(np.abs(b))[1]
            assert ((mine & everything) == mine).all()
        assert len(tessellator.tessellate(scene, eps=eps, pattern="esc").triangles) <= len(device.triangles)


def test_random_patch_levels_stay_watertight(tessellator, rng, monkeypatch):
    """Random levels per patch (every divisor level of the lattice, neighbours differing), through
    the mirror's stage 1 and OR, then the device's stages 4-5 (Tessellator.upload_plan): bitwise
    watertight with 0 T-junctions; a shared edge's bits equal on both sides after the OR."""
    import dataclasses

    import cltess.esc.masks as masks
    for max_level in (1, 2, 3):
        allowed = [d - 1 for d in range(1, max_level + 2) if (max_level + 1) % d == 0]
        monkeypatch.setattr(masks, "patch_levels", lambda f, level: rng.choice(allowed, len(f)))
        for name, scene in closed_scenes(rng):
            for eps in 10.0 ** rng.uniform(-3.5, -1.5, 2):
                request = Request.of(eps=float(eps), pattern="esc", max_level=max_level)
                host = NumpyBackend().plan(scene, request)
                device = tessellator.plan(scene, request).to_host()
                device = dataclasses.replace(device, factors=host.factors, vertex_offsets=host.vertex_offsets,
                                             index_offsets=host.index_offsets, num_vertices=host.num_vertices,
                                             num_indices=host.num_indices)
                tess = tessellator.emit(tessellator.upload_plan(device), 0, scene.num_patches)
                assert_closed(tess)
                groups = edge_groups(scene.patches)
                flat = np.abs(host.factors).reshape(-1)
                for g in range(groups.num_groups):
                    members = groups.members[groups.group_start[g]:groups.group_start[g + 1]]
                    assert len(set((flat[members] & esc.BOUNDARY_BITS).tolist())) == 1


def test_max_level_1_to_3_closed_and_monotone(tessellator, rng):
    """--max-level 1, 2, 3 (and the default) with per-patch levels: watertight, 0 T-junctions,
    device == mirror, triangle count monotone in eps."""
    scene = closed_torus_grid(rng, 6, 4, noise=0.2)
    for max_level in (1, 2, 3, None):
        options = {} if max_level is None else {"max_level": max_level}
        previous = None
        for eps in sorted(10.0 ** rng.uniform(-3.5, -0.5, 3), reverse=True):
            request = Request.of(eps=float(eps), pattern="esc", **options)
            device, host = tessellator.tessellate(scene, request), NumpyBackend().tessellate(scene, request)
            assert np.array_equal(device.factors, host.factors)
            assert np.array_equal(device.triangles, host.triangles)
            assert_closed(device)
            assert previous is None or len(device.triangles) >= previous
            previous = len(device.triangles)


# --- strips from the device (patterns/esc.h pattern_strips, cltess/backends/opencl/strips.py) ---

def test_device_strips_equal_the_mirror_on_random_records(tessellator, rng):
    """Random records (levels 0..3, every mask density, collapsed edges, culled): the strip counts
    and the strips of stages 3 and 5 equal esc.strip_indices, a batch in the middle the same slice,
    and they expand to exactly stage 5's triangle list (order and winding included)."""
    from types import SimpleNamespace

    import pyopencl.array as cl_array

    from cltess.backends.opencl.strips import emit_strips, strip_offsets
    from cltess.strips import expand_strips
    from support.factors import random_esc_records
    factors = random_esc_records(rng, 400)
    count = len(factors)
    device = cl_array.to_device(tessellator.queue, factors)
    vertex_offsets, index_offsets, _ = tessellator.stage_counts(device, [(esc.ESC, 0, count)])
    part = SimpleNamespace(pattern=esc.ESC, base=0, count=count)
    offsets, _ = strip_offsets(tessellator, device, [part])
    expected_local = [esc.strip_indices(f) for f in factors]
    assert np.array_equal(np.diff(offsets.get()), [len(s) for s in expected_local])
    plan = SimpleNamespace(num_patches=count, num_strip_indices=int(offsets[count].get()), strip_offsets=offsets,
                           parts=[part], factors=device, vertex_offsets=vertex_offsets)
    strips, _ = emit_strips(tessellator, plan, 0, count)
    firsts = vertex_offsets.get()
    expected = np.concatenate([np.where(s == 0xFFFFFFFF, s, s + firsts[p]) for p, s in enumerate(expected_local)])
    assert np.array_equal(strips.astype(np.int64), expected[:-1])
    middle, _ = emit_strips(tessellator, plan, 100, 300)
    host = offsets.get()
    assert np.array_equal(middle, strips[host[100]:host[300] - 1])
    triangles, _ = tessellator.stage_indices(device, vertex_offsets, index_offsets,
                                             (0, int(index_offsets[count].get())), (0, count), kind=esc.ESC)
    assert np.array_equal(expand_strips(strips, drop_degenerate=True), triangles.get())


def test_strips_on_scenes_equal_the_mirror_expand_to_the_triangles_and_keep_in_npz(tessellator, rng, tmp_path):
    """--pattern esc fills Tessellation.strips on the device: equal to the NumPy backend's, expanding
    (zero-area rule-4 copies and collapsed sides dropped) to the triangle list in its order, so with
    its winding; the NPZ keeps them; a batched run gives the same strips."""
    from cltess.io.npz import load_npz, write_npz
    from cltess.strips import expand_strips, split_strips
    scenes = [("teapot", load_scene(SCENES / "teapot.bez"), Request.of(eps=1e-2, pattern="esc")),
              ("teacup", load_scene(SCENES / "teacup.bez"), Request.of(eps=0.05, pattern="esc")),
              ("torus_grid", closed_torus_grid(rng, 6, 4, noise=0.2), Request.of(eps=3e-3, pattern="esc", max_level=2))]
    for name, scene, request in scenes:
        device, host = tessellator.tessellate(scene, request), NumpyBackend().tessellate(scene, request)
        assert device.strips is not None and len(device.strips), name
        assert np.array_equal(device.strips, host.strips), name
        assert np.array_equal(expand_strips(device.strips, drop_degenerate=True), device.triangles), name
        assert all(len(s) >= 3 for s in split_strips(device.strips))
        write_npz(device, tmp_path / f"{name}.npz")
        assert np.array_equal(load_npz(tmp_path / f"{name}.npz").strips, device.strips)
    batched = list(tessellator.tessellate_in_batches(scene, 20_000, request)[1])
    assert len(batched) > 1
    joined = [b.strips for b in batched if len(b.strips)]
    parts = [joined[0]] + [np.concatenate([[0xFFFFFFFF], s]) for s in joined[1:]]
    assert np.array_equal(np.concatenate(parts).astype(np.uint32), device.strips)
