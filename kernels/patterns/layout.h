/* The vertex layout every pattern shares, written once: the ring (f_e points per edge e,
 * counter-clockwise, edge e's point k at pattern_ring_param(f, e, k)), then the interior rows
 * j = 1 .. pattern_rows(f), row j's points i = 1 .. steps - 1 at pattern_row_point(f, j, i)
 * (steps = pattern_row(f, j); points 0 and steps are the row's ends, on the ring).
 * Stage 3 counts with pattern_vertex_count; stage 4 (stages/vertices.cl) walks the same loops. */
#ifndef CLTESS_PATTERNS_LAYOUT_H
#define CLTESS_PATTERNS_LAYOUT_H
#include "common.h"

inline uint pattern_vertex_count(int4 f)
{
    if (f.s0 <= 0)
        return 0;
    uint count = (uint)(f.s0 + f.s1 + f.s2 + f.s3);  /* the ring; unused factor slots are 0 */
    int rows = pattern_rows(f);
    for (int j = 1; j <= rows; ++j)
        count += (uint)(pattern_row(f, j) - 1);
    return count;
}

#endif
