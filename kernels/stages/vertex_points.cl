/* Stage 4 a work-item per output vertex (issue 15, for GPUs): consecutive work-items write
 * consecutive vertices, so the stores of a vector or warp fall side by side (coalesced), where
 * stages/vertices.cl (a work-item per patch) and stages/vertex_rows.cl (per row) have each
 * work-item write its own run.  A work-group of G work-items owns G * per_item consecutive
 * vertices of the batch; in step k its work-item l writes vertex k G + l of them, so each step's
 * stores are side by side, and a work-item finds and loads a patch only when its next vertex is
 * in another one (put_points in stages/rows.h: a binary search over vertex_offsets).  Each
 * vertex is put_point's (stages/rows.h): bitwise what stages/vertices.cl writes, forward
 * differencing included (replayed from the row's start).  The batch is patches first_patch ..
 * first_patch + num_patches - 1; work-items past its last vertex stop, so the host may launch
 * over the emit's whole vertex range, whatever the kinds. */
#include "stages/rows.h"

__kernel void vertex_points(__global const float4 *controls, __global const int4 *factors,
                            __global const ulong *vertex_offsets, __global const int *patch_objects,
                            uint first_patch, uint num_patches, uint patch_base, ulong vertex_base,
                            int forward_differencing, ulong capacity, uint per_item,
                            __global float *positions, __global float *normals, __global float *uv,
                            __global int *patch_ids, __global int *object_ids)
{
    vertex_out out = {positions, normals, uv, patch_ids, object_ids};
    put_points(controls, patch_base, 0, 0, factors, vertex_offsets, patch_objects, first_patch, num_patches,
               vertex_base, forward_differencing, capacity, per_item, out);
}
