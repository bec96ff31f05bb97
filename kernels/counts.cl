/* Stage 3: per-patch vertex and index counts, from the final factors alone.  The index count
 * runs the pattern routine in "count" mode, the same routine stage 5 runs in "emit" mode.
 * The exclusive scan into offsets is pyopencl.scan's (cltess/pipeline.py).
 * Mirror: reference.counts.  One work-item per patch. */
#include "cltess.h"

__kernel void quad_counts(__global const int4 *factors, uint num_patches,
                          __global ulong *vertex_counts, __global ulong *index_counts)
{
    uint p = get_global_id(0);
    if (p >= num_patches)
        return;
    int4 f = factors[p];
    vertex_counts[p] = quad_vertex_count(f);
    index_counts[p] = 3 * (ulong)quad_triangles(f, 0, 0);
}
