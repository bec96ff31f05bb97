/* Shared device math of the cltess pipeline: Bernstein bases, rational patch evaluation,
 * Zheng-Sederberg steps and the quad tessellation pattern.  Every stage includes this file;
 * cltess/reference.py is the NumPy mirror of each routine (same names).
 *
 * Patch layout: 16 float4 homogeneous control points b[4*j + i] = (w*x, w*y, w*z, w),
 * i along u, j along v.  Edges counter-clockwise: 0: v=0, 1: u=1, 2: v=1, 3: u=0.
 */
#ifndef CLTESS_H
#define CLTESS_H

/* No fused multiply-add: neighbouring patches must evaluate shared boundary points with the
 * same roundings whatever code path (vector lanes or scalar tail) the compiler gives them. */
#pragma OPENCL FP_CONTRACT OFF

#define NORMAL_SHIFT 1.0e-3f     /* reference.NORMAL_SHIFT */
#define NORMAL_DEGENERATE 1.0e-5f /* reference.NORMAL_DEGENERATE */

/* --- Bernstein bases ------------------------------------------------------------------------ */

inline void bernstein3(float t, float b[4])
{
    float s = 1.0f - t;
    b[0] = s * s * s;
    b[1] = 3.0f * t * s * s;
    b[2] = 3.0f * t * t * s;
    b[3] = t * t * t;
}

inline void bernstein2(float t, float b[3])
{
    float s = 1.0f - t;
    b[0] = s * s;
    b[1] = 2.0f * t * s;
    b[2] = t * t;
}

inline void load_patch(__global const float4 *patches, uint p, float4 b[16])
{
    for (int k = 0; k < 16; ++k)
        b[k] = patches[16 * p + k];
}

/* --- rational patch evaluation (DESIGN.md section 2) ----------------------------------------- */

/* Collapse the patch to the row v = const: cubic controls c[i] of B(., v) and d[i] of B_v(., v).
 * Derivatives use differences of control points, so a collapsed edge gives exactly zero. */
inline void row_controls(const float4 b[16], float v, float4 c[4], float4 d[4])
{
    float bv[4], dv[3];
    bernstein3(v, bv);
    bernstein2(v, dv);
    for (int i = 0; i < 4; ++i) {
        c[i] = bv[0] * b[i] + bv[1] * b[4 + i] + bv[2] * b[8 + i] + bv[3] * b[12 + i];
        d[i] = 3.0f * (dv[0] * (b[4 + i] - b[i]) + dv[1] * (b[8 + i] - b[4 + i])
                       + dv[2] * (b[12 + i] - b[8 + i]));
    }
}

/* B, B_u, B_v at (u, v) by the tensor-product Bernstein form. */
inline void surface_eval(const float4 b[16], float u, float v, float4 *s, float4 *s_u, float4 *s_v)
{
    float4 c[4], d[4];
    float bu[4], du[3];
    row_controls(b, v, c, d);
    bernstein3(u, bu);
    bernstein2(u, du);
    *s = bu[0] * c[0] + bu[1] * c[1] + bu[2] * c[2] + bu[3] * c[3];
    *s_u = 3.0f * (du[0] * (c[1] - c[0]) + du[1] * (c[2] - c[1]) + du[2] * (c[3] - c[2]));
    *s_v = bu[0] * d[0] + bu[1] * d[1] + bu[2] * d[2] + bu[3] * d[3];
}

/* Unnormalised t_u x t_v with t = (B_d.xyz - B_d.w p) / B.w (the 1/B.w is dropped: same
 * direction).  Sets *ok when it is not (nearly) vanishing. */
inline float3 tangent_cross(float4 s, float4 s_u, float4 s_v, int *ok)
{
    float3 p = s.xyz / s.w;
    float3 t_u = s_u.xyz - s_u.w * p;
    float3 t_v = s_v.xyz - s_v.w * p;
    float3 n = cross(t_u, t_v);
    float scale = dot(t_u, t_u) + dot(t_v, t_v);
    *ok = dot(n, n) > NORMAL_DEGENERATE * NORMAL_DEGENERATE * scale * scale;
    return n;
}

/* Unit normal at (u, v), given B, B_u, B_v there.  At a collapsed edge t_u x t_v vanishes; the
 * normal is then taken a little way towards the domain centre, where it tends to the limit. */
inline float3 surface_normal(const float4 b[16], float u, float v, float4 s, float4 s_u, float4 s_v)
{
    int ok;
    float3 n = tangent_cross(s, s_u, s_v, &ok);
    if (!ok) {
        surface_eval(b, u + NORMAL_SHIFT * (0.5f - u), v + NORMAL_SHIFT * (0.5f - v), &s, &s_u, &s_v);
        n = tangent_cross(s, s_u, s_v, &ok);
    }
    float len = length(n);
    return len > 0.0f ? n / len : (float3)(0.0f, 0.0f, 1.0f);
}

/* The 4 control points of edge e, counter-clockwise (cltess/scene.py, boundary_curves). */
inline void edge_controls(const float4 b[16], int e, float4 c[4])
{
    for (int k = 0; k < 4; ++k) {
        int idx = e == 0 ? k : e == 1 ? 4 * k + 3 : e == 2 ? 15 - k : 12 - 4 * k;
        c[k] = b[idx];
    }
}

inline float4 lerp4(float4 a, float4 b, float t) { return a + t * (b - a); }

/* Point k of f on a boundary curve, placed symmetrically about the midpoint: de Casteljau
 * from the nearer end, and at the midpoint the commutative (a + b) / 2.  A neighbour walking
 * the shared curve the other way gets bitwise the same point (Mesa's tessellator does the
 * same for D3D11 patterns).  t = 0 returns the end control point exactly. */
inline float4 boundary_point(const float4 c[4], int k, int f)
{
    float4 q[4];
    int forward = 2 * k < f;
    for (int i = 0; i < 4; ++i)
        q[i] = forward ? c[i] : c[3 - i];
    if (2 * k == f) {
        for (int level = 3; level > 0; --level)
            for (int i = 0; i < level; ++i)
                q[i] = (q[i] + q[i + 1]) * 0.5f;
    } else {
        float t = (float)min(k, f - k) / (float)f;
        for (int level = 3; level > 0; --level)
            for (int i = 0; i < level; ++i)
                q[i] = lerp4(q[i], q[i + 1], t);
    }
    return q[0];
}

/* Domain parameters of point k of f on edge e. */
inline float2 edge_uv(int e, int k, int f)
{
    float t = (float)k / (float)f;
    return e == 0 ? (float2)(t, 0.0f) : e == 1 ? (float2)(1.0f, t)
         : e == 2 ? (float2)(1.0f - t, 1.0f) : (float2)(0.0f, 1.0f - t);
}

/* --- Zheng-Sederberg steps (DESIGN.md section 2) ---------------------------------------------- */

/* Steps with d_uu du^2 + 2 d_uv du dv + d_vv dv^2 <= c and du*dv largest, at most 1
 * (reference.zs_steps: the optimum du/dv = sqrt(d_vv/d_uu), written with s = sqrt(d_uu),
 * t = sqrt(d_vv) so that no 0 * inf appears; inputs scaled by their max; NaN -> 0 = saturated). */
inline float2 zs_steps(float d_uu, float d_uv, float d_vv, float c)
{
    float scale = max(max(d_uu, d_uv), d_vv);
    if (!(scale > 0.0f))
        return (float2)(1.0f, 1.0f);
    float a = d_uu / scale, d = d_uv / scale, b = d_vv / scale;
    c /= scale;
    float du, dv;
    if (a > 0.0f && b > 0.0f) {
        float s = sqrt(a), t = sqrt(b);
        du = s * (s * t + d) > 0.0f ? sqrt(c * t / (2.0f * s * (s * t + d))) : INFINITY;
        dv = t * (s * t + d) > 0.0f ? sqrt(c * s / (2.0f * t * (s * t + d))) : INFINITY;
    } else if (a > 0.0f) {
        dv = 1.0f;
        du = c / (d + sqrt(d * d + a * c));
    } else if (b > 0.0f) {
        du = 1.0f;
        dv = c / (d + sqrt(d * d + b * c));
    } else {
        du = dv = sqrt(c / (2.0f * d));
    }
    du = isnan(du) ? 0.0f : min(du, 1.0f);
    dv = isnan(dv) ? 0.0f : min(dv, 1.0f);
    return (float2)(du, dv);
}

/* --- the quad pattern (DESIGN.md section 5, reference.quad_pattern) ---------------------------- */

/* Core grid factors: the regular grid when uniform, else the inner grid of the ring pattern. */
inline int2 quad_core(int4 f, int *uniform)
{
    *uniform = f.s0 == f.s2 && f.s1 == f.s3;
    if (*uniform)
        return (int2)(f.s0, f.s1);
    return (int2)(max(min(f.s0, f.s2), 2), max(min(f.s1, f.s3), 2));
}

inline int factor_of(int4 f, int e) { return e == 0 ? f.s0 : e == 1 ? f.s1 : e == 2 ? f.s2 : f.s3; }

inline uint quad_vertex_count(int4 f)
{
    int uniform;
    if (f.s0 <= 0)
        return 0;
    int2 core = quad_core(f, &uniform);
    return (uint)(f.s0 + f.s1 + f.s2 + f.s3 + (core.x - 1) * (core.y - 1));
}

/* Local vertex numbers: the boundary ring first, then the inner grid row by row. */
inline uint ring_index(int4 f, int e, int k)
{
    int ring = f.s0 + f.s1 + f.s2 + f.s3;
    int base = e == 0 ? 0 : e == 1 ? f.s0 : e == 2 ? f.s0 + f.s1 : f.s0 + f.s1 + f.s2;
    return (uint)((base + k) % ring);
}

inline uint inner_index(int4 f, int2 core, int i, int j)
{
    return (uint)(f.s0 + f.s1 + f.s2 + f.s3 + (j - 1) * (core.x - 1) + (i - 1));
}

inline uint grid_index(int4 f, int2 core, int i, int j)
{
    if (j == 0) return ring_index(f, 0, i);
    if (i == core.x) return ring_index(f, 1, j);
    if (j == core.y) return ring_index(f, 2, core.x - i);
    if (i == 0) return ring_index(f, 3, core.y - j);
    return inner_index(f, core, i, j);
}

/* Point k of the inner polyline that faces edge e, counter-clockwise. */
inline uint inner_edge_index(int4 f, int2 core, int e, int k)
{
    int a = core.x, b = core.y;
    return e == 0 ? inner_index(f, core, 1 + k, 1)
         : e == 1 ? inner_index(f, core, a - 1, 1 + k)
         : e == 2 ? inner_index(f, core, a - 1 - k, b - 1)
         : inner_index(f, core, 1, b - 1 - k);
}

/* One triangle: written when out is not null, always counted. */
inline void put_triangle(__global uint *out, uint *count, uint base, uint a, uint b, uint c)
{
    if (out) {
        out[3 * *count + 0] = base + a;
        out[3 * *count + 1] = base + b;
        out[3 * *count + 2] = base + c;
    }
    ++*count;
}

inline void grid_cells(__global uint *out, uint *count, uint base, int4 f, int2 core,
                       int i0, int i1, int j0, int j1)
{
    for (int j = j0; j < j1; ++j)
        for (int i = i0; i < i1; ++i) {
            uint a = grid_index(f, core, i, j), b = grid_index(f, core, i + 1, j);
            uint c = grid_index(f, core, i + 1, j + 1), d = grid_index(f, core, i, j + 1);
            put_triangle(out, count, base, a, b, c);
            put_triangle(out, count, base, a, c, d);
        }
}

/* The quad pattern's triangles, in "count" mode (out == 0) or "emit" mode (out != 0): one
 * routine, so the counts of stage 3 and the indices of stage 5 cannot disagree.  Returns the
 * number of triangles; vertex numbers are offset by base. */
inline uint quad_triangles(int4 f, __global uint *out, uint base)
{
    uint count = 0;
    int uniform;
    if (f.s0 <= 0)
        return 0;
    int2 core = quad_core(f, &uniform);
    if (uniform) {
        grid_cells(out, &count, base, f, core, 0, core.x, 0, core.y);
        return count;
    }
    grid_cells(out, &count, base, f, core, 1, core.x - 1, 1, core.y - 1);
    /* Transition strips (CudaTess section 3, Moreton 2001): between an edge's f_e segments and
     * the facing inner polyline's core-2 segments, advance the side whose next segment's
     * midpoint comes first: (o + 1/2) / f_e <= (k + 3/2) / core, in integers. */
    for (int e = 0; e < 4; ++e) {
        int outer_n = factor_of(f, e), along = (e % 2 == 0) ? core.x : core.y, inner_n = along - 2;
        int o = 0, k = 0;
        while (o < outer_n || k < inner_n) {
            if (k == inner_n || (o < outer_n && (2 * o + 1) * along <= (2 * k + 3) * outer_n)) {
                put_triangle(out, &count, base, ring_index(f, e, o), ring_index(f, e, o + 1),
                             inner_edge_index(f, core, e, k));
                ++o;
            } else {
                put_triangle(out, &count, base, ring_index(f, e, o), inner_edge_index(f, core, e, k + 1),
                             inner_edge_index(f, core, e, k));
                ++k;
            }
        }
    }
    return count;
}

#endif
