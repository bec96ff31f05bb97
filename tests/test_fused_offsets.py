"""Stage 3 in one launch per range (stages/offsets.cl, Tessellator.fused_offsets, issue 15):
the same counts and offsets as the counts kernel and pyopencl.scan, and as the NumPy mirror,
over several tiles of the work-group, two patterns in a row, culled and collapsed patches."""
import numpy as np
import pyopencl.array as cl_array
import pytest

from cltess import reference
from cltess.backends.opencl import tessellator as opencl
from support.factors import random_factors, random_triangle_factors


@pytest.fixture
def fused(tessellator):
    fused = opencl.Tessellator(tessellator.device, work="patch")
    fused.fused_offsets = True
    return fused


@pytest.mark.parametrize("group", [1, 64, opencl.FUSED_OFFSETS_GROUP])  # 1: no scan step at all
def test_fused_offsets_are_the_scans(tessellator, fused, rng, monkeypatch, group):
    from cltess.pipeline import BEZIER, PN

    monkeypatch.setattr(opencl, "FUSED_OFFSETS_GROUP", group)
    # factors below 12: the mirror's counts emit every patch's pattern in Python (below 70: 6-7 s a case)
    quads, triangles = random_factors(rng, 1000, high=12), random_triangle_factors(rng, 700, high=12)
    quads[::7] = 0  # culled
    quads[3::11, 0] *= -1  # a collapsed edge (stored negated by stage 2)
    factors = np.concatenate([quads, triangles])
    ranges = [(BEZIER, 0, 1000), (PN, 1000, 700)]
    scans = opencl.Tessellator(tessellator.device, work="patch")
    scans.fused_offsets = False
    results = []
    for tess in (scans, fused):
        scratch = {}
        for _ in range(2):  # a second call on the same scratch arrays (a session's frames)
            vertex_offsets, index_offsets, events = tess.stage_counts(
                cl_array.to_device(tess.queue, factors), kind=ranges, scratch=scratch)
        results.append((vertex_offsets.get(), index_offsets.get(), scratch["vertex_counts"].get(),
                        scratch["index_counts"].get(), len(events)))
    assert results[1][4] == 2  # one launch per range
    for expected, got in zip(results[0][:4], results[1][:4]):
        assert np.array_equal(expected, got)
    counts = reference.counts(quads), reference.counts(triangles, kind="pn")  # the mirror reads the signs
    for got, field in ((results[1][0], 0), (results[1][1], 1)):
        assert np.array_equal(got, reference.offsets(np.concatenate([counts[0][field], counts[1][field]])))


def test_fused_offsets_above_the_cap_use_the_scans(fused, monkeypatch, rng):
    monkeypatch.setattr(opencl, "FUSED_OFFSETS_MAX_PATCHES", 10)
    factors = random_factors(rng, 50)
    _, _, events = fused.stage_counts(cl_array.to_device(fused.queue, factors))
    assert len(events) == 2  # the counts kernel and the pair scan


def test_a_pattern_that_counts_by_walking_uses_the_scans(fused, rng):
    """A pattern whose counts walk it (Pattern.counts_walk: ESC before its tables, esc.ESC_WALK):
    one work-group would run that walk for every patch on one compute unit, so stage 3 keeps the
    counts kernel and the scan; a pattern with closed-form or table counts takes the one launch."""
    from cltess.patterns import PATTERNS
    from cltess.patterns.esc import ESC_WALK
    from support.factors import random_esc_records

    records = cl_array.to_device(fused.queue, random_esc_records(rng, 50))
    assert ESC_WALK.counts_walk and not PATTERNS["esc"].counts_walk
    _, _, walked = fused.stage_counts(records, kind=ESC_WALK)
    _, _, tabled = fused.stage_counts(records, kind=PATTERNS["esc"])
    assert len(walked) == 2 and len(tabled) == 1  # counts kernel + pair scan; one launch


def test_esc_offsets_in_one_launch_are_the_scans(tessellator, fused, rng):
    """ESC's counts from its tables (patterns/esc_counts.h) in stages/offsets.cl: the offsets of
    the counts kernel and the scan, over several tiles."""
    from cltess.patterns import PATTERNS
    from support.factors import random_esc_records

    records = random_esc_records(rng, 3000)
    scans = opencl.Tessellator(tessellator.device, work="patch")
    scans.fused_offsets = False
    got = [[a.get() for a in tess.stage_counts(cl_array.to_device(tess.queue, records), kind=PATTERNS["esc"])[:2]]
           for tess in (scans, fused)]
    assert np.array_equal(got[0][0], got[1][0]) and np.array_equal(got[0][1], got[1][1])
    assert got[1][1][-1] > 0


def test_fused_offsets_setting(tessellator, monkeypatch):
    monkeypatch.setenv("CLTESS_FUSED_OFFSETS", "1")
    assert opencl.Tessellator(tessellator.device).fused_offsets
    monkeypatch.setenv("CLTESS_FUSED_OFFSETS", "0")
    assert not opencl.Tessellator(tessellator.device).fused_offsets
    monkeypatch.setenv("CLTESS_FUSED_OFFSETS", "yes")
    with pytest.raises(ValueError, match="CLTESS_FUSED_OFFSETS"):
        opencl.Tessellator(tessellator.device)


@pytest.mark.parametrize("path", ["fused/1", "fused/64", "fused", "tiled/1", "tiled/64", "tiled", "scan"])
def test_stage_3_summary_is_the_totals_and_the_flag_counts(tessellator, rng, monkeypatch, path):
    """A frame's summary (Tessellator.stage_counts(summary=...): stages/offsets.cl
    offsets_summary on the last range, or the summary scan, programs.py): the vertex and index
    totals, and how many of stage 1's flags have FLAG_CULLED and FLAG_SATURATED (other bits and
    both together included), as NumPy counts them; the offsets are the plain stage 3's."""
    from cltess.kinds import FLAG_CULLED, FLAG_FOLDED, FLAG_SATURATED
    from cltess.pipeline import BEZIER, PN

    if "/" in path:  # work-groups of this many patches: several tiles per range, tiles across kinds
        monkeypatch.setattr(opencl, "FUSED_OFFSETS_GROUP" if path.startswith("fused") else "TILED_OFFSETS_GROUP",
                            int(path.split("/")[1]))
    tess = opencl.Tessellator(tessellator.device, work="patch")
    tess.fused_offsets, tess.tiled_offsets, tess._cpu = path.startswith("fused"), path.startswith("tiled"), False
    plain = opencl.Tessellator(tessellator.device, work="patch")
    plain.fused_offsets = False
    quads, triangles = random_factors(rng, 900), random_triangle_factors(rng, 450)
    quads[::7] = 0
    factors = np.concatenate([quads, triangles])
    flags = rng.choice(np.array([0, FLAG_SATURATED, FLAG_CULLED, FLAG_FOLDED, FLAG_SATURATED | FLAG_CULLED,
                                 FLAG_FOLDED | FLAG_SATURATED], np.int32), len(factors))
    ranges = [(BEZIER, 0, 900), (PN, 900, 450)]
    assert tess.writes_summary(len(factors), ranges)
    summary = cl_array.empty(tess.queue, opencl.SUMMARY_FIELDS, np.uint64)
    scratch = {}
    for _ in range(2):  # again on the same arrays (a session's frames)
        vertex_offsets, index_offsets, events = tess.stage_counts(
            cl_array.to_device(tess.queue, factors), kind=ranges, scratch=scratch,
            flags=cl_array.to_device(tess.queue, flags), summary=summary)
    expected = plain.stage_counts(cl_array.to_device(plain.queue, factors), kind=ranges)
    assert np.array_equal(vertex_offsets.get(), expected[0].get())
    assert np.array_equal(index_offsets.get(), expected[1].get())
    assert len(events) == 3 if tess.tiled_offsets or not tess.fused_offsets else 2  # fused: one per range
    if tess.tiled_offsets:  # tiles per range, then carries; the tiles' records
        group = min(opencl.TILED_OFFSETS_GROUP, 256)
        records = scratch["tiles"].get().reshape(-1, 4)
        assert len(records) >= -(-900 // group) + -(-450 // group)
    assert summary.get().tolist() == [int(expected[0].get()[-1]), int(expected[1].get()[-1]),
                                      int(np.count_nonzero(flags & FLAG_CULLED)),
                                      int(np.count_nonzero(flags & FLAG_SATURATED))]


def test_a_frame_reads_back_one_summary(tessellator, tea_table):
    """A plan's totals and flag counts come back in one copy of stage 3's summary (fused, tiled
    or scanned); with two scans (CLTESS_ONE_SCAN=0), as the totals and the flags (three copies),
    with the same stats."""
    import cltess

    scene, stats = tea_table, []
    for fused, tiled, one_scan in ((True, False, True), (False, True, True), (False, False, True),
                                   (False, False, False)):
        tess = opencl.Tessellator(tessellator.device, work="patch")
        tess.fused_offsets, tess.tiled_offsets, tess.one_scan = fused, tiled, one_scan
        plan = tess.plan(scene, pixels=0.5)
        assert None not in (plan.stats["culled"], plan.stats["saturated"])
        session = cltess.Session(scene, tessellator=tess, pixels=0.5)
        session.tessellate()
        frame = session.tessellate(wait=False)
        pending = session._plans[-1]._pending
        assert len(pending[2]) == (1 if one_scan else 3) and (pending[1] is None) == one_scan
        stats.append((plan.stats, frame.stats))
    assert stats[0] == stats[1] == stats[2] == stats[3]
