/* The semi-uniform pattern (Dyken, Reimers and Seland, "Semi-uniform adaptive patch
 * tessellation", CGF 2009, section 3), for the domain of PATTERN_EDGES (4: quad, 3: triangle),
 * which quad_semi_uniform.h / tri_semi_uniform.h define before including this.  NumPy mirror:
 * cltess/patterns/semi_uniform.py (same layout, same triangles in the same order).
 *
 * A patch at level m is the uniform pattern P^m on the n = 2^m lattice (a grid split along the
 * diagonals (i, j)-(i+1, j+1) for a quad, 4^m triangles for a triangle); the boundary points of
 * an edge whose level p_e is below m are snapped to the nearest p_e-dyadic point (eq. 1, applied
 * to the edge parameter alone, so the level-0 midpoint goes to the edge's end instead of the
 * paper's invalid (1, 1, 0)), and the triangles that collapse are dropped.  All in integers.
 *
 * Record: f = the dyadic edge factors 2^p_e (stage 1 rounds them, common.h dyadic_factors;
 * 0: culled; a triangle's f.s3 is 0), so ring point k of edge e is point k of f_e as for the
 * transition patterns, the crack-free max keeps them dyadic, and n = 2^m = max_e f_e.
 * Vertex layout (patterns/layout.h): the ring, then the interior lattice points (i, j) / n row
 * by row, rows j = 1 .., points i = 1 .. (quad: i < n; tri: i < n - j): the uniform transition
 * pattern's layout at factor n. */
#ifndef CLTESS_PATTERNS_SEMI_UNIFORM_H
#define CLTESS_PATTERNS_SEMI_UNIFORM_H
#include "common.h"

#if !defined(PATTERN_EDGES) || (PATTERN_EDGES != 3 && PATTERN_EDGES != 4)
#error "include patterns/quad_semi_uniform.h or patterns/tri_semi_uniform.h"
#endif

/* n = 2^m, the patch's lattice size: the largest edge factor (unused slots are 0). */
inline int su_size(int4 f) { return max(max(f.s0, f.s1), max(f.s2, f.s3)); }

/* --- the vertex layout ------------------------------------------------------------------------ */

/* Ring point k (0 <= k < f_e) of edge e: t = k / f_e, the p_e-dyadic points of the edge. */
inline edge_param pattern_ring_param(int4 f, int e, int k)
{
    edge_param t = {k, factor_of(f, e)};
    return t;
}

#if PATTERN_EDGES == 4
inline float3 pattern_edge_point(int e, edge_param t) { return quad_edge_point(e, t); }

inline int pattern_rows(int4 f) { return su_size(f) - 1; }

/* Row j runs along v = j / n from u = 0 to 1 in n steps: point i at (i / n, j / n). */
inline int pattern_row(int4 f, int j) { return su_size(f); }

inline float3 pattern_row_point(int4 f, int j, int i)
{
    float n = (float)su_size(f);
    return (float3)((float)i / n, (float)j / n, 0.0f);
}
#else
inline float3 pattern_edge_point(int e, edge_param t) { return tri_edge_point(e, t); }

inline int pattern_rows(int4 f) { return max(su_size(f) - 2, 0); }

/* Row j (v = j / n) runs from (0, v, 1-v) to (1-v, v, 0) in n - j steps. */
inline int pattern_row(int4 f, int j) { return su_size(f) - j; }

inline float3 pattern_row_point(int4 f, int j, int i)
{
    return tri_grid_point(su_size(f), j, i);
}
#endif

#include "patterns/layout.h"

/* --- the snap function (eq. 1) ---------------------------------------------------------------- */

/* sigma_p on the edge parameter t = a / n, as a lattice index: the nearest multiple of
 * d = n / 2^p, ties towards 0 when t < 1/2 and towards 1 otherwise: ceil((2a - d) / 2d) =
 * floor((2a + d - 1) / 2d) for t < 1/2, floor((2a + d) / 2d) otherwise; numerators >= 0. */
inline int su_snap(int a, int n, int d)
{
    return (2 * a + d - (2 * a < n ? 1 : 0)) / (2 * d) * d;
}

/* Local number of the point of edge e at edge parameter a / n, after the snap: ring point
 * snap / d of the edge (its end, a = n, is the next edge's point 0). */
inline uint su_ring_vertex(int4 f, int n, int e, int a)
{
    int d = n / factor_of(f, e);
    return ring_index(f, e, su_snap(a, n, d) / d);
}

/* Whether lattice point (i, j) lies strictly inside the domain: phi keeps it, and no collapsed
 * edge reaches it. */
inline int su_inside(int n, int i, int j)
{
#if PATTERN_EDGES == 4
    return i > 0 && j > 0 && i < n && j < n;
#else
    return i > 0 && j > 0 && i + j < n;
#endif
}

/* Local number of the interior lattice point (i, j), less the ring's size: the rows j = 1..,
 * points i = 1.. of the layout. */
inline uint su_interior_vertex(int n, int i, int j)
{
#if PATTERN_EDGES == 4
    return (uint)((j - 1) * (n - 1) + (i - 1));
#else
    return (uint)((j - 1) * (2 * n - 2 - j) / 2 + (i - 1));
#endif
}

/* Local number of phi(lattice point (i, j)): a boundary point through its edge's snap (corners
 * are kept by either edge), an interior point in its row. */
inline uint su_vertex(int4 f, int n, int i, int j)
{
    int ring = f.s0 + f.s1 + f.s2 + f.s3;
#if PATTERN_EDGES == 4
    if (j == 0) return su_ring_vertex(f, n, 0, i);
    if (i == n) return su_ring_vertex(f, n, 1, j);
    if (j == n) return su_ring_vertex(f, n, 2, n - i);
    if (i == 0) return su_ring_vertex(f, n, 3, n - j);
#else
    if (i + j == n) return su_ring_vertex(f, n, 0, j);
    if (i == 0) return su_ring_vertex(f, n, 1, n - j);
    if (j == 0) return su_ring_vertex(f, n, 2, i);
#endif
    return (uint)ring + su_interior_vertex(n, i, j);
}

/* --- the triangles ---------------------------------------------------------------------------- */

/* The triangles of P^m, cell by cell: cells (i, j) in rows j = 0 .. n-1, i = 0 .. su_cells(n, j)-1;
 * triangle t of a cell (su_cell_triangles of them) as lattice points, counter-clockwise (the
 * mirror's uniform_triangles, in its order). */
inline int su_cells(int n, int j) { return PATTERN_EDGES == 4 ? n : n - j; }

inline int su_cell_triangles(int n, int i, int j) { return PATTERN_EDGES == 4 ? 2 : 1 + (i + j < n - 1); }

inline void su_cell_triangle(int i, int j, int t, int2 c[3])
{
#if PATTERN_EDGES == 4
    c[0] = (int2)(i, j);
    c[1] = t ? (int2)(i + 1, j + 1) : (int2)(i + 1, j);
    c[2] = t ? (int2)(i, j + 1) : (int2)(i + 1, j + 1);
#else
    c[0] = (int2)(i + 1, j);
    c[1] = t ? (int2)(i + 1, j + 1) : (int2)(i, j + 1);
    c[2] = t ? (int2)(i, j + 1) : (int2)(i, j);
#endif
}

inline int su_triangle_inside(int n, int2 c[3])
{
    return su_inside(n, c[0].x, c[0].y) && su_inside(n, c[1].x, c[1].y) && su_inside(n, c[2].x, c[2].y);
}

/* Whether local vertex v is a point of ring edge e, its two corners included. */
inline int su_on_edge(int4 f, int e, uint v)
{
    int ring = f.s0 + f.s1 + f.s2 + f.s3;
    return v < (uint)ring && ((int)v - (int)ring_index(f, e, 0) + ring) % ring <= factor_of(f, e);
}

/* A band triangle is dropped when the snap collapsed it, or when one of its sides lies on a
 * collapsed edge (patch_factors: that edge's points coincide, issue 9 item 2). */
inline void su_put(__global uint *out, uint *count, uint base, int4 f, int collapsed, uint a, uint b, uint c)
{
    if (a == b || b == c || c == a)  /* collapsed by the snap */
        return;
    for (int e = 0; e < PATTERN_EDGES; ++e)
        if ((collapsed >> e & 1) && su_on_edge(f, e, a) + su_on_edge(f, e, b) + su_on_edge(f, e, c) >= 2)
            return;
    put_triangle(out, count, base, a, b, c);
}

/* The interior triangles of P^m (all three corners inside: phi leaves them, none is dropped),
 * in the cells' order: (n - 2)^2 cells of 2 (quad) or (n - 3)^2 triangles (tri, n >= 3).
 * stages/level_indices.cl level_interior reads the same list from the level's template
 * (cltess/patterns/semi_uniform.py interior_template). */
inline uint su_interior_count(int n)
{
    return PATTERN_EDGES == 4 ? (n > 2 ? 2 * (n - 2) * (n - 2) : 0) : (n > 3 ? (n - 3) * (n - 3) : 0);
}

inline void su_interior(int4 f, int n, __global uint *out, uint *count, uint base)
{
    uint ring = (uint)(f.s0 + f.s1 + f.s2 + f.s3);
    int2 c[3];
    for (int j = 1; j < n - 1; ++j)
        for (int i = 1; i < su_cells(n, j) - 1; ++i)
            for (int t = 0; t < su_cell_triangles(n, i, j); ++t) {
                su_cell_triangle(i, j, t, c);
                if (su_triangle_inside(n, c))
                    put_triangle(out, count, base, ring + su_interior_vertex(n, c[0].x, c[0].y),
                                 ring + su_interior_vertex(n, c[1].x, c[1].y),
                                 ring + su_interior_vertex(n, c[2].x, c[2].y));
            }
}

/* The band: the triangles with a corner on the boundary, where phi acts, in the cells' order
 * through phi, collapsed ones dropped.  Only the cells along the boundary are visited (rows 0
 * and n-1, and the first and last cells of the others), O(n) work; the tri's row j has band
 * cells 0, n-2-j (its second triangle) and n-1-j. */
inline void su_band(int4 f, int collapsed, int n, __global uint *out, uint *count, uint base)
{
    int2 c[3];
    for (int j = 0; j < n; ++j) {
        int cells = su_cells(n, j), last = PATTERN_EDGES == 4 ? cells - 1 : cells - 2;
        for (int i = 0; i < cells; i = (j == 0 || j == n - 1) ? i + 1 : max(i + 1, last))
            for (int t = 0; t < su_cell_triangles(n, i, j); ++t) {
                su_cell_triangle(i, j, t, c);
                if (!su_triangle_inside(n, c))
                    su_put(out, count, base, f, collapsed, su_vertex(f, n, c[0].x, c[0].y),
                           su_vertex(f, n, c[1].x, c[1].y), su_vertex(f, n, c[2].x, c[2].y));
            }
    }
}

/* The triangles of P^m through phi, counter-clockwise, in "count" mode (out == 0) or "emit"
 * mode: one routine for stages 3 and 5.  The interior triangles first, then the band's, so that
 * the triangles by level (stages/level_indices.cl) land where these do: 2 n^2 (quad) or n^2
 * (tri) less one per boundary point snapped away (n - f_e per edge: each is an edge collapse),
 * less those on collapsed edges (bit e of collapsed). */
inline uint pattern_primitives(int4 f, int collapsed, __global uint *out, uint base)
{
    uint count = 0;
    if (f.s0 <= 0)
        return 0;
    int n = su_size(f);
    su_interior(f, n, out, &count, base);
    su_band(f, collapsed, n, out, &count, base);
    return count;
}

/* The band's triangles of a patch in emit mode, placed after its interior ones (the second half
 * of pattern_primitives): stages/level_indices.cl level_band. */
inline void pattern_band_primitives(int4 f, int collapsed, __global uint *out, uint base)
{
    int n = su_size(f);
    uint count = su_interior_count(n);
    su_band(f, collapsed, n, out, &count, base);
}

/* --- the templates: P^m's points and interior triangles, for evaluation by level ---------------- */

/* The paper's section 4.2 draws each level's patches as instances of one template; here
 * stages/level_vertices.cl runs one work-item per (patch of level m, template point) and
 * stages/level_indices.cl one per (patch, interior template triangle) and one per patch for the
 * band.  The templates are built on the host (cltess/patterns/semi_uniform.py point_template,
 * interior_template): template point t is lattice point (i, j) of P^m, row by row, (n+1)^2
 * (quad) or (n+1)(n+2)/2 (triangle) of them. */
inline int pattern_template_size(int level)
{
    int n = 1 << level;
    return PATTERN_EDGES == 4 ? (n + 1) * (n + 1) : (n + 1) * (n + 2) / 2;
}

/* Where the lattice point (i, j) of a patch with record f (n = 2^level = su_size(f)) goes in the
 * vertex layout: vertex < 0 when the snap removes it (a boundary point of an edge below the
 * level); else its local vertex number, and either the ring point k of edge e (edge >= 0; each
 * edge owns its points a = 0 .. n-1, the end being the next edge's point 0, as
 * stages/vertices.cl writes them), or the interior point (i, j) (edge = -1, at
 * pattern_row_point(f, j, i)). */
typedef struct {
    int vertex;
    int edge;
    int k;
} template_point;

inline template_point pattern_template_point(int4 f, int level, int i, int j)
{
    int n = 1 << level, e = -1, a = 0;
#if PATTERN_EDGES == 4
    if (j == 0 && i < n) { e = 0; a = i; }
    else if (i == n && j < n) { e = 1; a = j; }
    else if (j == n && i > 0) { e = 2; a = n - i; }
    else if (i == 0 && j > 0) { e = 3; a = n - j; }
#else
    if (i + j == n && j < n) { e = 0; a = j; }
    else if (i == 0 && j > 0) { e = 1; a = n - j; }
    else if (j == 0 && i < n) { e = 2; a = i; }
#endif
    template_point point = {e >= 0 ? 0 : (int)(f.s0 + f.s1 + f.s2 + f.s3) + (int)su_interior_vertex(n, i, j), e, 0};
    if (e >= 0) {
        int d = n / factor_of(f, e);  /* the edge's own points: multiples of d */
        point.k = a / d;
        point.vertex = a % d ? -1 : (int)ring_index(f, e, a / d);
    }
    return point;
}

#endif
