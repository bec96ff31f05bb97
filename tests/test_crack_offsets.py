"""Stages 2 and 3 in one launch (stages/crack_offsets.cl, Tessellator.fused_crack_free, issue 15:
a Session frame of a small scene, one launch fewer): the crack-free factors of the NumPy mirror
(reference.crack_free_factors, collapsed edges negated) and its counts and offsets, and the
frame's summary, over random edge groups of any size, several tiles, two patterns; Session
frames bitwise those of stage 2's own launch, with one launch fewer."""
import numpy as np
import pyopencl.array as cl_array
import pytest

from cltess import reference
from cltess.adjacency import EdgeGroups
from cltess.backends.opencl import tessellator as opencl
from support.factors import random_factors, random_triangle_factors


def random_groups(rng, edges: int, groups: int, collapsible: int) -> EdgeGroups:
    """A random CSR partition of ``edges`` patch-edges into ``groups`` groups (singletons,
    pairs and non-manifold groups), a few of the first ``collapsible`` edges collapsed (Bézier
    patches' edges: a PN triangle has none)."""
    members = rng.permutation(edges).astype(np.int32)
    cuts = np.sort(rng.choice(np.arange(1, edges), size=groups - 1, replace=False))
    group_start = np.concatenate([[0], cuts, [edges]]).astype(np.int32)
    group_of = np.empty(edges, np.int32)
    for g in range(groups):
        group_of[members[group_start[g]:group_start[g + 1]]] = g
    collapsed = (rng.random(edges) < 0.03) & (np.arange(edges) < collapsible)
    return EdgeGroups(group_of, group_start, members, np.zeros(edges, bool), 0, 0, int(collapsed.sum()), 0, 0, 0,
                      collapsed_edges=collapsed)


@pytest.mark.parametrize("group", [1, 64, opencl.FUSED_OFFSETS_GROUP])  # 1: no scan step at all
@pytest.mark.parametrize("with_summary", [True, False])
def test_crack_offsets_are_the_mirrors_stage_2_and_3(tessellator, rng, monkeypatch, group, with_summary):
    from cltess.kinds import FLAG_CULLED, FLAG_SATURATED
    from cltess.pipeline import BEZIER, PN

    monkeypatch.setattr(opencl, "FUSED_OFFSETS_GROUP", group)
    tess = opencl.Tessellator(tessellator.device, work="patch")
    tess.fused_offsets, tess._cpu = True, False
    # factors below 12: the mirror's counts emit every patch's pattern in Python (below 70: 12 s a case)
    quads, triangles = random_factors(rng, 600, high=12), random_triangle_factors(rng, 300, high=12)
    raw = np.concatenate([quads, triangles])
    groups = random_groups(rng, raw.size, 1500, quads.size)
    flags = rng.choice(np.array([0, FLAG_SATURATED, FLAG_CULLED, FLAG_SATURATED | FLAG_CULLED], np.int32), len(raw))
    ranges = [(BEZIER, 0, 600), (PN, 600, 300)]  # the first range's launch runs stage 2 for both
    uploaded = tess.upload_groups(groups, len(raw))
    final = cl_array.to_device(tess.queue, np.full(raw.shape, 12345, np.int32))  # none left as it was
    summary = cl_array.empty(tess.queue, opencl.SUMMARY_FIELDS, np.uint64) if with_summary else None
    scratch = {}
    for _ in range(2):  # again on the same arrays (a session's frames)
        vertex_offsets, index_offsets, events = tess.stage_counts(
            final, ranges, scratch=scratch, flags=cl_array.to_device(tess.queue, flags), summary=summary,
            crack_free=(cl_array.to_device(tess.queue, raw), uploaded, "crack/max.h"))
    assert len(events) == 2  # one launch per range, stage 2 in the first
    expected = reference.crack_free_factors(raw, groups.group_of, groups.group_start, groups.members,
                                            groups.collapsed_edges)
    assert np.array_equal(final.get(), expected)
    assert (expected < 0).any() and (expected == 0).any()  # collapsed and culled edges were there
    counts = reference.counts(expected[:600]), reference.counts(expected[600:], kind="pn")
    vertex_expected = reference.offsets(np.concatenate([counts[0][0], counts[1][0]]))
    index_expected = reference.offsets(np.concatenate([counts[0][1], counts[1][1]]))
    assert np.array_equal(vertex_offsets.get(), vertex_expected)
    assert np.array_equal(index_offsets.get(), index_expected)
    if with_summary:
        assert summary.get().tolist() == [int(vertex_expected[-1]), int(index_expected[-1]),
                                          int(np.count_nonzero(flags & FLAG_CULLED)),
                                          int(np.count_nonzero(flags & FLAG_SATURATED))]


def test_crack_offsets_only_where_stage_3_is_one_launch(tessellator, rng):
    from cltess.pipeline import BEZIER

    tess = opencl.Tessellator(tessellator.device, work="patch")
    tess.fused_offsets = tess.tiled_offsets = False
    raw = random_factors(rng, 40)
    groups = tess.upload_groups(random_groups(rng, raw.size, 100, raw.size), len(raw))
    device = cl_array.to_device(tess.queue, raw)
    assert not tess.fuses_crack_free(len(raw), [(BEZIER, 0, len(raw))])
    with pytest.raises(ValueError, match="one launch"):
        tess.stage_counts(device, BEZIER, crack_free=(device, groups, "crack/max.h"))


def frames(tess, scene, cameras) -> list:
    """Each camera's Session frame (host fields and stats) and the frames' launches of stages 2-3."""
    import cltess

    session = cltess.Session(scene, tessellator=tess, pixels=0.5)
    out = []
    for camera in cameras:
        frame = session.tessellate(camera=camera).fetch()
        out.append((frame, len(frame_events(session, "crack_free")), len(frame_events(session, "counts"))))
    return out


def frame_events(session, stage: str) -> list:
    return session._plans[-1].events[stage]


@pytest.mark.parametrize("work", ["patch", "point"])
def test_session_frames_with_stage_2_in_stage_3_are_bitwise_the_same(tessellator, tea_table, monkeypatch, work):
    """A Session's frames (the first, sized by its totals; a normal one, recorded; replayed ones)
    with stage 2 in stage 3's launch are bit for bit those with its own launch, with no stage 2
    launch; above FUSED_CRACK_FREE_MAX_PATCHES, or with fused_crack_free off, stage 2 keeps its
    launch; a one-shot plan always does."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "bench"))
    import frame_loop as fl
    from cltess.tessellation import HOST_FIELDS

    cameras = list(fl.orbit(tea_table.camera, 4))
    runs = {}
    for name, fused, cap in (("fused", True, opencl.FUSED_CRACK_FREE_MAX_PATCHES), ("own launch", False, 1 << 20),
                             ("above the cap", True, tea_table.num_patches - 1)):
        monkeypatch.setattr(opencl, "FUSED_CRACK_FREE_MAX_PATCHES", cap)
        tess = opencl.Tessellator(tessellator.device, work=work)
        tess.fused_offsets, tess._cpu, tess.fused_crack_free = True, False, fused
        runs[name] = frames(tess, tea_table, cameras)
        plan = tess.plan(tea_table, pixels=0.5, camera=cameras[0])
        assert len(plan.events["crack_free"]) == 1  # one-shot: stage 2's own launch
    assert [(c, n) for _, c, n in runs["fused"]] == [(0, 1)] * len(cameras)
    assert [(c, n) for _, c, n in runs["own launch"]] == [(1, 1)] * len(cameras)
    assert [(c, n) for _, c, n in runs["above the cap"]] == [(1, 1)] * len(cameras)
    for frame, other, over in zip(*(runs[name] for name in ("fused", "own launch", "above the cap"))):
        for field in HOST_FIELDS:
            assert np.array_equal(getattr(frame[0], field), getattr(other[0], field)), field
            assert np.array_equal(getattr(frame[0], field), getattr(over[0], field)), field
        assert {k: v for k, v in frame[0].stats.items() if k != "output_fit"} == \
               {k: v for k, v in other[0].stats.items() if k != "output_fit"}


def test_fused_crack_free_setting(tessellator, monkeypatch):
    monkeypatch.setenv("CLTESS_FUSED_CRACK_FREE", "1")
    assert opencl.Tessellator(tessellator.device).fused_crack_free
    monkeypatch.setenv("CLTESS_FUSED_CRACK_FREE", "0")
    assert not opencl.Tessellator(tessellator.device).fused_crack_free
    monkeypatch.setenv("CLTESS_FUSED_CRACK_FREE", "on")
    with pytest.raises(ValueError, match="CLTESS_FUSED_CRACK_FREE"):
        opencl.Tessellator(tessellator.device)
    monkeypatch.delenv("CLTESS_FUSED_CRACK_FREE")
    monkeypatch.delenv("CLTESS_FUSED_OFFSETS", raising=False)
    device = opencl.Tessellator(tessellator.device)
    assert device.fused_crack_free == device.fused_offsets  # by default where stage 3 is one launch
