"""work="auto" (the GPU default since session 7, issue 15): each frame runs "rows-prep" where its
patches average at least AUTO_ROWS_MIN_VERTICES_PER_PATCH output vertices, else "point"; a Session
frame launched before its totals are read goes by the latest settled frame.  Every choice writes
the per-patch kernels' bits; rows-prep's work-groups shrink on scenes of few patches
(Tessellator.line_patches_for)."""
import numpy as np
import pytest

import cltess
from cltess.backends.opencl import tessellator as opencl
from cltess.io import load_scene
from support import SCENES, assert_same_output

UNIFORM = dict(eps=1e-7, max_factor=16)  # every edge factor 16: 17 x 17 = 289 vertices per patch
SMALL = dict(eps=1e-7, max_factor=4)  # 25 vertices per patch


@pytest.fixture(scope="module")
def teapot():
    return load_scene(SCENES / "teapot.bez")


@pytest.fixture
def auto(tessellator):
    return opencl.Tessellator(tessellator.device, work="auto")


def test_the_rule(auto):
    per_patch, patches = opencl.AUTO_ROWS_MIN_VERTICES_PER_PATCH, opencl.AUTO_ROWS_MIN_PATCHES
    assert auto.auto_work() == "point"  # nothing seen yet
    assert auto.auto_work(per_patch * patches, patches) == "rows-prep"
    assert auto.auto_work(per_patch * patches - 1, patches) == "point"  # fewer vertices per patch
    assert auto.auto_work(per_patch * 10 * (patches - 1), patches - 1) == "point"  # too few patches
    assert set(opencl.AUTO_WORK) == {"point", "rows-prep"} and "auto" in opencl.WORK_DISTRIBUTIONS
    fixed = opencl.Tessellator(auto.device, work="point-prep")
    assert fixed.auto_work(10 * per_patch * patches, patches) == "point-prep"  # only "auto" chooses


@pytest.fixture
def few_patches(monkeypatch):
    """The teapot's 32 patches count as many (the rule's other half is tested above)."""
    monkeypatch.setattr(opencl, "AUTO_ROWS_MIN_PATCHES", 16)


def test_gpus_default_to_auto():
    assert opencl.DEFAULT_WORK["gpu"] == "auto" and opencl.DEFAULT_WORK["other"] == "patch"


def test_line_patches_follow_the_batch(auto):
    groups = opencl.LINE_WARPS_PER_UNIT * auto.device.max_compute_units
    enough = opencl.LINE_PATCHES * -(-groups // 2)  # half the groups at LINE_PATCHES each
    assert auto.line_patches_for(enough) == opencl.LINE_PATCHES
    assert auto.line_patches_for(10 ** 9) == opencl.LINE_PATCHES
    assert auto.line_patches_for(enough - opencl.LINE_PATCHES) == min(opencl.LINE_PATCHES, -(-(enough - opencl.LINE_PATCHES) // groups))
    assert auto.line_patches_for(1) == 1
    assert auto.line_patches_for(groups + 1) == 2
    assert auto.line_patches_for(3 * groups) == 3
    auto.patches_per_group = 7
    assert auto.line_patches_for(1) == 7 and auto.line_patches_for(10 ** 9) == 7


@pytest.mark.parametrize("options, chosen", [(UNIFORM, "rows-prep"), (SMALL, "point")])
def test_one_shot_chooses_by_the_plan_and_writes_the_same_bits(tessellator, auto, teapot, few_patches, options,
                                                                  chosen):
    per_patch = opencl.Tessellator(tessellator.device, work="patch")
    got = auto.tessellate(teapot, **options)
    assert auto.auto_work() == chosen
    vertices_per_patch = got.num_vertices / teapot.num_patches
    assert (vertices_per_patch >= opencl.AUTO_ROWS_MIN_VERTICES_PER_PATCH) == (chosen == "rows-prep")
    assert_same_output(got, per_patch.tessellate(teapot, **options))


def test_emit_launches_the_chosen_kernels(auto, teapot, few_patches, monkeypatch):
    launched = []
    original = opencl.Tessellator.stage_vertices

    def spy(self, *args, **kwargs):
        launched.append(kwargs.get("work"))
        return original(self, *args, **kwargs)

    monkeypatch.setattr(opencl.Tessellator, "stage_vertices", spy)
    auto.tessellate(teapot, **UNIFORM)
    auto.tessellate(teapot, **SMALL)
    assert launched == ["rows-prep", "point"]


def test_a_session_follows_its_frames(tessellator, auto, teapot, few_patches):
    """Frames switch between many and few vertices per patch: each is bitwise the per-patch
    kernels' output; the choice follows the latest settled frame (a frame launched on the
    buffers' capacity before its totals are read may run the previous frame's choice), and the
    frame key (recorded frames) carries it."""
    per_patch = opencl.Tessellator(tessellator.device, work="patch")
    expected = {key: per_patch.tessellate(teapot, **options) for key, options in (("big", UNIFORM), ("small", SMALL))}
    session = cltess.Session(teapot, tessellator=auto, **SMALL)
    chosen, keys = [], []
    for key in ["small", "small", "big", "big", "big", "small", "small", "small"]:
        frame = session.tessellate(**({} if key == "small" else {"max_factor": 16}))
        assert_same_output(frame, expected[key])
        chosen.append(auto.auto_work())
        keys.append(session._frame_key())
    assert chosen[:2] == ["point", "point"]
    assert chosen[4] == "rows-prep" and chosen[-1] == "point"
    assert all(key[-2] == choice for key, choice in zip(keys, chosen))


def test_direct_stage_calls_choose_by_their_batch(tessellator, auto, teapot, few_patches):
    """stage_vertices / stage_indices called with work="auto" (as levels.py does) choose by the
    batch's own vertices per patch; the bits are the per-patch kernels'."""
    plan = auto.plan(teapot, **UNIFORM)
    plan.settle()
    auto._batch_seen = (1, 1)  # a noted plan that would choose "point": the batch decides
    part = plan.parts[0]
    vertices, events = auto.stage_vertices(part.data["controls"], plan.factors, plan.vertex_offsets, plan.objects,
                                           plan.vertex_range(0, plan.num_patches), (0, plan.num_patches),
                                           kind=part.kind, pattern=part.pattern)
    auto.queue.finish()
    expected = opencl.Tessellator(tessellator.device, work="patch").tessellate(teapot, **UNIFORM)
    assert len(events) == 2  # prepare_patches and prepared_rows: rows-prep
    assert np.array_equal(vertices["positions"].get(), expected.positions)
    assert np.array_equal(vertices["normals"].get(), expected.normals)


@pytest.mark.parametrize("min_patches, made", [(16, True), (64, False)])
def test_compose_makes_the_scratch_where_auto_may_prepare(auto, teapot, monkeypatch, min_patches, made):
    """The prepared patches' scratch buffer is made before the plan's buffers (Oclgrind's
    uninitialised-value pass, Tessellator.prepared_scratch) on scenes where auto may choose
    rows-prep (at least AUTO_ROWS_MIN_PATCHES patches), not on others."""
    from cltess.request import Request
    monkeypatch.setattr(opencl, "AUTO_ROWS_MIN_PATCHES", min_patches)
    auto.compose(teapot, Request.of(**UNIFORM))
    assert (auto._prepared is not None) == made
