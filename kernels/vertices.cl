/* Stage 4: vertex data of each patch in the pattern's layout (reference.quad_pattern,
 * reference.tri_pattern): the boundary ring first, evaluated canonically from the edge curves so
 * that neighbours agree bitwise, then the inner grid row by row, by forward differencing or
 * direct evaluation.  Mirror: reference.tessellate, reference.pn_tessellate.
 * One work-item per patch. */
#include "cltess.h"

typedef struct {
    __global float *positions;   /* (V, 3) */
    __global float *normals;     /* (V, 3) */
    __global float *uvs;         /* (V, 2) */
    __global int *patch_ids;     /* (V,) */
    __global int *object_ids;    /* (V,) */
} vertex_out;

inline void put_vertex(vertex_out out, ulong at, float3 position, float3 normal, float2 uv,
                       int patch, int object)
{
    vstore3(position, at, out.positions);
    vstore3(normal, at, out.normals);
    vstore2(uv, at, out.uvs);
    out.patch_ids[at] = patch;
    out.object_ids[at] = object;
}

/* Forward differences of a cubic a0 + a1 u + a2 u^2 + a3 u^3 at u = 0, step h (Wallace 1990):
 * value, first, second, third difference. */
inline void cubic_differences(float4 a0, float4 a1, float4 a2, float4 a3, float h, float4 d[4])
{
    float h2 = h * h, h3 = h2 * h;
    d[0] = a0;
    d[1] = a1 * h + a2 * h2 + a3 * h3;
    d[2] = 2.0f * a2 * h2 + 6.0f * a3 * h3;
    d[3] = 6.0f * a3 * h3;
}

/* Power-form coefficients of the cubic Bernstein polynomial with controls c. */
inline void power_form(const float4 c[4], float4 a[4])
{
    a[0] = c[0];
    a[1] = 3.0f * (c[1] - c[0]);
    a[2] = 3.0f * (c[2] - 2.0f * c[1] + c[0]);
    a[3] = c[3] - 3.0f * c[2] + 3.0f * c[1] - c[0];
}

inline void step_differences(float4 d[4])
{
    d[0] += d[1];
    d[1] += d[2];
    d[2] += d[3];
}

/* Patches first_patch .. first_patch + num_patches - 1 (one batch, scene numbering: the kind's
 * own patch p - patch_base); their vertices go to vertex_offsets[p] - vertex_base of the output
 * arrays. */
__kernel void quad_vertices(__global const float4 *patches, __global const int4 *factors,
                            __global const ulong *vertex_offsets, __global const int *patch_objects,
                            uint first_patch, uint num_patches, uint patch_base, ulong vertex_base,
                            int forward_differencing,
                            __global float *positions, __global float *normals, __global float *uvs,
                            __global int *patch_ids, __global int *object_ids)
{
    uint p;
    int4 f;
    if (!batch_patch(first_patch, num_patches, factors, &p, &f))
        return;
    vertex_out out = {positions, normals, uvs, patch_ids, object_ids};
    int object = patch_objects[p];
    float4 b[16], t[16];
    load_patch(patches, p - patch_base, b);
    float3 centre = centred_patch(b, t);  /* the surface is evaluated about its centre, t */
    ulong at = vertex_offsets[p] - vertex_base;

    /* The boundary ring, counter-clockwise from (0, 0): positions canonical from the edge's own
     * control points (bitwise equal to the neighbour's), normals from the centred patch. */
    for (int e = 0; e < 4; ++e) {
        float4 c[4];
        edge_controls(b, e, c);
        int fe = factor_of(f, e);
        for (int k = 0; k < fe; ++k) {
            float4 h = boundary_point(c, k, fe);
            float2 uv = edge_uv(e, k, fe);
            float4 s, s_u, s_v;
            surface_eval(t, uv.x, uv.y, &s, &s_u, &s_v);
            put_vertex(out, at++, h.xyz / h.w, surface_normal(t, uv.x, uv.y, s, s_u, s_v), uv, p, object);
        }
    }

    /* The inner grid (i / A, j / B), i = 1..A-1, j = 1..B-1. */
    int uniform;
    int2 core = quad_core(f, &uniform);
    float h = 1.0f / (float)core.x;
    for (int j = 1; j < core.y; ++j) {
        float v = (float)j / (float)core.y;
        /* Along the row v = const, B is a cubic in u with controls c, B_v one with controls d,
         * and B_u the derivative of B (DESIGN.md section 6). */
        float4 c[4], d[4], a[4], av[4], s[4], s_u[4], s_v[4];
        row_controls(t, v, c, d);
        power_form(c, a);
        power_form(d, av);
        cubic_differences(a[0], a[1], a[2], a[3], h, s);
        cubic_differences(a[1], 2.0f * a[2], 3.0f * a[3], (float4)(0.0f), h, s_u);
        cubic_differences(av[0], av[1], av[2], av[3], h, s_v);
        for (int i = 1; i < core.x; ++i) {
            float u = (float)i / (float)core.x;
            float4 value, du, dv;
            if (forward_differencing) {
                step_differences(s);
                step_differences(s_u);
                step_differences(s_v);
                value = s[0];
                du = s_u[0];
                dv = s_v[0];
            } else {
                surface_eval(t, u, v, &value, &du, &dv);
            }
            put_vertex(out, at++, value.xyz / value.w + centre, surface_normal(t, u, v, value, du, dv),
                       (float2)(u, v), p, object);
        }
    }
}

/* Barycentric (u, v, w) of point k of f on triangle edge e (corner e to corner e+1). */
inline float3 tri_edge_point(int e, int k, int f)
{
    float t = (float)k / (float)f, s = (float)(f - k) / (float)f;
    return e == 0 ? (float3)(s, t, 0.0f) : e == 1 ? (float3)(0.0f, s, t) : (float3)(t, 0.0f, s);
}

/* PN triangles, same arguments as quad_vertices with controls = stage 1's PN control points.
 * (u, v) of a vertex are its barycentric coordinates of P1 and P2. */
__kernel void pn_vertices(__global const float4 *controls, __global const int4 *factors,
                          __global const ulong *vertex_offsets, __global const int *patch_objects,
                          uint first_patch, uint num_patches, uint patch_base, ulong vertex_base,
                          int forward_differencing,
                          __global float *positions, __global float *normals, __global float *uvs,
                          __global int *patch_ids, __global int *object_ids)
{
    uint p;
    int4 f;
    if (!batch_patch(first_patch, num_patches, factors, &p, &f))
        return;
    vertex_out out = {positions, normals, uvs, patch_ids, object_ids};
    int object = patch_objects[p];
    float4 b[16];
    load_patch(controls, p - patch_base, b);
    ulong at = vertex_offsets[p] - vertex_base;

    /* The boundary ring, counter-clockwise from P1: each edge's own curve, points placed
     * symmetrically (boundary_point), so the neighbour's are bitwise the same; corners exact. */
    for (int e = 0; e < 3; ++e) {
        float4 c[4];
        pn_edge_curve(b, e, c);
        int fe = factor_of(f, e);
        for (int k = 0; k < fe; ++k) {
            float3 t = tri_edge_point(e, k, fe);
            put_vertex(out, at++, boundary_point(c, k, fe).xyz, pn_unit_normal(b, pn_normal_field(b, t)),
                       t.xy, p, object);
        }
    }

    /* The interior grid (i / n, j / n), rows j = 1..n-2 of constant v.  Row j runs from
     * x = (0, v, 1-v) to y = (1-v, v, 0); on it the patch is the cubic Bezier curve with controls
     * B(x,x,x) .. B(y,y,y) (blossoms) in s = u / (1-v), the normal field a quadratic, and the
     * points i = 1..n-1-j sit at s = i / (n - j). */
    int n = tri_core(f);
    for (int j = 1; j < n - 1; ++j) {
        float v = (float)j / (float)n, rest = (float)(n - j) / (float)n;
        float3 x = (float3)(0.0f, v, rest), y = (float3)(rest, v, 0.0f);
        float4 c[4], a[4], s[4], nd[4];
        float h = 1.0f / (float)(n - j);
        if (forward_differencing) {
            c[0] = pn_blossom3(b, x, x, x);
            c[1] = pn_blossom3(b, x, x, y);
            c[2] = pn_blossom3(b, x, y, y);
            c[3] = pn_blossom3(b, y, y, y);
            power_form(c, a);
            cubic_differences(a[0], a[1], a[2], a[3], h, s);
            float4 q0 = pn_blossom2(b, x, x), q1 = pn_blossom2(b, x, y), q2 = pn_blossom2(b, y, y);
            cubic_differences(q0, 2.0f * (q1 - q0), q0 - 2.0f * q1 + q2, (float4)(0.0f), h, nd);
        }
        for (int i = 1; i < n - j; ++i) {
            float3 t = (float3)((float)i / (float)n, v, (float)(n - i - j) / (float)n);
            float3 position, normal;
            if (forward_differencing) {
                step_differences(s);
                step_differences(nd);
                position = s[0].xyz;
                normal = nd[0].xyz;
            } else {
                position = pn_position(b, t);
                normal = pn_normal_field(b, t);
            }
            put_vertex(out, at++, position, pn_unit_normal(b, normal), t.xy, p, object);
        }
    }
}
