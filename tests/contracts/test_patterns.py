"""Every registered pattern (cltess.patterns.PATTERNS), on the device against its NumPy mirror on
random factors: counts (stage 3) equal to the mirror's and to what stages 4 and 5 emit, the
triangles (stage 5) and the vertex parameters (stage 4) those of the mirror."""
import numpy as np
import pyopencl.array as cl_array
import pytest

from cltess.criteria import ObjectSpace
from cltess.patterns import PATTERNS
from support.factors import device_counts_and_indices, random_pattern_factors
from support.kinds import kind_for, random_source

PATTERN_LIST = list(PATTERNS.values())


@pytest.fixture(params=PATTERN_LIST, ids=[p.name for p in PATTERN_LIST])
def pattern(request):
    return request.param


def test_counts_and_triangles_equal_the_mirror(tessellator, rng, pattern):
    factors = random_pattern_factors(rng, pattern, 600)
    layouts, firsts, triangles = device_counts_and_indices(tessellator, pattern, factors)
    expected = np.concatenate([np.reshape(t, (-1, 3)) + first for (_, t), first in zip(layouts, firsts)])
    assert np.array_equal(triangles, expected)


@pytest.mark.parametrize("fd", [True, False], ids=["fd", "direct"])
def test_vertex_layout_equals_the_mirror(tessellator, rng, pattern, fd):
    """Stage 4 writes as many vertices as stage 3 counted, at the mirror's (u, v), patch by patch."""
    kind = kind_for(pattern)
    factors = random_pattern_factors(rng, pattern, 200)
    count = len(factors)
    data = tessellator.upload(kind, random_source(rng, kind, count))
    scratch = cl_array.empty(tessellator.queue, (count, 4), np.int32), cl_array.empty(tessellator.queue, count, np.int32)
    tessellator.stage_factors_of(kind, data, ObjectSpace(0.1), 64, *scratch)  # the kind's stage-4 input
    device_factors = cl_array.to_device(tessellator.queue, factors)
    vertex_offsets, _, _ = tessellator.stage_counts(device_factors, [(pattern, 0, count)])
    total = int(vertex_offsets[count].get())
    objects = cl_array.to_device(tessellator.queue, np.arange(count, dtype=np.int32))
    out, _ = tessellator.stage_vertices(data["controls"], device_factors, vertex_offsets, objects, (0, total),
                                        (0, count), fd, kind=kind, pattern=pattern)
    layouts = [pattern.layout(f)[0] for f in factors]
    expected_ids = np.concatenate([np.full(len(uv), p) for p, uv in enumerate(layouts)])
    assert np.array_equal(out["patch_ids"].get(), expected_ids)
    assert np.array_equal(out["object_ids"].get(), expected_ids)
    assert np.allclose(out["uv"].get(), np.concatenate(layouts), rtol=0, atol=1e-6)
    assert np.isfinite(out["positions"].get()).all()


CHORD_PATTERNS = [p for p in PATTERN_LIST if p.chords is not None]


@pytest.mark.parametrize("pattern", CHORD_PATTERNS, ids=[p.name for p in CHORD_PATTERNS])
@pytest.mark.parametrize("fd", [True, False], ids=["fd", "direct"])
def test_chord_points_equal_the_mirror(tessellator, rng, pattern, fd):
    """Stage 4 puts a pattern's chord points (Pattern.chords; SD-2's tie-zone centres) at
    P[start] + mu (P[end] - P[start]) of its own vertices, exactly P[start] at mu = 0
    (cltess/patterns/base.py place_chords, kernels/stages/rows.h chord_position), on random
    hinted records, ring and interior ends alike; every other vertex stays where it was."""
    from cltess.patterns.base import place_chords

    kind = kind_for(pattern)
    factors = random_pattern_factors(rng, pattern, 300)
    count = len(factors)
    data = tessellator.upload(kind, random_source(rng, kind, count))
    scratch = cl_array.empty(tessellator.queue, (count, 4), np.int32), cl_array.empty(tessellator.queue, count, np.int32)
    tessellator.stage_factors_of(kind, data, ObjectSpace(0.1), 64, *scratch)
    device_factors = cl_array.to_device(tessellator.queue, factors)
    vertex_offsets, _, _ = tessellator.stage_counts(device_factors, [(pattern, 0, count)])
    total = int(vertex_offsets[count].get())
    objects = cl_array.to_device(tessellator.queue, np.zeros(count, np.int32))
    out, _ = tessellator.stage_vertices(data["controls"], device_factors, vertex_offsets, objects, (0, total),
                                        (0, count), fd, kind=kind, pattern=pattern)
    positions, firsts = out["positions"].get().reshape(-1, 3), vertex_offsets.get()
    chord_count = exact = 0
    for p, f in enumerate(factors):
        got = positions[firsts[p]:firsts[p + 1]]
        chords = pattern.chords(f)
        vertices, start, _, mu = chords
        chord_count += len(vertices)
        expected = place_chords(got, chords)
        assert np.allclose(got, expected, rtol=0, atol=2e-6), p
        still = mu == 0
        assert np.array_equal(got[vertices[still]], got[start[still]]), p  # bitwise on its start
        exact += still.sum()
    assert chord_count > 100 and 0 < exact < chord_count  # zone patches, both kinds of mu, were drawn
