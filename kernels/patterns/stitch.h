/* The transition stitch shared by the quad and triangle patterns (CudaTess sections 3 and 4,
 * Moreton 2001; docs/design.md section 5): one strip of triangles between the f_e segments of
 * ring edge e and an inner polyline of the pattern's grid, advancing the side whose next
 * segment's midpoint comes first.
 *
 * The including pattern defines, before including this file, its grid: a type pattern_grid
 * (what it computes once per patch: the factors and its core) and
 * uint pattern_grid_index(pattern_grid g, int2 point), the local vertex number of a grid point. */
#ifndef CLTESS_PATTERNS_STITCH_H
#define CLTESS_PATTERNS_STITCH_H
#include "common.h"

/* The inner polyline: grid points start + k * step for k = first .. last, whose segment k
 * (from point k to k + 1) has its midpoint at (2k + lead) / (2 along) of the edge. */
typedef struct {
    int2 start, step;
    int first, last;
    int along, lead;
} stitch_row;

/* Outer segment o's midpoint (o + 1/2) / f_e comes first when (2o + 1) along <= (2k + lead) f_e,
 * in integers.  Triangles counter-clockwise, as the ring runs.  collapsed: the edge's points
 * coincide (patch_factors), so the triangles on its segments are left out. */
/* POCL_INLINE: always inline on PoCL, which kept it out of line (28% of PN stage 5's samples in it;
 * inline, stage 5 -4.9% on PN triangles, -1.7% on the teapots: bench/RESULTS.md, "Issue 15: PoCL's
 * other out-of-line calls (session 10, branch `cpu15g`)"); plain inline elsewhere. */
POCL_INLINE void stitch_strip(__global uint *out, uint *count, uint base, pattern_grid g, int e, stitch_row row,
                              int collapsed)
{
    int4 f = g.f;
    int outer_n = factor_of(f, e), o = 0, k = row.first;
    while (o < outer_n || k < row.last) {
        if (k == row.last || (o < outer_n && (2 * o + 1) * row.along <= (2 * k + row.lead) * outer_n)) {
            if (!collapsed)
                put_triangle(out, count, base, ring_index(f, e, o), ring_index(f, e, o + 1),
                             pattern_grid_index(g, row.start + k * row.step));
            ++o;
        } else {
            put_triangle(out, count, base, ring_index(f, e, o),
                         pattern_grid_index(g, row.start + (k + 1) * row.step),
                         pattern_grid_index(g, row.start + k * row.step));
            ++k;
        }
    }
}

#endif
