/* Stage 3 in one launch (issue 15, for GPUs; Tessellator.fused_offsets): the counts of
 * stages/counts.cl and the exclusive scan into vertex and index offsets, by one work-group, for
 * one range of patches of one pattern (patch_base .. patch_base + num_patches - 1).  The
 * counts kernel and pyopencl.scan's three kernels are four launches, whose gaps on a GPU cost more
 * than the work for a few ten thousand patches.
 *
 * Tile by tile of G = get_local_size(0) patches (G a power of two): work-item l counts patch
 * tile + l (as counts.cl: pattern_vertex_count, pattern_primitives in count mode; the counts are
 * stored too), a Hillis-Steele inclusive scan of the G counts in local memory, plus the carry of
 * the earlier tiles, is offsets[p + 1].  The range starts from offsets[patch_base], which the
 * launch of the previous range wrote (the queue is in order) or which is 0 for the first; so
 * several ranges (kinds or patterns) need no host round trip.  Integer sums: the same offsets
 * as the scans. */
__kernel void offsets(__global const int4 *factors, uint num_patches, uint patch_base,
                      __global ulong *vertex_counts, __global ulong *index_counts,
                      __global ulong *vertex_offsets, __global ulong *index_offsets,
                      __local ulong *scan_v, __local ulong *scan_i)
{
    uint l = (uint)get_local_id(0), group = (uint)get_local_size(0);
    ulong carry_v = vertex_offsets[patch_base], carry_i = index_offsets[patch_base];
    for (uint tile = 0; tile < num_patches; tile += group) {
        uint q = tile + l;
        ulong v = 0, i = 0;
        if (q < num_patches) {
            uint p = patch_base + q;
            int collapsed;
            int4 f = patch_factors(factors[p], &collapsed);
            v = pattern_vertex_count(f);
            i = 3 * (ulong)pattern_primitives(f, collapsed, 0, 0);
            vertex_counts[p] = v;
            index_counts[p] = i;
        }
        scan_v[l] = v;
        scan_i[l] = i;
        barrier(CLK_LOCAL_MEM_FENCE);
        for (uint d = 1; d < group; d <<= 1) {
            ulong add_v = l >= d ? scan_v[l - d] : 0, add_i = l >= d ? scan_i[l - d] : 0;
            barrier(CLK_LOCAL_MEM_FENCE);
            scan_v[l] += add_v;
            scan_i[l] += add_i;
            barrier(CLK_LOCAL_MEM_FENCE);
        }
        if (q < num_patches) {
            vertex_offsets[patch_base + q + 1] = carry_v + scan_v[l];
            index_offsets[patch_base + q + 1] = carry_i + scan_i[l];
        }
        carry_v += scan_v[group - 1];
        carry_i += scan_i[group - 1];
        barrier(CLK_LOCAL_MEM_FENCE);  /* every work-item has read scan_* before the next tile */
    }
}
