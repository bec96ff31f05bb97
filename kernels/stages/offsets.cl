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
/* The counts and offsets of one range; returns the offsets past its end (the totals, for the
 * last range), the same in every work-item. */
inline ulong2 offsets_of_range(__global const int4 *factors, uint num_patches, uint patch_base,
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
    return (ulong2)(carry_v, carry_i);
}

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
    uint l = (uint)get_local_id(0), group = (uint)get_local_size(0);
    ulong culled = 0, saturated = 0;
    for (uint p = l; p < num_flags; p += group) {
        int flag = flags[p];
        culled += (flag & FLAG_CULLED) != 0;
        saturated += (flag & FLAG_SATURATED) != 0;
    }
    scan_v[l] = culled;  /* (the range's last barrier: every work-item is done with scan_*) */
    scan_i[l] = saturated;
    barrier(CLK_LOCAL_MEM_FENCE);
    for (uint step = group >> 1; step > 0; step >>= 1) {  /* a tree sum (group: a power of two) */
        if (l < step) {
            scan_v[l] += scan_v[l + step];
            scan_i[l] += scan_i[l + step];
        }
        barrier(CLK_LOCAL_MEM_FENCE);
    }
    if (l == 0) {
        summary[0] = totals.x;
        summary[1] = totals.y;
        summary[2] = scan_v[0];
        summary[3] = scan_i[0];
    }
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
    ulong v = 0, i = 0, f = 0;
    if (q < num_patches) {
        int collapsed, flag = flags[p];
        int4 factor = patch_factors(factors[p], &collapsed);
        v = pattern_vertex_count(factor);
        i = 3 * (ulong)pattern_primitives(factor, collapsed, 0, 0);
        vertex_counts[p] = v;
        index_counts[p] = i;
        f = (ulong)((flag & FLAG_CULLED) != 0) | ((ulong)((flag & FLAG_SATURATED) != 0) << 32);
    }
    scan_v[l] = v;
    scan_i[l] = i;
    barrier(CLK_LOCAL_MEM_FENCE);
    for (uint d = 1; d < group; d <<= 1) {  /* Hillis-Steele, as offsets_of_range */
        ulong add_v = l >= d ? scan_v[l - d] : 0, add_i = l >= d ? scan_i[l - d] : 0;
        barrier(CLK_LOCAL_MEM_FENCE);
        scan_v[l] += add_v;
        scan_i[l] += add_i;
        barrier(CLK_LOCAL_MEM_FENCE);
    }
    if (q < num_patches) {
        vertex_offsets[p + 1] = scan_v[l];
        index_offsets[p + 1] = scan_i[l];
    }
    ulong sum_v = scan_v[group - 1], sum_i = scan_i[group - 1];
    barrier(CLK_LOCAL_MEM_FENCE);  /* every work-item has read scan_v before it holds the flags */
    scan_v[l] = f;
    barrier(CLK_LOCAL_MEM_FENCE);
    for (uint step = group >> 1; step > 0; step >>= 1) {
        if (l < step)
            scan_v[l] += scan_v[l + step];
        barrier(CLK_LOCAL_MEM_FENCE);
    }
    if (l == 0) {
        __global ulong *record = tiles + 4 * (ulong)(tile_base + tile);
        record[0] = sum_v;
        record[1] = sum_i;
        record[2] = scan_v[0];
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
    scan_v[l] = carry_v;
    scan_i[l] = carry_i;
    barrier(CLK_LOCAL_MEM_FENCE);
    for (uint step = group >> 1; step > 0; step >>= 1) {
        if (l < step) {
            scan_v[l] += scan_v[l + step];
            scan_i[l] += scan_i[l + step];
        }
        barrier(CLK_LOCAL_MEM_FENCE);
    }
    carry_v = scan_v[0];
    carry_i = scan_i[0];
    ulong span = tiles[4 * (ulong)tile + 3];
    uint first = (uint)span, count = (uint)(span >> 32);
    for (uint q = l; q < count; q += group) {
        vertex_offsets[first + q + 1] += carry_v;
        index_offsets[first + q + 1] += carry_i;
    }
    if (last) {  /* (uniform across the work-group: its barriers are reached by all or none) */
        barrier(CLK_LOCAL_MEM_FENCE);  /* every work-item has read the carries */
        scan_v[l] = flag_counts;
        barrier(CLK_LOCAL_MEM_FENCE);
        for (uint step = group >> 1; step > 0; step >>= 1) {
            if (l < step)
                scan_v[l] += scan_v[l + step];
            barrier(CLK_LOCAL_MEM_FENCE);
        }
        if (l == 0) {
            ulong flags_all = scan_v[0] + tiles[4 * (ulong)tile + 2];
            summary[0] = carry_v + tiles[4 * (ulong)tile];
            summary[1] = carry_i + tiles[4 * (ulong)tile + 1];
            summary[2] = flags_all & 0xffffffffUL;
            summary[3] = flags_all >> 32;
        }
    }
}
