/* Stage 5: triangle indices, the pattern routine in "emit" mode.  Mirror: reference.quad_pattern.
 * One work-item per patch. */
#include "cltess.h"

__kernel void quad_indices(__global const int4 *factors, __global const ulong *vertex_offsets,
                           __global const ulong *index_offsets, uint num_patches,
                           __global uint *indices)
{
    uint p = get_global_id(0);
    if (p >= num_patches)
        return;
    quad_triangles(factors[p], indices + index_offsets[p], (uint)vertex_offsets[p]);
}
