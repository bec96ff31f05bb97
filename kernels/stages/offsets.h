/* Stage 3 in one work-group (stages/offsets.cl, stages/crack_offsets.cl): patch counts, the
 * work-group's scan of them, the offsets of a range of patches tile by tile, and a frame's summary. */
#ifndef CLTESS_STAGES_OFFSETS_H
#define CLTESS_STAGES_OFFSETS_H

/* Patch p's counts (as counts.cl: pattern_vertex_count, pattern_primitives in count mode),
 * stored; returns (vertices, indices). */
inline ulong2 count_patch(__global const int4 *factors, uint p, __global ulong *vertex_counts,
                          __global ulong *index_counts)
{
    int collapsed;
    int4 f = patch_factors(factors[p], &collapsed);
    ulong v = pattern_vertex_count(f), i = 3 * (ulong)pattern_primitives(f, collapsed, 0, 0);
    vertex_counts[p] = v;
    index_counts[p] = i;
    return (ulong2)(v, i);
}

/* The Hillis-Steele inclusive scan of the work-group's (v, i) in local memory: work-item l's is
 * left in scan_v[l], scan_i[l] (G = get_local_size(0) a power of two; scan_* free on entry). */
inline void scan_pairs(ulong v, ulong i, __local ulong *scan_v, __local ulong *scan_i)
{
    uint l = (uint)get_local_id(0), group = (uint)get_local_size(0);
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
}

/* The sum of value over the work-group, in every work-item: a tree in scratch (G ulongs, G a
 * power of two), after a barrier, so that what scratch held before has been read. */
inline ulong group_sum(ulong value, __local ulong *scratch)
{
    uint l = (uint)get_local_id(0), group = (uint)get_local_size(0);
    barrier(CLK_LOCAL_MEM_FENCE);
    scratch[l] = value;
    barrier(CLK_LOCAL_MEM_FENCE);
    for (uint step = group >> 1; step > 0; step >>= 1) {
        if (l < step)
            scratch[l] += scratch[l + step];
        barrier(CLK_LOCAL_MEM_FENCE);
    }
    return scratch[0];
}

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
        ulong2 counts = q < num_patches ? count_patch(factors, patch_base + q, vertex_counts, index_counts)
                                        : (ulong2)(0, 0);
        scan_pairs(counts.x, counts.y, scan_v, scan_i);
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

/* The frame's summary (offsets_summary): the totals, and how many of flags[0 .. num_flags-1]
 * have FLAG_CULLED and FLAG_SATURATED, counted by the work-group (scan_* free on entry). */
inline void write_summary(ulong2 totals, __global const int *flags, uint num_flags, __global ulong *summary,
                          __local ulong *scan_v, __local ulong *scan_i)
{
    uint l = (uint)get_local_id(0), group = (uint)get_local_size(0);
    ulong culled = 0, saturated = 0;
    for (uint p = l; p < num_flags; p += group) {
        int flag = flags[p];
        culled += (flag & FLAG_CULLED) != 0;
        saturated += (flag & FLAG_SATURATED) != 0;
    }
    culled = group_sum(culled, scan_v);
    saturated = group_sum(saturated, scan_i);
    if (l == 0) {
        summary[0] = totals.x;
        summary[1] = totals.y;
        summary[2] = culled;
        summary[3] = saturated;
    }
}

#endif
