/* Stage 3: per-patch vertex and index counts, from the final factors alone.  The index count
 * runs the pattern routine in "count" mode, the same routine stage 5 runs in "emit" mode.
 * The exclusive scan into offsets is pyopencl.scan's (cltess/pipeline.py).
 * Mirror: reference.counts.  One work-item per patch; a kind's patch p is patch_base + p of
 * the scene. */
#include "cltess.h"

__kernel void quad_counts(__global const int4 *factors, uint num_patches, uint patch_base,
                          __global ulong *vertex_counts, __global ulong *index_counts)
{
    if (get_global_id(0) >= num_patches)
        return;
    uint p = patch_base + (uint)get_global_id(0);
    int4 f = factors[p];
    vertex_counts[p] = quad_vertex_count(f);
    index_counts[p] = 3 * (ulong)quad_triangles(f, 0, 0);
}

__kernel void pn_counts(__global const int4 *factors, uint num_patches, uint patch_base,
                        __global ulong *vertex_counts, __global ulong *index_counts)
{
    if (get_global_id(0) >= num_patches)
        return;
    uint p = patch_base + (uint)get_global_id(0);
    int4 f = factors[p];
    vertex_counts[p] = tri_vertex_count(f);
    index_counts[p] = 3 * (ulong)tri_triangles(f, 0, 0);
}
