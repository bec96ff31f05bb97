/* Stage 5 for strip output: the pattern's strips in "emit" mode (cltess/strips.py: uint32
 * indices, each strip followed by STRIP_RESTART).  One work-item per patch of one batch; its
 * strip indices go to strip_offsets[p] - index_base and number the vertices globally. */
__kernel void strip_indices(__global const int4 *factors, __global const ulong *vertex_offsets,
                            __global const ulong *strip_offsets, uint first_patch, uint num_patches,
                            ulong index_base, __global uint *strips)
{
    uint p;
    int4 f;
    int collapsed;
    if (batch_patch(first_patch, num_patches, factors, &p, &f, &collapsed))
        pattern_strips(f, collapsed, strips + (strip_offsets[p] - index_base), (uint)vertex_offsets[p]);
}
