/* The vertex layout every pattern shares, written once: the ring (f_e points per edge e,
 * counter-clockwise, edge e's point k at pattern_ring_param(f, e, k)), then the interior rows
 * j = 1 .. pattern_rows(f), row j's points i = 1 .. steps - 1 at pattern_row_point(f, j, i)
 * (steps = pattern_row(f, j); points 0 and steps are the row's ends, on the ring).
 * Stage 3 counts with pattern_vertex_count; stage 4 (stages/vertices.cl) walks the same loops. */
#ifndef CLTESS_PATTERNS_LAYOUT_H
#define CLTESS_PATTERNS_LAYOUT_H
#include "common.h"

/* Ring points of edge e: the factor, unless the pattern's record is not a count
 * (PATTERN_HAS_RING_COUNT: it defines pattern_ring_count itself, e.g. patterns/esc.h). */
#ifndef PATTERN_HAS_RING_COUNT
inline int pattern_ring_count(int4 f, int e) { return factor_of(f, e); }
#endif

/* 1: the rows' points are not equally spaced between their ends (patterns/esc.h), so stage 4
 * evaluates them directly, never by forward differencing along the row. */
#ifndef PATTERN_DIRECT_ROWS
#define PATTERN_DIRECT_ROWS 0
#endif

inline uint pattern_vertex_count(int4 f)
{
    if (f.s0 <= 0)
        return 0;
    uint count = 0;  /* the ring; unused factor slots are 0 */
    for (int e = 0; e < PATTERN_EDGES; ++e)
        count += (uint)pattern_ring_count(f, e);
    int rows = pattern_rows(f);
    for (int j = 1; j <= rows; ++j)
        count += (uint)(pattern_row(f, j) - 1);
    return count;
}

#endif
