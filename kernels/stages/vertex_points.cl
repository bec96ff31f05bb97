/* Stage 4 a work-item per output vertex (issue 15, for GPUs): consecutive work-items write
 * consecutive vertices, so the stores of a vector or warp fall side by side (coalesced), where
 * stages/vertices.cl (a work-item per patch) and stages/vertex_rows.cl (per row) have each
 * work-item write its own run.  A work-group of G work-items owns G * per_item consecutive
 * vertices of the batch; in step k its work-item l writes vertex k G + l of them, so each step's
 * stores are side by side, and a work-item finds and loads a patch only when its next vertex is
 * in another one (patch_of over vertex_offsets: a binary search, from the last patch on).  Each
 * vertex is put_point's (stages/rows.h): bitwise what stages/vertices.cl writes, forward
 * differencing included (replayed from the row's start).  The batch is patches first_patch ..
 * first_patch + num_patches - 1; work-items past its last vertex stop, so the host may launch
 * over the emit's whole vertex range, whatever the kinds. */
#include "stages/rows.h"

__kernel void vertex_points(__global const float4 *controls, __global const int4 *factors,
                            __global const ulong *vertex_offsets, __global const int *patch_objects,
                            uint first_patch, uint num_patches, uint patch_base, ulong vertex_base,
                            int forward_differencing, uint per_item,
                            __global float *positions, __global float *normals, __global float *uv,
                            __global int *patch_ids, __global int *object_ids)
{
    uint last = first_patch + num_patches;
    ulong end = vertex_offsets[last], group = get_local_size(0);
    ulong at = vertex_offsets[first_patch] + get_group_id(0) * group * per_item + get_local_id(0);
    vertex_out out = {positions, normals, uv, patch_ids, object_ids};
    uint p = first_patch;
    ulong patch_end = 0;  /* no patch loaded yet */
    int4 f = (int4)(0);
    int collapsed = 0, object = 0;
    kind_patch patch;
    for (uint k = 0; k < per_item && at < end; ++k, at += group) {
        if (at >= patch_end) {
            p = patch_of(vertex_offsets, p, last, at);
            patch_end = vertex_offsets[p + 1];
            f = patch_factors(factors[p], &collapsed);
            object = patch_objects[p];
            kind_load(controls, p - patch_base, &patch);
        }
        put_point(&patch, f, collapsed, (uint)(at - vertex_offsets[p]), forward_differencing, out, at - vertex_base,
                  p, object);
    }
}
