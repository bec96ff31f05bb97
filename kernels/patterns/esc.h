/* ESC (Hu et al., GRAPP 2014, section 3): the pattern of a bicubic patch from its candidate masks
 * alone, so stage 3 counts what stage 5 emits before any vertex exists.  Mirror and the record's
 * layout: cltess/patterns/esc.py; decisions: docs/esc.md.
 *
 * Lattice: n = L + 1 steps per coarse edge, m = 3 n per patch side, points (x, y), uv = (x, y) / m.
 * Coarse edges (canonical directions +u, +v, (0,0)->(1,1)): horizontal 3 J + I, vertical
 * 12 + 3 I + J, diagonal 24 + 3 J + I; a mask of L bits each (bit k-1: candidate k / n). */
#ifndef CLTESS_PATTERNS_ESC_H
#define CLTESS_PATTERNS_ESC_H
#include "common.h"

#define PATTERN_EDGES 4
#define PATTERN_EDGE_POINTS(f, e) esc_ring_count(f, e)  /* the record is masks, not counts (patterns/layout.h) */
#define PATTERN_UNIFORM_ROWS 0  /* rows are the inserted points only: evaluated directly (stages/vertices.cl) */

/* The record (cltess/patterns/esc.py; tests/contracts/test_constants.py checks them equal). */
#define ESC_BOUNDARY_BITS 0x1FF
#define ESC_REVERSED (1 << 9)
#define ESC_INTERIOR_SHIFT 10
#define ESC_INTERIOR_BITS 16
#define ESC_LEVEL_SHIFT 26
#define ESC_ALIVE (1 << 28)
#define ESC_MAX_LEVEL 3

#define ESC_H(i, j) (3 * (j) + (i))
#define ESC_V(i, j) (12 + 3 * (i) + (j))
#define ESC_D(i, j) (24 + 3 * (j) + (i))

inline uint esc_reverse_bits(uint mask, int count)
{
    uint out = 0;
    for (int k = 0; k < count; ++k)
        out |= ((mask >> k) & 1u) << (count - 1 - k);
    return out;
}

inline int esc_level(int4 f) { return (f.s0 >> ESC_LEVEL_SHIFT) & 3; }

/* Coarse edge c of patch edge e's segment s (counter-clockwise), and whether counter-clockwise
 * runs against c's canonical direction (esc.py PATCH_EDGE_COARSE, PATCH_EDGE_AGAINST). */
inline int esc_boundary_coarse(int e, int s)
{
    return e == 0 ? ESC_H(s, 0) : e == 1 ? ESC_V(3, s) : e == 2 ? ESC_H(2 - s, 3) : ESC_V(0, 2 - s);
}

/* The 33 masks (canonical directions) of a record. */
inline void esc_decode(int4 f, __private uint masks[33])
{
    int level = esc_level(f);
    uint full = (1u << level) - 1u;
    ulong interior = 0;
    for (int e = 0; e < 4; ++e)
        interior |= (ulong)(((uint)factor_of(f, e) >> ESC_INTERIOR_SHIFT) & ((1u << ESC_INTERIOR_BITS) - 1u))
                    << (ESC_INTERIOR_BITS * e);
    int k = 0;
    for (int c = 0; c < 33; ++c) {
        int boundary = (c < 3) || (c >= 9 && c < 12) || (c >= 12 && c < 15) || (c >= 21 && c < 24);
        if (!boundary) {
            masks[c] = (uint)(interior >> (k * level)) & full;
            ++k;
        }
    }
    for (int e = 0; e < 4; ++e) {
        uint slot = (uint)factor_of(f, e);
        uint bits = slot & ESC_BOUNDARY_BITS & ((1u << (3 * level)) - 1u);
        uint ccw = (slot & ESC_REVERSED) ? esc_reverse_bits(bits, 3 * level) : bits;
        for (int s = 0; s < 3; ++s) {
            uint mask = (ccw >> (s * level)) & full;
            masks[esc_boundary_coarse(e, s)] = e >= 2 ? esc_reverse_bits(mask, level) : mask;
        }
    }
}

/* Is lattice point (x, y) inserted?  Coarse corners always; a point on a coarse edge by its bit;
 * a point inside a coarse triangle when its row's left or right end is (rows parallel to the
 * diagonal base; esc.py coarse_triangle). */
inline int esc_present(__private const uint masks[33], int n, int x, int y)
{
    int i = min(x / n, 2), a = x - n * i, j = min(y / n, 2), b = y - n * j;
    if (a == n) { ++i; a = 0; }  /* the last lattice line belongs to coarse corner 3 */
    if (b == n) { ++j; b = 0; }
    if (a == 0 && b == 0)
        return 1;
    if (b == 0)
        return (masks[ESC_H(i, j)] >> (a - 1)) & 1u;
    if (a == 0)
        return (masks[ESC_V(i, j)] >> (b - 1)) & 1u;
    if (a == b)
        return (masks[ESC_D(i, j)] >> (a - 1)) & 1u;
    if (a > b) {  /* the lower triangle, apex (i+1, j): row r = n - (a - b) */
        int r = n - (a - b);
        return ((masks[ESC_V(i + 1, j)] >> (r - 1)) | (masks[ESC_H(i, j)] >> (n - r - 1))) & 1u;
    }
    int r = n - (b - a);  /* the upper triangle, apex (i, j+1) */
    return ((masks[ESC_V(i, j)] >> (n - r - 1)) | (masks[ESC_H(i, j + 1)] >> (r - 1))) & 1u;
}

/* Lattice point k of patch edge e, counter-clockwise from its first corner. */
inline int2 esc_edge_lattice(int e, int k, int m)
{
    return e == 0 ? (int2)(k, 0) : e == 1 ? (int2)(m, k) : e == 2 ? (int2)(m - k, m) : (int2)(0, m - k);
}

inline int esc_count_edge(__private const uint masks[33], int n, int e)
{
    int count = 0;
    for (int k = 0; k < 3 * n; ++k) {
        int2 p = esc_edge_lattice(e, k, 3 * n);
        count += esc_present(masks, n, p.x, p.y);
    }
    return count;
}

inline int esc_count_row(__private const uint masks[33], int n, int y)
{
    int count = 0;
    for (int x = 1; x < 3 * n; ++x)
        count += esc_present(masks, n, x, y);
    return count;
}

/* --- the vertex layout (docs/extending.md; patterns/layout.h) -------------------------------- */

inline int esc_ring_count(int4 f, int e)
{
    uint masks[33];
    esc_decode(f, masks);
    return esc_count_edge(masks, esc_level(f) + 1, e);
}

inline edge_param pattern_ring_param(int4 f, int e, int k)
{
    uint masks[33];
    esc_decode(f, masks);
    int n = esc_level(f) + 1, m = 3 * n, seen = -1, at = 0;
    for (; at < m; ++at) {
        int2 p = esc_edge_lattice(e, at, m);
        seen += esc_present(masks, n, p.x, p.y);
        if (seen == k)
            break;
    }
    edge_param t = {at, m};
    return t;
}

inline float3 pattern_edge_point(int e, edge_param t) { return quad_edge_point(e, t); }

/* Rows: the lattice rows y = 1 .. m-1; row y's points i = 1 .. steps-1 are its inserted interior
 * points left to right (steps = their count + 1); its ends (0, y) and (1, y). */
inline int pattern_rows(int4 f) { return 3 * (esc_level(f) + 1) - 1; }

inline int pattern_row(int4 f, int j)
{
    uint masks[33];
    esc_decode(f, masks);
    return esc_count_row(masks, esc_level(f) + 1, j) + 1;
}

inline float3 pattern_row_point(int4 f, int j, int i)
{
    int n = esc_level(f) + 1, m = 3 * n, x = 0;
    if (i > 0) {
        uint masks[33];
        esc_decode(f, masks);
        int seen = 0;
        for (x = 1; x < m; ++x) {
            seen += esc_present(masks, n, x, j);
            if (seen == i)
                break;
        }
    }
    return (float3)((float)x / (float)m, (float)j / (float)m, 0.0f);
}

#include "patterns/layout.h"

/* --- the primitives ------------------------------------------------------------------------- */

typedef struct {
    uint masks[33];
    int n, m, ring[5];   /* ring[e]: local number of edge e's first point; ring[4] = the ring */
    int rows[13];        /* rows[y]: local number of row y's first interior point (y = 1 .. m-1) */
    int collapsed;
} esc_patch;

/* Local vertex number of lattice point p (inserted), a collapsed edge's points as its first
 * corner (esc.py patch_mesh remap, in its order). */
inline uint esc_index(__private const esc_patch *g, int2 p)
{
    int m = g->m;
    for (int e = 0; e < 4; ++e) {  /* a collapsed edge's points, both corners included */
        int on = e == 0 ? p.y == 0 : e == 1 ? p.x == m : e == 2 ? p.y == m : p.x == 0;
        if (on && ((g->collapsed >> e) & 1))
            return (uint)g->ring[e];
    }
    for (int e = 0; e < 4; ++e) {
        int k = e == 0 ? (p.y == 0 ? p.x : -1) : e == 1 ? (p.x == m ? p.y : -1)
              : e == 2 ? (p.y == m ? m - p.x : -1) : (p.x == 0 ? m - p.y : -1);
        if (k < 0 || k >= m)
            continue;  /* not on edge e, or its last corner (edge e+1's first) */
        int rank = 0;
        for (int q = 0; q < k; ++q) {
            int2 r = esc_edge_lattice(e, q, m);
            rank += esc_present(g->masks, g->n, r.x, r.y);
        }
        return (uint)(g->ring[e] + rank);
    }
    int rank = 0;
    for (int x = 1; x < p.x; ++x)
        rank += esc_present(g->masks, g->n, x, p.y);
    return (uint)(g->rows[p.y] + rank);
}

/* Coarse triangle t (0..17: cell (i, j) = (t/2 % 3, t/6), lower then upper): apex, B0, B1 in
 * coarse units and its left (A->B0), right (A->B1) and base (B0->B1) masks, counter-clockwise
 * order (esc.py COARSE_TRIANGLES). */
inline void esc_coarse(__private const esc_patch *g, int t, __private int2 corner[3], __private uint bits[3])
{
    int cell = t / 2, i = cell % 3, j = cell / 3, level = g->n - 1;
    if ((t & 1) == 0) {
        corner[0] = (int2)(i + 1, j);
        corner[1] = (int2)(i + 1, j + 1);
        corner[2] = (int2)(i, j);
        bits[0] = g->masks[ESC_V(i + 1, j)];
        bits[1] = esc_reverse_bits(g->masks[ESC_H(i, j)], level);
        bits[2] = esc_reverse_bits(g->masks[ESC_D(i, j)], level);
    } else {
        corner[0] = (int2)(i, j + 1);
        corner[1] = (int2)(i, j);
        corner[2] = (int2)(i + 1, j + 1);
        bits[0] = esc_reverse_bits(g->masks[ESC_V(i, j)], level);
        bits[1] = g->masks[ESC_H(i, j + 1)];
        bits[2] = g->masks[ESC_D(i, j)];
    }
}

/* The next inserted row below row r on an edge of mask `bits` (the base corner at n): the
 * virtual vertex of a missing end (rule 1). */
inline int esc_next_row(uint bits, int r, int n)
{
    for (int q = r + 1; q < n; ++q)
        if ((bits >> (q - 1)) & 1u)
            return q;
    return n;
}

/* Chain of row r, point k counted from the right end (esc.py coarse_triangle chain, reversed):
 * (row, column) of the coarse triangle's lattice. */
inline int esc_chain_length(__private const uint bits[3], int r, int n)
{
    return r == 0 ? 1 : r == n ? 2 + popcount(bits[2]) : r + 1;
}

inline int2 esc_chain_point(__private const uint bits[3], int r, int k, int n)
{
    int length = esc_chain_length(bits, r, n), left = length - 1 - k;  /* from the left end */
    if (r == 0)
        return (int2)(0, 0);
    if (r == n) {
        if (left == 0)
            return (int2)(n, 0);
        int seen = 0;
        for (int i = 1; i < n; ++i)
            if ((bits[2] >> (i - 1)) & 1u)
                if (++seen == left)
                    return (int2)(n, i);
        return (int2)(n, n);
    }
    if (left == 0)
        return (bits[0] >> (r - 1)) & 1u ? (int2)(r, 0) : (int2)(esc_next_row(bits[0], r, n), 0);
    if (left == r) {
        int q = (bits[1] >> (r - 1)) & 1u ? r : esc_next_row(bits[1], r, n);
        return (int2)(q, q);
    }
    return (int2)(r, left);
}

/* Patch lattice point of coarse-triangle point (row, column). */
inline int2 esc_lattice(__private const int2 corner[3], int n, int2 p)
{
    return n * corner[0] + (p.x - p.y) * (corner[1] - corner[0]) + p.y * (corner[2] - corner[0]);
}

inline uint esc_triangle(__private const esc_patch *g, __private const int2 corner[3], int2 a, int2 b, int2 c,
                         __global uint *out, uint *count, uint base)
{
    if ((a.x == b.x && a.y == b.y) || (b.x == c.x && b.y == c.y) || (a.x == c.x && a.y == c.y))
        return 0;
    uint ia = esc_index(g, esc_lattice(corner, g->n, a)), ib = esc_index(g, esc_lattice(corner, g->n, b));
    uint ic = esc_index(g, esc_lattice(corner, g->n, c));
    if (ia == ib || ib == ic || ia == ic)
        return 0;  /* a side on a collapsed edge */
    put_triangle(out, count, base, ia, ib, ic);
    return 1;
}

/* The zipper of esc.py coarse_triangle over the bands between consecutive active rows. */
inline void esc_coarse_triangle(__private const esc_patch *g, int t, __global uint *out, uint *count, uint base)
{
    int2 corner[3];
    uint bits[3];
    esc_coarse(g, t, corner, bits);
    int n = g->n, a = 0;
    for (int b = 1; b <= n; ++b) {
        if (b < n && !(((bits[0] | bits[1]) >> (b - 1)) & 1u))
            continue;  /* an inactive row: its band merges with the next */
        int upper_length = esc_chain_length(bits, a, n), lower_length = esc_chain_length(bits, b, n);
        int u = esc_chain_point(bits, a, 0, n).x != a ? 1 : 0, w = 0;
        while (u < upper_length - 1 || w < lower_length - 1) {
            int advance_upper;
            int2 next_upper = esc_chain_point(bits, a, min(u + 1, upper_length - 1), n);
            int2 next_lower = esc_chain_point(bits, b, min(w + 1, lower_length - 1), n);
            if (w == lower_length - 1) {
                advance_upper = 1;
            } else if (u == upper_length - 1) {
                advance_upper = 0;
            } else {
                int along_upper = (next_upper.x - next_upper.y) * next_lower.x;  /* (j - i)/j compared */
                int along_lower = (next_lower.x - next_lower.y) * next_upper.x;
                advance_upper = along_upper != along_lower ? along_upper < along_lower : next_upper.x < next_lower.x;
            }
            int2 lower_point = esc_chain_point(bits, b, w, n), upper_point = esc_chain_point(bits, a, u, n);
            if (advance_upper) {
                esc_triangle(g, corner, lower_point, upper_point, next_upper, out, count, base);
                ++u;
            } else {
                esc_triangle(g, corner, lower_point, upper_point, next_lower, out, count, base);
                ++w;
            }
        }
        a = b;
    }
}

inline void esc_setup(int4 f, int collapsed, __private esc_patch *g)
{
    esc_decode(f, g->masks);
    g->n = esc_level(f) + 1;
    g->m = 3 * g->n;
    g->collapsed = collapsed;
    g->ring[0] = 0;
    for (int e = 0; e < 4; ++e)
        g->ring[e + 1] = g->ring[e] + esc_count_edge(g->masks, g->n, e);
    int at = g->ring[4];
    for (int y = 1; y < g->m; ++y) {
        g->rows[y] = at;
        at += esc_count_row(g->masks, g->n, y);
    }
}

inline uint pattern_primitives(int4 f, int collapsed, __global uint *out, uint base)
{
    if (f.s0 <= 0)
        return 0;
    esc_patch g;
    esc_setup(f, collapsed, &g);
    uint count = 0;
    for (int t = 0; t < 18; ++t)
        esc_coarse_triangle(&g, t, out, &count, base);
    return count;
}

#endif
