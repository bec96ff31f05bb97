"""Every backend (cltess.backends.backends()) keeps the plan / emit contract: counts equal to the
emitted data, batches that concatenate to the single pass; and the backends agree."""
import numpy as np
import pytest

from cltess.backends import backends
from cltess.request import Request
from cltess.scene import Scene
from support import closed_torus_grid, icosphere

ARRAYS = ("positions", "normals", "uv", "patch_ids", "object_ids", "triangles", "factors")


def mixed_scene(rng):
    grid = closed_torus_grid(rng, 4, 3)
    mesh = Scene.from_trimesh(icosphere(1), name="ico")
    return Scene(grid.patches, grid.object_ids, name="mixed", meshes=mesh.meshes)


@pytest.fixture(params=list(backends()))
def backend(request, tessellator):
    return tessellator if request.param == "opencl" else backends()[request.param]()


def test_counts_equal_the_output_and_batches_concatenate(backend, rng):
    scene = mixed_scene(rng)
    plan = backend.plan(scene, Request.of(eps=0.02))
    whole = backend.emit(plan, 0, plan.num_patches)
    assert len(whole.positions) == plan.num_vertices and 3 * len(whole.triangles) == plan.num_indices
    assert whole.triangles.max() < plan.num_vertices
    cut = scene.num_bezier + 7  # inside the mesh: both kinds in the first batch
    parts = [backend.emit(plan, 0, cut), backend.emit(plan, cut, plan.num_patches)]
    for name in ARRAYS:
        assert np.array_equal(np.concatenate([getattr(p, name) for p in parts]), getattr(whole, name)), name


def test_backends_agree(tessellator, rng):
    scene = mixed_scene(rng)
    request = Request.of(eps=0.02)
    results = {name: (tessellator if name == "opencl" else cls()).tessellate(scene, request)
               for name, cls in backends().items()}
    reference = results.pop("numpy")
    for name, tess in results.items():
        assert np.array_equal(tess.factors, reference.factors), name
        assert np.array_equal(tess.triangles, reference.triangles), name
        assert np.allclose(tess.positions, reference.positions, atol=1e-5), name
        assert np.allclose(tess.normals, reference.normals, atol=1e-3), name
