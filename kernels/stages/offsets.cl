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
 * as the scans.
 *
 * offsets_summary (the last range of a frame, Tessellator.stage_counts with a summary): the same,
 * then the frame's summary in one 32-byte buffer that the host reads once (issue 15: one read
 * per frame instead of three): summary[0], [1] the vertex and index totals (offsets[P]),
 * summary[2], [3] how many of flags[0 .. num_flags-1] (stage 1's, every patch of the scene) have
 * FLAG_CULLED and FLAG_SATURATED. */
#include "stages/offsets.h"

__kernel void offsets(__global const int4 *factors, uint num_patches, uint patch_base,
                      __global ulong *vertex_counts, __global ulong *index_counts,
                      __global ulong *vertex_offsets, __global ulong *index_offsets,
                      __local ulong *scan_v, __local ulong *scan_i)
{
    offsets_of_range(factors, num_patches, patch_base, vertex_counts, index_counts, vertex_offsets,
                     index_offsets, scan_v, scan_i);
}

__kernel void offsets_summary(__global const int4 *factors, uint num_patches, uint patch_base,
                              __global ulong *vertex_counts, __global ulong *index_counts,
                              __global ulong *vertex_offsets, __global ulong *index_offsets,
                              __global const int *flags, uint num_flags, __global ulong *summary,
                              __local ulong *scan_v, __local ulong *scan_i)
{
    ulong2 totals = offsets_of_range(factors, num_patches, patch_base, vertex_counts, index_counts,
                                     vertex_offsets, index_offsets, scan_v, scan_i);
    write_summary(totals, flags, num_flags, summary, scan_v, scan_i);
}

/* Stage 3 in two launches for many patches (Tessellator.stage_counts, tiled: a scene above the
 * one-launch cap, where one work-group would be too slow; issue 15: two launches and no
 * temporaries from the host, where the counts kernel and pyopencl.scan were four launches and two
 * arrays made per frame).  offsets_tiles, a work-group per tile of G = get_local_size(0)
 * consecutive patches of one range (launched per range; its tiles are tile_base, tile_base + 1,
 * ...): the counts (stored), their inclusive scan within the tile as offsets[p + 1], and the
 * tile's record in tiles[4 t ..]: vertex sum, index sum, flag counts (culled in the low 32 bits,
 * saturated in the high: fewer than 2^32 patches), first patch | patch count << 32.
 * offsets_carries, a work-group per tile: adds to the tile's offsets the sums of every earlier
 * tile, and the last tile writes the summary as offsets_summary does.  Integer sums: the offsets
 * of the scans. */
__kernel void offsets_tiles(__global const int4 *factors, uint num_patches, uint patch_base, uint tile_base,
                            __global const int *flags, __global ulong *vertex_counts,
                            __global ulong *index_counts, __global ulong *vertex_offsets,
                            __global ulong *index_offsets, __global ulong *tiles,
                            __local ulong *scan_v, __local ulong *scan_i)
{
    uint l = (uint)get_local_id(0), group = (uint)get_local_size(0), tile = (uint)get_group_id(0);
    uint first = tile * group, q = first + l, p = patch_base + q;
    ulong2 counts = (ulong2)(0, 0);
    ulong f = 0;
    if (q < num_patches) {
        int flag = flags[p];
        counts = count_patch(factors, p, vertex_counts, index_counts);
        f = (ulong)((flag & FLAG_CULLED) != 0) | ((ulong)((flag & FLAG_SATURATED) != 0) << 32);
    }
    scan_pairs(counts.x, counts.y, scan_v, scan_i);
    if (q < num_patches) {
        vertex_offsets[p + 1] = scan_v[l];
        index_offsets[p + 1] = scan_i[l];
    }
    ulong sum_v = scan_v[group - 1], sum_i = scan_i[group - 1];
    f = group_sum(f, scan_v);  /* (its barrier: every work-item has read scan_v) */
    if (l == 0) {
        __global ulong *record = tiles + 4 * (ulong)(tile_base + tile);
        record[0] = sum_v;
        record[1] = sum_i;
        record[2] = f;
        record[3] = (ulong)(patch_base + first) | ((ulong)min(group, num_patches - first) << 32);
    }
}

__kernel void offsets_carries(uint num_tiles, __global const ulong *tiles, __global ulong *vertex_offsets,
                              __global ulong *index_offsets, __global ulong *summary,
                              __local ulong *scan_v, __local ulong *scan_i)
{
    uint l = (uint)get_local_id(0), group = (uint)get_local_size(0), tile = (uint)get_group_id(0);
    bool last = tile + 1 == num_tiles;
    ulong carry_v = 0, carry_i = 0, flag_counts = 0;
    for (uint t = l; t < tile; t += group) {  /* the earlier tiles' sums */
        carry_v += tiles[4 * (ulong)t];
        carry_i += tiles[4 * (ulong)t + 1];
        flag_counts += tiles[4 * (ulong)t + 2];
    }
    carry_v = group_sum(carry_v, scan_v);
    carry_i = group_sum(carry_i, scan_i);
    ulong span = tiles[4 * (ulong)tile + 3];
    uint first = (uint)span, count = (uint)(span >> 32);
    for (uint q = l; q < count; q += group) {
        vertex_offsets[first + q + 1] += carry_v;
        index_offsets[first + q + 1] += carry_i;
    }
    if (last) {  /* (uniform across the work-group: its barriers are reached by all or none) */
        flag_counts = group_sum(flag_counts, scan_v);
        if (l == 0) {
            ulong flags_all = flag_counts + tiles[4 * (ulong)tile + 2];
            summary[0] = carry_v + tiles[4 * (ulong)tile];
            summary[1] = carry_i + tiles[4 * (ulong)tile + 1];
            summary[2] = flags_all & 0xffffffffUL;
            summary[3] = flags_all >> 32;
        }
    }
}
