/* On request (Request(bound="integral")): the integral-form bound of every emitted triangle of
 * the patches marked in `check` (criteria/integral_bound.h; mirror cltess.criteria.integral
 * triangle_bound).  One work-item per triangle of the output (triangles index it, uv its
 * vertices' (u, v), patch_ids its vertices' scene patch); writes bound / tolerance of the
 * triangle's patch, or 0 where the patch has no table (pyramid_of < 0) or is not checked. */
__kernel void integral_bound(__global const float4 *pyramids, __global const int *pyramid_of,
                             __global const int *check, __global const float *uv,
                             __global const int *patch_ids, __global const uint *triangles,
                             uint num_triangles, int levels, int cells, int k_first, int k_last,
                             __global const float *tolerances, __global float *ratios)
{
    uint t = get_global_id(0);
    if (t >= num_triangles)
        return;
    uint a = triangles[3 * t], b = triangles[3 * t + 1], c = triangles[3 * t + 2];
    int p = patch_ids[a];
    int table = pyramid_of[p];
    if (table < 0 || !check[p]) {
        ratios[t] = 0.0f;
        return;
    }
    float2 x0 = (float2)(uv[2 * a], uv[2 * a + 1]);
    float2 x1 = (float2)(uv[2 * b], uv[2 * b + 1]);
    float2 x2 = (float2)(uv[2 * c], uv[2 * c + 1]);
    ratios[t] = integral_triangle_ratio(pyramids + (ulong)table * (ulong)cells, levels, x0, x1, x2,
                                        tolerances[p], k_first, k_last);
}
