/* The triangle transition pattern (CudaTess section 4; docs/design.md section 5; NumPy mirror
 * cltess/patterns/tri_transition.py).  Core factor N = the largest edge factor.  Vertex layout
 * (patterns/layout.h): the ring of f0 + f1 + f2 points counter-clockwise from P1, then the
 * interior points (i/N, j/N) of the factor-N grid, i, j, k >= 1, in rows j = 1..N-2,
 * i = 1..N-1-j.  All of the factor-N grid's interior points are vertices whatever the edges. */
#ifndef CLTESS_PATTERNS_TRI_TRANSITION_H
#define CLTESS_PATTERNS_TRI_TRANSITION_H
#include "common.h"

#define PATTERN_EDGES 3

/* imin, imax: int min, max, inline on PoCL (common.h; bench/RESULTS.md, "Issue 15: PoCL's other
 * out-of-line calls (session 10, branch `cpu15g`)") */
inline int tri_core(int4 f) { return imax(imax(f.s0, f.s1), f.s2); }

/* --- the vertex layout ------------------------------------------------------------------------ */

/* Ring point k of edge e is point k of f_e: the edge's own factor. */
inline edge_param pattern_ring_param(int4 f, int e, int k)
{
    edge_param t = {k, factor_of(f, e)};
    return t;
}

inline float3 pattern_edge_point(int e, edge_param t) { return tri_edge_point(e, t); }

inline int pattern_rows(int4 f) { return imax(tri_core(f) - 2, 0); }

/* Row j (v = j / N) runs from (0, v, 1-v) to (1-v, v, 0) in N - j steps. */
inline int pattern_row(int4 f, int j) { return tri_core(f) - j; }

inline float3 pattern_row_point(int4 f, int j, int i)
{
    return tri_grid_point(tri_core(f), j, i);
}

#include "patterns/layout.h"

/* --- the triangles ---------------------------------------------------------------------------- */

/* The factor-N grid of a patch, computed once: its factors and N. */
typedef struct {
    int4 f;
    int n;
} pattern_grid;

/* Local number of grid point (i, j, n-i-j) of the factor-n grid: a corner, a point of an edge
 * whose factor is n (the pattern uses no other boundary grid points), or an interior point. */
inline uint pattern_grid_index(pattern_grid g, int2 point)
{
    int4 f = g.f;
    int n = g.n, i = point.x, j = point.y, k = n - i - j;
    if (i == n) return 0;
    if (j == n) return (uint)f.s0;
    if (k == n) return (uint)(f.s0 + f.s1);
    if (k == 0) return ring_index(f, 0, j);
    if (i == 0) return ring_index(f, 1, k);
    if (j == 0) return ring_index(f, 2, i);
    return (uint)(f.s0 + f.s1 + f.s2 + (j - 1) * (2 * n - 2 - j) / 2 + (i - 1));
}

#include "patterns/stitch.h"

/* Grid point (i, j) of the point m (0..n-1, along the edge's direction) of the grid row one step
 * inside edge e: coordinate e is n-1-m, coordinate e+1 is m, coordinate e+2 is 1. */
inline int2 tri_row_point(int n, int e, int m)
{
    int c[3];
    c[e] = n - 1 - m;
    c[(e + 1) % 3] = m;
    c[(e + 2) % 3] = 1;
    return (int2)(c[0], c[1]);
}

/* The triangles, in "count" mode (out == 0) or "emit" mode (out != 0), like the quad pattern's.
 * The uniform core is the regular factor-N grid less the band along each edge whose factor is
 * below N (a transition edge; at most two, since one edge has N).  Each transition band is
 * stitched between the edge's f_e segments and the grid row inside it, whose points sit at
 * (m + 1/2) / N (midway between their two projections onto the edge): segment midpoints at
 * (2m + 2) / (2N).  With two transition edges, each row stops where the two rows cross (the
 * paper's modification: the row runs on the extended core grid, less its first, virtual
 * segment).  Factors (1, 1, 1) give the triangle (P1, P2, P3). */
inline uint pattern_primitives(int4 f, int collapsed, __global uint *out, uint base)
{
    uint count = 0;
    if (f.s0 <= 0)
        return 0;
    int n = tri_core(f);
    pattern_grid g = {f, n};
    int t[3] = {f.s0 < n, f.s1 < n, f.s2 < n};
    /* The core: the regular grid of factor m on the points whose coordinate (e+2)%3, which is 0
     * on edge e, is at least t[e]; up and down triangles, counter-clockwise. */
    int m = n - t[0] - t[1] - t[2];
    for (int j = 0; j < m; ++j)
        for (int i = 0; i + j < m; ++i) {
            int a = t[1] + i, b = t[2] + j;  /* grid point (a, b, n-a-b) */
            put_triangle(out, &count, base, pattern_grid_index(g, (int2)(a + 1, b)),
                         pattern_grid_index(g, (int2)(a, b + 1)), pattern_grid_index(g, (int2)(a, b)));
            if (i + j < m - 1)
                put_triangle(out, &count, base, pattern_grid_index(g, (int2)(a + 1, b)),
                             pattern_grid_index(g, (int2)(a + 1, b + 1)), pattern_grid_index(g, (int2)(a, b + 1)));
        }
    for (int e = 0; e < 3; ++e) {
        if (!t[e])
            continue;
        int2 start = tri_row_point(n, e, 0);
        stitch_row row = {start, tri_row_point(n, e, 1) - start, t[(e + 2) % 3], n - 1 - t[(e + 1) % 3], n, 2};
        stitch_strip(out, &count, base, g, e, row, (collapsed >> e) & 1);
    }
    return count;
}

#endif
