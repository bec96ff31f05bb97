/* Stage 4 with more parallelism (issue 15, for GPUs): a work-item per (patch, row) of one
 * batch, row 0 the ring and rows 1 .. pattern_rows(f) the interior rows, in the layout of
 * patterns/layout.h.  Each vertex is computed by the same code as stages/vertices.cl (one
 * work-item per patch), so the output is bitwise the same; a row's offset in its patch is the
 * ring's size plus the rows before it.  rows_per_patch work-items per patch, the rows of one
 * patch side by side; the last of them also does every row beyond it, so any rows_per_patch
 * >= 1 is right (the host gives max_factor + 1: no pattern has more rows than its largest
 * factor). */
#include "stages/rows.h"

__kernel void vertex_rows(__global const float4 *controls, __global const int4 *factors,
                          __global const ulong *vertex_offsets, __global const int *patch_objects,
                          uint first_patch, uint num_patches, uint patch_base, ulong vertex_base,
                          int forward_differencing, ulong capacity, uint rows_per_patch,
                          __global float *positions, __global float *normals, __global float *uv,
                          __global int *patch_ids, __global int *object_ids)
{
    size_t item = get_global_id(0);
    uint q = (uint)(item / rows_per_patch);
    int first_row = (int)(item % rows_per_patch);
    if (q >= num_patches || !batch_fits(vertex_offsets, first_patch + num_patches, vertex_base, capacity))
        return;
    uint p = first_patch + q;
    int collapsed;
    int4 f = patch_factors(factors[p], &collapsed);
    int rows = pattern_rows(f);
    if (f.s0 <= 0 || first_row > rows)
        return;
    int last_row = first_row == (int)rows_per_patch - 1 ? rows : first_row;
    vertex_out out = {positions, normals, uv, patch_ids, object_ids};
    int object = patch_objects[p];
    kind_patch patch;
    kind_load(controls, p - patch_base, &patch);
    ulong at = vertex_offsets[p] - vertex_base;
    if (first_row == 0) {
        at = put_ring(&patch, f, collapsed, out, at, p, object);  /* stages/rows.h */
        first_row = 1;
    } else {
        for (int e = 0; e < PATTERN_EDGES; ++e)  /* the ring */
            at += (ulong)PATTERN_EDGE_POINTS(f, e);
        for (int j = 1; j < first_row; ++j)
            at += (ulong)(pattern_row(f, j) - 1);
    }
    put_rows(&patch, f, collapsed, first_row, last_row, forward_differencing, out, at, p, object);
}
