"""The semi-uniform patterns on the device, through the pipeline's own stages, beyond the random
factors of the contract tests (tests/contracts/test_patterns.py): every record of levels m <= 5
(every edge level p_e <= m), counts equal to the closed forms, triangles in the mirror's order,
uv bit for bit; and stage 1's dyadic rounding (-D PATTERN_DYADIC, common.h dyadic_factors)
against its mirror (cltess.backends.numpy.dyadic_stage) for every kind."""
import itertools

import numpy as np
import pyopencl.array as cl_array
import pytest

from cltess.backends.numpy import dyadic_stage
from cltess.criteria import ObjectSpace
from cltess.kinds import FLAG_SATURATED, KINDS
from cltess.patterns import QUAD_SEMI_UNIFORM, TRI_SEMI_UNIFORM, pattern_named
from cltess.patterns import semi_uniform as su
from support.kinds import kind_for, random_source

MAX_TESTED_LEVEL = 5


def records_of(domain, max_level=MAX_TESTED_LEVEL):
    """Every record of edge levels p_e <= max_level (m = max p_e), and one culled record."""
    edges = su.EDGES[domain]
    records = [[1 << p for p in levels] + [0] * (4 - edges)
               for levels in itertools.product(range(max_level + 1), repeat=edges)]
    return np.array(records + [[0, 0, 0, 0]], np.int32)


def offsets(counts):
    return np.concatenate([[0], np.cumsum(counts)])


@pytest.mark.parametrize("pattern", [QUAD_SEMI_UNIFORM, TRI_SEMI_UNIFORM], ids=lambda p: p.name)
def test_every_record_up_to_level_5(tessellator, rng, pattern):
    records = records_of(pattern.domain)
    count = len(records)
    factors = cl_array.to_device(tessellator.queue, records)
    vertex_offsets, index_offsets, _ = tessellator.stage_counts(factors, [(pattern, 0, count)])
    mirror = [pattern.layout(r) for r in records]
    vertex_counts, index_counts = su.counts(records, pattern.domain)  # the closed forms
    assert np.array_equal(vertex_counts, [len(uv) for uv, _ in mirror])
    assert np.array_equal(index_counts, [3 * len(t) for _, t in mirror])
    assert np.array_equal(vertex_offsets.get(), offsets(vertex_counts))
    assert np.array_equal(index_offsets.get(), offsets(index_counts))

    total = int(index_offsets[count].get())
    triangles, _ = tessellator.stage_indices(factors, vertex_offsets, index_offsets, (0, total), (0, count),
                                             kind=pattern)
    firsts = offsets(vertex_counts)
    assert np.array_equal(triangles.get(), np.concatenate([t + first for (_, t), first in zip(mirror, firsts)]))

    kind = kind_for(pattern)
    data = tessellator.upload(kind, random_source(rng, kind, count))
    scratch = cl_array.empty(tessellator.queue, (count, 4), np.int32), cl_array.empty(tessellator.queue, count, np.int32)
    tessellator.stage_factors_of(kind, data, ObjectSpace(0.1), 64, *scratch)  # the kind's stage-4 input
    objects = cl_array.zeros(tessellator.queue, count, np.int32)
    for fd in (True, False):
        out, _ = tessellator.stage_vertices(data["controls"], factors, vertex_offsets, objects,
                                            (0, int(vertex_offsets[count].get())), (0, count), fd, kind=kind,
                                            pattern=pattern)
        # dyadic parameters: exact in float32, bit for bit
        assert np.array_equal(out["uv"].get(), np.concatenate([uv for uv, _ in mirror]).astype(np.float32))


@pytest.mark.parametrize("max_level", [0, 2, 6])
@pytest.mark.parametrize("kind", KINDS, ids=lambda k: k.name)
def test_stage_1_rounds_up_to_dyadic_factors(tessellator, rng, kind, max_level):
    """With a dyadic pattern, stage 1 gives 2^min(ceil(log2 f), max_level) of the factors it
    gives otherwise, saturated where the cap lowers one; culled patches stay 0."""
    count = 400
    data = tessellator.upload(kind, random_source(rng, kind, count))

    def stage_1(pattern):
        factors = cl_array.empty(tessellator.queue, (count, 4), np.int32)
        flags = cl_array.empty(tessellator.queue, count, np.int32)
        tessellator.stage_factors_of(kind, data, ObjectSpace(0.001), 100, factors, flags, pattern=pattern,
                                     max_level=max_level)
        return factors.get(), flags.get()

    plain, plain_flags = stage_1(kind.pattern)
    dyadic, dyadic_flags = stage_1(pattern_named("semi_uniform", kind.domain))
    expected, expected_flags = dyadic_stage(plain, plain_flags, max_level)
    assert np.array_equal(dyadic, expected)
    assert np.array_equal(dyadic_flags, expected_flags)
    assert (plain > 1 << max_level).any() and (dyadic_flags & ~plain_flags & FLAG_SATURATED).any()
    assert ((dyadic == 0) == (plain == 0)).all()


def test_dyadic_factors_mirror_is_exact():
    """The mirror of common.h dyadic_factor: the smallest 2^p >= f, p capped; 0 kept."""
    factors = np.concatenate([np.arange(0, 5000), [2 ** 29 + 1, 2 ** 30 - 1, 2 ** 30]])
    for max_level in (0, 3, 6, 30):
        got = su.dyadic_factors(factors, max_level).astype(np.int64)
        expected = [0 if f == 0 else min(1 << (int(f) - 1).bit_length(), 1 << max_level) for f in factors]
        assert got.tolist() == expected
