/* Stage 3 for strip output (a pattern with pattern_strips: patterns/sd2.h, esc.h): per-patch strip
 * index counts (restart markers included), the pattern's strips in "count" mode, the same walk
 * stages/strip_indices.cl runs in "emit" mode.  One work-item per patch. */
__kernel void strip_counts(__global const int4 *factors, uint num_patches, uint patch_base,
                           __global ulong *strip_counts)
{
    if (get_global_id(0) >= num_patches)
        return;
    uint p = patch_base + (uint)get_global_id(0);
    int collapsed;
    int4 f = patch_factors(factors[p], &collapsed);
    strip_counts[p] = pattern_strips(f, collapsed, 0, 0);
}
