/* Level functions, the bound-keeping variant (criteria/level.h LEVEL_BOUND): each welded
 * vertex's value is the largest error-bound factor (stage 1's, rounded up to odd: fractional_odd
 * places an odd whole factor's points evenly) of the edges at it.  One work-item per patch of
 * one kind (scene patch patch_base + p); bounds start at 0. */
__kernel void vertex_bounds(__global const int4 *factors, __global const int *corners, uint num_patches,
                            uint patch_base, __global int *bounds)
{
    uint p = get_global_id(0);
    if (p >= num_patches)
        return;
    int4 f = factors[patch_base + p];
    if (f.s0 <= 0)
        return;
    for (int e = 0; e < 3; ++e) {
        int odd = factor_of(f, e) | 1;
        atomic_max(&bounds[corners[3 * p + e]], odd);
        atomic_max(&bounds[corners[3 * p + (e + 1) % 3]], odd);
    }
}
