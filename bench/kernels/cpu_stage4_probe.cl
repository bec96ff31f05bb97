/* Probes of stage 4 on a CPU device (bench/cpu_stages.py; not used by the engine).  Built like
 * stages/vertices.cl, against kinds/bezier.h and patterns/quad_transition.h, with the same
 * arguments; each writes its share of the vertices exactly where stages/vertices.cl does, so the
 * bench compares the union's bits with the engine's stage 4.
 *
 *   ring_only  a work-item per patch: the ring (stages/rows.h put_ring), nothing else.
 *   rows_only  a work-item per patch: the interior rows (put_rows), nothing else.
 *   ring_soa8  a work-item per (patch, edge, octet of its ring points): 8 ring points in float8
 *              lanes, the operations of ring_position (boundary_point's de Casteljau, or the
 *              midpoint's halving, from the nearer end) and kind_eval's normal per lane
 *              (surface_eval, then surface_normal as in rows_soa8).
 *   rows_soa8  a work-item per (patch, octet of rows): 8 rows walked at once in float8 lanes
 *              ("structure of arrays"), the operations of kind_row_next and surface_normal per
 *              lane (FP_CONTRACT off), so the same bits where cross, dot and length are
 *              written as the runtime's builtins compute them: with -D INTEL_FORMS the double
 *              forms of Intel's CPU runtime 2026.2 (its scalar code: cross and length in
 *              double, dot by dpps); a lane whose normal needs a fall-back calls
 *              surface_normal itself.  Uniform rows only (every row pattern_row(f, 1) steps,
 *              the quad transition pattern's).  SINK_ONLY: no stores, one float per work-item
 *              (the arithmetic alone); STORE_LANES: the same bytes stored as whole float8
 *              vectors, lane-major, into the same arrays (not the output's layout: what the
 *              stores would cost after a transpose, the transpose left out). */
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
    put_rows(&patch, f, collapsed, 1, pattern_rows(f), forward_differencing, out, at, p, patch_objects[p]);
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
                    float3 normal = surface_normal(patch.t, x.x, x.y, s, projected(s), s_u, s_v);
                    LANE(ox, k) = normal.x;
                    LANE(oy, k) = normal.y;
                    LANE(oz, k) = normal.z;
                }
        }
#ifdef SINK_ONLY
        sink += qx + qy + qz + ox + oy + oz;
#elif defined(STORE_LANES)
        /* the same bytes written as whole float8 vectors, lane-major (not the output's layout:
         * what stores after a transpose would cost, the transpose left out) */
        ulong at = min(8 * (at0 / 8 + (ulong)(i - 1)), (vertex_offsets[first_patch + num_patches] - vertex_base) / 8 * 8 - 8);
        vstore8(qx, 3 * at / 8, positions); vstore8(qy, 3 * at / 8 + 1, positions); vstore8(qz, 3 * at / 8 + 2, positions);
        vstore8(ox, 3 * at / 8, normals); vstore8(oy, 3 * at / 8 + 1, normals); vstore8(oz, 3 * at / 8 + 2, normals);
        vstore8((float8)(x0.x), 2 * at / 8, uv); vstore8(row_v, 2 * at / 8 + 1, uv);
        vstore8((int8)((int)p), at / 8, patch_ids); vstore8((int8)(object), at / 8, object_ids);
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

/* The unit normal of surface_normal from B, B_u, B_v in lanes (s*, u*, v*: their components; the
 * engine's own is kinds/bezier.h normal_lanes);
 * a lane that needs a fall-back gets surface_normal's own (at its (u, v)). */
inline void probe_normal_lanes(__private const kind_patch *patch, float8 u, float8 v, float8 sx, float8 sy, float8 sz,
                               float8 sw, float8 sux, float8 suy, float8 suz, float8 suw, float8 svx,
                               float8 svy, float8 svz, float8 svw, int lanes, float8 *ox, float8 *oy, float8 *oz)
{
    float8 px = sx / sw, py = sy / sw, pz = sz / sw;
    float8 ux = sux - suw * px, uy = suy - suw * py, uz = suz - suw * pz;
    float8 vx = svx - svw * px, vy = svy - svw * py, vz = svz - svw * pz;
    float8 nx = cross_lanes(uy, vz, uz, vy), ny = cross_lanes(uz, vx, ux, vz), nz = cross_lanes(ux, vy, uy, vx);
    float8 scale = dot_lanes(ux, uy, uz, ux, uy, uz) + dot_lanes(vx, vy, vz, vx, vy, vz);
    int8 ok = dot_lanes(nx, ny, nz, nx, ny, nz) > NORMAL_DEGENERATE * NORMAL_DEGENERATE * scale * scale;
    float8 len = length_lanes(nx, ny, nz);
    int8 positive = len > 0.0f;
    *ox = select((float8)(0.0f), nx / len, positive);
    *oy = select((float8)(0.0f), ny / len, positive);
    *oz = select((float8)(1.0f), nz / len, positive);
    int8 fall_back = ~ok;
    if (any(fall_back))
        for (int k = 0; k < lanes; ++k)
            if (((int *)&fall_back)[k]) {
                float4 s = (float4)(LANE(sx, k), LANE(sy, k), LANE(sz, k), LANE(sw, k));
                float4 s_u = (float4)(LANE(sux, k), LANE(suy, k), LANE(suz, k), LANE(suw, k));
                float4 s_v = (float4)(LANE(svx, k), LANE(svy, k), LANE(svz, k), LANE(svw, k));
                float3 normal = surface_normal(patch->t, LANE(u, k), LANE(v, k), s, projected(s), s_u, s_v);
                LANE(*ox, k) = normal.x;
                LANE(*oy, k) = normal.y;
                LANE(*oz, k) = normal.z;
            }
}

/* Component c of a float4 */
#define COMP(a, c) ((c) == 0 ? (a).x : (c) == 1 ? (a).y : (c) == 2 ? (a).z : (a).w)

__kernel void ring_soa8(__global const float4 *controls, __global const int4 *factors,
                        __global const ulong *vertex_offsets, __global const int *patch_objects,
                        uint first_patch, uint num_patches, uint patch_base, ulong vertex_base,
                        int forward_differencing, uint octets,
                        __global float *positions, __global float *normals, __global float *uv,
                        __global int *patch_ids, __global int *object_ids)
{
    size_t item = get_global_id(0);
    uint q = (uint)(item / (4 * octets));
    int e = (int)(item / octets % 4), octet = (int)(item % octets);
    if (q >= num_patches)
        return;
    uint p = first_patch + q;
    int collapsed;
    int4 f = patch_factors(factors[p], &collapsed);
    int count = PATTERN_EDGE_POINTS(f, e), first = 8 * octet;
    if (f.s0 <= 0 || first >= count)
        return;
    int lanes = min(8, count - first), object = patch_objects[p];
    kind_patch patch;
    kind_load(controls, p - patch_base, &patch);
    ulong at = vertex_offsets[p] - vertex_base + (ulong)first;
    for (int edge = 0; edge < e; ++edge)
        at += (ulong)PATTERN_EDGE_POINTS(f, edge);
    int fe = factor_of(f, e);
    /* lane k: point first + k of the edge (ring_position, whole factors) */
    float8 near_s, t_loc;
    int8 forward, middle, corner;
    for (int k = 0; k < 8; ++k) {
        int point = first + min(k, lanes - 1);
        edge_param t = pattern_ring_param(f, e, point);
        int kk = (collapsed >> e) & 1 ? 0 : t.k;  /* a collapsed edge: its first corner */
        int near = min(kk, t.f - kk);
        LANE(near_s, k) = kk == 0 || 2 * kk == t.f ? 0.0f : (float)near / (float)t.f;
        LANE(t_loc, k) = edge_location(t);
        ((int *)&forward)[k] = 2 * kk < t.f ? -1 : 0;
        ((int *)&middle)[k] = 2 * kk == t.f ? -1 : 0;
        ((int *)&corner)[k] = kk == 0 ? -1 : 0;
    }
    /* boundary_point on edge e's controls, component by component */
    float8 h[4];
    for (int c = 0; c < 4; ++c) {
        float8 qv[4];
        for (int i = 0; i < 4; ++i)
            qv[i] = select((float8)(COMP(patch.edges[e][3 - i], c)), (float8)(COMP(patch.edges[e][i], c)), forward);
        float8 m[4] = {qv[0], qv[1], qv[2], qv[3]}, l[4] = {qv[0], qv[1], qv[2], qv[3]};
        for (int level = 3; level > 0; --level)
            for (int i = 0; i < level; ++i) {
                m[i] = (m[i] + m[i + 1]) * 0.5f;
                l[i] = l[i] + near_s * (l[i + 1] - l[i]);
            }
        h[c] = select(select(l[0], m[0], middle), (float8)(COMP(patch.edges[e][0], c)), corner);
    }
    float8 qx = h[0] / h[3], qy = h[1] / h[3], qz = h[2] / h[3];
    /* the domain point (quad_edge_point) */
    float8 u = e == 0 ? t_loc : e == 1 ? (float8)(1.0f) : e == 2 ? 1.0f - t_loc : (float8)(0.0f);
    float8 v = e == 0 ? (float8)(0.0f) : e == 1 ? t_loc : e == 2 ? (float8)(1.0f) : 1.0f - t_loc;
    /* surface_eval: row_controls at v, then the u direction */
    float8 sv = 1.0f - v;
    float8 bv0 = sv * sv * sv, bv1 = 3.0f * v * sv * sv, bv2 = 3.0f * v * v * sv, bv3 = v * v * v;
    float8 dv0 = sv * sv, dv1 = 2.0f * v * sv, dv2 = v * v;
    float8 su = 1.0f - u;
    float8 bu0 = su * su * su, bu1 = 3.0f * u * su * su, bu2 = 3.0f * u * u * su, bu3 = u * u * u;
    float8 du0 = su * su, du1 = 2.0f * u * su, du2 = u * u;
    float8 s[4], s_u[4], s_v[4];
    for (int c = 0; c < 4; ++c) {
        float8 cc[4], dd[4];
        for (int i = 0; i < 4; ++i) {
            float b0 = COMP(patch.t[i], c), b1 = COMP(patch.t[4 + i], c), b2 = COMP(patch.t[8 + i], c),
                  b3 = COMP(patch.t[12 + i], c);
            cc[i] = bv0 * b0 + bv1 * b1 + bv2 * b2 + bv3 * b3;
            dd[i] = 3.0f * (dv0 * (b1 - b0) + dv1 * (b2 - b1) + dv2 * (b3 - b2));
        }
        s[c] = bu0 * cc[0] + bu1 * cc[1] + bu2 * cc[2] + bu3 * cc[3];
        s_u[c] = 3.0f * (du0 * (cc[1] - cc[0]) + du1 * (cc[2] - cc[1]) + du2 * (cc[3] - cc[2]));
        s_v[c] = bu0 * dd[0] + bu1 * dd[1] + bu2 * dd[2] + bu3 * dd[3];
    }
    float8 ox, oy, oz;
    probe_normal_lanes(&patch, u, v, s[0], s[1], s[2], s[3], s_u[0], s_u[1], s_u[2], s_u[3], s_v[0], s_v[1],
                       s_v[2], s_v[3], lanes, &ox, &oy, &oz);
    for (int k = 0; k < lanes; ++k, ++at) {
        positions[3 * at] = LANE(qx, k);
        positions[3 * at + 1] = LANE(qy, k);
        positions[3 * at + 2] = LANE(qz, k);
        normals[3 * at] = LANE(ox, k);
        normals[3 * at + 1] = LANE(oy, k);
        normals[3 * at + 2] = LANE(oz, k);
        uv[2 * at] = LANE(u, k);
        uv[2 * at + 1] = LANE(v, k);
        patch_ids[at] = (int)p;
        object_ids[at] = object;
    }
}
