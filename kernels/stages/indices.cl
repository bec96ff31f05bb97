/* Stage 5: triangle indices, the pattern's primitives in "emit" mode.  One work-item per patch
 * of one batch (as stage 4); its indices go to index_offsets[p] - index_base and number the
 * vertices globally (vertex_offsets[p]); none is written when the batch's indices do not fit
 * the `capacity` of the output (batch_fits in common.h). */
__kernel void indices(__global const int4 *factors, __global const ulong *vertex_offsets,
                      __global const ulong *index_offsets, uint first_patch, uint num_patches,
                      ulong index_base, ulong capacity, __global uint *indices)
{
    uint p;
    int4 f;
    int collapsed;
    if (batch_fits(index_offsets, first_patch + num_patches, index_base, capacity)
        && batch_patch(first_patch, num_patches, factors, &p, &f, &collapsed))
        pattern_primitives(f, collapsed, indices + (index_offsets[p] - index_base), (uint)vertex_offsets[p]);
}
