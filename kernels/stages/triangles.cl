/* Stage 5 a work-item per output triangle (issue 15, for GPUs): consecutive work-items write
 * consecutive triangles (coalesced stores).  Work-item id owns the batch's triangle id: its
 * patch by binary search over index_offsets (patch_of, common.h), its local number t.
 * A pattern with random access to a regular patch's triangles (PATTERN_TRIANGLE_AT,
 * pattern_triangle_at) gives triangle t directly; any other patch is emitted whole by the
 * work-item of its triangle 0 with pattern_primitives, as stages/indices.cl does.  Either way
 * the bits of stages/indices.cl.  The batch is patches
 * first_patch .. first_patch + num_patches - 1; work-items past its last triangle return. */
__kernel void triangles(__global const int4 *factors, __global const ulong *vertex_offsets,
                        __global const ulong *index_offsets, uint first_patch, uint num_patches,
                        ulong index_base, __global uint *indices)
{
    uint last = first_patch + num_patches;
    ulong at = index_offsets[first_patch] + 3 * (ulong)get_global_id(0);  /* the triangle's first index */
    if (at >= index_offsets[last])
        return;
    uint p = patch_of(index_offsets, first_patch, last, at);
    int collapsed;
    int4 f = patch_factors(factors[p], &collapsed);
    uint t = (uint)((at - index_offsets[p]) / 3), base = (uint)vertex_offsets[p];
#ifdef PATTERN_TRIANGLE_AT
    uint3 triangle;
    if (pattern_triangle_at(f, collapsed, t, &triangle)) {
        vstore3(triangle + base, (at - index_base) / 3, indices);
        return;
    }
#endif
    if (t == 0)
        pattern_primitives(f, collapsed, indices + (index_offsets[p] - index_base), base);
}
