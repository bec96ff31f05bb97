"""Every registered pattern (cltess.patterns.PATTERNS), on the device against its NumPy mirror on
random factors: counts (stage 3) equal to the mirror's and to what stages 4 and 5 emit, the
triangles (stage 5) and the vertex parameters (stage 4) those of the mirror."""
import numpy as np
import pyopencl.array as cl_array
import pytest

from cltess.criteria import ObjectSpace
from cltess.patterns import PATTERNS
from support.factors import random_pattern_factors
from support.kinds import kind_for, random_source

PATTERN_LIST = list(PATTERNS.values())


def offsets(counts):
    return np.concatenate([[0], np.cumsum(counts)])


@pytest.fixture(params=PATTERN_LIST, ids=[p.name for p in PATTERN_LIST])
def pattern(request):
    return request.param


def test_counts_and_triangles_equal_the_mirror(tessellator, rng, pattern):
    factors = random_pattern_factors(rng, pattern, 600)
    count = len(factors)
    device_factors = cl_array.to_device(tessellator.queue, factors)
    vertex_offsets, index_offsets, _ = tessellator.stage_counts(device_factors, [(pattern, 0, count)])
    layouts = [pattern.layout(f) for f in factors]
    vertex_counts = [len(uv) for uv, _ in layouts]
    assert np.array_equal(vertex_offsets.get(), offsets(vertex_counts))
    assert np.array_equal(index_offsets.get(), offsets([3 * len(t) for _, t in layouts]))
    total = int(index_offsets[count].get())
    triangles, _ = tessellator.stage_indices(device_factors, vertex_offsets, index_offsets, (0, total), (0, count),
                                             kind=pattern)
    expected = np.concatenate([t + first for (_, t), first in zip(layouts, offsets(vertex_counts))])
    assert np.array_equal(triangles.get(), expected)


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
