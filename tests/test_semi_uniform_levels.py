"""Stages 4-5 by level (cltess/backends/opencl/levels.py, ``Request(emit="by_level")``) against
the patch-parallel stages 4-5: the queues partition the patches by level (the histogram is the
plan's), and the output is the same mesh, bit for bit and in the same places (the
patch-parallel one without forward differencing): vertices from the level's point template,
triangles from its interior template and the band walk; on both kinds, with culled, saturated
and collapsed-edge patches, with a kind left on the transition pattern, whole and in batches."""
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from cltess.backends.opencl.levels import emit_by_level, level_queues, plan_by_level
from cltess.formats import load_scene
from cltess.request import Request
from cltess.scene import Scene
from oclgrind_scenarios import mixed_culled, rational_sphere
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
    scene, options = rational_sphere()  # collapsed edges at the poles
    yield scene, Request.of(**dict(options, forward_differencing=True), pattern="semi_uniform")


def per_patch(tessellator, scene, request, first=0, last=None):
    plan = tessellator.plan(scene, replace(request, emit="per_patch"))
    return tessellator.emit(plan, first, plan.num_patches if last is None else last, forward_differencing=False)


def assert_same(got, expected, what):
    for field in FIELDS:
        assert np.array_equal(getattr(got, field), getattr(expected, field)), (what, field)


def test_level_path_gives_the_patch_parallel_mesh(tessellator, rng):
    for scene, request in scenes(rng):
        plan = plan_by_level(tessellator, scene, request)
        expected = per_patch(tessellator, scene, request)
        got = emit_by_level(tessellator, plan)
        assert_same(got, expected, scene.name)
        assert np.array_equal(got.triangles, tessellator.tessellate(scene, replace(request, emit="by_level")).triangles)
        if "patch_levels" in plan.stats:
            levels = plan.stats["patch_levels"]
            assert got.stats["level_queues"][:len(levels)] == levels and sum(got.stats["level_queues"]) == sum(levels)
        else:
            assert got.stats["level_queues"] == []


def test_level_path_in_batches(tessellator, rng):
    """emit(plan, first, last) by level: each batch is the patch-parallel batch (vertex and
    index numbering global, as for every batch)."""
    scene = closed_torus_grid(rng, 14, 9, noise=0.15)
    request = Request.of(eps=0.1, pattern="semi_uniform", max_factor=512, max_level=9, emit="by_level")
    plan = tessellator.plan(scene, request)
    expected_plan = tessellator.plan(scene, replace(request, emit="per_patch"))
    for first, last in ((0, 40), (40, 41), (41, plan.num_patches)):
        got = tessellator.emit(plan, first, last)
        assert_same(got, tessellator.emit(expected_plan, first, last, forward_differencing=False), (first, last))
    batches = list(tessellator.tessellate_in_batches(scene, 200_000, request)[1])
    assert len(batches) > 1
    assert np.array_equal(np.concatenate([b.triangles for b in batches]), per_patch(tessellator, scene, request).triangles)


def test_queues_partition_the_patches_by_level(tessellator, rng):
    """Each patch in exactly one queue, that of its level, in patch order; the sizes sum to the
    patches that are not culled; on a patch range too."""
    teapot = load_scene(SCENES / "teapot.bez")
    scene, options = mixed_culled()
    for scene, request in ((teapot, Request.of(eps=3e-3, pattern="semi_uniform")),
                           (scene, Request.of(**options, pattern="semi_uniform", max_level=4)),
                           (teapot, Request.of(eps=3e-3, pattern="semi_uniform", max_level=14))):
        plan = tessellator.plan(scene, request)
        levels = np.log2(np.maximum(np.abs(plan.host_factors()).max(axis=1), 1)).astype(int)
        levels[np.abs(plan.host_factors())[:, 0] == 0] = -1  # culled
        for part in plan.parts:
            ranges = [(part.base, part.base + part.count)]
            ranges += [(part.base + 3, part.base + part.count - 5)] if part.count > 10 else []
            for first, last in ranges:
                queues, _ = level_queues(tessellator, plan, first, last, request.max_level)
                patches = queues.patches.get()
                assert len(queues.histogram) == request.max_level + 1
                for level in range(request.max_level + 1):
                    queue = patches[queues.starts[level]:queues.starts[level + 1]].tolist()
                    assert queue == (first + np.flatnonzero(levels[first:last] == level)).tolist()
                assert queues.starts[-1] == np.count_nonzero(levels[first:last] >= 0)
    assert len({level for level in levels if level >= 0}) > 1


def test_emit_mode_is_checked():
    with pytest.raises(ValueError, match="emit must be one of per_patch, by_level"):
        Request.of(eps=1e-3, emit="queued")
