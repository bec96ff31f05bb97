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
/* generated: cltess/patterns/esc.py count_table_header (no comment on an #include line: pyopencl's
 * binary cache looks for the headers a program depends on only in plain #include lines) */
#include "patterns/esc_counts.h"

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

/* Coarse edge c's end corners (I, J) in its canonical direction (esc.py COARSE_EDGES). */
inline void esc_coarse_ends(int c, __private int2 *start, __private int2 *end)
{
    if (c < 12) {
        *start = (int2)(c % 3, c / 3);
        *end = *start + (int2)(1, 0);
    } else if (c < 24) {
        *start = (int2)((c - 12) / 3, (c - 12) % 3);
        *end = *start + (int2)(0, 1);
    } else {
        *start = (int2)((c - 24) % 3, (c - 24) / 3);
        *end = *start + (int2)(1, 1);
    }
}

/* Coarse edge number of segment s (counter-clockwise) of patch edge e (esc.py PATCH_EDGE_COARSE). */
inline int esc_boundary_coarse(int e, int s) { return e == 0 ? s : e == 1 ? 21 + s : e == 2 ? 11 - s : 14 - s; }

/* Is corner p on a pole, a patch edge of bit e in `poles`? */
inline int esc_on_pole(int2 p, int poles, int e)
{
    return (poles >> e) & 1 && (e == 0 ? p.y == 0 : e == 1 ? p.x == 3 : e == 2 ? p.y == 3 : p.x == 0);
}

/* The pole rule (esc.py pole_edges; docs/esc.md): does coarse edge c run into a pole (an end on
 * it, not lying on it)?  Stage 1 inserts all its candidates. */
inline int esc_pole_edge(int c, int poles)
{
    int2 start, end;
    esc_coarse_ends(c, &start, &end);
    int touches = 0, lies = 0;
    for (int e = 0; e < 4; ++e) {
        int a = esc_on_pole(start, poles, e), b = esc_on_pole(end, poles, e);
        touches |= a | b;
        lies |= a & b;
    }
    return touches && !lies;
}

inline uint esc_reverse_bits(uint mask, int count)
{
    uint out = 0;
    for (int k = 0; k < count; ++k)
        out |= ((mask >> k) & 1u) << (count - 1 - k);
    return out;
}

inline int esc_level(int4 f) { return (f.s0 >> ESC_LEVEL_SHIFT) & 3; }

/* Where coarse edge c's mask lives in the record: its number among the interior edges (bits
 * k L .. of the 64 interior bits), or -1 on the boundary; there patch edge e = ESC_EDGE_OF[c],
 * segment s = ESC_SEGMENT_OF[c] counter-clockwise (esc.py INTERIOR_EDGES, PATCH_EDGE_COARSE). */
__constant int ESC_INTERIOR_INDEX[33] = {-1, -1, -1, 0, 1, 2, 3, 4, 5, -1, -1, -1, -1, -1, -1, 6, 7, 8,
                                         9, 10, 11, -1, -1, -1, 12, 13, 14, 15, 16, 17, 18, 19, 20};
__constant int ESC_EDGE_OF[33] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 2, 2, 3, 3, 3, 0, 0, 0,
                                  0, 0, 0, 1, 1, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0};
__constant int ESC_SEGMENT_OF[33] = {0, 1, 2, 0, 0, 0, 0, 0, 0, 2, 1, 0, 2, 1, 0, 0, 0, 0,
                                     0, 0, 0, 0, 1, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0};

/* A record read once: its slots, the 64 interior bits, the level. */
typedef struct {
    int4 f;
    ulong interior;
    int level, n, m;
} esc_record;

inline esc_record esc_read(int4 f)
{
    esc_record r;
    r.f = f;
    r.level = esc_level(f);
    r.n = r.level + 1;
    r.m = 3 * r.n;
    r.interior = 0;
    for (int e = 0; e < 4; ++e)
        r.interior |= (ulong)(((uint)factor_of(f, e) >> ESC_INTERIOR_SHIFT) & ((1u << ESC_INTERIOR_BITS) - 1u))
                      << (ESC_INTERIOR_BITS * e);
    return r;
}

/* The L-bit mask of coarse edge c, in its canonical direction. */
inline uint esc_mask(__private const esc_record *r, int c)
{
    int level = r->level;
    uint full = (1u << level) - 1u;
    int k = ESC_INTERIOR_INDEX[c];
    if (k >= 0)
        return (uint)(r->interior >> (k * level)) & full;
    int e = ESC_EDGE_OF[c], s = ESC_SEGMENT_OF[c];
    uint slot = (uint)factor_of(r->f, e);
    int reversed = (slot & ESC_REVERSED) != 0;  /* stored in the curve's direction, not counter-clockwise */
    uint mask = (slot >> ((reversed ? 2 - s : s) * level)) & full;
    return reversed != (e >= 2) ? esc_reverse_bits(mask, level) : mask;  /* edges 2, 3 run against +u, +v */
}

/* Is lattice point (x, y) inserted?  Coarse corners always; a point on a coarse edge by its bit;
 * a point inside a coarse triangle when its row's left or right end is (rows parallel to the
 * diagonal base; esc.py coarse_triangle). */
inline int esc_present(__private const esc_record *r, int x, int y)
{
    int n = r->n;
    int i = min(x / n, 2), a = x - n * i, j = min(y / n, 2), b = y - n * j;
    if (a == n) { ++i; a = 0; }  /* the last lattice line belongs to coarse corner 3 */
    if (b == n) { ++j; b = 0; }
    if (a == 0 && b == 0)
        return 1;
    if (b == 0)
        return (esc_mask(r, ESC_H(i, j)) >> (a - 1)) & 1u;
    if (a == 0)
        return (esc_mask(r, ESC_V(i, j)) >> (b - 1)) & 1u;
    if (a == b)
        return (esc_mask(r, ESC_D(i, j)) >> (a - 1)) & 1u;
    if (a > b) {  /* the lower triangle, apex (i+1, j): row q = n - (a - b) */
        int q = n - (a - b);
        return ((esc_mask(r, ESC_V(i + 1, j)) >> (q - 1)) | (esc_mask(r, ESC_H(i, j)) >> (n - q - 1))) & 1u;
    }
    int q = n - (b - a);  /* the upper triangle, apex (i, j+1) */
    return ((esc_mask(r, ESC_V(i, j)) >> (n - q - 1)) | (esc_mask(r, ESC_H(i, j + 1)) >> (q - 1))) & 1u;
}

/* Lattice point k of patch edge e, counter-clockwise from its first corner. */
inline int2 esc_edge_lattice(int e, int k, int m)
{
    return e == 0 ? (int2)(k, 0) : e == 1 ? (int2)(m, k) : e == 2 ? (int2)(m - k, m) : (int2)(0, m - k);
}

/* Bit t: point t (0 .. m) of the lattice line along +u (y = index n) or +v (x = index n) is
 * inserted: its coarse corners and its 3 coarse edges' candidates. */
inline uint esc_line_bits(__private const esc_record *r, int vertical, int index)
{
    int n = r->n;
    uint bits = 1u << r->m;
    for (int s = 0; s < 3; ++s)
        bits |= (1u << (s * n)) | (esc_mask(r, vertical ? ESC_V(index, s) : ESC_H(s, index)) << (s * n + 1));
    return bits;
}

/* Bit k: point k of patch edge e (k = 0 .. m-1, counter-clockwise) is inserted. */
inline uint esc_edge_bits(__private const esc_record *r, int e)
{
    uint line = esc_line_bits(r, e & 1, e == 0 ? 0 : e == 1 ? 3 : e == 2 ? 3 : 0);
    return (e >= 2 ? esc_reverse_bits(line, r->m + 1) : line) & ((1u << r->m) - 1u);
}

/* Bit x: interior point (x, y) is inserted (x = 1 .. m-1, y = 1 .. m-1): esc_present row-wise. */
inline uint esc_row_bits(__private const esc_record *r, int y)
{
    int n = r->n, j = y / n, b = y - n * j;
    uint bits = 0;
    if (b == 0) {
        bits = esc_line_bits(r, 0, j);
    } else {
        for (int i = 0; i < 3; ++i) {
            uint v = esc_mask(r, ESC_V(i, j)), v1 = esc_mask(r, ESC_V(i + 1, j)), d = esc_mask(r, ESC_D(i, j));
            uint h = esc_mask(r, ESC_H(i, j)), h1 = esc_mask(r, ESC_H(i, j + 1));
            int x0 = i * n;
            bits |= ((v >> (b - 1)) & 1u) << x0 | ((d >> (b - 1)) & 1u) << (x0 + b);
            for (int a = 1; a < b; ++a)  /* the upper triangle */
                bits |= (((v >> (b - a - 1)) | (h1 >> (n - b + a - 1))) & 1u) << (x0 + a);
            for (int a = b + 1; a < n; ++a)  /* the lower triangle */
                bits |= (((v1 >> (n - a + b - 1)) | (h >> (a - b - 1))) & 1u) << (x0 + a);
        }
    }
    return bits & ((1u << r->m) - 2u);
}

/* The position of the k-th set bit of bits (k from 0); 32 if none. */
inline int esc_nth_bit(uint bits, int k)
{
    for (int at = 0; at < 32; ++at)
        if ((bits >> at) & 1u)
            if (k-- == 0)
                return at;
    return 32;
}

/* --- the vertex layout (docs/extending.md; patterns/layout.h) -------------------------------- */

inline int esc_ring_count(int4 f, int e)
{
    esc_record r = esc_read(f);
    return popcount(esc_edge_bits(&r, e));
}

inline edge_param pattern_ring_param(int4 f, int e, int k)
{
    esc_record r = esc_read(f);
    edge_param t = {esc_nth_bit(esc_edge_bits(&r, e), k), r.m};
    return t;
}

inline float3 pattern_edge_point(int e, edge_param t) { return quad_edge_point(e, t); }

/* Rows: the lattice rows y = 1 .. m-1; row y's points i = 1 .. steps-1 are its inserted interior
 * points left to right (steps = their count + 1); its ends (0, y) and (1, y). */
inline int pattern_rows(int4 f) { return 3 * (esc_level(f) + 1) - 1; }

inline int pattern_row(int4 f, int j)
{
    esc_record r = esc_read(f);
    return popcount(esc_row_bits(&r, j)) + 1;
}

inline float3 pattern_row_point(int4 f, int j, int i)
{
    esc_record r = esc_read(f);
    int x = i == 0 ? 0 : min(esc_nth_bit(esc_row_bits(&r, j), i - 1), r.m);
    return (float3)((float)x / (float)r.m, (float)j / (float)r.m, 0.0f);
}

#include "patterns/layout.h"

/* --- the primitives ------------------------------------------------------------------------- */

typedef struct {
    esc_record r;
    uint edge_bits[4], row_bits[13];  /* esc_edge_bits, esc_row_bits (rows 1 .. m-1) */
    int ring[5];         /* ring[e]: local number of edge e's first point; ring[4] = the ring */
    int rows[13];        /* rows[y]: local number of row y's first interior point */
    int collapsed;
} esc_patch;

/* Local vertex number of lattice point p (inserted), a collapsed edge's points as its first
 * corner (esc.py patch_mesh remap, in its order). */
inline uint esc_index(__private const esc_patch *g, int2 p)
{
    int m = g->r.m;
    if (p.x > 0 && p.x < m && p.y > 0 && p.y < m)  /* inside: most points */
        return (uint)(g->rows[p.y] + popcount(g->row_bits[p.y] & ((1u << p.x) - 1u)));
    for (int e = 0; g->collapsed && e < 4; ++e) {  /* a collapsed edge's points, both corners included */
        int on = e == 0 ? p.y == 0 : e == 1 ? p.x == m : e == 2 ? p.y == m : p.x == 0;
        if (on && ((g->collapsed >> e) & 1))
            return (uint)g->ring[e];
    }
    for (int e = 0; e < 4; ++e) {
        int k = e == 0 ? (p.y == 0 ? p.x : -1) : e == 1 ? (p.x == m ? p.y : -1)
              : e == 2 ? (p.y == m ? m - p.x : -1) : (p.x == 0 ? m - p.y : -1);
        if (k >= 0 && k < m)  /* on edge e, not its last corner (edge e+1's first) */
            return (uint)(g->ring[e] + popcount(g->edge_bits[e] & ((1u << k) - 1u)));
    }
    return (uint)(g->rows[p.y] + popcount(g->row_bits[p.y] & ((1u << p.x) - 1u)));
}

/* Coarse triangle t (0..17: cell (i, j) = (t/2 % 3, t/6), lower then upper): apex, B0, B1 in
 * coarse units and its left (A->B0), right (A->B1) and base (B0->B1) masks, counter-clockwise
 * order (esc.py COARSE_TRIANGLES). */
inline void esc_coarse(__private const esc_record *r, int t, __private int2 corner[3], __private uint bits[3])
{
    int cell = t / 2, i = cell % 3, j = cell / 3, level = r->level;
    if ((t & 1) == 0) {
        corner[0] = (int2)(i + 1, j);
        corner[1] = (int2)(i + 1, j + 1);
        corner[2] = (int2)(i, j);
        bits[0] = esc_mask(r, ESC_V(i + 1, j));
        bits[1] = esc_reverse_bits(esc_mask(r, ESC_H(i, j)), level);
        bits[2] = esc_reverse_bits(esc_mask(r, ESC_D(i, j)), level);
    } else {
        corner[0] = (int2)(i, j + 1);
        corner[1] = (int2)(i, j);
        corner[2] = (int2)(i + 1, j + 1);
        bits[0] = esc_reverse_bits(esc_mask(r, ESC_V(i, j)), level);
        bits[1] = esc_mask(r, ESC_H(i, j + 1));
        bits[2] = esc_mask(r, ESC_D(i, j));
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

/* Where the walk writes (one walk, four modes): triangles (stage 5 list) or strips (each followed
 * by STRIP_RESTART, cltess/strips.py), counted either way; null pointers: count only. */
typedef struct {
    __global uint *triangles, *strips;
    uint base, triangle_count, strip_count;
    int strip_mode;                      /* walk for strips (else for triangles) */
    int2 strip[2 * ESC_MAX_LEVEL + 12];  /* the band's strip (esc.py coarse_triangle), its points */
    int length, band_triangles;
} esc_writer;

inline void esc_triangle(__private const esc_patch *g, __private const int2 corner[3], int2 a, int2 b, int2 c,
                         __private esc_writer *w)
{
    if ((a.x == b.x && a.y == b.y) || (b.x == c.x && b.y == c.y) || (a.x == c.x && a.y == c.y))
        return;
    ++w->band_triangles;  /* a triangle of the band (rule 3 dropped the repeated points) */
    if (w->strip_mode)
        return;
    uint ia = esc_index(g, esc_lattice(corner, g->r.n, a)), ib = esc_index(g, esc_lattice(corner, g->r.n, b));
    uint ic = esc_index(g, esc_lattice(corner, g->r.n, c));
    if (ia == ib || ib == ic || ia == ic)
        return;  /* a side on a collapsed edge */
    put_triangle(w->triangles, &w->triangle_count, w->base, ia, ib, ic);
}

inline void esc_strip_put(__private esc_writer *w, int2 p)
{
    if (w->strip_mode)
        w->strip[w->length++] = p;
}

inline int esc_same(int2 a, int2 b) { return a.x == b.x && a.y == b.y; }

/* The band's strip, once the band is done: trailing zero-area steps trimmed, written (local
 * vertex numbers + base, then STRIP_RESTART) when the band has a triangle. */
inline void esc_strip_end(__private const esc_patch *g, __private const int2 corner[3], __private esc_writer *w)
{
    if (!w->strip_mode)
        return;
    while (w->length >= 3) {
        int2 a = w->strip[w->length - 3], b = w->strip[w->length - 2], c = w->strip[w->length - 1];
        if (!(esc_same(a, b) || esc_same(b, c) || esc_same(a, c)))
            break;
        --w->length;
    }
    if (w->band_triangles) {
        for (int k = 0; k < w->length; ++k) {
            if (w->strips)
                w->strips[w->strip_count] = w->base + esc_index(g, esc_lattice(corner, g->r.n, w->strip[k]));
            ++w->strip_count;
        }
        if (w->strips)
            w->strips[w->strip_count] = STRIP_RESTART;
        ++w->strip_count;
    }
}

/* The zipper of esc.py coarse_triangle over the bands between consecutive active rows: each
 * step a triangle (lower, upper, next) and, in strip mode, its strip point(s) (rule 4: a copy
 * of the other side's point where one side advances twice; lower points at even positions). */
inline void esc_coarse_triangle(__private const esc_patch *g, int t, __private esc_writer *w)
{
    int2 corner[3], upper[ESC_MAX_LEVEL + 3], lower[ESC_MAX_LEVEL + 3];  /* chains, right to left */
    uint bits[3];
    esc_coarse(&g->r, t, corner, bits);
    int n = g->r.n, a = 0, upper_length = 1;
    upper[0] = (int2)(0, 0);
    for (int b = 1; b <= n; ++b) {
        if (b < n && !(((bits[0] | bits[1]) >> (b - 1)) & 1u))
            continue;  /* an inactive row: its band merges with the next */
        int lower_length = esc_chain_length(bits, b, n);
        for (int k = 0; k < lower_length; ++k)
            lower[k] = esc_chain_point(bits, b, k, n);
        int u = upper[0].x != a ? 1 : 0, v = 0;  /* a virtual right end: the lower chain's start */
        w->length = 0;
        w->band_triangles = 0;
        esc_strip_put(w, lower[0]);
        esc_strip_put(w, upper[u]);
        while (u < upper_length - 1 || v < lower_length - 1) {
            int advance_upper;
            int2 next_upper = upper[min(u + 1, upper_length - 1)], next_lower = lower[min(v + 1, lower_length - 1)];
            if (v == lower_length - 1) {
                advance_upper = 1;
            } else if (u == upper_length - 1) {
                advance_upper = 0;
            } else {
                int along_upper = (next_upper.x - next_upper.y) * next_lower.x;  /* (j - i)/j compared */
                int along_lower = (next_lower.x - next_lower.y) * next_upper.x;
                advance_upper = along_upper != along_lower ? along_upper < along_lower : next_upper.x < next_lower.x;
            }
            esc_triangle(g, corner, lower[v], upper[u], advance_upper ? next_upper : next_lower, w);
            if (advance_upper) {
                ++u;
                if (!(w->length & 1))  /* upper points at odd positions: copy the lower one */
                    esc_strip_put(w, lower[v]);
                esc_strip_put(w, upper[u]);
            } else {
                ++v;
                if (w->length & 1)
                    esc_strip_put(w, upper[u]);
                esc_strip_put(w, lower[v]);
            }
        }
        esc_strip_end(g, corner, w);
        for (int k = 0; k < lower_length; ++k)  /* the lower chain is the next band's upper one */
            upper[k] = lower[k];
        upper_length = lower_length;
        a = b;
    }
}

inline void esc_setup(int4 f, int collapsed, __private esc_patch *g)
{
    g->r = esc_read(f);
    g->collapsed = collapsed;
    g->ring[0] = 0;
    for (int e = 0; e < 4; ++e) {
        g->edge_bits[e] = esc_edge_bits(&g->r, e);
        g->ring[e + 1] = g->ring[e] + popcount(g->edge_bits[e]);
    }
    int at = g->ring[4];
    for (int y = 1; y < g->r.m; ++y) {
        g->row_bits[y] = esc_row_bits(&g->r, y);
        g->rows[y] = at;
        at += popcount(g->row_bits[y]);
    }
}

/* The walk over the 18 coarse triangles, in either mode. */
inline void esc_walk(int4 f, int collapsed, __private esc_writer *w)
{
    if (f.s0 <= 0)
        return;
    esc_patch g;
    esc_setup(f, collapsed, &g);
    for (int t = 0; t < 18; ++t)
        esc_coarse_triangle(&g, t, w);
}

/* Coarse triangle t of record r: its corners and its sides' candidate bits (esc_coarse), and its
 * row among its level's rows of the tables (esc.py count_table: side 0's bits lowest). */
inline uint esc_table_row(__private const esc_record *r, int t, __private int2 corner[3], __private uint bits[3])
{
    esc_coarse(r, t, corner, bits);
    return bits[0] | bits[1] << r->level | bits[2] << (2 * r->level);
}

/* A table's point code (lattice point (i, j) of the coarse triangle as i * ESC_STRIP_POINT_BASE
 * + j) as the patch's vertex number. */
inline uint esc_table_vertex(__private const esc_patch *g, __private const int2 corner[3], int code)
{
    return esc_index(g, esc_lattice(corner, g->r.n, (int2)(code / ESC_STRIP_POINT_BASE, code % ESC_STRIP_POINT_BASE)));
}

/* Stage 3's counts from the masks alone (esc.py counts): each coarse triangle's row of the
 * generated table (its triangles and strip indices as esc_coarse_triangle walks them; checked
 * exhaustively against the walk, tests/test_esc_counts.py), less, for a side on a collapsed edge,
 * its popcount + 1 segments (each one triangle's side; those have two points in one and are left
 * out).  Two adjacent collapsed edges (their shared corner is one edge's point only): 0, the
 * caller walks. */
inline int esc_table_counts(int4 f, int collapsed, __private uint *triangles, __private uint *strip_indices)
{
    *triangles = *strip_indices = 0;
#ifdef ESC_WALK
    return 0;  /* patterns/esc_walk.h: the baseline of bench/esc.py --stages */
#endif
    if (f.s0 <= 0)
        return 1;
    if (collapsed & ((collapsed << 1) | (collapsed >> 3)) & 15)
        return 0;
    esc_record r = esc_read(f);
    int level = r.level;
    __constant const uchar *tris = ESC_TABLE_TRIANGLES + ESC_TABLE_START[level];
    __constant const uchar *strips = ESC_TABLE_STRIP_INDICES + ESC_TABLE_START[level];
    for (int t = 0; t < 18; ++t) {
        int2 corner[3];
        uint bits[3];
        uint row = esc_table_row(&r, t, corner, bits);
        *triangles += tris[row];
        *strip_indices += strips[row];
        for (int side = 0; collapsed && side < 2; ++side) {
            int on = 0;
            for (int e = 0; e < 4; ++e)
                on |= esc_on_pole(corner[0], collapsed, e) && esc_on_pole(corner[1 + side], collapsed, e);
            if (on)
                *triangles -= popcount(bits[side]) + 1;
        }
    }
    return 1;
}

/* Stage 5's triangle list from the table (esc.py triangle_table: coarse_triangle's triangles in
 * order) through the patch's vertex numbering, a triangle with two points in one (a side on a
 * collapsed edge) left out as the walk does; counted only when out == 0. */
inline uint esc_table_triangles(int4 f, int collapsed, __global uint *out, uint base)
{
    if (f.s0 <= 0)
        return 0;
    esc_patch g;
    esc_setup(f, collapsed, &g);
    uint count = 0;
    for (int t = 0; t < 18; ++t) {
        int2 corner[3];
        uint bits[3];
        int row = ESC_TABLE_START[g.r.level] + (int)esc_table_row(&g.r, t, corner, bits);
        __constant const uchar *points = ESC_TABLE_TRIANGLE_POINTS + ESC_TABLE_TRIANGLE_FIRST[row];
        for (int k = 0, end = 3 * ESC_TABLE_TRIANGLES[row]; k < end; k += 3) {
            uint index[3];
            for (int c = 0; c < 3; ++c)
                index[c] = esc_table_vertex(&g, corner, points[k + c]);
            if (index[0] != index[1] && index[1] != index[2] && index[0] != index[2])
                put_triangle(out, &count, base, index[0], index[1], index[2]);
        }
    }
    return count;
}

/* Triangles ("count" mode when out == 0: the table's sums, or, with two adjacent collapsed
 * edges, the table's triangles through the numbering; "emit" otherwise). */
inline uint pattern_primitives(int4 f, int collapsed, __global uint *out, uint base)
{
    uint triangles, strip_indices;
    if (!out && esc_table_counts(f, collapsed, &triangles, &strip_indices))
        return triangles;
#ifndef ESC_WALK
    return esc_table_triangles(f, collapsed, out, base);
#endif
    esc_writer w;
    w.triangles = out;
    w.strips = 0;
    w.base = base;
    w.triangle_count = w.strip_count = 0;
    w.strip_mode = 0;
    esc_walk(f, collapsed, &w);
    return w.triangle_count;
}

/* Stage 5's strips from the table (esc.py strip_table: coarse_triangle's strips, each band's
 * points in order, rule-4 copies included) through the patch's vertex numbering: the walk's
 * strips without zipping the bands again (tests: equal to the walk and the mirror). */
inline uint esc_table_strips(int4 f, int collapsed, __global uint *out, uint base)
{
    if (f.s0 <= 0)
        return 0;
    esc_patch g;
    esc_setup(f, collapsed, &g);
    uint at = 0;
    for (int t = 0; t < 18; ++t) {
        int2 corner[3];
        uint bits[3];
        int row = ESC_TABLE_START[g.r.level] + (int)esc_table_row(&g.r, t, corner, bits);
        __constant const uchar *points = ESC_TABLE_STRIP_POINTS + ESC_TABLE_STRIP_FIRST[row];
        int count = ESC_TABLE_STRIP_INDICES[row];
        for (int k = 0; out && k < count; ++k) {
            int code = points[k];
            out[at + k] = code == ESC_STRIP_TABLE_RESTART ? STRIP_RESTART : base + esc_table_vertex(&g, corner, code);
        }
        at += count;
    }
    return at;
}

/* Strip indices, each strip followed by STRIP_RESTART (count mode when out == 0): one strip per
 * band of a coarse triangle, esc.py patch_mesh's strips in its order (stages/strip_counts.cl,
 * strip_indices.cl; cltess/backends/opencl/strips.py). */
inline uint pattern_strips(int4 f, int collapsed, __global uint *out, uint base)
{
    uint triangles, strip_indices;
    if (!out && esc_table_counts(f, collapsed, &triangles, &strip_indices))
        return strip_indices;
#ifndef ESC_WALK
    return esc_table_strips(f, collapsed, out, base);  /* out == 0 here: adjacent collapsed edges, counted */
#endif
    esc_writer w;
    w.triangles = 0;
    w.strips = out;
    w.base = base;
    w.triangle_count = w.strip_count = 0;
    w.strip_mode = 1;
    esc_walk(f, collapsed, &w);
    return w.strip_count;
}

#endif
