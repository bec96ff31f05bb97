/* Stage 4: vertex data of each patch in the pattern's layout (patterns/layout.h): the ring, each
 * point placed canonically on its edge by the kind (kind_boundary_point: bitwise the
 * neighbour's), then the interior rows by forward differencing (kind_row_begin/next) or direct
 * evaluation (kind_eval).  One work-item per patch of one batch, first_patch ..
 * first_patch + num_patches - 1 (scene numbering: the kind's own patch p - patch_base); their
 * vertices go to vertex_offsets[p] - vertex_base of the output arrays. */
__kernel void vertices(__global const float4 *controls, __global const int4 *factors,
                       __global const ulong *vertex_offsets, __global const int *patch_objects,
                       uint first_patch, uint num_patches, uint patch_base, ulong vertex_base,
                       int forward_differencing,
                       __global float *positions, __global float *normals, __global float *uv,
                       __global int *patch_ids, __global int *object_ids)
{
    uint p;
    int4 f;
    int collapsed;
    if (!batch_patch(first_patch, num_patches, factors, &p, &f, &collapsed))
        return;
    vertex_out out = {positions, normals, uv, patch_ids, object_ids};
    int object = patch_objects[p];
    kind_patch patch;
    kind_load(controls, p - patch_base, &patch);
    ulong at = vertex_offsets[p] - vertex_base;
    float3 position, normal;

    __attribute__((opencl_unroll_hint))  /* e constant in each copy: the edge's data in registers */
    for (int e = 0; e < PATTERN_EDGES; ++e) {
        int ring_count = PATTERN_EDGE_POINTS(f, e);
        for (int k = 0; k < ring_count; ++k) {
            edge_param t = pattern_ring_param(f, e, k);
            float3 x = pattern_edge_point(e, t);
            kind_eval(&patch, x, 0, &normal);  /* the normal; the position is the edge's */
            edge_param corner = {0, t.f};  /* a collapsed edge: every point is its first corner */
            put_vertex(out, at++, kind_boundary_point(&patch, e, (collapsed >> e) & 1 ? corner : t), normal, x.xy,
                       p, object);
        }
    }

#if !PATTERN_UNIFORM_ROWS
    forward_differencing = 0;  /* the rows' points are not equally spaced (patterns/layout.h) */
#endif
    int rows = pattern_rows(f);
    for (int j = 1; j <= rows; ++j) {
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
