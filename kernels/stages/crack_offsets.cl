/* Stages 2 and 3 in one launch, by one work-group (issue 15: a Session frame of a small scene
 * on a GPU, one launch fewer; Tessellator.fused_crack_free, up to FUSED_CRACK_FREE_MAX_PATCHES
 * patches).  First stage 2 as stages/crack_free.cl writes it: work-item l takes edges l, l + G,
 * ... (G = get_local_size(0)) of all num_edges, its crack-free factor by the crack policy
 * (crack_free_factor, kernels/crack/), negated where the edge is collapsed.  A barrier with a
 * global fence makes every final factor visible to the whole work-group (the only one), then
 * stage 3 as stages/offsets.cl runs on them for the first range of patches (offsets_of_range);
 * crack_offsets_summary, for a frame of one range, also writes its summary (write_summary).
 * Later ranges take stages/offsets.cl's launches, after this one (the queue is in order).  The
 * same functions on the same factors: bitwise stages/crack_free.cl followed by stages/offsets.cl. */
#include "stages/offsets.h"

/* Stage 2 for every edge, then the work-group's barrier (global fence). */
inline void crack_free_edges(__global const int *factors, __global const int *group_of,
                             __global const int *group_start, __global const int *members,
                             __global const int *collapsed_edges, uint num_edges, __global int *final_factors)
{
    for (uint edge = (uint)get_local_id(0); edge < num_edges; edge += (uint)get_local_size(0)) {
        int factor = crack_free_factor(factors, edge, group_of, group_start, members);
        final_factors[edge] = collapsed_edges[edge] ? -factor : factor;
    }
    barrier(CLK_GLOBAL_MEM_FENCE | CLK_LOCAL_MEM_FENCE);
}

__kernel void crack_offsets(__global const int *factors, __global const int *group_of,
                            __global const int *group_start, __global const int *members,
                            __global const int *collapsed_edges, uint num_edges, __global int *final_factors,
                            uint num_patches, uint patch_base,
                            __global ulong *vertex_counts, __global ulong *index_counts,
                            __global ulong *vertex_offsets, __global ulong *index_offsets,
                            __local ulong *scan_v, __local ulong *scan_i)
{
    crack_free_edges(factors, group_of, group_start, members, collapsed_edges, num_edges, final_factors);
    offsets_of_range((__global const int4 *)final_factors, num_patches, patch_base, vertex_counts,
                     index_counts, vertex_offsets, index_offsets, scan_v, scan_i);
}

__kernel void crack_offsets_summary(__global const int *factors, __global const int *group_of,
                                    __global const int *group_start, __global const int *members,
                                    __global const int *collapsed_edges, uint num_edges,
                                    __global int *final_factors, uint num_patches, uint patch_base,
                                    __global ulong *vertex_counts, __global ulong *index_counts,
                                    __global ulong *vertex_offsets, __global ulong *index_offsets,
                                    __global const int *flags, uint num_flags, __global ulong *summary,
                                    __local ulong *scan_v, __local ulong *scan_i)
{
    crack_free_edges(factors, group_of, group_start, members, collapsed_edges, num_edges, final_factors);
    ulong2 totals = offsets_of_range((__global const int4 *)final_factors, num_patches, patch_base,
                                     vertex_counts, index_counts, vertex_offsets, index_offsets, scan_v, scan_i);
    write_summary(totals, flags, num_flags, summary, scan_v, scan_i);
}
