/* Stage 5: triangle indices, the pattern routine in "emit" mode.  Mirror: reference.quad_pattern
 * and reference.tri_pattern.  One work-item per patch. */
#include "cltess.h"

/* Patches first_patch .. first_patch + num_patches - 1 (one batch, scene numbering); their
 * indices go to index_offsets[p] - index_base and number the vertices globally
 * (vertex_offsets[p]). */
__kernel void quad_indices(__global const int4 *factors, __global const ulong *vertex_offsets,
                           __global const ulong *index_offsets, uint first_patch, uint num_patches,
                           ulong index_base, __global uint *indices)
{
    uint p;
    int4 f;
    if (batch_patch(first_patch, num_patches, factors, &p, &f))
        quad_triangles(f, indices + (index_offsets[p] - index_base), (uint)vertex_offsets[p]);
}

__kernel void pn_indices(__global const int4 *factors, __global const ulong *vertex_offsets,
                         __global const ulong *index_offsets, uint first_patch, uint num_patches,
                         ulong index_base, __global uint *indices)
{
    uint p;
    int4 f;
    if (batch_patch(first_patch, num_patches, factors, &p, &f))
        tri_triangles(f, indices + (index_offsets[p] - index_base), (uint)vertex_offsets[p]);
}
