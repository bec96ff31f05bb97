/* Stage 1: per-patch tolerance, culling and edge factors, by the kind's kind_factors (which
 * calls its criterion; kernels/kinds/).  Mirror: cltess/backends/numpy.py.  One work-item per
 * patch; patch p of a kind writes factors[patch_base + p], flags likewise (the scene numbers
 * all patches, kind after kind).  flags: FLAG_SATURATED (the bound is not met at max_factor),
 * FLAG_CULLED, FLAG_FOLDED (common.h). */
__kernel void factors(__global const float4 *source, __global float4 *controls, uint num_patches,
                      uint patch_base, float eps, float16 view, float4 frustum, float pixels,
                      float pixel_size, int max_factor, __global int4 *factors, __global int *flags)
{
    uint p = get_global_id(0);
    if (p >= num_patches)
        return;
    tolerance_args tol = {eps, view, frustum, pixels, pixel_size};
    int flag = 0;
    factors[patch_base + p] = kind_factors(source, controls, p, tol, max_factor, &flag);
    flags[patch_base + p] = flag;
}
