/* Stage 4: vertex data of each patch in the pattern's layout (patterns/layout.h): the ring, each
 * point placed canonically on its edge by the kind (kind_boundary_point: bitwise the
 * neighbour's), then the interior rows by forward differencing (kind_row_begin/next) or direct
 * evaluation (kind_eval).  One work-item per patch of one batch, first_patch ..
 * first_patch + num_patches - 1 (scene numbering: the kind's own patch p - patch_base); their
 * vertices go to vertex_offsets[p] - vertex_base of the output arrays, which hold `capacity`
 * (none is written when the batch's do not fit: batch_fits in common.h). */
#include "stages/rows.h"

__kernel void vertices(__global const float4 *controls, __global const int4 *factors,
                       __global const ulong *vertex_offsets, __global const int *patch_objects,
                       uint first_patch, uint num_patches, uint patch_base, ulong vertex_base,
                       int forward_differencing, ulong capacity,
                       __global float *positions, __global float *normals, __global float *uv,
                       __global int *patch_ids, __global int *object_ids)
{
    uint p;
    int4 f;
    int collapsed;
    if (!batch_fits(vertex_offsets, first_patch + num_patches, vertex_base, capacity)
        || !batch_patch(first_patch, num_patches, factors, &p, &f, &collapsed))
        return;
    vertex_out out = {positions, normals, uv, patch_ids, object_ids};
    int object = patch_objects[p];
    kind_patch patch;
    kind_load(controls, p - patch_base, &patch);
    ulong at = vertex_offsets[p] - vertex_base;
    at = put_ring(&patch, f, collapsed, out, at, p, object);  /* stages/rows.h */
    put_rows(&patch, f, collapsed, 1, pattern_rows(f), forward_differencing, out, at, p, object);
}
