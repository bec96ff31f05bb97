/* Stage 4 with more parallelism (issue 15, for GPUs): a work-item per (patch, row) of one
 * batch, row 0 the ring and rows 1 .. pattern_rows(f) the interior rows, in the layout of
 * patterns/layout.h.  Each vertex is computed by the same code as stages/vertices.cl (one
 * work-item per patch), so the output is bitwise the same; a row's offset in its patch is the
 * ring's size plus the rows before it.  rows_per_patch work-items per patch, the rows of one
 * patch side by side; the last of them also does every row beyond it, so any rows_per_patch
 * >= 1 is right (the host gives max_factor + 1: no pattern has more rows than its largest
 * factor). */
__kernel void vertex_rows(__global const float4 *controls, __global const int4 *factors,
                          __global const ulong *vertex_offsets, __global const int *patch_objects,
                          uint first_patch, uint num_patches, uint patch_base, ulong vertex_base,
                          int forward_differencing, uint rows_per_patch,
                          __global float *positions, __global float *normals, __global float *uv,
                          __global int *patch_ids, __global int *object_ids)
{
    size_t item = get_global_id(0);
    uint q = (uint)(item / rows_per_patch);
    int first_row = (int)(item % rows_per_patch);
    if (q >= num_patches)
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
    float3 position, normal;

    if (first_row == 0) {
        __attribute__((opencl_unroll_hint))
        for (int e = 0; e < PATTERN_EDGES; ++e)
            for (int k = 0; k < PATTERN_EDGE_POINTS(f, e); ++k) {  /* patterns/layout.h */
                edge_param t = pattern_ring_param(f, e, k);
                float3 x = pattern_edge_point(e, t);
                kind_eval(&patch, x, 0, &normal);
                edge_param corner = {0, t.f};
                put_vertex(out, at++, kind_boundary_point(&patch, e, (collapsed >> e) & 1 ? corner : t), normal,
                           x.xy, p, object);
            }
        first_row = 1;
    } else {
        for (int e = 0; e < PATTERN_EDGES; ++e)  /* the ring */
            at += (ulong)PATTERN_EDGE_POINTS(f, e);
        for (int j = 1; j < first_row; ++j)
            at += (ulong)(pattern_row(f, j) - 1);
    }

#if !PATTERN_UNIFORM_ROWS
    forward_differencing = 0;  /* the rows' points are not equally spaced (patterns/layout.h) */
#endif
    for (int j = first_row; j <= last_row; ++j) {
        int steps = pattern_row(f, j);
        if (forward_differencing) {
            kind_row row;
            kind_row_begin(&patch, pattern_row_point(f, j, 0), pattern_row_point(f, j, steps), steps, &row);
            for (int i = 1; i < steps; ++i) {
                float3 x = pattern_row_point(f, j, i);
                kind_row_next(&patch, &row, x, &position, &normal);
                put_vertex(out, at++, position, normal, x.xy, p, object);
            }
        } else {
            for (int i = 1; i < steps; ++i) {
                float3 x = pattern_row_point(f, j, i);
                kind_eval(&patch, x, &position, &normal);
                put_vertex(out, at++, position, normal, x.xy, p, object);
            }
        }
    }
}
