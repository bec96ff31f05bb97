/* Stage 4's vertices of one patch in the pattern's layout (patterns/layout.h), shared by
 * stages/vertices.cl (a work-item per patch), stages/vertex_rows.cl (a work-item per run of
 * rows) and stages/vertex_points.cl (a work-item per vertex), so all three write the same bits.
 * Built against a kind header and a pattern header. */
#ifndef CLTESS_STAGES_ROWS_H
#define CLTESS_STAGES_ROWS_H

/* Ring point k of edge e: its domain point *x and its position, placed canonically on its edge
 * by the kind (kind_boundary_point: bitwise the neighbour's); a collapsed edge's points are all
 * its first corner.  Its normal is kind_eval's at *x. */
ALWAYS_INLINE float3 ring_position(__private const kind_patch *patch, int4 f, int collapsed, int e, int k,
                                   __private float3 *x)
{
    edge_param t = pattern_ring_param(f, e, k);
    *x = pattern_edge_point(e, t);
    edge_param corner = {0, t.f};
    return kind_boundary_point(patch, e, (collapsed >> e) & 1 ? corner : t);
}

#ifdef KIND_LANES
/* Ring points first .. first + KIND_LANES - 1 of edge e to output slot at, bitwise what put_ring's
 * loop writes: their positions by ring_position, their normals by kind_eval_lanes (kinds/bezier.h
 * on the CPU runtimes); where a lane is not plain, the eight one by one as put_ring's loop makes
 * them. */
ALWAYS_INLINE void put_ring_lanes(__private const kind_patch *patch, int4 f, int collapsed, int e, int first,
                                  vertex_out out, ulong at, uint p, int object)
{
    float3 position[KIND_LANES], x[KIND_LANES];
    __attribute__((opencl_unroll_hint))
    for (int k = 0; k < KIND_LANES; ++k)
        position[k] = ring_position(patch, f, collapsed, e, first + k, &x[k]);
    float8 domain[3], normal[3], positions[3];
    int8 plain;
    lanes_of3(x, domain);
    kind_eval_lanes(patch, domain[0], domain[1], normal, &plain);
    if (every_lane(plain)) {
        lanes_of3(position, positions);
        put_vertex_lanes(out, at, positions, normal, domain[0], domain[1], p, object);
        return;
    }
    for (int k = 0; k < KIND_LANES; ++k) {
        float3 alone;
        kind_eval(patch, x[k], 0, &alone);
        put_vertex(out, at + k, position[k], alone, x[k].xy, p, object);
    }
}

/* Row j's points first .. first + KIND_LANES - 1 to output slot at, from *row stepped to just
 * before them (kind_row_begin'd, then first - 1 steps), and on past them, bitwise what put_rows'
 * loop writes: by kind_row_next_lanes, or, where a lane is not plain, one by one by kind_row_next. */
ALWAYS_INLINE void put_row_lanes(__private const kind_patch *patch, int4 f, int j, int first,
                                 __private kind_row *row, vertex_out out, ulong at, uint p, int object)
{
    kind_row start = *row;
    float3 x[KIND_LANES];
    __attribute__((opencl_unroll_hint))
    for (int k = 0; k < KIND_LANES; ++k)
        x[k] = pattern_row_point(f, j, first + k);
    float8 position[3], normal[3], domain[3];
    int8 plain;
    kind_row_next_lanes(patch, row, position, normal, &plain);
    if (every_lane(plain)) {
        lanes_of3(x, domain);
        put_vertex_lanes(out, at, position, normal, domain[0], domain[1], p, object);
        return;
    }
    for (int k = 0; k < KIND_LANES; ++k) {
        float3 alone_position, alone_normal;
        kind_row_next(patch, &start, x[k], &alone_position, &alone_normal);
        put_vertex(out, at + k, alone_position, alone_normal, x[k].xy, p, object);
    }
}

/* Whether rows j .. j + KIND_LANES - 1 all have `steps` steps, at least KIND_LANES + 1 (a block). */
ALWAYS_INLINE int rows_alike(int4 f, int j, int steps)
{
    int alike = steps > KIND_LANES;
    for (int r = 0; r < KIND_LANES; ++r)
        alike &= pattern_row(f, j + r) == steps;
    return alike;
}

/* Points first .. first + KIND_LANES - 1 of rows j .. j + KIND_LANES - 1 (each `points` long, row j's
 * first point at output slot at) to their slots: made[c][(i - 1) % KIND_LANES] holds component c
 * (position x, y, z, normal x, y, z) of point i of every row, a lane a row; transposed, a lane a
 * point. */
ALWAYS_INLINE void put_block_points(int4 f, int j, int points, int first, float8 made[6][KIND_LANES],
                                    vertex_out out, ulong at, uint p, int object)
{
    float8 along[6][KIND_LANES];
    __attribute__((opencl_unroll_hint))
    for (int c = 0; c < 6; ++c) {
        float8 by_point[KIND_LANES];
        __attribute__((opencl_unroll_hint))
        for (int k = 0; k < KIND_LANES; ++k)
            by_point[k] = made[c][(first - 1 + k) & (KIND_LANES - 1)];
        transposed_lanes(by_point, along[c]);
    }
    for (int r = 0; r < KIND_LANES; ++r) {
        float3 x[KIND_LANES];
        __attribute__((opencl_unroll_hint))
        for (int k = 0; k < KIND_LANES; ++k)
            x[k] = pattern_row_point(f, j + r, first + k);
        float8 domain[3], position[3] = {along[0][r], along[1][r], along[2][r]},
                          normal[3] = {along[3][r], along[4][r], along[5][r]};
        lanes_of3(x, domain);
        put_vertex_lanes(out, at + (ulong)(r * points + first - 1), position, normal, domain[0], domain[1], p, object);
    }
}

/* Rows j .. j + KIND_LANES - 1 (rows_alike, `steps` steps each) a row a lane, from output slot at
 * (row j's first point): stepped together (kind_rows_begin / kind_rows_next), each set of
 * KIND_LANES points of every row transposed and written as put_row_lanes writes it, the last set
 * overlapping the one before.  Bitwise what put_rows' one row at a time writes, where every lane
 * was plain: returns whether they all were (otherwise the caller writes the rows again one by
 * one). */
ALWAYS_INLINE int put_row_block(__private const kind_patch *patch, int4 f, int j, int steps, vertex_out out, ulong at,
                                uint p, int object)
{
    float v[KIND_LANES];
    __attribute__((opencl_unroll_hint))
    for (int r = 0; r < KIND_LANES; ++r)
        v[r] = pattern_row_point(f, j + r, 0).y;
    kind_rows rows;
    kind_rows_begin(patch, (float8)(v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7]), steps, &rows);
    int points = steps - 1;
    float8 made[6][KIND_LANES];
    int8 plain = (int8)(-1);
    for (int i = 1; i <= points; ++i) {
        float8 position[3], normal[3];
        int8 ok;
        kind_rows_next(patch, &rows, position, normal, &ok);
        plain &= ok;
        int slot = (i - 1) & (KIND_LANES - 1);
        __attribute__((opencl_unroll_hint))
        for (int c = 0; c < 3; ++c) {
            made[c][slot] = position[c];
            made[3 + c][slot] = normal[c];
        }
        if ((i & (KIND_LANES - 1)) == 0 || i == points)
            put_block_points(f, j, points, i - (KIND_LANES - 1), made, out, at, p, object);
    }
    return every_lane(plain);
}
#endif

/* The ring of patch p from output slot at; returns the slot after it.  Where the kind has lanes
 * (KIND_LANES), an edge of at least KIND_LANES points goes by put_ring_lanes, its last lanes
 * overlapping the ones before (the same points again, the same bits). */
ALWAYS_INLINE ulong put_ring(__private const kind_patch *patch, int4 f, int collapsed, vertex_out out, ulong at,
                             uint p, int object)
{
    float3 normal, x;
    __attribute__((opencl_unroll_hint))  /* e constant in each copy: the edge's data in registers */
    for (int e = 0; e < PATTERN_EDGES; ++e) {
        int ring_count = PATTERN_EDGE_POINTS(f, e);
#ifdef KIND_LANES
        if (ring_count >= KIND_LANES) {
            for (int k = 0; k < ring_count; k += KIND_LANES) {
                int first = imin(k, ring_count - KIND_LANES);
                put_ring_lanes(patch, f, collapsed, e, first, out, at + first, p, object);
            }
            at += ring_count;
            continue;
        }
#endif
        for (int k = 0; k < ring_count; ++k) {
            float3 position = ring_position(patch, f, collapsed, e, k, &x);
            kind_eval(patch, x, 0, &normal);  /* the normal; the position is the edge's */
            put_vertex(out, at++, position, normal, x.xy, p, object);
        }
    }
    return at;
}

/* Vertex v (0 .. pattern_vertex_count(f) - 1) of a patch alone, as put_ring / put_rows compute it
 * before chord_position: *x its domain point, *position, *normal; *j its row (0: the ring) and *i
 * its point.  A ring point as put_ring computes it; a row point directly, or by forward
 * differencing replayed from its row's start (kind_row_begin, then kind_row_next i times: the
 * same operations in the same order as put_rows, so the same bits; the earlier steps' positions
 * and normals are dead and left out by the compiler). */
ALWAYS_INLINE void layout_point(__private const kind_patch *patch, int4 f, int collapsed, uint v,
                                int forward_differencing, __private float3 *x, __private float3 *position,
                                __private float3 *normal, __private int *j, __private int *i)
{
#if !PATTERN_UNIFORM_ROWS
    forward_differencing = 0;
#endif
    int on_ring = 0;
    __attribute__((opencl_unroll_hint))  /* e constant in each copy, as in put_ring */
    for (int e = 0; e < PATTERN_EDGES; ++e) {
        uint ring_count = (uint)PATTERN_EDGE_POINTS(f, e);
        if (!on_ring && v < ring_count) {
            *position = ring_position(patch, f, collapsed, e, (int)v, x);
            on_ring = 1;
        } else if (!on_ring) {
            v -= ring_count;
        }
    }
    if (on_ring) {
        kind_eval(patch, *x, 0, normal);
        *j = 0;
        *i = 0;
        return;
    }
    int rows = pattern_rows(f), row = 1, steps = pattern_row(f, 1);  /* row holds points 1 .. steps - 1 */
    while (row < rows && v >= (uint)(steps - 1)) {
        v -= (uint)(steps - 1);
        steps = pattern_row(f, ++row);
    }
    int point = (int)v + 1;
    *x = pattern_row_point(f, row, point);
    *j = row;
    *i = point;
    if (forward_differencing) {
        kind_row r;
        float3 unused_position, unused_normal;
        kind_row_begin(patch, pattern_row_point(f, row, 0), pattern_row_point(f, row, steps), steps, &r);
        for (int s = 1; s < point; ++s)
            kind_row_next(patch, &r, pattern_row_point(f, row, s), &unused_position, &unused_normal);
        kind_row_next(patch, &r, *x, position, normal);
    } else {
        kind_eval(patch, *x, position, normal);
    }
}

/* Row point (j, i) on a chord (patterns/layout.h PATTERN_CHORD_POINTS; mirror
 * cltess/patterns/base.py place_chords): *position moved to P_start + mu (P_end - P_start), the
 * layout vertices' own positions (layout_point: the ring's by kind_boundary_point), exactly
 * P_start at mu = 0; the normal stays the surface's at the point's domain point. */
ALWAYS_INLINE void chord_position(__private const kind_patch *patch, int4 f, int collapsed, int j, int i,
                                  int forward_differencing, __private float3 *position)
{
#if PATTERN_CHORD_POINTS
    uint start, end;
    float mu;
    if (pattern_chord_point(f, j, i, &start, &end, &mu)) {
        float3 x, p0, p1, normal;
        int row, point;
        layout_point(patch, f, collapsed, start, forward_differencing, &x, &p0, &normal, &row, &point);
        layout_point(patch, f, collapsed, end, forward_differencing, &x, &p1, &normal, &row, &point);
        *position = mu > 0.0f ? p0 + mu * (p1 - p0) : p0;
    }
#endif
}

/* Interior rows first_row .. last_row of patch p from output slot at: each row's points
 * i = 1 .. steps - 1 by forward differencing (kind_row_begin/next) or direct evaluation
 * (kind_eval); a pattern whose rows are not equally spaced (PATTERN_UNIFORM_ROWS 0) always
 * directly. */
ALWAYS_INLINE void put_rows(__private const kind_patch *patch, int4 f, int collapsed, int first_row, int last_row,
                            int forward_differencing, vertex_out out, ulong at, uint p, int object)
{
#if !PATTERN_UNIFORM_ROWS
    forward_differencing = 0;  /* the rows' points are not equally spaced (patterns/layout.h) */
#endif
    float3 position, normal;
#if defined(KIND_LANES) && !PATTERN_CHORD_POINTS
    int alone_until = first_row - 1;  /* rows up to it one at a time: a block of them was not plain */
#endif
    for (int j = first_row; j <= last_row; ++j) {
        int steps = pattern_row(f, j);
#if defined(KIND_LANES) && !PATTERN_CHORD_POINTS
        /* KIND_LANES rows at once, the last block overlapping the one before (CPU runtimes) */
        int block = imin(j, last_row - (KIND_LANES - 1));
        if (forward_differencing && j > alone_until && block >= first_row && rows_alike(f, block, steps)) {
            ulong block_at = at - (ulong)((j - block) * (steps - 1));
            int plain = put_row_block(patch, f, block, steps, out, block_at, p, object);
            if (!plain)  /* the block's rows again from its first, one at a time */
                alone_until = block + KIND_LANES - 1;
            at = plain ? block_at + (ulong)(KIND_LANES * (steps - 1)) : block_at;
            j = plain ? block + KIND_LANES - 1 : block - 1;
            continue;
        }
#endif
        if (forward_differencing) {
            kind_row row;
            kind_row_begin(patch, pattern_row_point(f, j, 0), pattern_row_point(f, j, steps), steps, &row);
#if defined(KIND_LANES) && !PATTERN_CHORD_POINTS
            if (steps - 1 >= KIND_LANES) {  /* KIND_LANES points at once (kinds/bezier.h, CPU runtimes) */
                kind_row start = row;
                int i = 1;
                for (; i + KIND_LANES <= steps; i += KIND_LANES)
                    put_row_lanes(patch, f, j, i, &row, out, at + (i - 1), p, object);
                if (i < steps) {  /* the last KIND_LANES points, overlapping the ones before: stepped again */
                    kind_row_skip(&start, steps - 1 - KIND_LANES);
                    put_row_lanes(patch, f, j, steps - KIND_LANES, &start, out, at + (steps - 1 - KIND_LANES), p,
                                  object);
                }
                at += steps - 1;
                continue;
            }
#endif
            for (int i = 1; i < steps; ++i) {
                float3 x = pattern_row_point(f, j, i);
                kind_row_next(patch, &row, x, &position, &normal);
                chord_position(patch, f, collapsed, j, i, forward_differencing, &position);
                put_vertex(out, at++, position, normal, x.xy, p, object);
            }
        } else {
            for (int i = 1; i < steps; ++i) {
                float3 x = pattern_row_point(f, j, i);
                kind_eval(patch, x, &position, &normal);
                chord_position(patch, f, collapsed, j, i, forward_differencing, &position);
                put_vertex(out, at++, position, normal, x.xy, p, object);
            }
        }
    }
}

/* Vertex v (0 .. pattern_vertex_count(f) - 1) of patch p alone, to output slot at, bitwise what
 * put_ring / put_rows write there (layout_point, then chord_position). */
ALWAYS_INLINE void put_point(__private const kind_patch *patch, int4 f, int collapsed, uint v,
                             int forward_differencing, vertex_out out, ulong at, uint p, int object)
{
    float3 x, position, normal;
    int j, i;
    layout_point(patch, f, collapsed, v, forward_differencing, &x, &position, &normal, &j, &i);
    if (j > 0)
        chord_position(patch, f, collapsed, j, i, forward_differencing, &position);
    put_vertex(out, at, position, normal, x.xy, p, object);
}

/* Stage 4 by line (stages/prepared_points.cl prepared_rows): a patch's lines are its interior
 * rows j = 1 .. pattern_rows(f) and its ring edges e = 0 .. PATTERN_EDGES - 1, each a run of
 * points side by side in the output.  line_start: the first point's slot in the patch's layout
 * (patterns/layout.h: the ring, edge by edge, then the rows) and its point count. */
ALWAYS_INLINE uint line_start(int4 f, int edge, int row, __private int *count)
{
    uint at = 0;
    for (int e = 0; e < PATTERN_EDGES; ++e)
        if (edge < 0 || e < edge)
            at += (uint)PATTERN_EDGE_POINTS(f, e);
    if (edge >= 0) {
        *count = PATTERN_EDGE_POINTS(f, edge);
        return at;
    }
    for (int j = 1; j < row; ++j)
        at += (uint)(pattern_row(f, j) - 1);
    *count = pattern_row(f, row) - 1;
    return at;
}

/* Point k (0 ..) of ring edge `edge`, bitwise what put_ring writes there (the edge loop unrolled
 * as there, so that each copy has its edge's data at constant offsets; a warp whose lanes share
 * the edge runs one copy). */
ALWAYS_INLINE void edge_point(__private const kind_patch *patch, int4 f, int collapsed, int edge, int k,
                              __private float3 *x, __private float3 *position, __private float3 *normal)
{
    __attribute__((opencl_unroll_hint))
    for (int e = 0; e < PATTERN_EDGES; ++e)
        if (e == edge)
            *position = ring_position(patch, f, collapsed, e, k, x);
    kind_eval(patch, *x, 0, normal);
}

/* Point k + 1 of interior row `row`, bitwise what put_rows writes there: directly, or as the next
 * step of `walk` (kind_row_begin'd by the caller, stepped once per point in order, as put_rows
 * does), then moved onto its chord where the pattern puts it there (chord_position). */
ALWAYS_INLINE void row_point(__private const kind_patch *patch, int4 f, int collapsed, int row, int k,
                             int forward_differencing, __private kind_row *walk, __private float3 *x,
                             __private float3 *position, __private float3 *normal)
{
    *x = pattern_row_point(f, row, k + 1);
    if (forward_differencing)
        kind_row_next(patch, walk, *x, position, normal);
    else
        kind_eval(patch, *x, position, normal);
    chord_position(patch, f, collapsed, row, k + 1, forward_differencing, position);
}

/* Stage 4 by vertex (stages/vertex_points.cl, prepared_points.cl): a work-group of G work-items
 * owns G * per_item consecutive vertices of the batch (patches first_patch .. first_patch +
 * num_patches - 1), and in step k its work-item l writes vertex k G + l of them, so each step's
 * stores are side by side.  A work-item finds its patch (patch_of) only when its next vertex is
 * in another one.  Without from_prepared (a literal, so each kernel keeps one of the two) it then
 * makes the patch by kind_load from controls and keeps it; with it, it copies the patch from
 * prepared[p - first_patch] for each vertex (no arithmetic, cached: the lanes of a warp mostly
 * read the same patch), so no kind_patch is live across the steps: on the H100 that took
 * prepared_points from 232 to 162 registers and stage 4 of uniform level 16 from 1.32 to 1.14 ms
 * (bench/RESULTS.md, "Issue 15: GPU stages 4-5, session 5").  Work-items past the
 * batch's last vertex stop; a batch of more than `capacity` vertices writes none (batch_fits). */
ALWAYS_INLINE void put_points(__global const float4 *controls, uint patch_base, const int from_prepared,
                              __global const kind_patch *prepared, __global const int4 *factors,
                              __global const ulong *vertex_offsets, __global const int *patch_objects,
                              uint first_patch, uint num_patches, ulong vertex_base,
                              int forward_differencing, ulong capacity, uint per_item, vertex_out out)
{
    uint last = first_patch + num_patches;
    if (!batch_fits(vertex_offsets, last, vertex_base, capacity))
        return;
    ulong end = vertex_offsets[last], group = get_local_size(0);
    ulong at = vertex_offsets[first_patch] + get_group_id(0) * group * per_item + get_local_id(0);
    uint p = first_patch;
    ulong patch_start = 0, patch_end = 0;  /* no patch loaded yet */
    int4 f = (int4)(0);
    int collapsed = 0, object = 0;
    kind_patch patch;
    for (uint k = 0; k < per_item && at < end; ++k, at += group) {
        if (at >= patch_end) {
            p = patch_of(vertex_offsets, p, last, at);  /* a binary search from the last patch on */
            patch_start = vertex_offsets[p];
            patch_end = vertex_offsets[p + 1];
            f = patch_factors(factors[p], &collapsed);
            object = patch_objects[p];
            if (!from_prepared)
                kind_load(controls, p - patch_base, &patch);
        }
        if (from_prepared)  /* copied for this vertex alone: no patch held in registers across the steps */
            patch = prepared[p - first_patch];
        put_point(&patch, f, collapsed, (uint)(at - patch_start), forward_differencing, out, at - vertex_base,
                  p, object);
    }
}

#endif
