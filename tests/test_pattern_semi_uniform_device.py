"""kernels/patterns/semi_uniform.h against its mirror (cltess/patterns/semi_uniform.py), every
level m <= 5 and every edge level p_e <= m, quads and triangles: the same uv bit for bit, the same
triangles in the same order, count mode == emit mode == the closed forms, the row contract.

The header is built into a tiny test program with the few common definitions it needs (the
pattern contract's edge_param, factor_of, put_triangle), on the default device (PoCL here)."""
import itertools
import os
import subprocess
import sys
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
        row_ends[c * MAX_ROWS + j] = (float4)(uv0.x, uv0.y, uv1.x, uv1.y);
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


def records_of(domain, max_level=MAX_TESTED_LEVEL):
    """Every case m <= max_level, p_e <= m, as records of dyadic factors, and one culled record."""
    edges = su.EDGES[domain]
    records = [[1 << p for p in levels] + [0] * (4 - edges)
               for m in range(max_level + 1) for levels in itertools.product(range(m + 1), repeat=edges)
               if max(levels) == m]
    return np.array(records + [[0, 0, 0, 0]], np.int32)


def offsets(counts):
    return np.concatenate([[0], np.cumsum(counts)]).astype(np.uint32)


def run_kernels(context, domain, records, short=0):
    """Both test kernels on records: (counts: vertices, count mode, closed form, rows; emit:
    uvs, row_ends, row_counts, indices, emitted), the emit buffers offset by the count kernel's
    counts.  short: triangles left out of the index buffer (the Oclgrind self-test)."""
    ctx, queue = context
    program = build(ctx, domain)
    cases = len(records)
    mf = cl.mem_flags

    def run(kernel, shapes, *inputs):
        hosts = [np.zeros(shape, dtype) for shape, dtype in shapes]
        outs = [cl.Buffer(ctx, mf.READ_WRITE | mf.COPY_HOST_PTR, hostbuf=host) for host in hosts]
        inputs = [cl.Buffer(ctx, mf.READ_ONLY | mf.COPY_HOST_PTR, hostbuf=x) for x in inputs]
        kernel(queue, (cases,), None, inputs[0], np.uint32(cases), *inputs[1:], *outs)
        for out, host in zip(outs, hosts):
            cl.enqueue_copy(queue, host, out)
        return hosts

    counts = run(cl.Kernel(program, "counts"), [(cases, np.uint32)] * 3 + [(cases, np.int32)], records)
    vertex_offsets, triangle_offsets = offsets(counts[0]), offsets(counts[1])
    shapes = [((int(vertex_offsets[-1]), 2), np.float32), ((cases * MAX_ROWS, 4), np.float32),
              (cases * MAX_ROWS, np.int32), ((max(int(triangle_offsets[-1]) - short, 1), 3), np.uint32),
              (cases, np.uint32)]
    emit = run(cl.Kernel(program, "emit"), shapes, records, vertex_offsets, triangle_offsets)
    return counts, emit


def check_device_pattern(context, domain, max_level=MAX_TESTED_LEVEL):
    records = records_of(domain, max_level)
    mirror = [su.pattern(domain, r) for r in records]
    (vertices, count_mode, closed_form, rows), (uvs, row_ends, row_counts, indices, emitted) = \
        run_kernels(context, domain, records)

    expected_triangles = [len(t) for _, t in mirror]
    assert vertices.tolist() == [len(uv) for uv, _ in mirror]
    assert count_mode.tolist() == expected_triangles
    assert closed_form.tolist() == expected_triangles
    assert closed_form.tolist() == [0 if r[0] == 0 else su.triangle_count(domain, *su.record_levels(r, domain))
                                    for r in records]
    assert np.array_equal(emitted, count_mode)  # emit mode == count mode

    vertex_offsets, triangle_offsets = offsets(vertices), offsets(count_mode)
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


@pytest.mark.parametrize("domain", ["quad", "tri"])
def test_device_pattern_equals_mirror(context, domain):
    check_device_pattern(context, domain)


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


def check_dyadic_factor(context):
    test_dyadic_factor_on_device_equals_mirror(context)


# --- Oclgrind: every kernel path of the header, checked (tests/test_oclgrind.py's two passes) ---

OCLGRIND_PASSES = {
    "checks": {"OCLGRIND_CHECK_API": "1", "OCLGRIND_DATA_RACES": "1", "OCLGRIND_UNIFORM_WRITES": "1"},
    # unoptimised: the plugin stops at LLVM's freeze instruction otherwise (oclgrind_scenarios.py)
    "uninitialized": {"OCLGRIND_UNINITIALIZED": "1", "PYOPENCL_BUILD_OPTIONS": "-O0"},
}
OCLGRIND_LEVEL = 3  # every case up to m = 3: all code paths, a few seconds in the simulator
# pyopencl itself asks the device for a property Oclgrind does not know (at build and kernel
# creation, no launch involved): that API report is not about our kernels.
PYOPENCL_QUERY = "Oclgrind - OpenCL runtime error detected\n\tFunction: clGetDeviceInfo\n\tError:    CL_INVALID_VALUE\n"


def oclgrind_reports(pass_name, *args):
    from cltess.device import list_devices
    if not any(info.matches("oclgrind") for info in list_devices()):
        pytest.skip("no Oclgrind platform (the test extra installs it)")
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OCLGRIND_", "PYOPENCL_BUILD"))}
    env.update(OCLGRIND_PASSES[pass_name], CLTESS_DEVICE="oclgrind", OCLGRIND_MAX_ERRORS="1000000")
    process = subprocess.run([sys.executable, __file__, *args], capture_output=True, text=True, env=env,
                             timeout=300)
    blocks = [b.strip("\n") + "\n" for b in process.stderr.split("\n\n") if b.strip()]
    return process, [b for b in blocks if not b.startswith(PYOPENCL_QUERY) and b.strip() != "done"]


@pytest.mark.parametrize("pass_name", OCLGRIND_PASSES)
def test_oclgrind_clean(pass_name):
    process, reports = oclgrind_reports(pass_name, str(OCLGRIND_LEVEL))
    assert process.returncode == 0, process.stderr[-3000:]
    assert "done" in process.stderr and reports == [], "\n".join(reports[:5])


def test_oclgrind_sees_a_short_index_buffer():
    """The harness can fail: one triangle too few in the index buffer is an invalid write."""
    _, reports = oclgrind_reports("checks", "1", "--short")
    assert any(r.startswith("Invalid write") and "Kernel: emit" in r for r in reports), reports


if __name__ == "__main__":  # the Oclgrind runner: python this_file.py MAX_LEVEL [--short]
    device_context = make_queue(pick_device())
    if "--short" in sys.argv:
        run_kernels(device_context, "quad", records_of("quad", int(sys.argv[1])), short=1)
    else:
        for name in ("quad", "tri"):
            check_device_pattern(device_context, name, int(sys.argv[1]))
        check_dyadic_factor(device_context)
    print("done", file=sys.stderr)
