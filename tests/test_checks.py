"""cltess.checks.t_junctions: hand-made meshes with and without hanging nodes, exactness (no
tolerance either way), the semi-uniform pattern's snap on a flat patch grid, and today's
transition-pattern output of closed scenes (zero T-junctions)."""
from pathlib import Path

import numpy as np
import pytest

from cltess.checks import exact_weld, strictly_inside, t_junctions
from cltess.patterns import semi_uniform as su
from support import closed_torus_grid, icosphere, torus

SCENES = Path(__file__).resolve().parent.parent / "scenes"


def flat(points):
    """(x, y) -> float32 (x, y, x + 2y): a tilted plane, exact for dyadic input."""
    points = np.asarray(points, np.float64)
    return np.stack([points[:, 0], points[:, 1], points[:, 0] + 2 * points[:, 1]], 1).astype(np.float32)


# Two unit squares side by side; the right one fans from a point of the shared edge x = 1.
LEFT = [(0, 0), (1, 0), (1, 1), (0, 1)]
LEFT_TRIANGLES = [(0, 1, 2), (0, 2, 3)]


def two_squares(hanging_at=(1, 0.5)):
    right = [(1, 0), (2, 0), (2, 1), (1, 1), hanging_at]
    positions = flat(LEFT + right)  # separate copies per square, welded by the checker
    triangles = LEFT_TRIANGLES + [(4, 5, 8), (5, 6, 8), (6, 7, 8)]
    return positions, np.array(triangles)


def test_a_hanging_node_is_found_and_a_conforming_mesh_has_none():
    positions, triangles = two_squares()
    assert t_junctions(positions, triangles).tolist() == [8]
    conforming = np.array(LEFT_TRIANGLES + [(4, 5, 6), (4, 6, 7)])
    assert t_junctions(positions, conforming).tolist() == []
    # the hanging node as two welded copies: both reported
    positions = np.concatenate([positions, positions[8:9]])
    triangles = np.concatenate([triangles, [[4, 9, 7]]])
    assert t_junctions(positions, triangles).tolist() == [8, 9]


def test_no_tolerance_one_ulp_off_the_edge_is_not_on_it():
    positions, triangles = two_squares()
    positions[8, 0] = np.nextafter(np.float32(1), np.float32(2))
    assert t_junctions(positions, triangles).tolist() == []


def test_objects_do_not_see_each_other():
    positions, triangles = two_squares()
    objects = np.array([0] * 4 + [1] * 5)
    assert t_junctions(positions, triangles, objects).tolist() == []
    assert t_junctions(positions, triangles, np.zeros(9, int)).tolist() == [8]


def test_a_vertex_on_its_own_degenerate_triangle_edge_is_no_t_junction():
    a, v, b, c = (0, 0, 0), (1, 2, 3), (2, 4, 6), (0, 1, 0)
    positions = np.array([a, v, b, c], np.float32)
    assert t_junctions(positions, [[0, 1, 2]]).tolist() == []          # collinear, its own edge
    assert t_junctions(positions, [[0, 1, 2], [0, 2, 3]]).tolist() == [1]  # the neighbour's edge


def test_exact_predicate_on_skew_lines_and_far_apart_exponents():
    a = np.array([[1, 2, 3], [3e-30, 0, 0], [3e-30, 0, 0], [0, 0, 0], [0, 0, 0]], np.float32)
    b = np.array([[5, 10, 15], [1, 0, 0], [1, 0, 0], [1, 1, 1], [1, 1, 1]], np.float32)
    v = np.array([[2, 4, 6], [0.5, 0, 0], [0.5, 1e-30, 0], [1, 1, 1], [0.1, 0.1, 0.1]], np.float32)
    # 1 - 3e-30 is not a float64: that pair takes the Fraction path; a vertex at an end is not
    # inside; float32(0.1) is the same number on all three axes, so exactly on the diagonal
    assert strictly_inside(v, a, b).tolist() == [True, True, False, False, True]
    near = v.copy()
    near[4, 2] = np.nextafter(near[4, 2], np.float32(1))
    assert strictly_inside(near[4:], a[4:], b[4:]).tolist() == [False]


def test_exact_weld_keeps_objects_and_signed_zeros_apart():
    positions = np.array([[0, 0, 0], [0, 0, 0], [-0.0, 0, 0], [0, 0, 0]], np.float32)
    first, remap = exact_weld(positions, [0, 0, 0, 1])
    assert len(first) == 3 and remap[0] == remap[1] and len({remap[0], remap[2], remap[3]}) == 3


def flat_patch_grid(rng, size, snapped):
    """size x size flat unit patches of the semi-uniform pattern, random levels 0..4 per shared
    edge (both sides agree), m = the patch's largest; unsnapped: every edge at m (hanging nodes).
    Returns (positions, triangles, the (u, v) the hanging nodes of the unsnapped grid must have)."""
    horizontal = rng.integers(0, 5, size=(size + 1, size))  # edges v = const
    vertical = rng.integers(0, 5, size=(size, size + 1))    # edges u = const
    levels = [[[horizontal[y, x], vertical[y, x + 1], horizontal[y + 1, x], vertical[y, x]]
               for x in range(size)] for y in range(size)]
    m = np.array([[max(p) for p in row] for row in levels])
    positions, triangles, first = [], [], 0
    for y in range(size):
        for x in range(size):
            points, tris = su.lattice_layout("quad", m[y, x], levels[y][x] if snapped else [m[y, x]] * 4)
            positions.append(points / (1 << m[y, x]) + (x, y))
            triangles.append(tris + first)
            first += len(points)
    hanging = set()
    for (y, x), (y2, x2) in [(((y, x - 1), (y, x))) for y in range(size) for x in range(1, size)] + \
                            [(((y - 1, x), (y, x))) for y in range(1, size) for x in range(size)]:
        fine, coarse = max(m[y, x], m[y2, x2]), min(m[y, x], m[y2, x2])
        for k in range(1, 1 << fine):
            if k % (1 << (fine - coarse)):
                t = y2 + k / (1 << fine) if x2 != x else x2 + k / (1 << fine)
                hanging.add((x2, t) if x2 != x else (t, y2))
    return flat(np.concatenate(positions)), np.concatenate(triangles), hanging


@pytest.mark.parametrize("snapped", [True, False], ids=["snapped", "hanging"])
def test_semi_uniform_patch_grid(rng, snapped):
    """Exactly the hanging nodes are found: none once snapped."""
    positions, triangles, hanging = flat_patch_grid(rng, 6, snapped)
    found = t_junctions(positions, triangles)
    if snapped:
        assert found.tolist() == []
    else:
        assert len(hanging) > 20
        assert sorted(map(tuple, positions[found, :2].tolist())) == sorted(hanging)


def test_sphere_scene_has_no_t_junctions(tessellator):
    from cltess.io import load_scene
    scene = load_scene(SCENES / "sphere.bpt")
    for eps in (2e-2, 1e-3):  # the sphere gets one factor throughout at 1e-2
        tess = tessellator.tessellate(scene, eps=eps)
        assert len(np.unique(tess.factors)) > 1
        assert t_junctions(tess.positions, tess.triangles, tess.object_ids).tolist() == []


@pytest.mark.parametrize("fd", [True, False], ids=["fd", "direct"])
def test_closed_grids_have_no_t_junctions(tessellator, rng, fd):
    for eps in (0.3, 0.1):
        scene = closed_torus_grid(rng, 14, 9, noise=0.15)
        tess = tessellator.tessellate(scene, eps=eps, forward_differencing=fd, max_factor=512)
        transitions = (tess.factors[:, 0] != tess.factors[:, 2]) | (tess.factors[:, 1] != tess.factors[:, 3])
        assert transitions.sum() > scene.num_patches // 4
        assert t_junctions(tess.positions, tess.triangles, tess.object_ids).tolist() == []


@pytest.mark.parametrize("fd", [True, False], ids=["fd", "direct"])
def test_pn_closed_meshes_have_no_t_junctions(tessellator, fd):
    from cltess.scene import Scene
    for mesh in (icosphere(2), torus()):
        tess = tessellator.tessellate(Scene.from_trimesh(mesh), eps=3e-3, forward_differencing=fd)
        assert t_junctions(tess.positions, tess.triangles, tess.object_ids).tolist() == []
