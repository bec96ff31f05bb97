/* Probes of stage 4 on a CPU device (bench/cpu_stages.py; not used by the engine).  Built like
 * stages/vertices.cl, against kinds/bezier.h and patterns/quad_transition.h, with the same
 * arguments; each writes its share of the vertices exactly where stages/vertices.cl does, so the
 * bench compares the union's bits with the engine's stage 4.
 *
 *   ring_only  a work-item per patch: the ring (stages/rows.h put_ring), nothing else.
 *   rows_only  a work-item per patch: the interior rows (put_rows), nothing else.
 *   rows_soa8  a work-item per (patch, octet of rows): 8 rows walked at once in float8 lanes
 *              ("structure of arrays"), the operations of kind_row_next and surface_normal per
 *              lane (FP_CONTRACT off), so the same bits where cross, dot and length are
 *              written as the runtime's builtins compute them: with -D INTEL_FORMS the double
 *              forms of Intel's CPU runtime 2026.2 (its scalar code: cross and length in
 *              double, dot by dpps); a lane whose normal needs a fall-back calls
 *              surface_normal itself.  Uniform rows only (every row pattern_row(f, 1) steps,
 *              the quad transition pattern's).  SINK_ONLY: no stores, one float per work-item
 *              (the arithmetic alone). */
#include "stages/rows.h"
#pragma OPENCL EXTENSION cl_khr_fp64 : enable

__kernel void ring_only(__global const float4 *controls, __global const int4 *factors,
                        __global const ulong *vertex_offsets, __global const int *patch_objects,
                        uint first_patch, uint num_patches, uint patch_base, ulong vertex_base,
                        int forward_differencing,
                        __global float *positions, __global float *normals, __global float *uv,
                        __global int *patch_ids, __global int *object_ids)
{
    uint p;
    int4 f;
    int collapsed;
    if (!batch_patch(first_patch, num_patches, factors, &p, &f, &collapsed))
        return;
    vertex_out out = {positions, normals, uv, patch_ids, object_ids};
    kind_patch patch;
    kind_load(controls, p - patch_base, &patch);
    put_ring(&patch, f, collapsed, out, vertex_offsets[p] - vertex_base, p, patch_objects[p]);
}

__kernel void rows_only(__global const float4 *controls, __global const int4 *factors,
                        __global const ulong *vertex_offsets, __global const int *patch_objects,
                        uint first_patch, uint num_patches, uint patch_base, ulong vertex_base,
                        int forward_differencing,
                        __global float *positions, __global float *normals, __global float *uv,
                        __global int *patch_ids, __global int *object_ids)
{
    uint p;
    int4 f;
    int collapsed;
    if (!batch_patch(first_patch, num_patches, factors, &p, &f, &collapsed))
        return;
    vertex_out out = {positions, normals, uv, patch_ids, object_ids};
    kind_patch patch;
    kind_load(controls, p - patch_base, &patch);
    ulong at = vertex_offsets[p] - vertex_base;
    for (int e = 0; e < PATTERN_EDGES; ++e)
        at += (ulong)PATTERN_EDGE_POINTS(f, e);
    put_rows(&patch, f, 1, pattern_rows(f), forward_differencing, out, at, p, patch_objects[p]);
}

/* dot, cross and length of float3, lane by lane, as the runtime's builtins round them. */
inline float8 dot_lanes(float8 ax, float8 ay, float8 az, float8 bx, float8 by, float8 bz)
{
#ifdef INTEL_FORMS
    return (ax * bx + ay * by) + (az * bz + 0.0f);  /* dpps: (p0 + p1) + (p2 + p3), p3 = +0 */
#else
    return (ax * bx + ay * by) + az * bz;
#endif
}

inline float8 cross_lanes(float8 a1, float8 b2, float8 a2, float8 b1)  /* a1 b2 - a2 b1 */
{
#ifdef INTEL_FORMS
    return convert_float8(convert_double8(a1) * convert_double8(b2) - convert_double8(a2) * convert_double8(b1));
#else
    return a1 * b2 - a2 * b1;
#endif
}

inline float8 length_lanes(float8 x, float8 y, float8 z)
{
#ifdef INTEL_FORMS
    double8 dx = convert_double8(x), dy = convert_double8(y), dz = convert_double8(z);
    return convert_float8(sqrt((dx * dx + dy * dy) + dz * dz));
#else
    return sqrt(dot_lanes(x, y, z, x, y, z));
#endif
}

#define LANE(v, k) (((float *)&(v))[k])

__kernel void rows_soa8(__global const float4 *controls, __global const int4 *factors,
                        __global const ulong *vertex_offsets, __global const int *patch_objects,
                        uint first_patch, uint num_patches, uint patch_base, ulong vertex_base,
                        int forward_differencing, uint octets,
                        __global float *positions, __global float *normals, __global float *uv,
                        __global int *patch_ids, __global int *object_ids)
{
    size_t item = get_global_id(0);
    uint q = (uint)(item / octets);
    int octet = (int)(item % octets);
    if (q >= num_patches)
        return;
    uint p = first_patch + q;
    int collapsed;
    int4 f = patch_factors(factors[p], &collapsed);
    int rows = pattern_rows(f);
    int first = 1 + 8 * octet;
    if (f.s0 <= 0 || first > rows)
        return;
    int object = patch_objects[p];
    kind_patch patch;
    kind_load(controls, p - patch_base, &patch);
    ulong ring = 0;
    for (int e = 0; e < PATTERN_EDGES; ++e)
        ring += (ulong)PATTERN_EDGE_POINTS(f, e);
    int steps = pattern_row(f, first);
    int lanes = min(8, rows - first + 1);
    ulong at0 = vertex_offsets[p] - vertex_base + ring + (ulong)(first - 1) * (ulong)(steps - 1);
    float8 d[3][4][4];  /* (s, s_u, s_v), difference, component; lane k: row first + k */
    float8 row_v;
    for (int k = 0; k < 8; ++k) {
        int j = first + min(k, lanes - 1);
        kind_row row;
        kind_row_begin(&patch, pattern_row_point(f, j, 0), pattern_row_point(f, j, steps), steps, &row);
        LANE(row_v, k) = pattern_row_point(f, j, 0).y;
        for (int m = 0; m < 4; ++m) {
            float4 a = row.s[m], b = row.s_u[m], c = row.s_v[m];
            LANE(d[0][m][0], k) = a.x; LANE(d[0][m][1], k) = a.y; LANE(d[0][m][2], k) = a.z; LANE(d[0][m][3], k) = a.w;
            LANE(d[1][m][0], k) = b.x; LANE(d[1][m][1], k) = b.y; LANE(d[1][m][2], k) = b.z; LANE(d[1][m][3], k) = b.w;
            LANE(d[2][m][0], k) = c.x; LANE(d[2][m][1], k) = c.y; LANE(d[2][m][2], k) = c.z; LANE(d[2][m][3], k) = c.w;
        }
    }
    float3 centre = patch.centre;
#ifdef SINK_ONLY
    float8 sink = 0.0f;
#endif
    for (int i = 1; i < steps; ++i) {
        for (int n = 0; n < 3; ++n)  /* step_differences */
            for (int c = 0; c < 4; ++c) {
                d[n][0][c] += d[n][1][c];
                d[n][1][c] += d[n][2][c];
                d[n][2][c] += d[n][3][c];
            }
        /* kind_row_next: position, then surface_normal's tangent_cross, length and division */
        float8 sx = d[0][0][0], sy = d[0][0][1], sz = d[0][0][2], sw = d[0][0][3];
        float8 px = sx / sw, py = sy / sw, pz = sz / sw;
        float8 ux = d[1][0][0] - d[1][0][3] * px, uy = d[1][0][1] - d[1][0][3] * py, uz = d[1][0][2] - d[1][0][3] * pz;
        float8 vx = d[2][0][0] - d[2][0][3] * px, vy = d[2][0][1] - d[2][0][3] * py, vz = d[2][0][2] - d[2][0][3] * pz;
        float8 nx = cross_lanes(uy, vz, uz, vy), ny = cross_lanes(uz, vx, ux, vz), nz = cross_lanes(ux, vy, uy, vx);
        float8 scale = dot_lanes(ux, uy, uz, ux, uy, uz) + dot_lanes(vx, vy, vz, vx, vy, vz);
        int8 ok = dot_lanes(nx, ny, nz, nx, ny, nz) > NORMAL_DEGENERATE * NORMAL_DEGENERATE * scale * scale;
        float8 len = length_lanes(nx, ny, nz);
        int8 positive = len > 0.0f;
        float8 ox = select((float8)(0.0f), nx / len, positive);
        float8 oy = select((float8)(0.0f), ny / len, positive);
        float8 oz = select((float8)(1.0f), nz / len, positive);
        float8 qx = px + centre.x, qy = py + centre.y, qz = pz + centre.z;
        float3 x0 = pattern_row_point(f, first, i);  /* u of step i, the same in every row */
        int8 fall_back = ~ok;
        if (any(fall_back)) {
            for (int k = 0; k < lanes; ++k)
                if (((int *)&fall_back)[k]) {
                    float3 x = pattern_row_point(f, first + k, i);
                    float4 s = (float4)(LANE(sx, k), LANE(sy, k), LANE(sz, k), LANE(sw, k));
                    float4 s_u = (float4)(LANE(d[1][0][0], k), LANE(d[1][0][1], k), LANE(d[1][0][2], k), LANE(d[1][0][3], k));
                    float4 s_v = (float4)(LANE(d[2][0][0], k), LANE(d[2][0][1], k), LANE(d[2][0][2], k), LANE(d[2][0][3], k));
                    float3 normal = surface_normal(patch.t, x.x, x.y, s, s_u, s_v);
                    LANE(ox, k) = normal.x;
                    LANE(oy, k) = normal.y;
                    LANE(oz, k) = normal.z;
                }
        }
#ifdef SINK_ONLY
        sink += qx + qy + qz + ox + oy + oz;
#else
        ulong at = at0 + (ulong)(i - 1);
        for (int k = 0; k < lanes; ++k, at += (ulong)(steps - 1)) {  /* lane k's vertex: a scatter */
            positions[3 * at] = LANE(qx, k);
            positions[3 * at + 1] = LANE(qy, k);
            positions[3 * at + 2] = LANE(qz, k);
            normals[3 * at] = LANE(ox, k);
            normals[3 * at + 1] = LANE(oy, k);
            normals[3 * at + 2] = LANE(oz, k);
            uv[2 * at] = x0.x;
            uv[2 * at + 1] = LANE(row_v, k);
            patch_ids[at] = (int)p;
            object_ids[at] = object;
        }
#endif
    }
#ifdef SINK_ONLY
    positions[item] = sink.s0 + sink.s1 + sink.s2 + sink.s3 + sink.s4 + sink.s5 + sink.s6 + sink.s7;
#endif
}
