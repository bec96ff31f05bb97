/* The vertex layout every pattern shares, written once: the ring (f_e points per edge e,
 * counter-clockwise, edge e's point k at pattern_ring_param(f, e, k)), then the interior rows
 * j = 1 .. pattern_rows(f), row j's points i = 1 .. steps - 1 at pattern_row_point(f, j, i)
 * (steps = pattern_row(f, j); points 0 and steps are the row's ends, on the ring).
 * Stage 3 counts with pattern_vertex_count; stage 4 (stages/vertices.cl) walks the same loops. */
#ifndef CLTESS_PATTERNS_LAYOUT_H
#define CLTESS_PATTERNS_LAYOUT_H
#include "common.h"

/* Ring points of edge e: its factor, unless the pattern reads its factors otherwise (a
 * fractional pattern, patterns/sd2.h: the segments of a fixed-point factor). */
#ifndef PATTERN_EDGE_POINTS
#define PATTERN_EDGE_POINTS(f, e) factor_of(f, e)
#endif
/* 0: the pattern's rows are not equally spaced, so stage 4 evaluates them directly. */
#ifndef PATTERN_UNIFORM_ROWS
#define PATTERN_UNIFORM_ROWS 1
#endif
/* 1: some row points go on a chord of the mesh rather than on the surface: the pattern defines
 * pattern_chord_point(f, j, i, &start, &end, &mu) (patterns/sd2.h), and stage 4 puts row point
 * (j, i), when it returns 1, at P_start + mu (P_end - P_start), P_v the position it gives layout
 * vertex v (itself never a chord point; stages/rows.h chord_position). */
#ifndef PATTERN_CHORD_POINTS
#define PATTERN_CHORD_POINTS 0
#endif

inline uint pattern_vertex_count(int4 f)
{
    if (f.s0 <= 0)
        return 0;
    uint count = 0;  /* the ring */
    for (int e = 0; e < PATTERN_EDGES; ++e)
        count += (uint)PATTERN_EDGE_POINTS(f, e);
    int rows = pattern_rows(f);
    for (int j = 1; j <= rows; ++j)
        count += (uint)(pattern_row(f, j) - 1);
    return count;
}

#endif
