/* Stage 3: per-patch vertex and index counts, from the final factors alone: the vertex layout
 * that stage 4 walks (patterns/layout.h) and the pattern's primitives in "count" mode, the same
 * routine stage 5 runs in "emit" mode.  The exclusive scan into offsets is pyopencl.scan's.
 * One work-item per patch; a kind's patch p is patch_base + p of the scene. */
__kernel void counts(__global const int4 *factors, uint num_patches, uint patch_base,
                     __global ulong *vertex_counts, __global ulong *index_counts)
{
    if (get_global_id(0) >= num_patches)
        return;
    uint p = patch_base + (uint)get_global_id(0);
    int collapsed;
    int4 f = patch_factors(factors[p], &collapsed);
    vertex_counts[p] = pattern_vertex_count(f);
    index_counts[p] = 3 * (ulong)pattern_primitives(f, collapsed, 0, 0);
}
