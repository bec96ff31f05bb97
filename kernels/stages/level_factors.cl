/* Level functions, step 2 (criteria/level.h): each triangle's edge factors from its corners'
 * welded vertex values (levels, or bounds for LEVEL_BOUND), as 16.16 fixed point for the SD-2
 * pattern; edge e runs from corner e to corner e+1.  Culled and folded triangles (stage 1's
 * factor 0) stay 0.  One work-item per patch of one kind (scene patch patch_base + p). */
__kernel void level_factors(__global const int *corners, __global const float *levels, __global const int *bounds,
                            uint num_patches, uint patch_base, int function, int map, float4 range,
                            __global int4 *factors)
{
    uint p = get_global_id(0);
    if (p >= num_patches)
        return;
    if (factors[patch_base + p].s0 <= 0)
        return;
    float value[3];
    for (int c = 0; c < 3; ++c) {
        int v = corners[3 * p + c];
        value[c] = function == LEVEL_BOUND ? (float)bounds[v] : levels[v];
    }
    int f[3];
    for (int e = 0; e < 3; ++e)
        f[e] = level_edge_factor(function, value[e], value[(e + 1) % 3], map, range);
    /* slot 3: the pattern's hint, which corner would tie with the tip next (docs/sd2.md 5) */
    factors[patch_base + p] = (int4)(f[0], f[1], f[2], level_hint(function, value, map, range));
}
