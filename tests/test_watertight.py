"""Crack-freeness: shared boundary vertices come out bitwise identical, so merging exactly equal
positions gives a watertight mesh with no T-junctions (docs/design.md section 4)."""
from pathlib import Path

import numpy as np
import pytest

from cltess.io import load_scene
from cltess.scene import Camera, Scene
from support import closed_torus_grid, weld_exact

SCENES = Path(__file__).resolve().parent.parent / "scenes"


def assert_watertight(tess):
    mesh = weld_exact(tess.positions, tess.triangles)
    # Every edge used by exactly two triangles: no holes, no cracks, no T-junctions.
    assert mesh.is_watertight, f"{len(mesh.edges) - 2 * len(mesh.edges_unique)} unmatched edge uses"
    assert mesh.is_winding_consistent
    return mesh


@pytest.mark.parametrize("eps", [2e-2, 1e-3, 3e-4])  # each gives neighbours different factors
def test_sphere_is_watertight(tessellator, eps):
    tess = tessellator.tessellate(load_scene(SCENES / "sphere.bpt"), eps=eps)
    mesh = assert_watertight(tess)
    assert abs(mesh.volume - 4 / 3 * np.pi) < 4 * np.pi * eps  # within the shell of width eps
    assert len(np.unique(tess.factors)) > 1  # neighbours with different factors were stitched


def test_culled_neighbours_leave_only_open_boundaries(tessellator, rng):
    """With half the grid culled, the visible part is a mesh whose boundary runs only along
    edges shared with culled patches: still no crack between visible patches."""
    scene = closed_torus_grid(rng, 14, 9, noise=0.1)
    scene.camera = Camera(eye=np.array([0.0, -9.0, 0.5]), target=np.array([0.0, 0.0, 0.0]),
                          fov_y_deg=25, width=400, height=300)
    tess = tessellator.tessellate(scene, pixels=1.0)
    assert 0 < tess.stats["culled"] < scene.num_patches
    mesh = weld_exact(tess.positions, tess.triangles)
    assert mesh.is_winding_consistent
    counts = np.bincount(mesh.edges_unique_inverse, minlength=len(mesh.edges_unique))
    assert counts.max() == 2


# --- PN triangles: closed meshes stay closed ---------------------------------------------------

def pn_watertight(tessellator, mesh, name, eps, **options):
    """Tessellate, weld exactly equal positions: closed, consistently wound, and of the same
    topology as the input mesh welded by position."""
    tess = tessellator.tessellate(Scene.from_trimesh(mesh, name=name), eps=eps, **options)
    assert tess.stats["boundary_edges"] == 0 and tess.stats["nonmanifold_edges"] == 0
    welded = assert_watertight(tess)
    assert welded.euler_number == weld_exact(np.asarray(mesh.vertices, np.float32), mesh.faces).euler_number
    return tess, welded


@pytest.mark.parametrize("fd", [True, False], ids=["fd", "direct"])
@pytest.mark.parametrize("eps", [1e-2, 1e-3])
def test_pn_closed_meshes_are_watertight(tessellator, eps, fd):
    from support import genus2, icosphere, torus

    for name, mesh, genus in (("icosphere", icosphere(2), 0), ("torus", torus(), 1), ("genus 2", genus2(), 2)):
        tess, welded = pn_watertight(tessellator, mesh, name, eps, forward_differencing=fd)
        assert welded.euler_number == 2 - 2 * genus
        assert len(np.unique(tess.factors[:, :3])) > 1  # neighbours with different factors were stitched
        assert welded.volume > 0  # outward, like the input


def test_pn_icosphere_volume_is_near_the_pn_surface(tessellator):
    """The PN sphere lies within eps of the tessellation: the volumes differ by at most the
    shell's, and finer tolerances converge."""
    from support import icosphere

    volumes = [pn_watertight(tessellator, icosphere(1), "ico", eps)[1].volume for eps in (1e-2, 1e-3, 1e-4)]
    area = 4 * np.pi
    assert abs(volumes[0] - volumes[2]) < 1.1e-2 * area and abs(volumes[1] - volumes[2]) < 1.1e-3 * area


@pytest.mark.parametrize("sharp_edges", ["straight", "average"])
def test_pn_meshes_with_sharp_edges_are_watertight(tessellator, rng, sharp_edges):
    """Split vertices with different normals on the two sides of an edge: the choice makes both
    sides use one boundary curve."""
    from support import genus2, split_some_vertices, torus

    for name, mesh in (("torus", torus()), ("genus 2", genus2())):
        split = split_some_vertices(rng, mesh, fraction=0.3)
        tess, _ = pn_watertight(tessellator, split, name, 3e-3, sharp_edges=sharp_edges)
        assert tess.stats["sharp_edges"] > 30


def test_keeping_sharp_edges_cracks_and_is_reported(tessellator, rng):
    """With each side's own PN curve (plain PN triangles), a sharp edge is a crack."""
    from support import split_some_vertices, torus

    split = split_some_vertices(rng, torus(), fraction=0.3)
    tess = tessellator.tessellate(Scene.from_trimesh(split, name="torus"), eps=3e-3, sharp_edges="keep")
    assert tess.stats["sharp_edges"] > 30
    assert not weld_exact(tess.positions, tess.triangles).is_watertight


def test_pn_flat_shaded_meshes_come_back_as_themselves(tessellator):
    """Every edge sharp and kept straight, normals = face normals: every patch is its flat
    triangle, factors 1, and the output is the input mesh, triangle for triangle."""
    from support import flat_shaded, genus2, icosphere

    for mesh in (flat_shaded(icosphere(2)), flat_shaded(genus2())):
        tess, welded = pn_watertight(tessellator, mesh, "flat", 1e-4)
        assert (tess.factors[:, :3] == 1).all()
        assert np.array_equal(tess.positions, np.asarray(mesh.vertices, np.float32))
        assert np.array_equal(tess.triangles, np.asarray(mesh.faces))


def test_pn_mesh_split_along_seams_is_welded_by_position(tessellator):
    """A mesh whose vertices are split (same position, same normal: a UV seam) connects there."""
    from support import flat_shaded, torus

    mesh = torus()
    soup = flat_shaded(mesh)  # every vertex split per face ...
    smooth = Scene.from_trimesh(soup, name="seams")
    from cltess.scene import vertex_normals
    smooth.meshes[0].normals = vertex_normals(soup.vertices, soup.faces)  # ... but one normal per point
    tess = tessellator.tessellate(smooth, eps=3e-3)
    assert tess.stats["sharp_edges"] == 0 and tess.stats["shared_edges"] == len(mesh.edges_unique)
    assert assert_watertight(tess).euler_number == 0
    assert (tess.factors[:, :3] > 1).any()
