/* On request (Request(bound="error-hull")): the error-hull bound of every emitted triangle of the
 * patches marked in `check` (criteria/error_hull.h; mirror cltess.criteria.error_hull
 * triangle_ratio).  `nets`: 16 float4 per Bézier patch (its homogeneous control points, centred:
 * error_hull.centred_nets), `radii`: max_k |X_k| / w_k of each, rounded up.  One work-item per
 * triangle of the output (triangles index it, uv its vertices' (u, v), patch_ids its vertices'
 * scene patch; Bézier patches come first in scene numbering); writes bound / tolerance of the
 * triangle's patch, or 0 where the patch is not checked, and the max per patch to patch_worst
 * (float bits; 0 before the launch).  vec_type_hint(float4): as stages/integral_bound.cl, no
 * implicit vectorisation across work-items on the Intel CPU runtime.  The padding work-items
 * compute nothing. */
__kernel __attribute__((vec_type_hint(float4))) void error_hull_bound(
    __global const float4 *nets, __global const float *radii, __global const int *check,
    __global const float *uv, __global const int *patch_ids, __global const uint *triangles,
    uint num_triangles, __global const float *tolerances, __global float *ratios,
    __global volatile int *patch_worst, int skip_failed)
{
    uint gid = get_global_id(0);
    if (gid >= num_triangles)
        return;
    uint a = triangles[3 * gid], b = triangles[3 * gid + 1], c = triangles[3 * gid + 2];
    int p = patch_ids[a];
    int wanted = check[p];
    /* patch_worst[p]: the float bits of its worst ratio so far (non-negative floats order as ints);
     * once over 1 the patch fails this round, and with skip_failed its other triangles stop here */
    if (wanted && skip_failed && as_float(atomic_or(&patch_worst[p], 0)) > 1.0f)
        wanted = 0;
    float ratio = 0.0f;
    if (wanted) {
        float2 x0 = (float2)(uv[2 * a], uv[2 * a + 1]);
        float2 x1 = (float2)(uv[2 * b], uv[2 * b + 1]);
        float2 x2 = (float2)(uv[2 * c], uv[2 * c + 1]);
        ratio = error_hull_ratio(nets + 16 * (ulong)p, radii[p], x0, x1, x2, tolerances[p]);
        atomic_max(&patch_worst[p], as_int(ratio));
    }
    ratios[gid] = ratio;
}
