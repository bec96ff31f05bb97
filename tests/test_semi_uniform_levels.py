"""Stage 4 by level (cltess/backends/opencl/levels.py) against the patch-parallel stage 4: the
queues partition the patches by level (the histogram is the plan's), and the output is the same
mesh, bit for bit (the patch-parallel one without forward differencing), on both kinds, with
culled and saturated patches, and with a kind left on the transition pattern."""
from pathlib import Path

import numpy as np
import pytest

from cltess.backends.opencl.levels import emit_by_level, level_queues, plan_by_level
from cltess.formats import load_scene
from cltess.request import Request
from cltess.scene import Scene
from oclgrind_scenarios import mixed_culled
from support import closed_torus_grid, genus2

SCENES = Path(__file__).resolve().parent.parent / "scenes"

FIELDS = ("positions", "normals", "uv", "patch_ids", "object_ids", "triangles", "factors")


def scenes(rng):
    teapot = load_scene(SCENES / "teapot.bez")
    mixed = Scene(teapot.patches, teapot.object_ids, None, "teapot and genus 2",
                  [Scene.from_trimesh(genus2()).meshes[0]])
    yield mixed, Request.of(eps=3e-3, pattern="semi_uniform")
    yield mixed, Request.of(eps=3e-3, pattern="semi_uniform", max_level=3)  # saturated at level 3
    yield mixed, Request.of(eps=3e-3, pattern="tri_semi_uniform")  # the patches stay transition ones
    yield closed_torus_grid(rng, 14, 9, noise=0.15), Request.of(eps=0.1, pattern="semi_uniform", max_factor=512,
                                                                 max_level=9)
    scene, options = mixed_culled()
    yield scene, Request.of(**options, pattern="semi_uniform")


def test_level_path_gives_the_patch_parallel_mesh(tessellator, rng):
    for scene, request in scenes(rng):
        plan = plan_by_level(tessellator, scene, request)
        expected = tessellator.emit(plan, 0, plan.num_patches, forward_differencing=False)
        got = emit_by_level(tessellator, plan)
        for field in FIELDS:
            assert np.array_equal(getattr(got, field), getattr(expected, field)), (scene.name, field)
        if "patch_levels" in plan.stats:
            levels = plan.stats["patch_levels"]
            assert got.stats["level_queues"][:len(levels)] == levels and sum(got.stats["level_queues"]) == sum(levels)


def test_queues_partition_the_patches_by_level(tessellator):
    teapot = load_scene(SCENES / "teapot.bez")
    plan = tessellator.plan(teapot, Request.of(eps=3e-3, pattern="semi_uniform"))
    (part,) = plan.parts
    queues, _ = level_queues(tessellator, plan, part, 6)
    levels = np.log2(plan.host_factors().max(axis=1)).astype(int)
    for queue in queues:
        assert queue.patches.get()[:queue.count].tolist() == np.flatnonzero(levels == queue.level).tolist()
    assert sum(queue.count for queue in queues) == plan.num_patches and len({q.level for q in queues if q.count}) > 1
