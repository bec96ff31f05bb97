/* The quad transition pattern (CudaTess section 3, Fig. 3; docs/design.md section 5; NumPy
 * mirror cltess/patterns/quad_transition.py).  Uniform factors (f0 = f2, f1 = f3): the regular
 * f0 x f1 grid.  Otherwise an inner grid of core factors A = max(min(f0, f2), 2),
 * B = max(min(f1, f3), 2) and a transition strip along each edge (patterns/stitch.h).
 * Vertex layout (patterns/layout.h): the ring, then the inner grid (i / A, j / B), rows
 * j = 1..B-1, i = 1..A-1. */
#ifndef CLTESS_PATTERNS_QUAD_TRANSITION_H
#define CLTESS_PATTERNS_QUAD_TRANSITION_H
#include "common.h"

#define PATTERN_EDGES 4

/* Core grid factors: the regular grid when uniform, else the inner grid of the ring pattern. */
inline int2 quad_core(int4 f, int *uniform)
{
    *uniform = f.s0 == f.s2 && f.s1 == f.s3;
    if (*uniform)
        return (int2)(f.s0, f.s1);
    /* imin, imax: int min, max, inline on PoCL (common.h; bench/RESULTS.md, "Issue 15: PoCL's other
     * out-of-line calls (session 10, branch `cpu15g`)") */
    return (int2)(imax(imin(f.s0, f.s2), 2), imax(imin(f.s1, f.s3), 2));
}

/* --- the vertex layout ------------------------------------------------------------------------ */

/* Ring point k of edge e is point k of f_e: the edge's own factor. */
inline edge_param pattern_ring_param(int4 f, int e, int k)
{
    edge_param t = {k, factor_of(f, e)};
    return t;
}

inline float3 pattern_edge_point(int e, edge_param t) { return quad_edge_point(e, t); }

inline int pattern_rows(int4 f)
{
    int uniform;
    return quad_core(f, &uniform).y - 1;
}

/* Row j runs along v = j / B from u = 0 to 1 in A steps: point i at (i / A, j / B). */
inline int pattern_row(int4 f, int j)
{
    int uniform;
    return quad_core(f, &uniform).x;
}

inline float3 pattern_row_point(int4 f, int j, int i)
{
    int uniform;
    int2 core = quad_core(f, &uniform);
    return (float3)((float)i / (float)core.x, (float)j / (float)core.y, 0.0f);
}

#include "patterns/layout.h"

/* --- the triangles ---------------------------------------------------------------------------- */

/* The A x B grid of a patch, computed once: its factors and core. */
typedef struct {
    int4 f;
    int2 core;
    int uniform;
} pattern_grid;

inline pattern_grid quad_grid(int4 f)
{
    pattern_grid g;
    g.f = f;
    g.core = quad_core(f, &g.uniform);
    return g;
}

/* Local number of grid point (i, j) of the A x B grid: on the boundary a ring point, else an
 * inner point. */
inline uint pattern_grid_index(pattern_grid g, int2 point)
{
    int4 f = g.f;
    int i = point.x, j = point.y;
    if (j == 0) return ring_index(f, 0, i);
    if (i == g.core.x) return ring_index(f, 1, j);
    if (j == g.core.y) return ring_index(f, 2, g.core.x - i);
    if (i == 0) return ring_index(f, 3, g.core.y - j);
    return (uint)(f.s0 + f.s1 + f.s2 + f.s3 + (j - 1) * (g.core.x - 1) + (i - 1));
}

#include "patterns/stitch.h"

/* pattern_grid_index of a uniform grid (f = (A, B, A, B), core (A, B)), without ring_index's
 * "% ring" (an integer division): there every point's ring number base + k is below the ring's
 * 2A + 2B points (edge 0: i <= A; edge 1: A + j <= A + B; edge 2: A + B + (A - i) <= 2A + B;
 * edge 3: 2A + B + (B - j) <= 2A + 2B - 1), so the remainder is the number itself.  Stage 5 of
 * uniform level 16 on PoCL spent two thirds of its time in the ring's cells before this
 * (bench/RESULTS.md, "PoCL's stages, session 7"). */
inline uint uniform_index(int a, int b, int i, int j)
{
    if (j == 0) return (uint)i;                      /* ring_index(f, 0, i) */
    if (i == a) return (uint)(a + j);                /* ring_index(f, 1, j) */
    if (j == b) return (uint)(2 * a + b - i);        /* ring_index(f, 2, A - i) */
    if (i == 0) return (uint)(2 * a + 2 * b - j);    /* ring_index(f, 3, B - j) */
    return (uint)(2 * a + 2 * b) + (uint)(j - 1) * (uint)(a - 1) + (uint)(i - 1);
}

inline uint uniform_grid_index(pattern_grid g, int2 point)
{
    return uniform_index(g.core.x, g.core.y, point.x, point.y);
}

/* pattern_grid_index, by uniform_grid_index where the grid is uniform. */
inline uint grid_point_index(pattern_grid g, int2 point)
{
    return g.uniform ? uniform_grid_index(g, point) : pattern_grid_index(g, point);
}

/* Cell (i, j) of the grid, two triangles (a, b, c), (a, c, d) with a = (i, j), b = (i + 1, j),
 * c = (i + 1, j + 1), d = (i, j + 1); a triangle with a side on a collapsed edge (bit e of
 * collapsed) joins two coincident points and is left out. */
POCL_INLINE void grid_cell(__global uint *out, uint *count, uint base, pattern_grid g, int collapsed, int i, int j)
{
    uint a = grid_point_index(g, (int2)(i, j)), b = grid_point_index(g, (int2)(i + 1, j));
    uint c = grid_point_index(g, (int2)(i + 1, j + 1)), d = grid_point_index(g, (int2)(i, j + 1));
    if (!((j == 0 && (collapsed & 1)) || (i + 1 == g.core.x && (collapsed & 2))))
        put_triangle(out, count, base, a, b, c);
    if (!((j + 1 == g.core.y && (collapsed & 4)) || (i == 0 && (collapsed & 8))))
        put_triangle(out, count, base, a, c, d);
}

/* Cells i0..i1-1 x j0..j1-1 of the grid, row by row (grid_cell).  The cells of the inner grid
 * (no corner on the ring: 0 < i < A - 1, 0 < j < B - 1) take their corners' numbers directly:
 * inner point (i, j) is ring + (j - 1)(A - 1) + (i - 1) (pattern_grid_index), so its row
 * neighbour is + 1 and the point above it + (A - 1); the same numbers as pattern_grid_index.
 * A row's inner cells are one loop without branches or a running count, six indices a cell
 * at out[3 count + 6 n ..] (so that a CPU compiler can unroll and vectorise it; stage 5 on
 * CPUs: bench/RESULTS.md, "Issue 15: CPU stage bandwidth" and "PoCL's stages, session 7"). */
POCL_INLINE void grid_cells(__global uint *out, uint *count, uint base, pattern_grid g, int collapsed,
                            int i0, int i1, int j0, int j1)
{
    uint ring = (uint)(g.f.s0 + g.f.s1 + g.f.s2 + g.f.s3), inner = (uint)(g.core.x - 1);
    for (int j = j0; j < j1; ++j) {
        int inner_row = j > 0 && j + 1 < g.core.y;
        int lo = inner_row ? imin(imax(i0, 1), i1) : i1;  /* cells i0 .. lo - 1: on the ring (i = 0) */
        int hi = inner_row ? imax(lo, imin(i1, g.core.x - 1)) : i1;  /* lo .. hi - 1 inner */
        for (int i = i0; i < lo; ++i)
            grid_cell(out, count, base, g, collapsed, i, j);
        if (out) {
            __global uint *cells = out + 3 * *count;
            uint first = base + ring + (uint)(j - 1) * inner + (uint)(lo - 1);  /* base + a of cell lo */
            for (int n = 0; n < hi - lo; ++n) {
                uint a = first + (uint)n, d = a + inner;
                cells[6 * n + 0] = a;      /* (a, b, c) */
                cells[6 * n + 1] = a + 1;
                cells[6 * n + 2] = d + 1;
                cells[6 * n + 3] = a;      /* (a, c, d) */
                cells[6 * n + 4] = d + 1;
                cells[6 * n + 5] = d;
            }
        }
        *count += 2 * (uint)(hi - lo);
        for (int i = hi; i < i1; ++i)  /* on the ring (i = A - 1), or a row on it (j = 0, B - 1) */
            grid_cell(out, count, base, g, collapsed, i, j);
    }
}

#define PATTERN_TRIANGLE_AT 1

/* pattern_triangle_at in two parts, so that stage 5 (stages/triangles.cl) makes the per-patch part
 * once per patch and not once per triangle: pattern_triangles_of, a patch's grid and the layout of
 * its kept slots (0 for a patch without random access); pattern_triangle_in, triangle t of it, and
 * pattern_triangle_pair, which also gives triangle t + 1 where it is the other half of t's cell.
 * With the row by a reciprocal and three corners a triangle: stage 5 of uniform level 16 on the
 * H200 0.133 -> 0.120 ms, 0.115 with a cell's two triangles a work-item (bench/RESULTS.md,
 * "Issue 15: stage 4's write-out and stage 5's instructions (session 10, branch gpu15i)"). */
typedef struct {
    int a, b;          /* the grid's steps A, B */
    uint c0, c1, c2, c3;  /* collapsed edges */
    uint first;        /* row 0's triangles */
    uint middle;       /* each of rows 1 .. B - 2's triangles */
    uint inner;        /* rows 1 .. B - 2's triangles together */
    float middle_rcp;  /* 1 / middle (the row by one multiplication: exact_quotient) */
} pattern_triangles;

inline int pattern_triangles_of(int4 f, int collapsed, __private pattern_triangles *g)
{
    pattern_grid grid = quad_grid(f);
    int a_steps = grid.core.x, b_steps = grid.core.y;
    g->a = a_steps;
    g->b = b_steps;
    g->c0 = collapsed & 1;
    g->c1 = (collapsed >> 1) & 1;
    g->c2 = (collapsed >> 2) & 1;
    g->c3 = (collapsed >> 3) & 1;
    g->middle = 2 * (uint)a_steps - g->c1 - g->c3;  /* a row that touches neither edge 0 nor edge 2 */
    g->first = (g->c0 ? 0 : (uint)a_steps - g->c1) + (b_steps == 1 && g->c2 ? 0 : (uint)a_steps - g->c3);
    g->inner = (uint)imax(b_steps - 2, 0) * g->middle;
    g->middle_rcp = g->middle ? 1.0f / (float)g->middle : 0.0f;
    return grid.uniform;
}

/* x / m for m > 0, exactly, by one float multiplication where x < 2^20: (float)x is exact, and
 * x * (1 / m) (even with a division of 2.5 ulp) is within 0.4 of x / m, so the truncated q is
 * x / m or one off, and the remainder's sign puts it right.  Larger x by the integer division. */
inline uint exact_quotient(uint x, uint m, float m_rcp)
{
    if (x >= (1u << 20))
        return x / m;
    uint q = (uint)((float)x * m_rcp);
    int r = (int)x - (int)(q * m);
    return r < 0 ? q - 1 : r >= (int)m ? q + 1 : q;
}

/* Triangle t; and *pairs: whether triangle t + 1 is the other half of t's cell (t its (a, b, c), a
 * row without a collapsed edge's gap after it: t + 1 is then (a, c, d)), with *d = d. */
inline uint3 pattern_triangle_pair(__private const pattern_triangles *g, uint t, __private int *pairs,
                                   __private uint *d)
{
    int j, plain = 0;
    uint k, x = t - g->first;
    if (t < g->first) {
        j = 0;
        k = t;
    } else if (x < g->inner) {
        uint q = exact_quotient(x, g->middle, g->middle_rcp);
        j = 1 + (int)q;
        k = x - q * g->middle;
    } else {
        j = g->b - 1;
        k = x - g->inner;
    }
    uint s;
    if (j == 0 && g->c0) {                  /* only (a, c, d) slots, less the first cell's on edge 3 */
        s = 2 * (k + g->c3) + 1;
    } else if (j == g->b - 1 && g->c2) {    /* only (a, b, c) slots, less the last cell's on edge 1 */
        s = 2 * k;
    } else {                                /* every slot but 1 (edge 3) and 2 (A - 1) (edge 1) */
        s = k + (g->c3 && k >= 1);
        s += g->c1 && s >= 2 * (uint)g->a - 2;
        plain = 1;
    }
    int i = (int)(s >> 1), h = (int)(s & 1);
    /* corners a = (i, j), c = (i + 1, j + 1), and b = (i + 1, j) for h = 0 or d = (i, j + 1) for h = 1 */
    uint a = uniform_index(g->a, g->b, i, j), c = uniform_index(g->a, g->b, i + 1, j + 1);
    uint o = uniform_index(g->a, g->b, i + 1 - h, j + h);
    *pairs = plain && !h && !(s == 0 && g->c3);  /* slot s + 1 kept: only slot 1 of the odd ones can go */
    *d = *pairs ? uniform_index(g->a, g->b, i, j + 1) : 0;
    return h ? (uint3)(a, c, o) : (uint3)(a, o, c);
}

inline uint3 pattern_triangle_in(__private const pattern_triangles *g, uint t)
{
    int pairs;
    uint d;
    return pattern_triangle_pair(g, t, &pairs, &d);
}

/* Triangle t of a patch whose triangles are the plain A x B grid (uniform factors): *triangle
 * its local vertex numbers, as grid_cells emits them (cells row by row, each (a, b, c) then
 * (a, c, d), less those grid_cells leaves out on collapsed edges).  In row j the triangle slots
 * are s = 2 i + h (h = 0: (a, b, c), 1: (a, c, d)); a collapsed edge 0 removes every h = 0 slot
 * of row 0, edge 2 every h = 1 slot of row B - 1, edge 1 slot 2 (A - 1) of every row and edge 3
 * slot 1; the k-th kept slot is found by stepping over the removed ones.  Returns 0 for any
 * other patch, whose triangles only pattern_primitives makes.  The corners' numbers by
 * uniform_grid_index (no "% ring"; the same numbers as grid_cell's): stage 5 of uniform level 16
 * on the H100 took 0.146 ms against 0.216 by pattern_grid_index (bench/RESULTS.md, "Issue 15:
 * stage 5's triangle math (session 8, branch gpu15f)").  Stage 5 a work-item per triangle
 * (stages/triangles.cl) uses the two parts; tests/test_triangle_at.py checks this against
 * grid_cells for every collapsed mask. */
inline int pattern_triangle_at(int4 f, int collapsed, uint t, __private uint3 *triangle)
{
    pattern_triangles g;
    if (!pattern_triangles_of(f, collapsed, &g))
        return 0;
    *triangle = pattern_triangle_in(&g, t);
    return 1;
}

/* The triangles, in "count" mode (out == 0) or "emit" mode (out != 0): one routine, so the counts
 * of stage 3 and the indices of stage 5 cannot disagree.  Returns the number of triangles;
 * vertex numbers are offset by base.  collapsed: bit e for a collapsed edge e (patch_factors),
 * whose points coincide: no triangle with a side on it. */
inline uint pattern_primitives(int4 f, int collapsed, __global uint *out, uint base)
{
    uint count = 0;
    if (f.s0 <= 0)
        return 0;
    pattern_grid g = quad_grid(f);
    int a = g.core.x, b = g.core.y;
    if (g.uniform) {
        grid_cells(out, &count, base, g, collapsed, 0, a, 0, b);
        return count;
    }
    grid_cells(out, &count, base, g, 0, 1, a - 1, 1, b - 1);
    /* Edge e's inner polyline runs counter-clockwise along the inner grid's boundary, its point k
     * at (k + 1) / along of the edge: segment midpoints at (2k + 3) / (2 along). */
    for (int e = 0; e < 4; ++e) {
        int along = (e % 2 == 0) ? a : b;
        stitch_row row;
        row.start = e == 0 ? (int2)(1, 1) : e == 1 ? (int2)(a - 1, 1) : e == 2 ? (int2)(a - 1, b - 1) : (int2)(1, b - 1);
        row.step = e == 0 ? (int2)(1, 0) : e == 1 ? (int2)(0, 1) : e == 2 ? (int2)(-1, 0) : (int2)(0, -1);
        row.first = 0;
        row.last = along - 2;
        row.along = along;
        row.lead = 3;
        stitch_strip(out, &count, base, g, e, row, (collapsed >> e) & 1);
    }
    return count;
}

#endif
