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

/* Row j (v = j / n) runs from (0, v, 1-v) to (1-v, v, 0) in n - j steps: point i at
 * (i / n, j / n, (n - i - j) / n). */
inline int pattern_row(int4 f, int j) { return su_size(f) - j; }

inline float3 pattern_row_point(int4 f, int j, int i)
{
    int n = su_size(f);
    return (float3)((float)i / (float)n, (float)j / (float)n, (float)(n - i - j) / (float)n);
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
    return (uint)(ring + (j - 1) * (n - 1) + (i - 1));
#else
    if (i + j == n) return su_ring_vertex(f, n, 0, j);
    if (i == 0) return su_ring_vertex(f, n, 1, n - j);
    if (j == 0) return su_ring_vertex(f, n, 2, i);
    return (uint)(ring + (j - 1) * (2 * n - 2 - j) / 2 + (i - 1));
#endif
}

/* --- the triangles ---------------------------------------------------------------------------- */

/* Whether local vertex v is a point of ring edge e, its two corners included. */
inline int su_on_edge(int4 f, int e, uint v)
{
    int ring = f.s0 + f.s1 + f.s2 + f.s3;
    return v < (uint)ring && ((int)v - (int)ring_index(f, e, 0) + ring) % ring <= factor_of(f, e);
}

/* A triangle is dropped when the snap collapsed it, or when one of its sides lies on a
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

/* The triangles of P^m through phi, collapsed ones dropped, counter-clockwise, in "count" mode
 * (out == 0) or "emit" mode: one routine for stages 3 and 5.  2 n^2 (quad) or n^2 (tri) less
 * one per boundary point snapped away (n - f_e per edge: each is an edge collapse), less those
 * on collapsed edges (bit e of collapsed). */
inline uint pattern_primitives(int4 f, int collapsed, __global uint *out, uint base)
{
    uint count = 0;
    if (f.s0 <= 0)
        return 0;
    int n = su_size(f);
    for (int j = 0; j < n; ++j)
#if PATTERN_EDGES == 4
        for (int i = 0; i < n; ++i) {
            uint a = su_vertex(f, n, i, j), b = su_vertex(f, n, i + 1, j);
            uint c = su_vertex(f, n, i + 1, j + 1), d = su_vertex(f, n, i, j + 1);
            su_put(out, &count, base, f, collapsed, a, b, c);
            su_put(out, &count, base, f, collapsed, a, c, d);
        }
#else
        for (int i = 0; i < n - j; ++i) {
            uint a = su_vertex(f, n, i + 1, j), b = su_vertex(f, n, i, j + 1);
            su_put(out, &count, base, f, collapsed, a, b, su_vertex(f, n, i, j));
            if (i + j < n - 1)
                su_put(out, &count, base, f, collapsed, a, su_vertex(f, n, i + 1, j + 1), b);
        }
#endif
    return count;
}

/* --- the template: P^m's lattice points, for evaluation by level ------------------------------ */

/* The paper's section 4.2 draws each level's patches as instances of one template, P^m's
 * vertices; stages/level_vertices.cl runs one work-item per (patch of level m, template point).
 * Template point t is lattice point (i, j), row by row: (n+1)^2 (quad) or (n+1)(n+2)/2
 * (triangle) of them. */
inline int pattern_template_size(int level)
{
    int n = 1 << level;
    return PATTERN_EDGES == 4 ? (n + 1) * (n + 1) : (n + 1) * (n + 2) / 2;
}

/* Where template point t of a patch with record f (n = 2^level = su_size(f)) goes in the vertex
 * layout: vertex < 0 when the snap removes it (a boundary point of an edge below the level);
 * else its local vertex number, and either the ring point k of edge e (edge >= 0; each edge owns
 * its points a = 0 .. n-1, the end being the next edge's point 0, as stages/vertices.cl writes
 * them), or the interior point (i, j) (edge = -1, at pattern_row_point(f, j, i)). */
typedef struct {
    int vertex;
    int edge;
    int k;
    int i;
    int j;
} template_point;

inline template_point pattern_template_point(int4 f, int level, int t)
{
    int n = 1 << level, i, j = 0, e = -1, a = 0;
#if PATTERN_EDGES == 4
    i = t % (n + 1);
    j = t / (n + 1);
    if (j == 0 && i < n) { e = 0; a = i; }
    else if (i == n && j < n) { e = 1; a = j; }
    else if (j == n && i > 0) { e = 2; a = n - i; }
    else if (i == 0 && j > 0) { e = 3; a = n - j; }
    int interior = (int)(f.s0 + f.s1 + f.s2 + f.s3) + (j - 1) * (n - 1) + (i - 1);
#else
    while (t > n - j) {  /* row j has n + 1 - j points */
        t -= n + 1 - j;
        ++j;
    }
    i = t;
    if (i + j == n && j < n) { e = 0; a = j; }
    else if (i == 0 && j > 0) { e = 1; a = n - j; }
    else if (j == 0 && i < n) { e = 2; a = i; }
    int interior = (int)(f.s0 + f.s1 + f.s2) + (j - 1) * (2 * n - 2 - j) / 2 + (i - 1);
#endif
    template_point point = {interior, e, 0, i, j};
    if (e >= 0) {
        int d = n / factor_of(f, e);  /* the edge's own points: multiples of d */
        point.k = a / d;
        point.vertex = a % d ? -1 : (int)ring_index(f, e, a / d);
    }
    return point;
}

#endif
