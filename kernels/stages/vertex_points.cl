/* Stage 4 a work-item per output vertex (issue 15, for GPUs): consecutive work-items write
 * consecutive vertices, so the stores of a vector or warp fall side by side (coalesced), where
 * stages/vertices.cl (a work-item per patch) and stages/vertex_rows.cl (per row) have each
 * work-item write its own run.  Work-item id of the batch owns the batch's vertex id: its
 * patch by binary search over vertex_offsets (patch_of), its place in the pattern's layout and
 * its value by put_point (stages/rows.h): bitwise what stages/vertices.cl writes, forward
 * differencing included (replayed from the row's start).  The batch is patches first_patch ..
 * first_patch + num_patches - 1; the global size may exceed its vertices (work-items past its
 * last vertex return): the host launches it over the emit's vertex range, whatever the kinds. */
#include "stages/rows.h"

__kernel void vertex_points(__global const float4 *controls, __global const int4 *factors,
                            __global const ulong *vertex_offsets, __global const int *patch_objects,
                            uint first_patch, uint num_patches, uint patch_base, ulong vertex_base,
                            int forward_differencing,
                            __global float *positions, __global float *normals, __global float *uv,
                            __global int *patch_ids, __global int *object_ids)
{
    uint last = first_patch + num_patches;
    ulong at = vertex_offsets[first_patch] + get_global_id(0);
    if (at >= vertex_offsets[last])
        return;
    uint p = patch_of(vertex_offsets, first_patch, last, at);
    int collapsed;
    int4 f = patch_factors(factors[p], &collapsed);
    vertex_out out = {positions, normals, uv, patch_ids, object_ids};
    kind_patch patch;
    kind_load(controls, p - patch_base, &patch);
    put_point(&patch, f, collapsed, (uint)(at - vertex_offsets[p]), forward_differencing, out, at - vertex_base, p,
              patch_objects[p]);
}
