"""Crack-freeness: shared boundary vertices come out bitwise identical, so merging exactly equal
positions gives a watertight mesh with no T-junctions (DESIGN.md section 4)."""
from pathlib import Path

import numpy as np
import pytest

from cltess.formats import load_scene
from cltess.scene import Camera, Scene
from support import closed_torus_grid, weld_exact

SCENES = Path(__file__).resolve().parent.parent / "scenes"


def assert_watertight(tess):
    mesh = weld_exact(tess.positions, tess.triangles)
    # Every edge used by exactly two triangles: no holes, no cracks, no T-junctions.
    assert mesh.is_watertight, f"{len(mesh.edges) - 2 * len(mesh.edges_unique)} unmatched edge uses"
    assert mesh.is_winding_consistent
    return mesh


@pytest.mark.parametrize("eps", [1e-2, 1e-3, 3e-4])
def test_sphere_is_watertight(tessellator, eps):
    tess = tessellator.tessellate(load_scene(SCENES / "sphere.bpt"), eps=eps)
    mesh = assert_watertight(tess)
    assert abs(mesh.volume - 4 / 3 * np.pi) < 4 * np.pi * eps  # within the shell of width eps
    assert len(np.unique(tess.factors)) > 1  # neighbours with different factors were stitched


@pytest.mark.parametrize("fd", [True, False], ids=["fd", "direct"])
@pytest.mark.parametrize("eps", [0.3, 0.1])
def test_closed_grid_with_random_weights_is_watertight(tessellator, rng, eps, fd):
    scene = closed_torus_grid(rng, 14, 9, noise=0.15)
    tess = tessellator.tessellate(scene, eps=eps, forward_differencing=fd, max_factor=512)
    assert tess.stats["saturated"] == 0
    assert tess.stats["boundary_edges"] == 0 and tess.stats["shared_edges"] == 2 * scene.num_patches
    mesh = assert_watertight(tess)
    assert mesh.euler_number == 0  # a torus
    transitions = (tess.factors[:, 0] != tess.factors[:, 2]) | (tess.factors[:, 1] != tess.factors[:, 3])
    assert transitions.sum() > scene.num_patches // 4


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
