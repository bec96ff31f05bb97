"""Session frames launched before stage 3's totals are read (issue 15, docs/design.md section 11):
stages 4-5 run on the output buffers' capacity and write nothing where the output does not fit
(batch_fits in kernels/common.h); the host then grows the buffers and runs them again."""
import numpy as np
import pytest

import pyopencl.array as cl_array

import cltess
from cltess.backends.opencl import tessellator as opencl
from cltess.tessellation import StaleOutput, VERTEX_RECORD
from support import assert_same_output

WORKS = ["patch", "rows", "point", "point-prep", "rows-prep", "auto"]
SENTINEL = 0xA5  # every byte of the output buffers before a launch


def sentinel(queue, shape, dtype):
    host = np.empty(shape, dtype)
    host.view(np.uint8)[...] = SENTINEL
    return cl_array.to_device(queue, host)


def untouched(array) -> bool:
    return bool(np.all(array.view(np.uint8) == SENTINEL))


def launch(tess, plan, vertices: int, indices: int) -> dict:
    """Stages 4-5 of the whole plan into sentinel-filled buffers of ``vertices`` and
    ``indices`` records (launched over that many, as a Session frame on its capacity)."""
    out = {name: sentinel(tess.queue, (vertices, *shape), dtype) for name, dtype, shape in VERTEX_RECORD}
    triangles = sentinel(tess.queue, (indices // 3, 3), np.uint32)
    part = plan.parts[0]
    tess.stage_vertices(part.data["controls"], plan.factors, plan.vertex_offsets, plan.objects, (0, vertices),
                        (0, plan.num_patches), kind=part.kind, pattern=part.pattern, out=out)
    tess.stage_indices(plan.factors, plan.vertex_offsets, plan.index_offsets, (0, indices), (0, plan.num_patches),
                       kind=part.pattern, out=triangles)
    tess.queue.finish()
    return {**{name: array.get() for name, array in out.items()}, "triangles": triangles.get()}


@pytest.mark.parametrize("work", WORKS)
def test_stages_4_and_5_write_all_that_fits_and_nothing_that_does_not(tessellator, tea_table, work):
    tess = opencl.Tessellator(tessellator.device, work=work)
    plan = tess.plan(tea_table, pixels=0.5)
    vertices, indices = plan.num_vertices, plan.num_indices
    exact = launch(tess, plan, vertices, indices)
    roomy = launch(tess, plan, vertices + 1000, indices + 3000)
    for name, array in plan_result(tess, plan).items():
        assert np.array_equal(array, exact[name]), name
    for name, array in exact.items():  # room to spare: the same records, nothing past them
        assert np.array_equal(roomy[name][:len(array)], array), name
        assert untouched(roomy[name][len(array):]), name
    for short_vertices, short_indices in ((vertices - 1, indices), (vertices, indices - 3)):
        short = launch(tess, plan, short_vertices, short_indices)
        for name, array in short.items():  # a stage whose output does not fit writes nothing
            fits = short_indices == indices if name == "triangles" else short_vertices == vertices
            assert untouched(array) != fits, name
            if fits:
                assert np.array_equal(array, exact[name]), name


def plan_result(tess, plan):
    """The plan's output the usual way (buffers of its totals), as host arrays by name."""
    result = tess.emit(plan, 0, plan.num_patches)
    return {name: getattr(result, name) for name, _, _ in VERTEX_RECORD} | {"triangles": result.triangles}


def one_shot(tessellator, scene, session, **overrides):
    return tessellator.tessellate(scene, request=session.request_for(**overrides))


def test_a_frame_larger_than_the_buffers_runs_stages_4_and_5_again(tessellator, tea_table):
    session = cltess.Session(tea_table, tessellator=tessellator, eps=0.02)
    first = session.tessellate()
    assert "output_fit" not in first.stats  # the first frame: no buffers yet, sized from its totals
    larger = session.tessellate(eps=0.002)
    assert larger.stats["output_fit"] is False
    assert_same_output(larger, one_shot(tessellator, tea_table, session, eps=0.002))
    again = session.tessellate(eps=0.002)
    assert again.stats["output_fit"] is True
    assert_same_output(again, one_shot(tessellator, tea_table, session, eps=0.002))
    assert again.stats == {**larger.stats, "output_fit": True}


def test_overlapped_frames_settle_when_looked_at(tessellator, tea_table):
    session = cltess.Session(tea_table, tessellator=tessellator, eps=0.02)
    session.tessellate()
    larger = session.tessellate(eps=0.002, wait=False)  # does not fit the buffers of the first frame
    assert larger.num_triangles == one_shot(tessellator, tea_table, session, eps=0.002).num_triangles
    assert larger.stats["output_fit"] is False  # ran again when its size was asked for
    assert_same_output(larger, one_shot(tessellator, tea_table, session, eps=0.002))


def test_a_stale_frame_is_not_run_again_and_the_next_one_fits(tessellator, tea_table):
    session = cltess.Session(tea_table, tessellator=tessellator, eps=0.02)
    session.tessellate()
    unseen = session.tessellate(eps=0.002, wait=False)  # too large; nobody looks before the next
    tessellator.queue.finish()  # its totals are there when the next frame starts
    following = session.tessellate(eps=0.002, wait=False)  # the buffers grew from its totals first
    assert following.stats["output_fit"] is True
    assert_same_output(following, one_shot(tessellator, tea_table, session, eps=0.002))
    assert unseen.stats["output_fit"] is False  # settled, not run again: its buffers are the next frame's
    assert (unseen.num_vertices, unseen.num_triangles) == (following.num_vertices, following.num_triangles)
    with pytest.raises(StaleOutput):
        unseen.fetch()


def test_no_more_than_two_frames_are_in_flight(tessellator, tea_table):
    """Each frame settles the frame before last (reads its totals), so the host never runs more
    than two frames ahead of the device."""
    session = cltess.Session(tea_table, tessellator=tessellator, pixels=0.5)
    frames, before_last = [], []
    for _ in range(6):
        frames.append(session.tessellate(wait=False))
        before_last.append(session._plans[0])
    assert all(plan.settled for plan in before_last[:-2])
    assert all(frame.stats["output_fit"] for frame in frames[1:])
