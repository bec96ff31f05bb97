/* On request (Request(bound="integral")): the integral-form bound of every emitted triangle of
 * the patches marked in `check` (criteria/integral_bound.h; mirror cltess.criteria.integral
 * triangle_bound).  `cells`: float8 rows of one patch's table (pyramid and graded cells, integral.table_cells),
 * `breaks`: the graded cells' breakpoints (graded_count + 1).  One work-item per triangle of the output (triangles index it, uv its
 * vertices' (u, v), patch_ids its vertices' scene patch); writes bound / tolerance of the
 * triangle's patch, or 0 where the patch has no table (pyramid_of < 0) or is not checked, and
 * the max per patch to patch_worst (float bits; 0 before the launch).
 * vec_type_hint(float4): the Intel CPU runtime's implicit vectorisation across work-items gave
 * wrong results, different from run to run, for some triangles of a batch (correct with a
 * work-group of one, with -cl-opt-disable, on PoCL and on Oclgrind, which reports nothing);
 * a vector type hint turns that vectorisation off.  The padding work-items compute the last
 * triangle again and store nothing. */
__kernel __attribute__((vec_type_hint(float4))) void integral_bound(
    __global const float8 *pyramids, __global const int *pyramid_of, __global const int *check,
    __global const float *uv, __global const int *patch_ids, __global const uint *triangles,
    uint num_triangles, int levels, int cells, __global const float *breaks, int graded_count, int k_first, int k_last,
    __global const float *tolerances, __global float *ratios, __global volatile int *patch_worst,
    int skip_failed)
{
    uint gid = get_global_id(0);
    uint t = min(gid, num_triangles - 1);
    uint a = triangles[3 * t], b = triangles[3 * t + 1], c = triangles[3 * t + 2];
    int p = patch_ids[a];
    int table = pyramid_of[p];
    int wanted = table >= 0 && check[p] && gid < num_triangles;
    /* patch_worst[p]: the float bits of its worst ratio so far (non-negative floats order as ints);
     * once over 1 the patch fails this round, and with skip_failed its other triangles stop here */
    if (wanted && skip_failed && as_float(atomic_or(&patch_worst[p], 0)) > 1.0f)
        wanted = 0;
    float2 x0 = (float2)(uv[2 * a], uv[2 * a + 1]);
    float2 x1 = (float2)(uv[2 * b], uv[2 * b + 1]);
    float2 x2 = (float2)(uv[2 * c], uv[2 * c + 1]);
    float ratio = integral_triangle_ratio(pyramids + (ulong)max(table, 0) * (ulong)cells, levels,
                                          breaks, graded_count, x0, x1, x2,
                                          tolerances[p], wanted ? k_first : 1, wanted ? k_last : 0);
    if (wanted)
        atomic_max(&patch_worst[p], as_int(ratio));
    if (gid < num_triangles)
        ratios[gid] = wanted ? ratio : 0.0f;
}
