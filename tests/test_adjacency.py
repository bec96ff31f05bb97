"""Patch-edge adjacency (cltess/adjacency.py, docs/design.md section 4) on the shipped models,
the exact sphere, hand-made grids and random re-orderings of grids."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cltess.adjacency import EdgeGroups, edge_groups
from cltess.io import load_scene
from cltess.scene import boundary_curves
from support import SCENES, load_make_scenes

make_scenes = load_make_scenes()


def check_invariants(groups: EdgeGroups, patches: np.ndarray) -> None:
    """CSR consistency, and every group's members are the same curve (either direction)."""
    num_edges = 4 * len(patches)
    for name in ("group_of", "group_start", "members"):
        assert getattr(groups, name).dtype == np.int32, name
    assert groups.group_of.shape == groups.members.shape == (num_edges,)
    assert np.array_equal(np.sort(groups.members), np.arange(num_edges))  # a permutation
    assert groups.group_start[0] == 0 and groups.group_start[-1] == num_edges
    sizes = np.diff(groups.group_start)
    assert (sizes >= 1).all()
    assert np.array_equal(groups.group_of[groups.members], np.repeat(np.arange(groups.num_groups), sizes))
    # groups are numbered by their first patch-edge, members ascending
    firsts = groups.members[groups.group_start[:-1]]
    assert (np.diff(firsts) > 0).all()
    curves = boundary_curves(patches).reshape(num_edges, 16) + 0.0
    backward = boundary_curves(patches)[:, :, ::-1].reshape(num_edges, 16) + 0.0
    canonical = np.where(groups.flipped[:, None], backward, curves)
    assert np.array_equal(canonical, canonical[firsts][groups.group_of])
    assert groups.shared + groups.boundary + groups.nonmanifold + groups.collapsed == groups.num_groups
    assert isinstance(groups.describe(), str) and "\n" not in groups.describe()


def stats(groups: EdgeGroups) -> tuple:
    return (groups.shared, groups.boundary, groups.collapsed, groups.nonmanifold, groups.self_glued, groups.reversed_pairs)


# ----------------------------------------------------------------------------- real models


@pytest.mark.parametrize(
    "name, expected",
    [
        # shared, boundary, collapsed, nonmanifold, self_glued, reversed_pairs
        ("teapot.bez", (52, 16, 8, 0, 0, 0)),
        ("teapot.bpt", (52, 16, 8, 0, 0, 0)),
        ("teacup.bez", (46, 12, 0, 0, 0, 0)),
        ("teaspoon.bez", (28, 8, 0, 0, 0, 0)),
        ("torus.bpt", (32, 0, 0, 0, 0, 0)),  # closed: 64 patch-edges in 32 pairs
    ],
)
def test_shipped_models(name, expected):
    patches = load_scene(SCENES / name).patches
    groups = edge_groups(patches)
    check_invariants(groups, patches)
    assert stats(groups) == expected


def test_teapot_open_edges():
    """The teapot's open boundary: body rim, lid rim (a gap between them), the ends of the
    handle and spout; collapsed: the lid's top and the bottom's centre."""
    groups = edge_groups(load_scene(SCENES / "teapot.bez").patches)
    singles = groups.members[groups.group_start[:-1][np.diff(groups.group_start) == 1]]
    edges = sorted(divmod(int(pe), 4) for pe in singles)
    body_rim = [(p, 0) for p in range(4)]
    handle_ends = [(12, 0), (13, 0), (14, 2), (15, 2)]
    spout_ends = [(16, 0), (17, 0), (18, 2), (19, 2)]
    lid_top = [(p, 0) for p in range(20, 24)]
    lid_rim = [(p, 2) for p in range(24, 28)]
    bottom_centre = [(p, 0) for p in range(28, 32)]
    assert edges == sorted(body_rim + handle_ends + spout_ends + lid_top + lid_rim + bottom_centre)


def test_bigguy_by_position():
    """bigguy's patches share no vertex indices: adjacency comes from equal positions.
    It holds 344 exact duplicate patches (the non-manifold groups and same-direction pairs);
    without them it is consistently oriented, but many neighbours differ by ~1e-7..1e-6
    (12-digit rounding) or meet at T-junctions, so they stay 'boundary' under exact matching."""
    patches = load_scene(SCENES / "bigguy.bez").patches
    assert len(patches) == 3570
    groups = edge_groups(patches)
    check_invariants(groups, patches)
    assert stats(groups) == (3244, 6765, 0, 326, 0, 966)

    _, first = np.unique(patches.reshape(len(patches), -1), axis=0, return_index=True)
    unique = patches[np.sort(first)]
    assert len(unique) == 3226
    assert stats(edge_groups(unique)) == (2569, 7766, 0, 0, 0, 0)


def test_sphere_is_closed():
    patches = load_scene(SCENES / "sphere.bpt").patches
    groups = edge_groups(patches)
    check_invariants(groups, patches)
    # 128 patch-edges: 16 collapsed at the poles, the other 112 in 56 pairs
    assert stats(groups) == (56, 0, 16, 0, 0, 0)
    sizes = groups.group_sizes[groups.group_of]
    curves = boundary_curves(patches)
    cart = curves[..., :3] / curves[..., 3:]
    collapsed = (cart == cart[:, :, :1]).all(axis=(2, 3)).ravel()
    assert np.array_equal(sizes == 1, collapsed)
    assert (sizes[~collapsed] == 2).all()


def test_instanced_scenes_keep_sharing():
    """Transforms apply the same arithmetic to shared points, so sharing survives."""
    groups = edge_groups(load_scene(SCENES / "teapots.json").patches)
    assert stats(groups) == (16 * 52, 16 * 16, 16 * 8, 0, 0, 0)
    groups = edge_groups(load_scene(SCENES / "tea_table.json").patches)
    table = edge_groups(load_scene(SCENES / "table.bpt").patches)
    assert groups.shared == table.shared + 52 + 6 * 46 + 6 * 28


# ----------------------------------------------------------------------------- hand-made


def grid(nx: int, ny: int, seed: int = 0) -> np.ndarray:
    """(ny * nx, 4, 4, 4) patches cut from one random (3 ny + 1, 3 nx + 1) control net, patch
    (a, b) at index b * nx + a: neighbours share their boundary points bitwise."""
    rng = np.random.default_rng(seed)
    net = np.concatenate([rng.normal(size=(3 * ny + 1, 3 * nx + 1, 3)), rng.uniform(0.5, 2, (3 * ny + 1, 3 * nx + 1, 1))], axis=-1)
    patches = [net[3 * b : 3 * b + 4, 3 * a : 3 * a + 4] for b in range(ny) for a in range(nx)]
    return np.array(patches)


def test_grid_interior_edges():
    patches = grid(3, 2)
    groups = edge_groups(patches)
    check_invariants(groups, patches)
    # interior edges (nx - 1) ny + nx (ny - 1) = 4 + 3; boundary 2 (nx + ny) = 10
    assert stats(groups) == (7, 10, 0, 0, 0, 0)
    # patch 0's right edge (1) meets patch 1's left edge (3); its top edge (2) patch 3's bottom (0)
    assert groups.group_of[4 * 0 + 1] == groups.group_of[4 * 1 + 3]
    assert groups.group_of[4 * 0 + 2] == groups.group_of[4 * 3 + 0]


def test_grid_reversed_neighbour():
    patches = grid(3, 2)
    patches[4] = patches[4][:, ::-1]  # flip u of the middle top patch: 3 neighbours
    groups = edge_groups(patches)
    check_invariants(groups, patches)
    assert stats(groups) == (7, 10, 0, 0, 0, 3)


def test_three_way_nonmanifold_edge():
    """Three patches hanging off one boundary curve (fins on a spine)."""
    rng = np.random.default_rng(3)
    base = grid(1, 1)[0]
    fins = []
    for _ in range(3):
        fin = base.copy()
        fin[1:] = rng.normal(size=(3, 4, 4)) + [0, 0, 0, 2]  # keep row v = 0, new rest
        fins.append(fin)
    fins[2] = fins[2][:, ::-1]  # one runs the other way round: still the same edge
    patches = np.array(fins)
    groups = edge_groups(patches)
    check_invariants(groups, patches)
    assert groups.nonmanifold == 1 and groups.shared == 0 and groups.boundary == 9
    group = groups.group_of[[0, 4, 8]]
    assert group[0] == group[1] == group[2]
    assert groups.group_sizes[group[0]] == 3


def test_self_glued_patch():
    """A single patch rolled into a tube: its u = 0 and u = 1 edges are one curve."""
    patch = grid(1, 1)[0]
    patch[:, 3] = patch[:, 0]
    groups = edge_groups(patch[None])
    check_invariants(groups, patch[None])
    assert stats(groups) == (1, 2, 0, 0, 1, 0)  # edges 1 (v rising) and 3 (v falling): opposite
    assert groups.group_of[1] == groups.group_of[3]


def test_collapsed_edges_stay_alone():
    """Two patches meeting at one point with collapsed edges (a pole): not grouped, even though
    the rows are equal; the weights along a collapsed row may differ (sphere poles)."""
    a = grid(1, 1, seed=1)[0]
    a[0, :, :3] = [1.0, 2.0, 3.0]
    a[0, :, 3] = [1.0, 0.5, 0.25, 1.0]
    a[0, :, :3] *= a[0, :, 3:]  # homogeneous: Cartesian (1, 2, 3) everywhere on the row
    b = grid(1, 1, seed=2)[0]
    b[0] = a[0]
    groups = edge_groups(np.array([a, b]))
    check_invariants(groups, np.array([a, b]))
    assert groups.collapsed == 2 and groups.shared == 0 and groups.boundary == 6
    assert groups.group_of[0] != groups.group_of[4]


def test_negative_zero_equals_zero():
    patches = grid(2, 1)
    patches[0, :, 3, 0] = 0.0  # the shared column at x = 0 ...
    patches[1, :, 0, 0] = -0.0  # ... written as -0.0 on one side
    assert np.signbit(patches[1, :, 0, 0]).all() and not np.signbit(patches[0, :, 3, 0]).any()
    assert edge_groups(patches).shared == 1


def test_empty_and_bad_shape():
    groups = edge_groups(np.zeros((0, 4, 4, 4)))
    assert groups.num_groups == 0 and len(groups.members) == 0
    with pytest.raises(ValueError):
        edge_groups(np.zeros((2, 4, 4, 3)))


# ----------------------------------------------------------------------------- properties

# Re-parametrisations of a patch [j, i]: turns keep its orientation, mirrors flip it.
REPARAM = [
    (lambda p: p, +1),
    (lambda p: np.rot90(p, 1, axes=(0, 1)), +1),
    (lambda p: np.rot90(p, 2, axes=(0, 1)), +1),
    (lambda p: np.rot90(p, 3, axes=(0, 1)), +1),
    (lambda p: p[:, ::-1], -1),
    (lambda p: p[::-1], -1),
    (lambda p: p.transpose(1, 0, 2), -1),
    (lambda p: p[::-1, ::-1].transpose(1, 0, 2), -1),
]


@settings(max_examples=60, deadline=None)
@given(
    nx=st.integers(1, 5),
    ny=st.integers(1, 5),
    seed=st.integers(0, 2**32 - 1),
)
def test_random_grids(nx, ny, seed):
    """Shuffled, re-parametrised grids: adjacency finds exactly the grid's interior edges,
    and a pair runs the same way exactly when its two patches have opposite orientation."""
    rng = np.random.default_rng(seed)
    patches = grid(nx, ny, seed)
    cell = [(a, b) for b in range(ny) for a in range(nx)]
    choice = rng.integers(0, len(REPARAM), len(patches))
    patches = np.array([REPARAM[c][0](p) for c, p in zip(choice, patches)])
    sign = np.array([REPARAM[c][1] for c in choice])
    order = rng.permutation(len(patches))
    patches, cell, sign = patches[order], [cell[k] for k in order], sign[order]

    groups = edge_groups(patches)
    check_invariants(groups, patches)
    interior = (nx - 1) * ny + nx * (ny - 1)
    assert groups.shared == interior
    assert groups.boundary == 2 * (nx + ny)
    assert groups.nonmanifold == groups.collapsed == groups.self_glued == 0
    flips = 0
    for g in np.flatnonzero(groups.group_sizes == 2):
        p, q = groups.members[groups.group_start[g] : groups.group_start[g] + 2] // 4
        (ax, ay), (bx, by) = cell[p], cell[q]
        assert abs(ax - bx) + abs(ay - by) == 1  # grid neighbours
        flips += sign[p] != sign[q]
    assert groups.reversed_pairs == flips


def test_100k_patches():
    """A grid of ~100k patches (~200k shared edges) groups every shared edge; its speed is
    measured in cltess bench's host adjacency figure, not here."""
    side = 316
    groups = edge_groups(grid(side, side))
    assert groups.shared == 2 * (side - 1) * side


def test_merged_groups_of_two_kinds_keep_each_kinds_groups(rng):
    """Bézier patch-edges (4 per patch) then triangle edges (3 per triangle, the fourth slot
    unused) in one (P, 4) layout: the same groups, unused slots alone, counts summed."""
    import trimesh

    from cltess.adjacency import merge_edge_groups, mesh_edge_groups
    from support import closed_torus_grid

    bezier = edge_groups(closed_torus_grid(rng, 4, 3).patches)
    sphere = trimesh.creation.icosphere(subdivisions=1)
    corners = np.asarray(sphere.vertices, np.float32)[sphere.faces]
    mesh, _ = mesh_edge_groups(corners)
    merged = merge_edge_groups([(bezier, 4, 0), (mesh, 3, 12)], 12 + 80)
    assert np.array_equal(np.sort(merged.members), np.arange(4 * 92))
    assert merged.shared == bezier.shared + mesh.shared == 24 + 120
    # Two entries share a merged group exactly when they shared a group in their own kind.
    same = lambda g, a, b: g.group_of[a] == g.group_of[b]  # noqa: E731
    for a, b in rng.integers(0, 48, size=(200, 2)):
        assert same(merged, a, b) == same(bezier, a, b)
    slot = lambda t, e: 4 * (12 + t) + e  # noqa: E731
    for (t, e), (u, f) in rng.integers(0, (80, 3), size=(200, 2, 2)):
        assert same(merged, slot(t, e), slot(u, f)) == same(mesh, 3 * t + e, 3 * u + f)
    assert (merged.group_sizes[merged.group_of[[slot(t, 3) for t in range(80)]]] == 1).all()
