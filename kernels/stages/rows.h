/* Stage 4's vertices of one patch in the pattern's layout (patterns/layout.h), shared by
 * stages/vertices.cl (a work-item per patch) and stages/vertex_rows.cl (a work-item per run of
 * rows), so both write the same bits.  Built against a kind header and a pattern header. */
#ifndef CLTESS_STAGES_ROWS_H
#define CLTESS_STAGES_ROWS_H

/* The ring of patch p from output slot at; returns the slot after it.  Each point is placed
 * canonically on its edge by the kind (kind_boundary_point: bitwise the neighbour's); a
 * collapsed edge's points are all its first corner. */
ALWAYS_INLINE ulong put_ring(__private const kind_patch *patch, int4 f, int collapsed, vertex_out out, ulong at,
                             uint p, int object)
{
    float3 normal;
    __attribute__((opencl_unroll_hint))  /* e constant in each copy: the edge's data in registers */
    for (int e = 0; e < PATTERN_EDGES; ++e) {
        int ring_count = PATTERN_EDGE_POINTS(f, e);
        for (int k = 0; k < ring_count; ++k) {
            edge_param t = pattern_ring_param(f, e, k);
            float3 x = pattern_edge_point(e, t);
            kind_eval(patch, x, 0, &normal);  /* the normal; the position is the edge's */
            edge_param corner = {0, t.f};
            put_vertex(out, at++, kind_boundary_point(patch, e, (collapsed >> e) & 1 ? corner : t), normal, x.xy,
                       p, object);
        }
    }
    return at;
}

/* Interior rows first_row .. last_row of patch p from output slot at: each row's points
 * i = 1 .. steps - 1 by forward differencing (kind_row_begin/next) or direct evaluation
 * (kind_eval); a pattern whose rows are not equally spaced (PATTERN_UNIFORM_ROWS 0) always
 * directly. */
ALWAYS_INLINE void put_rows(__private const kind_patch *patch, int4 f, int first_row, int last_row,
                            int forward_differencing, vertex_out out, ulong at, uint p, int object)
{
#if !PATTERN_UNIFORM_ROWS
    forward_differencing = 0;  /* the rows' points are not equally spaced (patterns/layout.h) */
#endif
    float3 position, normal;
    for (int j = first_row; j <= last_row; ++j) {
        int steps = pattern_row(f, j);
        if (forward_differencing) {
            kind_row row;
            kind_row_begin(patch, pattern_row_point(f, j, 0), pattern_row_point(f, j, steps), steps, &row);
            for (int i = 1; i < steps; ++i) {
                float3 x = pattern_row_point(f, j, i);
                kind_row_next(patch, &row, x, &position, &normal);
                put_vertex(out, at++, position, normal, x.xy, p, object);
            }
        } else {
            for (int i = 1; i < steps; ++i) {
                float3 x = pattern_row_point(f, j, i);
                kind_eval(patch, x, &position, &normal);
                put_vertex(out, at++, position, normal, x.xy, p, object);
            }
        }
    }
}

#endif
