"""kernels/patterns/semi_uniform.h against its mirror (cltess/patterns/semi_uniform.py), every
level m <= 5 and every edge level p_e <= m, quads and triangles: the same uv bit for bit, the same
triangles in the same order, count mode == emit mode == the closed forms, the row contract.

The header is built into a tiny test program with the few common definitions it needs (the
pattern contract's edge_param, factor_of, put_triangle), on the default device (PoCL here)."""
import itertools
from importlib import resources

import numpy as np
import pyopencl as cl
import pytest

from cltess.device import make_queue, pick_device
from cltess.patterns import semi_uniform as su

KERNELS_DIR = str(resources.files("cltess.kernels"))  # the top-level kernels/ folder

MAX_TESTED_LEVEL = 5
MAX_ROWS = (1 << MAX_TESTED_LEVEL) - 1

PRELUDE = """
typedef struct { int k; int f; } edge_param;
inline int factor_of(int4 f, int e) { return e == 0 ? f.s0 : e == 1 ? f.s1 : e == 2 ? f.s2 : f.s3; }
inline void put_triangle(__global uint *out, uint *count, uint base, uint a, uint b, uint c)
{
    if (out) {
        out[3 * *count + 0] = base + a;
        out[3 * *count + 1] = base + b;
        out[3 * *count + 2] = base + c;
    }
    ++*count;
}
"""

KERNELS = """
#include "patterns/semi_uniform.h"

/* uv of point k of f on edge e (the kinds' edge_uv / tri_edge_point) */
inline float2 ring_uv(int e, edge_param t)
{
    float s = (float)t.k / (float)t.f, r = (float)(t.f - t.k) / (float)t.f;
    if (PATTERN_EDGES == 4)
        return e == 0 ? (float2)(s, 0.0f) : e == 1 ? (float2)(1.0f, s)
             : e == 2 ? (float2)(r, 1.0f) : (float2)(0.0f, r);
    return e == 0 ? (float2)(r, s) : e == 1 ? (float2)(0.0f, r) : (float2)(s, 0.0f);
}

__kernel void counts(__global const int4 *records, uint cases, __global uint *vertices,
                     __global uint *count_mode, __global uint *closed_form, __global int *rows)
{
    uint c = get_global_id(0);
    if (c >= cases)
        return;
    int4 f = records[c];
    vertices[c] = pattern_vertex_count(f);
    count_mode[c] = pattern_primitives(f, 0, 0);
    closed_form[c] = su_triangle_count(PATTERN_EDGES, f);
    rows[c] = pattern_rows(f);
}

/* The vertex loop of ARCHITECTURE.md section 3 writing uv, the rows' ends and counts, and the
 * triangles (vertex numbers offset by the case's first vertex). */
__kernel void emit(__global const int4 *records, uint cases, __global const uint *vertex_offsets,
                   __global const uint *triangle_offsets, __global float2 *uvs,
                   __global float4 *row_ends, __global int *row_counts,
                   __global uint *indices, __global uint *emitted)
{
    uint c = get_global_id(0);
    if (c >= cases)
        return;
    int4 f = records[c];
    uint at = vertex_offsets[c];
    for (int e = 0; e < PATTERN_EDGES; ++e)
        for (int k = 0; k < factor_of(f, e); ++k)
            uvs[at++] = ring_uv(e, pattern_ring_param(f, e, k));
    for (int j = 0; j < pattern_rows(f); ++j) {
        float2 uv0, uv1;
        int n = pattern_row(f, j, &uv0, &uv1);
        row_ends[c * MAX_ROWS + j] = (float4)(uv0, uv1);
        row_counts[c * MAX_ROWS + j] = n;
        for (int i = 0; i < n; ++i)
            uvs[at++] = pattern_row_point(f, j, i);
    }
    emitted[c] = pattern_primitives(f, indices + 3 * triangle_offsets[c], vertex_offsets[c]);
}
"""


@pytest.fixture(scope="module")
def context():
    return make_queue(pick_device())


def build(context, domain):
    edges = su.EDGES[domain]
    source = PRELUDE + f"#define PATTERN_EDGES {edges}\n#define MAX_ROWS {MAX_ROWS}\n" + KERNELS
    return cl.Program(context, source).build(options=["-I", KERNELS_DIR])


def records_of(domain):
    """Every case m <= 5, p_e <= m, as records of dyadic factors, and one culled record."""
    edges = su.EDGES[domain]
    records = [[1 << p for p in levels] + [0] * (4 - edges)
               for m in range(MAX_TESTED_LEVEL + 1) for levels in itertools.product(range(m + 1), repeat=edges)
               if max(levels) == m]
    return np.array(records + [[0, 0, 0, 0]], np.int32)


def offsets(counts):
    return np.concatenate([[0], np.cumsum(counts)]).astype(np.uint32)


@pytest.mark.parametrize("domain", ["quad", "tri"])
def test_device_pattern_equals_mirror(context, domain):
    ctx, queue = context
    program = build(ctx, domain)
    records = records_of(domain)
    cases = len(records)
    mirror = [su.pattern(domain, r) for r in records]
    mf = cl.mem_flags

    def buffer(array):
        return cl.Buffer(ctx, mf.READ_WRITE | mf.COPY_HOST_PTR, hostbuf=array)

    def device(*shape, dtype=np.uint32):
        return np.zeros(shape, dtype)

    records_buf = buffer(records)
    vertices, count_mode, closed_form, rows = device(cases), device(cases), device(cases), device(cases, dtype=np.int32)
    outs = [buffer(a) for a in (vertices, count_mode, closed_form, rows)]
    program.counts(queue, (cases,), None, records_buf, np.uint32(cases), *outs)
    for out, host in zip(outs, (vertices, count_mode, closed_form, rows)):
        cl.enqueue_copy(queue, host, out)

    expected_vertices = [len(uv) for uv, _ in mirror]
    expected_triangles = [len(t) for _, t in mirror]
    assert vertices.tolist() == expected_vertices
    assert count_mode.tolist() == expected_triangles
    assert closed_form.tolist() == expected_triangles
    closed = [0 if r[0] == 0 else su.triangle_count(domain, *su.record_levels(r, domain)) for r in records]
    assert closed_form.tolist() == closed

    vertex_offsets, triangle_offsets = offsets(vertices), offsets(count_mode)
    uvs = device(int(vertex_offsets[-1]), 2, dtype=np.float32)
    row_ends = device(cases * MAX_ROWS, 4, dtype=np.float32)
    row_counts = device(cases * MAX_ROWS, dtype=np.int32)
    indices = device(int(triangle_offsets[-1]), 3)
    emitted = device(cases)
    outs = [buffer(a) for a in (uvs, row_ends, row_counts, indices, emitted)]
    program.emit(queue, (cases,), None, records_buf, np.uint32(cases), buffer(vertex_offsets),
                 buffer(triangle_offsets), *outs)
    for out, host in zip(outs, (uvs, row_ends, row_counts, indices, emitted)):
        cl.enqueue_copy(queue, host, out)

    assert np.array_equal(emitted, count_mode)  # emit mode == count mode
    for c, (record, (uv, triangles)) in enumerate(zip(records, mirror)):
        first, last = vertex_offsets[c], vertex_offsets[c + 1]
        assert np.array_equal(uvs[first:last].astype(np.float64), uv), record  # bit for bit
        got = indices[triangle_offsets[c]:triangle_offsets[c + 1]].astype(np.int64) - first
        assert np.array_equal(got, triangles), record                        # same order too
        # the row contract, in integers on the lattice: count points evenly between the row's
        # ends, point i at ((count + 1 - i) uv0 + i uv1) / (count + 1), exactly the layout's
        n = 1 << max(su.record_levels(record, domain)[0], 0)
        ends = row_ends[c * MAX_ROWS:c * MAX_ROWS + rows[c]].astype(np.float64) * n
        assert np.array_equal(ends, np.round(ends)), record                  # lattice points
        counts = row_counts[c * MAX_ROWS:c * MAX_ROWS + rows[c]]
        row = np.repeat(np.arange(rows[c]), counts)
        i = np.concatenate([np.arange(1, k + 1) for k in counts] + [np.zeros(0, np.int64)])[:, None]
        total = (counts[row] + 1)[:, None]
        points = (total - i) * ends[row, :2] + i * ends[row, 2:]
        ring = int(record[:su.EDGES[domain]].sum())
        assert len(uv) == ring + counts.sum(), record
        assert np.array_equal(points, uv[ring:] * n * total), record
        assert np.array_equal(ends[:, 1], np.arange(1, rows[c] + 1)), record


def test_dyadic_factor_on_device_equals_mirror(context):
    ctx, queue = context
    source = PRELUDE + """
#include "patterns/semi_uniform.h"
__kernel void dyadic(__global const int *f, __global int *out, int max_level)
{
    out[get_global_id(0)] = su_dyadic_factor(f[get_global_id(0)], max_level);
}
"""
    dyadic = cl.Kernel(cl.Program(ctx, source).build(options=["-I", KERNELS_DIR]), "dyadic")
    factors = np.concatenate([np.arange(0, 5000), [2 ** 29 + 1, 2 ** 30 - 1, 2 ** 30]]).astype(np.int32)
    for max_level in (0, 3, 6, 30):
        out = np.zeros_like(factors)
        mf = cl.mem_flags
        f_buf = cl.Buffer(ctx, mf.READ_ONLY | mf.COPY_HOST_PTR, hostbuf=factors)
        out_buf = cl.Buffer(ctx, mf.WRITE_ONLY, out.nbytes)
        dyadic(queue, (len(factors),), None, f_buf, out_buf, np.int32(max_level))
        cl.enqueue_copy(queue, out, out_buf)
        expected = su.dyadic_factors(factors.astype(np.int64), max_level)
        assert np.array_equal(out, expected), max_level
