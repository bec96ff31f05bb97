"""Silhouette refinement with blended levels (issue 12; Dyken, Reimers and Seland, CGF 2008):
silhouetteness per edge (eq. 1-2), fractional levels and the semi-uniform snap, blended vertices
(eq. 9-11), their identities, watertightness and T-junctions for random cameras, and continuity
along a camera path."""
import math

import numpy as np
import pytest
import trimesh

from cltess.backends.opencl.silhouette import SilhouetteRefiner, tessellate_silhouette
from cltess.checks import t_junctions
from cltess.criteria.silhouette import (MIN_BETA, RULE_ALWAYS, RULE_NEVER, RULE_PAIR, edge_levels, silhouette_f,
                                        silhouetteness, wedge_beta)
from cltess.io.camera_path import orbit
from cltess.kinds import BEZIER, PN, FACTOR_SLOTS
from cltess.patterns.silhouette import blended_patch
from cltess.scene import Scene, TriangleMesh
from cltess.surfaces.pn import pn_control_points

from support import closed_torus_grid, torus

M = 3


@pytest.fixture(scope="module")
def sphere():
    return Scene.from_trimesh(trimesh.creation.icosphere(2), name="icosphere")


@pytest.fixture(scope="module")
def refiner(tessellator, sphere):
    return SilhouetteRefiner(tessellator, sphere, max_level=M)


def random_eyes(rng, count, radius=(2.0, 6.0)):
    directions = rng.normal(size=(count, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    return directions * rng.uniform(*radius, size=(count, 1))


# --- silhouetteness ------------------------------------------------------------------------------

@pytest.mark.parametrize("phi", [None, 30.0])
def test_alpha_on_the_device_matches_the_reference(tessellator, sphere, rng, phi):
    refiner = SilhouetteRefiner(tessellator, sphere, max_level=M, phi=phi)
    for eye in random_eyes(rng, 8):
        reference = silhouetteness(refiner.edges, eye)
        device = refiner.alpha(eye)
        # alpha is Lipschitz in f with constant 1 / beta; f in float32 is good to a few 1e-7
        assert np.abs(device - reference).max() <= 4e-6 / refiner.edges.beta.min()


def test_alpha_in_unit_interval_and_one_exactly_at_silhouettes(refiner, rng):
    pairs = refiner.edges.rule == RULE_PAIR
    assert (pairs | (refiner.edges.rule == RULE_NEVER)).all()  # closed and manifold; the 4th slots unused
    for eye in random_eyes(rng, 20):
        alpha, f = silhouetteness(refiner.edges, eye), silhouette_f(refiner.edges, eye)
        assert ((alpha >= 0) & (alpha <= 1)).all()
        assert np.array_equal((alpha == 1)[pairs], (f <= 0)[pairs])
        device = refiner.alpha(eye)
        assert ((device >= 0) & (device <= 1)).all()
        assert (device[pairs & (f < -1e-6)] == 1).all() and (device[pairs & (f > 1e-6)] < 1).all()


def test_alpha_is_continuous_in_the_eye(refiner, rng):
    """max |alpha(x + h) - alpha(x)| shrinks in proportion to h (Lipschitz away from x = v)."""
    eyes = random_eyes(rng, 30)
    steps = rng.normal(size=eyes.shape)
    steps /= np.linalg.norm(steps, axis=1, keepdims=True)
    jumps = {}
    for h in (1e-2, 1e-3, 1e-4):
        jumps[h] = max(np.abs(silhouetteness(refiner.edges, eye + h * step) - silhouetteness(refiner.edges, eye)).max()
                       for eye, step in zip(eyes, steps))
    print("max |d alpha| for eye steps h:", {h: f"{j:.3g}" for h, j in jumps.items()})
    assert jumps[1e-3] <= 0.2 * jumps[1e-2] and jumps[1e-4] <= 0.2 * jumps[1e-3]


@pytest.mark.parametrize("phi", [10.0, 30.0, 60.0])
def test_a_point_on_the_wedge_boundary_gives_beta(tessellator, sphere, phi):
    """x at angle phi from face s's plane, beyond the edge (the paper's Fig. 3): f(x) = beta."""
    refiner = SilhouetteRefiner(tessellator, sphere, max_level=M, phi=phi)
    edges, mesh = refiner.edges, sphere.meshes[0]
    corners = mesh.vertices[mesh.faces]
    for g in np.flatnonzero(edges.rule == RULE_PAIR)[::37]:
        patch_edge = refiner.group_members(g)[0]
        t, e = divmod(patch_edge, FACTOR_SLOTS)
        a, b, c = corners[t, e], corners[t, (e + 1) % 3], corners[t, (e + 2) % 3]
        n_s = edges.normals[g, 0]
        along = (b - a) / np.linalg.norm(b - a)
        into_s = np.cross(n_s, along)
        into_s *= np.sign(np.dot(into_s, c - a))  # in face s's plane, towards its third corner
        direction = math.cos(math.radians(phi)) * -into_s + math.sin(math.radians(phi)) * n_s
        for distance in (0.5, 3.0):
            eye = edges.midpoints[g] + distance * direction
            f = silhouette_f(edges, eye)[g]
            assert f == pytest.approx(edges.beta[g], abs=1e-12)
            assert silhouetteness(edges, eye)[g] == pytest.approx(0.0, abs=1e-9)
    assert np.allclose(edges.beta, wedge_beta(np.arccos(np.clip((edges.normals[:, 0] * edges.normals[:, 1]).sum(1),
                                                                  -1, 1)), phi))


def test_paper_beta_and_the_floor():
    assert np.all(wedge_beta([0.1, 2.0], None) == 0.25)
    assert wedge_beta([math.pi - 0.01], 30.0)[0] == MIN_BETA  # theta + phi > pi


def test_boundary_and_nonmanifold_edges_are_always_silhouettes(tessellator):
    # three triangles on one edge (non-manifold) and their open outer edges
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0.5, 1, 0], [0.5, -1, 0.2], [0.5, 0, 1.0]], float)
    faces = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]])
    scene = Scene.from_meshes([TriangleMesh(vertices, faces)])
    refiner = SilhouetteRefiner(tessellator, scene, max_level=2)
    sizes = refiner.groups.group_sizes
    rule = refiner.edges.rule
    assert (rule[sizes > 2] == RULE_ALWAYS).all() and (sizes > 2).sum() == 1
    used = np.array([refiner.group_members(g)[0] % FACTOR_SLOTS < 3 for g in range(len(sizes))])
    assert (rule[(sizes == 1) & used] == RULE_ALWAYS).all()
    assert (rule[~used] == RULE_NEVER).all()
    frame = refiner.frame([5.0, 5.0, 5.0])
    assert (frame.alpha[rule == RULE_ALWAYS] == 1).all() and (frame.alpha[rule == RULE_NEVER] == 0).all()
    assert (frame.levels[:, :3] == 2).all()  # every edge of these triangles is an outline


def test_bezier_scenes_use_the_control_net_corner_quads(tessellator, rng):
    scene = closed_torus_grid(rng, 6, 4, noise=0.0)
    refiner = SilhouetteRefiner(tessellator, scene, max_level=M)
    assert (refiner.edges.rule == RULE_PAIR).sum() == 2 * 6 * 4  # every edge shared
    pairs = refiner.edges.rule == RULE_PAIR
    cosine = (refiner.edges.normals[pairs, 0] * refiner.edges.normals[pairs, 1]).sum(1)
    assert (cosine < 1 - 1e-6).all()  # the corner quads' normals differ across every edge
    eye = np.array([0.3, 9.0, 2.0])
    frame = refiner.frame(eye)
    assert np.abs(frame.alpha - silhouetteness(refiner.edges, eye)).max() < 1e-4
    assert frame.stats["silhouette_edges"] > 0
    welded = frame.tessellation.welded()
    assert welded.stats["welded_boundary_edges"] == 0 and welded.stats["welded_t_junctions"] == 0


def test_the_rules_are_the_kernels():
    import re
    from cltess.backends.opencl.programs import kernel_dir
    text = (kernel_dir() / "criteria" / "silhouette.h").read_text()
    found = {name: int(value) for name, value in re.findall(r"^#define SILHOUETTE_RULE_(\w+) (\d+)", text, re.MULTILINE)}
    assert found == {"PAIR": RULE_PAIR, "ALWAYS": RULE_ALWAYS, "NEVER": RULE_NEVER}


# --- levels ----------------------------------------------------------------------------------------

@pytest.mark.parametrize("use_eps", [False, True])
@pytest.mark.parametrize("snap", [True, False])
def test_edge_levels_on_the_device_match_the_mirror(tessellator, sphere, rng, use_eps, snap):
    refiner = SilhouetteRefiner(tessellator, sphere, max_level=M, eps=0.002 if use_eps else None, snap=snap)
    eye = random_eyes(rng, 1)[0]
    frame = refiner.frame(eye)
    bound = refiner.plan.host_factors()
    levels, records = edge_levels(frame.alpha, refiner.groups, bound, M, np.full(len(bound), 3), use_eps, snap)
    assert np.array_equal(frame.levels, levels)
    assert np.array_equal(frame.tessellation.factors, np.abs(records))
    if use_eps:  # criteria combine: at least the bound's level on every edge
        assert (frame.levels[:, :3] >= np.log2(np.abs(bound[:, :3]))).all()
        assert (np.abs(records[:, :3]) >= np.abs(bound[:, :3])).all()
    if snap:  # an edge at the larger level of its two patches
        assert (np.abs(records[:, :3]) >= 2.0 ** np.ceil(levels.max(axis=1, keepdims=True))).all()


def test_one_level_per_edge_from_both_sides(refiner, rng):
    frame = refiner.frame(random_eyes(rng, 1)[0])
    flat = frame.levels.reshape(-1)
    for g in range(refiner.edges.num_groups):
        members = refiner.group_members(g)
        assert len(set(flat[members].tobytes()[i:i + 4] for i in range(0, 4 * len(members), 4))) == 1


# --- blended vertices ------------------------------------------------------------------------------

@pytest.mark.parametrize("blend", [True, False])
def test_blended_vertices_match_the_mirror(tessellator, sphere, rng, blend):
    refiner = SilhouetteRefiner(tessellator, sphere, max_level=M, blend=blend)
    frame = refiner.frame(random_eyes(rng, 1, (1.5, 2.5))[0])
    tess = frame.tessellation
    controls = pn_control_points(PN.prepare(sphere).source.astype(np.float64))
    records = np.abs(refiner._records.get())
    start = 0
    checked = 0
    for p in range(0, len(records)):
        count = int((tess.patch_ids == p).sum())
        if p % 5 == 0 or len(set(frame.levels[p, :3])) > 1:
            positions, normals, lod = blended_patch(PN, controls[p], records[p], frame.levels[p], blend)
            assert len(positions) == count
            assert np.abs(tess.positions[start:start + count] - positions).max() < 2e-6
            assert np.abs(tess.normals[start:start + count] - normals).max() < 2e-5
            assert np.array_equal(frame.lod[start:start + count], lod.astype(np.float32))
            checked += 1
        start += count
    assert checked > 20


@pytest.mark.parametrize("level", range(M + 1))
def test_integer_levels_reproduce_the_uniform_pattern_bitwise(tessellator, sphere, refiner, level):
    """alpha = level / M everywhere: every edge at that integer level, so every vertex is F(p) (eq. 9
    with a = 0), bitwise the semi-uniform pattern's uniform P^level; level M is alpha = 1."""
    alpha = np.full(refiner.edges.num_groups, np.float32(level) / np.float32(M), np.float32)
    frame = refiner.frame([0, 0, 5.0], alpha=alpha)
    assert (frame.levels[:, :3] == level).all()
    uniform = tessellator.tessellate(sphere, eps=1e-9, pattern="semi_uniform", max_level=level,
                                     forward_differencing=False)
    assert (frame.tessellation.factors[:, :3] == 1 << level).all()
    for name in ("positions", "normals", "uv", "patch_ids", "triangles"):
        assert np.array_equal(getattr(frame.tessellation, name), getattr(uniform, name)), name
    assert (frame.lod == level).all()


def test_alpha_zero_everywhere_is_the_coarse_mesh(sphere, refiner):
    frame = refiner.frame([0, 0, 5.0], alpha=np.zeros(refiner.edges.num_groups, np.float32))
    tess, mesh = frame.tessellation, sphere.meshes[0]
    assert tess.num_triangles == mesh.num_faces and tess.num_vertices == 3 * mesh.num_faces
    corners = mesh.vertices[mesh.faces].astype(np.float32).reshape(-1, 3)
    assert np.array_equal(tess.positions[tess.triangles].reshape(-1, 3), corners)


def test_non_integer_levels_blend_between_the_two(refiner):
    """S_{m+a} = (1 - a) S_m + a S_{m+1} on the vertices of P^{m+1}: positions move linearly in a."""
    groups = refiner.edges.num_groups
    frames = [refiner.frame([0, 0, 5.0], alpha=np.full(groups, (1 + a) / M, np.float32)) for a in (0.25, 0.5, 0.75)]
    p = [f.tessellation.positions for f in frames]
    assert all(len(x) == len(p[0]) for x in p)
    assert np.abs((p[0] + p[2]) / 2 - p[1]).max() < 1e-6
    assert np.abs(p[0] - p[2]).max() > 1e-3


@pytest.mark.parametrize("level", [1, 2, 3])
def test_levels_just_below_an_integer_approach_it(refiner, level):
    """S_{m+1-} -> S_{m+1}: s = level - h has the topology of s = level (ceil), and its vertices
    move to level's in proportion to h."""
    groups = refiner.edges.num_groups
    at = refiner.frame([0, 0, 5.0], alpha=np.full(groups, np.float32(level) / np.float32(M))).tessellation
    gaps = []
    for h in (1e-2, 1e-3):
        below = refiner.frame([0, 0, 5.0], alpha=np.full(groups, np.float32((level - h) / M))).tessellation
        assert np.array_equal(below.triangles, at.triangles)
        gaps.append(np.abs(below.positions - at.positions).max())
    assert 0 < gaps[1] < 0.2 * gaps[0]


# --- topology ----------------------------------------------------------------------------------------

def closed_scenes(rng):
    return [Scene.from_trimesh(trimesh.creation.icosphere(2), name="icosphere"),
            Scene.from_trimesh(torus(), name="torus"), closed_torus_grid(rng, 6, 4)]


def test_snapped_frames_are_watertight_without_t_junctions_and_unsnapped_have_them(tessellator, rng):
    unsnapped_t_junctions = []
    for scene in closed_scenes(rng):
        lo, hi = scene.bounding_box()
        centre, size = (lo + hi) / 2, np.linalg.norm(hi - lo)
        refiner = SilhouetteRefiner(tessellator, scene, max_level=M)
        for eye in centre + random_eyes(rng, 4, (0.8 * size, 3 * size)):
            frame = refiner.frame(eye)
            welded = frame.tessellation.welded()
            assert welded.stats["welded_boundary_edges"] == 0, scene.name
            assert welded.stats["welded_nonmanifold_edges"] == 0, scene.name
            assert welded.stats["welded_t_junctions"] == 0, scene.name
            assert welded.to_trimesh().is_watertight
            loose = refiner.frame(eye, snap=False).tessellation
            open_edges = loose.welded(check_t_junctions=False).stats["welded_boundary_edges"]
            unsnapped_t_junctions.append((scene.name, len(t_junctions(loose.positions, loose.triangles,
                                                                      loose.object_ids)), open_edges))
    print("without the snap (scene, T-junction vertices, open edges after the weld):", unsnapped_t_junctions)
    # hanging nodes between patches of different levels: the weld leaves open edges, and the exact
    # checker finds the hanging nodes that float32 leaves exactly on the neighbour's edge (every
    # frame of the meshes; the 24-patch Bezier torus can have all its patches at one level)
    assert all(count > 0 and open_edges > 0 for name, count, open_edges in unsnapped_t_junctions
               if name != "torus-grid")
    assert any(open_edges > 0 for name, _, open_edges in unsnapped_t_junctions if name == "torus-grid")


# --- continuity along a camera path ------------------------------------------------------------------

def parametric_distance(a, b) -> float:
    """Largest distance, over the vertices of both tessellations, from a vertex to the other mesh at
    the same patch and (u, v): where the other mesh's triangle holding that (u, v) interpolates to
    (an upper bound of their Hausdorff distance where it is largest at vertices)."""
    worst = 0.0
    for one, other in ((a, b), (b, a)):
        order = np.argsort(other.patch_ids[other.triangles[:, 0]], kind="stable")
        tri = other.triangles[order]
        patch_of = other.patch_ids[tri[:, 0]]
        starts = np.searchsorted(patch_of, np.arange(patch_of.max() + 2))
        for p in np.unique(one.patch_ids):
            mine = np.flatnonzero(one.patch_ids == p)
            t = tri[starts[p]:starts[p + 1]]
            uv = other.uv[t].astype(np.float64)  # (T, 3, 2)
            x = one.uv[mine].astype(np.float64)
            d1, d2 = uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0]
            det = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
            rel = x[:, None] - uv[None, :, 0]
            s = (rel[..., 0] * d2[:, 1] - rel[..., 1] * d2[:, 0]) / det
            r = (d1[:, 0] * rel[..., 1] - d1[:, 1] * rel[..., 0]) / det
            slack = np.minimum(np.minimum(s, r), 1 - s - r)  # >= 0 inside
            best = slack.argmax(axis=1)
            k = np.arange(len(mine))
            s, r = s[k, best], r[k, best]
            corners = other.positions[t[best]].astype(np.float64)
            there = corners[:, 0] + s[:, None] * (corners[:, 1] - corners[:, 0]) + r[:, None] * (corners[:, 2] - corners[:, 0])
            worst = max(worst, float(np.linalg.norm(there - one.positions[mine], axis=1).max()))
    return worst


def orbit_jumps(refiner, step_deg, sweep_deg, blend):
    cameras = orbit([0, 0, 0], 3.0, int(round(sweep_deg / step_deg)) + 1, elevation_deg=25.0, start_deg=10.0,
                    sweep_deg=sweep_deg)
    frames = [refiner.frame(c, blend=blend).tessellation for c in cameras]
    return max(parametric_distance(a, b) for a, b in zip(frames, frames[1:]))


def test_consecutive_frames_move_in_proportion_to_the_step_with_blending(refiner):
    jumps = {(blend, step): orbit_jumps(refiner, step, 4.0, blend) for blend in (True, False) for step in (1.0, 0.25)}
    print(f"largest distance between consecutive frames on an orbit (icosphere, M = {M}):")
    for (blend, step), jump in jumps.items():
        print(f"  blend {blend!s:5}  step {step:4} deg: {jump:.3e}")
    assert jumps[True, 0.25] <= 0.4 * jumps[True, 1.0]  # O(step) with blending
    assert jumps[False, 0.25] > 0.5 * jumps[False, 1.0]  # pops stay pops
    assert jumps[False, 0.25] > 3 * jumps[True, 0.25]


# --- API ---------------------------------------------------------------------------------------------

def test_per_camera_entry_point_prepares_once(tessellator):
    scene = Scene.from_trimesh(trimesh.creation.icosphere(1))
    first = tessellate_silhouette(tessellator, scene, [0, 0, 4.0], max_level=2)
    frames = tessellate_silhouette(tessellator, scene, orbit([0, 0, 0], 4.0, 3), max_level=2)
    assert len(frames) == 3 and first.tessellation.num_triangles > scene.num_triangles
    from cltess.backends.opencl.silhouette import silhouette_refiner
    assert silhouette_refiner(tessellator, scene, max_level=2) is silhouette_refiner(tessellator, scene, max_level=2)


def test_bad_input_is_refused(tessellator, sphere, refiner):
    with pytest.raises(ValueError, match="phi"):
        SilhouetteRefiner(tessellator, sphere, phi=95)
    with pytest.raises(ValueError, match="eye"):
        refiner.frame([0, 0, float("nan")])
    with pytest.raises(ValueError, match="alpha"):
        refiner.frame([0, 0, 5.0], alpha=np.full(refiner.edges.num_groups, 2.0))


# --- crease construction (--sharp-edges crease, section 4) -----------------------------------------

@pytest.fixture(scope="module")
def cylinder(tmp_path_factory):
    path = tmp_path_factory.mktemp("crease") / "cylinder.stl"
    trimesh.creation.cylinder(radius=0.5, height=1.0, sections=12).export(path)
    from cltess.io import load_scene
    return load_scene(path)


def test_crease_keeps_smooth_ends_bitwise_and_follows_the_rim(tessellator, cylinder):
    keep = tessellator.plan(cylinder, eps=1e-3, sharp_edges="keep")
    crease = tessellator.plan(cylinder, eps=1e-3, sharp_edges="crease")
    a, b = keep.parts[0].data["controls"].get(), crease.parts[0].data["controls"].get()
    source = PN.prepare(cylinder, "crease").source
    vertex_normals = source[:, 3:6, :3]
    smooth_ends = moved = 0
    for e in range(3):
        for end, corner, slot in ((0, e, 3 + 2 * e), (1, (e + 1) % 3, 4 + 2 * e)):
            row = source[:, 6 + 2 * e + end]
            smooth = (row[:, 3] == 0) & (row[:, :3] == vertex_normals[:, corner]).all(axis=1)
            assert np.array_equal(a[smooth, slot], b[smooth, slot])  # today's PN, bitwise
            moved += int((a[~smooth, slot] != b[~smooth, slot]).any(axis=1).sum())
            smooth_ends += int(smooth.sum())
    assert 0 < smooth_ends < 6 * len(source) and (source[:, 6:12, 3] == 1).any() and moved > 0
    # the rim (side normal x cap normal = the circle's tangent): the crease curve follows the circle
    radii = {}
    for mode in ("straight", "crease"):
        tess = tessellator.tessellate(cylinder, eps=1e-4, sharp_edges=mode)
        faces = cylinder.meshes[0].vertices[cylinder.meshes[0].faces]
        face_normal = np.cross(faces[:, 1] - faces[:, 0], faces[:, 2] - faces[:, 0])
        side = np.abs(face_normal[:, 2]) < 1e-9 * np.linalg.norm(face_normal, axis=1)
        rim = (np.abs(np.abs(tess.positions[:, 2]) - 0.5) < 1e-6) & side[tess.patch_ids]
        radii[mode] = np.abs(np.linalg.norm(tess.positions[rim, :2], axis=1) - 0.5).max()
        welded = tess.welded()
        assert welded.stats["welded_boundary_edges"] == 0, mode
    print("largest distance of the rim from the circle:", radii)
    assert radii["crease"] < 0.2 * radii["straight"]


def test_crease_curves_are_one_from_both_sides(tessellator, cylinder):
    """Both triangles at a sharp edge build bitwise the same boundary curve (watertight weld)."""
    plan = tessellator.plan(cylinder, eps=1e-3, sharp_edges="crease")
    controls = plan.parts[0].data["controls"].get()
    source = PN.prepare(cylinder, "crease").source
    assert (source[:, 6:12, 3] == 1).any()
    reference = pn_control_points(source.astype(np.float64))
    assert np.abs(reference[:, :10, :3] - controls[:, :10, :3]).max() < 1e-6
    from cltess.kinds.pn import mesh_edge_groups
    mesh = cylinder.meshes[0]
    groups, sharp = mesh_edge_groups(mesh.vertices[mesh.faces], mesh.normals[mesh.faces])
    curves = np.stack([controls[:, [0, 3, 4, 1]], controls[:, [1, 5, 6, 2]], controls[:, [2, 7, 8, 0]]], axis=1)
    curves = curves.reshape(-1, 4, 4)
    for g in np.unique(groups.group_of[sharp]):
        first, second = groups.members[groups.group_start[g]:groups.group_start[g + 1]]
        assert np.array_equal(curves[first], curves[second][::-1])


def test_silhouette_frames_with_creases_stay_closed(tessellator, cylinder, rng):
    refiner = SilhouetteRefiner(tessellator, cylinder, max_level=M, sharp_edges="crease", phi=20.0)
    for eye in random_eyes(rng, 3, (2.0, 4.0)):
        welded = refiner.frame(eye).tessellation.welded()
        assert welded.stats["welded_boundary_edges"] == 0 and welded.stats["welded_t_junctions"] == 0


def test_the_average_centre_of_eq_5(tessellator, sphere, rng):
    """centre="average": b111 is the mean of the six edge control points (eq. 5), every other
    control point bitwise PN's, the patch flatter, the frames still closed."""
    eq4 = SilhouetteRefiner(tessellator, sphere, max_level=M)
    eq5 = SilhouetteRefiner(tessellator, sphere, max_level=M, centre="average")
    a, b = (r.plan.parts[0].data["controls"].get() for r in (eq4, eq5))
    keep = [k for k in range(16) if k != 9]
    assert np.array_equal(a[:, keep], b[:, keep])
    assert np.abs(b[:, 9, :3] - b[:, 3:9, :3].mean(axis=1)).max() < 1e-6
    corners = a[:, :3, :3].astype(np.float64)
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    height = lambda c: np.abs(((c[:, 9, :3] - corners.mean(axis=1)) * normal).sum(1))  # noqa: E731
    assert (height(b) < height(a)).all()
    from cltess.kinds.pn import with_centre
    source = with_centre(PN.prepare(sphere).source, "average")
    assert np.abs(pn_control_points(source.astype(np.float64))[:, :10, :3] - b[:, :10, :3]).max() < 1e-6
    for eye in random_eyes(rng, 2):
        welded = eq5.frame(eye).tessellation.welded()
        assert welded.stats["welded_boundary_edges"] == 0 and welded.stats["welded_t_junctions"] == 0
    with pytest.raises(ValueError, match="centre"):
        SilhouetteRefiner(tessellator, sphere, centre="flat")
