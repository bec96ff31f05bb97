/* PN triangles (Vlachos et al. 2001): the device side of the kind "pn" (docs/design.md section 3;
 * host cltess/kinds/pn.py, NumPy mirror cltess/surfaces/pn.py).
 *
 * Stage 1 reads a triangle's input (12 float4: kinds/pn.py) and writes its control points
 * (16 float4, pn_control_points): b[0..9] = b300 b030 b003 b210 b120 b021 b012 b102 b201 b111
 * (w = 1), b[10..15] = n200 n020 n002 n110 n011 n101 (w = 0).  Domain: barycentric (u, v, w =
 * 1-u-v) weighting corners P1, P2, P3 (tri_edge_point). */
#ifndef CLTESS_KINDS_PN_H
#define CLTESS_KINDS_PN_H
#include "common.h"
#include "criteria/tolerance.h"
#include "criteria/filip.h"

#define KIND_DOMAIN_EDGES 3

/* The inner control point of a boundary curve next to its end p_near (Vlachos et al.):
 * (2 p_near + p_far - ((p_far - p_near) . n_near) n_near) / 3.  One expression with the dot
 * product written out, so that the two triangles sharing an edge, which meet it from opposite
 * ends, compute bitwise the same point.  n_near = 0 gives the straight edge's third point. */
inline float3 pn_edge_control(float3 p_near, float3 p_far, float3 n_near)
{
    float w = dot3(p_far - p_near, n_near);
    return (2.0f * p_near + p_far - w * n_near) / 3.0f;
}

/* The inner control point next to p_near of an edge end's curve: PN's (pn_edge_control) from
 * the end's normal (w = 0), or at a crease end (w = 1, cltess/kinds/pn.py pn_crease_ends;
 * Dyken, Reimers and Seland 2008, section 4) along the crease direction t = n_s x n_t:
 * p_near + ((p_far - p_near) . t) / 3 t.  The other side computes the same point from the
 * same t. */
inline float3 pn_end_control(float3 p_near, float3 p_far, float4 n_near)
{
    if (n_near.w != 0.0f)
        return p_near + dot3(p_far - p_near, n_near.xyz) / 3.0f * n_near.xyz;
    return pn_edge_control(p_near, p_far, n_near.xyz);
}

/* n_ij of the quadratic normal field: normalize(N_i + N_j - v_ij (P_j - P_i)),
 * v_ij = 2 (P_j - P_i).(N_i + N_j) / |P_j - P_i|^2 (0 on a zero-length edge). */
inline float3 pn_mid_normal(float3 p_i, float3 p_j, float3 n_i, float3 n_j)
{
    float3 d = p_j - p_i;
    float len2 = dot3(d, d);
    float v = len2 > 0.0f ? 2.0f * dot3(d, n_i + n_j) / len2 : 0.0f;
    return unit_or_zero(n_i + n_j - v * d);
}

/* The control points from one triangle's input: in[0..2] positions P1 P2 P3, in[3..5] vertex
 * normals N1 N2 N3 (the normal field), in[6..11] the normals each boundary curve uses at its two
 * ends, edge e at in[6 + 2e] (start, corner e) and in[7 + 2e] (end, corner e+1): the vertex
 * normals, or 0 for a straight edge, or the average over the triangles at a sharp edge
 * (cltess/kinds/pn.py, pn_edge_normals; w = 1: a crease end, pn_end_control).  in[3].w = 1
 * chooses the centre control point of eq. 5 (cltess/kinds/pn.py PN_AVERAGE_CENTRE). */
inline void pn_control_points(const float4 in[12], float4 b[16])
{
    for (int c = 0; c < 3; ++c)
        b[c] = (float4)(in[c].xyz, 1.0f);
    float3 sum = (float3)(0.0f);
    __attribute__((opencl_unroll_hint))
    for (int e = 0; e < 3; ++e) {
        float3 p = in[e].xyz, q = in[(e + 1) % 3].xyz;
        float3 near = pn_end_control(p, q, in[6 + 2 * e]);
        float3 far = pn_end_control(q, p, in[7 + 2 * e]);
        b[3 + 2 * e] = (float4)(near, 1.0f);
        b[4 + 2 * e] = (float4)(far, 1.0f);
        sum += near + far;
    }
    float3 mean_edge = sum / 6.0f;
    float3 centre = (in[0].xyz + in[1].xyz + in[2].xyz) / 3.0f;
    /* in[3].w = 1: the centre by eq. 5 of Dyken et al. 2008 (the mean of the six, flatter);
     * else Vlachos' (their eq. 4) */
    b[9] = (float4)(in[3].w != 0.0f ? mean_edge : mean_edge + (mean_edge - centre) / 2.0f, 1.0f);
    __attribute__((opencl_unroll_hint))
    for (int c = 0; c < 3; ++c) {
        b[10 + c] = (float4)(in[3 + c].xyz, 0.0f);
        b[13 + c] = (float4)(pn_mid_normal(in[c].xyz, in[(c + 1) % 3].xyz, in[3 + c].xyz,
                                           in[3 + (c + 1) % 3].xyz), 0.0f);
    }
}

/* The 4 control points of edge e's boundary curve, from corner e to corner e+1. */
inline void pn_edge_curve(const float4 b[16], int e, float4 c[4])
{
    c[0] = b[e];
    c[1] = b[3 + 2 * e];
    c[2] = b[4 + 2 * e];
    c[3] = b[(e + 1) % 3];
}

/* Cubic and quadratic Bernstein-triangle sums at barycentric (u, v, w). */
inline float3 pn_position(const float4 b[16], float3 t)
{
    float u = t.x, v = t.y, w = t.z;
    return u * u * u * b[0].xyz + v * v * v * b[1].xyz + w * w * w * b[2].xyz
         + 3.0f * (u * u * v * b[3].xyz + u * v * v * b[4].xyz + v * v * w * b[5].xyz
                   + v * w * w * b[6].xyz + u * w * w * b[7].xyz + u * u * w * b[8].xyz)
         + 6.0f * u * v * w * b[9].xyz;
}

inline float3 pn_normal_field(const float4 b[16], float3 t)
{
    float u = t.x, v = t.y, w = t.z;
    return u * u * b[10].xyz + v * v * b[11].xyz + w * w * b[12].xyz
         + 2.0f * (u * v * b[13].xyz + v * w * b[14].xyz + u * w * b[15].xyz);
}

/* The unit normal from the normal field; where it vanishes, the flat triangle's normal. */
inline float3 pn_unit_normal(const float4 b[16], float3 n)
{
    if (dot3(n, n) > PN_NORMAL_VANISHES * PN_NORMAL_VANISHES)
        return unit_or_zero(n);
    /* cross3 and unit_or_zero's root: inline on PoCL (common.h; bench/RESULTS.md, "Issue 15: PoCL's
     * other out-of-line calls (session 10, branch `cpu15g`)") */
    float3 face = unit_or_zero(cross3(b[1].xyz - b[0].xyz, b[2].xyz - b[0].xyz));
    return dot3(face, face) > 0.0f ? face : (float3)(0.0f, 0.0f, 1.0f);
}

/* Blossoms (polar forms) of the cubic and of the normal field at barycentric points: the
 * Bezier controls of the patch restricted to the segment from x to y are B(x,x,x), B(x,x,y),
 * B(x,y,y), B(y,y,y) (forward differencing along rows, docs/design.md section 6). */
inline float4 pn_blossom3(const float4 b[16], float3 x, float3 y, float3 z)
{
    float4 q[6];  /* quadratic level, |I| = 2, in PN_QUADRATIC order minus 10 */
    for (int i = 0; i <= 2; ++i)
        for (int j = 0; i + j <= 2; ++j)
            q[PN_QUADRATIC[3 * i + j] - 10] = x.x * b[PN_CUBIC[4 * (i + 1) + j]]
                + x.y * b[PN_CUBIC[4 * i + j + 1]] + x.z * b[PN_CUBIC[4 * i + j]];
    float4 l[3];  /* linear level: (1,0,0), (0,1,0), (0,0,1) */
    l[0] = y.x * q[0] + y.y * q[3] + y.z * q[5];
    l[1] = y.x * q[3] + y.y * q[1] + y.z * q[4];
    l[2] = y.x * q[5] + y.y * q[4] + y.z * q[2];
    return z.x * l[0] + z.y * l[1] + z.z * l[2];
}

inline float4 pn_blossom2(const float4 b[16], float3 x, float3 y)
{
    float4 l[3];
    l[0] = x.x * b[10] + x.y * b[13] + x.z * b[15];
    l[1] = x.x * b[13] + x.y * b[11] + x.z * b[14];
    l[2] = x.x * b[15] + x.y * b[14] + x.z * b[12];
    return y.x * l[0] + y.y * l[1] + y.z * l[2];
}

/* --- the kind contract (docs/extending.md) ----------------------------------------------------- */

/* Stage 1: writes the control points to controls[16 p ..] and returns (f0, f1, f2, 0), f_e =
 * ceil(1 / delta_e) from the Filip bound.  A folded triangle (two corners at one point: its
 * other two edges are one edge, a zero-area fold between its neighbours, which meet directly)
 * gets factors 0 and FLAG_FOLDED (cltess/crack/adjacency.py leaves its edges out of the groups). */
inline int4 kind_factors(__global const float4 *source, __global float4 *controls, uint p,
                         tolerance_args tol, int max_factor, int *flags)
{
    float4 in[12], b[16];
    for (int k = 0; k < 12; ++k)
        in[k] = source[12 * p + k];
    pn_control_points(in, b);
    for (int k = 0; k < 16; ++k)
        controls[16 * p + k] = b[k];

    float3 p0 = in[0].xyz, p1 = in[1].xyz, p2 = in[2].xyz;
    if ((p0.x == p1.x && p0.y == p1.y && p0.z == p1.z) || (p1.x == p2.x && p1.y == p2.y && p1.z == p2.z)
        || (p2.x == p0.x && p2.y == p0.y && p2.z == p0.z)) {
        *flags = FLAG_FOLDED;
        return (int4)(0);
    }
    float3 lo = b[0].xyz, hi = lo;  /* the patch lies in its control points' hull */
    for (int k = 1; k < 10; ++k) {
        lo = min(lo, b[k].xyz);
        hi = max(hi, b[k].xyz);
    }
    int culled;
    float eps = factor_tolerance(patch_tolerance(lo, hi, tol, &culled), lo, hi);
    if (culled) {
        *flags = FLAG_CULLED;
        return (int4)(0);
    }
    float inverse[3];
    filip_inverse_steps(b, eps, inverse);
    int f[3], saturated = 0;
    for (int e = 0; e < 3; ++e)
        f[e] = edge_factor(inverse[e], max_factor, &saturated);
    *flags = saturated;
    return (int4)(f[0], f[1], f[2], 0);
}

typedef struct {
    float4 b[16];
    float4 edges[3][4];  /* its boundary curves, corner e to corner e+1 */
} kind_patch;

ALWAYS_INLINE void kind_load(__global const float4 *controls, uint p, __private kind_patch *patch)
{
    load_patch(controls, p, patch->b);
    for (int e = 0; e < 3; ++e)
        pn_edge_curve(patch->b, e, patch->edges[e]);
}

/* Position of point t of edge e: the edge's own curve, placed symmetrically, so the neighbour's
 * is bitwise the same; corners exact. */
ALWAYS_INLINE float3 kind_boundary_point(__private const kind_patch *patch, int e, edge_param t)
{
    return boundary_point(patch->edges[e], t).xyz;
}

/* Direct evaluation at barycentric x (position 0: the normal only). */
ALWAYS_INLINE void kind_eval(__private const kind_patch *patch, float3 x, __private float3 *position, __private float3 *normal)
{
    if (position)
        *position = pn_position(patch->b, x);
    *normal = pn_unit_normal(patch->b, pn_normal_field(patch->b, x));
}

/* Forward differencing along the segment from start to end in `steps` steps: on it the patch is
 * the cubic Bezier curve with controls B(x,x,x) .. B(y,y,y) (blossoms), the normal field a
 * quadratic. */
typedef struct {
    float4 s[4], nd[4];
} kind_row;

ALWAYS_INLINE void kind_row_begin(__private const kind_patch *patch, float3 start, float3 end, int steps, __private kind_row *row)
{
    float h = 1.0f / (float)steps;
    float4 c[4], a[4];
    c[0] = pn_blossom3(patch->b, start, start, start);
    c[1] = pn_blossom3(patch->b, start, start, end);
    c[2] = pn_blossom3(patch->b, start, end, end);
    c[3] = pn_blossom3(patch->b, end, end, end);
    power_form(c, a);
    cubic_differences(a[0], a[1], a[2], a[3], h, row->s);
    float4 q0 = pn_blossom2(patch->b, start, start), q1 = pn_blossom2(patch->b, start, end);
    float4 q2 = pn_blossom2(patch->b, end, end);
    cubic_differences(q0, 2.0f * (q1 - q0), q0 - 2.0f * q1 + q2, (float4)(0.0f), h, row->nd);
}

ALWAYS_INLINE void kind_row_next(__private const kind_patch *patch, __private kind_row *row, float3 x, __private float3 *position, __private float3 *normal)
{
    step_differences(row->s);
    step_differences(row->nd);
    *position = row->s[0].xyz;
    *normal = pn_unit_normal(patch->b, row->nd[0].xyz);
}

#endif
