/* Stage 1: per-patch tolerance, frustum culling and edge factors: Zheng-Sederberg for quads
 * (zs_factors), Filip for PN triangles (pn_factors, which also derives the control points).
 * Mirror: cltess/reference.py patch_tolerances + zs_factors, pn_control_points + pn_factors.
 * One work-item per patch; patch p of a kind writes factors[patch_base + p], flags likewise
 * (cltess/pipeline.py numbers all patches of a scene, kind after kind). */
#include "cltess.h"

/* Object-space tolerance of a patch and whether it is culled (DESIGN.md section 7).
 * camera_on == 0: every patch gets eps.  Otherwise eps = pixels * nearest depth * pixel_size,
 * and a box entirely outside one frustum plane is culled. */
inline float patch_tolerance(float3 lo, float3 hi, float eps, int camera_on, float16 view,
                             float4 frustum, float pixels, float pixel_size, int *culled)
{
    *culled = 0;
    if (!camera_on)
        return eps;
    float tan_x = frustum.s0, tan_y = frustum.s1, near = frustum.s2, far = frustum.s3;
    int out_mask = 0x3f;  /* bit per plane: set while every corner so far is outside it */
    float nearest = INFINITY;
    for (int c = 0; c < 8; ++c) {
        float3 w = (float3)((c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z);
        float x = dot(view.s012, w) + view.s3;
        float y = dot(view.s456, w) + view.s7;
        float depth = -(dot(view.s89a, w) + view.sb);
        int outside = (depth < near) | (depth > far) << 1 | (x > tan_x * depth) << 2
                    | (x < -tan_x * depth) << 3 | (y > tan_y * depth) << 4 | (y < -tan_y * depth) << 5;
        out_mask &= outside;
        nearest = min(nearest, depth);
    }
    *culled = out_mask != 0;
    return pixels * max(nearest, near) * pixel_size;
}

/* The factor for a step of 1/inverse: ceil, at least 1; above max_factor it is clamped and
 * *saturated set (the bound is not met there). */
inline int edge_factor(float inverse, int max_factor, int *saturated)
{
    if (inverse <= (float)max_factor)
        return max((int)ceil(inverse), 1);
    *saturated = 1;
    return max_factor;
}

/* A patch with no output (culled, or a folded triangle): factors 0 and why, in flags. */
inline void no_output(__global int4 *factors, __global int *flags, uint i, int why)
{
    factors[i] = (int4)(0);
    flags[i] = why;
}

/* factors[p] = (m, n, m, n) by edge; flags[p]: bit 0 saturated (the bound is not met at
 * max_factor), bit 1 culled (factors 0). */
__kernel void zs_factors(__global const float4 *patches, uint num_patches, uint patch_base, float eps,
                         int camera_on, float16 view, float4 frustum, float pixels,
                         float pixel_size, int max_factor,
                         __global int4 *factors, __global int *flags)
{
    uint p = get_global_id(0);
    if (p >= num_patches)
        return;
    float4 b[16];
    load_patch(patches, p, b);

    float3 lo = b[0].xyz / b[0].w, hi = lo;
    for (int k = 1; k < 16; ++k) {
        float3 point = b[k].xyz / b[k].w;
        lo = min(lo, point);
        hi = max(hi, point);
    }
    int culled;
    float tol = patch_tolerance(lo, hi, eps, camera_on, view, frustum, pixels, pixel_size, &culled);
    if (culled) {
        no_output(factors, flags, patch_base + p, 2);
        return;
    }

    float2 inverse = zs_inverse_steps(b, tol);  /* docs/rational-bound.md */
    int saturated = 0;
    int m = edge_factor(inverse.x, max_factor, &saturated);
    int n = edge_factor(inverse.y, max_factor, &saturated);
    factors[patch_base + p] = (int4)(m, n, m, n);
    flags[patch_base + p] = saturated;
}

/* PN triangles: controls[16 p ..] = the control points (cltess.h layout) from the triangle's
 * input (pn_control_points); factors[patch_base + p] = (f0, f1, f2, 0) with f_e = ceil(1 / delta_e)
 * from the Filip bound (DESIGN.md section 3, CudaTess section 4):
 * (1/8) (D_ee + max(D_e,e+1, D_e,e+2)) delta_e^2 <= eps / 2.  flags as for zs_factors, plus
 * bit 2: folded, two corners at one point (its other two edges are one edge: a zero-area fold
 * between its neighbours, which meet directly); factors 0, no output (cltess/adjacency.py leaves
 * its edges out of the groups). */
__kernel void pn_factors(__global const float4 *triangles, __global float4 *controls, uint num_patches,
                         uint patch_base, float eps, int camera_on, float16 view, float4 frustum,
                         float pixels, float pixel_size, int max_factor,
                         __global int4 *factors, __global int *flags)
{
    uint p = get_global_id(0);
    if (p >= num_patches)
        return;
    float4 in[12], b[16];
    for (int k = 0; k < 12; ++k)
        in[k] = triangles[12 * p + k];
    pn_control_points(in, b);
    for (int k = 0; k < 16; ++k)
        controls[16 * p + k] = b[k];

    float3 p0 = in[0].xyz, p1 = in[1].xyz, p2 = in[2].xyz;
    if ((p0.x == p1.x && p0.y == p1.y && p0.z == p1.z) || (p1.x == p2.x && p1.y == p2.y && p1.z == p2.z)
        || (p2.x == p0.x && p2.y == p0.y && p2.z == p0.z)) {
        no_output(factors, flags, patch_base + p, 4);
        return;
    }
    float3 lo = b[0].xyz, hi = lo;  /* the patch lies in its control points' hull */
    for (int k = 1; k < 10; ++k) {
        lo = min(lo, b[k].xyz);
        hi = max(hi, b[k].xyz);
    }
    int culled;
    float tol = patch_tolerance(lo, hi, eps, camera_on, view, frustum, pixels, pixel_size, &culled);
    if (culled) {
        no_output(factors, flags, patch_base + p, 2);
        return;
    }
    float d[9];
    pn_second_derivative_bounds(b, d);
    int f[3], saturated = 0;
    for (int e = 0; e < 3; ++e) {
        float curvature = d[4 * e] + max(d[3 * e + (e + 1) % 3], d[3 * e + (e + 2) % 3]);
        float inverse = sqrt(curvature / (4.0f * tol));  /* 1 / delta_e */
        f[e] = edge_factor(inverse, max_factor, &saturated);
    }
    factors[patch_base + p] = (int4)(f[0], f[1], f[2], 0);
    flags[patch_base + p] = saturated;
}
