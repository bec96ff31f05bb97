/* Stage 1: per-patch tolerance, culling and edge factors, by the kind's kind_factors (which
 * calls its criterion; kernels/kinds/).  Mirror: cltess/backends/numpy.py.  One work-item per
 * patch; patch p of a kind writes factors[patch_base + p], flags likewise (the scene numbers
 * all patches, kind after kind).  flags: FLAG_SATURATED (the bound is not met at max_factor, or
 * at 2^max_level), FLAG_CULLED, FLAG_FOLDED (common.h).  Built with -D PATTERN_DYADIC for a
 * dyadic pattern (semi-uniform): the factors are rounded up to 2^p_e here, before the crack-free
 * pass, for every kind alike (common.h dyadic_factors).  Built with -D PATTERN_ESC for the ESC
 * pattern (Bezier patches only): its candidate masks instead (criteria/esc_distance.h), from
 * the patches in controls.  source is writable for a kind that keeps per-patch constants there
 * (PatchKind.per_patch_constants: the Bezier kind's bound). */
#ifdef PATTERN_ESC
/* the pattern's own stage 1: candidate masks (patterns/esc.h) */
#include "criteria/esc_distance.h"
#endif

__kernel void factors(__global float4 *source, __global float4 *controls, uint num_patches,
                      uint patch_base, float eps, float16 view, float4 frustum, float pixels,
                      float pixel_size, int max_factor, int max_level, __global int4 *factors,
                      __global int *flags)
{
    uint p = get_global_id(0);
    if (p >= num_patches)
        return;
    tolerance_args tol = {eps, view, frustum, pixels, pixel_size};
    int flag = 0;
#ifdef PATTERN_ESC
    int4 f = esc_factors(source, controls, p, tol, max_factor, max_level, &flag);  /* masks; L_p from the bound */
#else
    int4 f = kind_factors(source, controls, p, tol, max_factor, &flag);
#endif
#ifdef PATTERN_DYADIC
    int saturated = 0;
    f = dyadic_factors(f, max_level, &saturated);
    flag |= saturated ? FLAG_SATURATED : 0;
#endif
    factors[patch_base + p] = f;
    flags[patch_base + p] = flag;
}
