/* The SD-2 pattern (Amresh and Fünfzig, section 3.3; docs/sd2.md; NumPy mirror
 * cltess/patterns/sd2.py, whose docstring has the layout and counts).  Factors are real, as
 * 16.16 fixed-point integers (common.h FIXED_ONE): edge e has odd_segments(f_e) segments at the
 * fractional_odd points (common.h fractional_location), the same from either end.
 *
 * Per patch, by its factors: two equal and one different, the SD-2 fan-and-bands with its tip
 * where the equal edges meet; all equal, the regular grid; all different, the transition
 * pattern on the segment counts (patterns/tri_transition.h, included here under other names).
 * One walk (sd2_walk) gives the triangle strips and the triangles (the strips expanded): stage 5
 * and stages/strip_indices.cl emit with it; stage 3 counts the fan and the grid in closed form
 * (sd2_closed_counts, tested equal to the walk) and the transition fallback by its walk. */
#ifndef CLTESS_PATTERNS_SD2_H
#define CLTESS_PATTERNS_SD2_H
#include "common.h"

/* The fallback, the transition pattern under its own names (its layout.h: whole factors). */
#define pattern_ring_param transition_ring_param
#define pattern_edge_point transition_edge_point
#define pattern_rows transition_rows
#define pattern_row transition_row
#define pattern_row_point transition_row_point
#define pattern_vertex_count transition_vertex_count
#define pattern_primitives transition_primitives
#include "patterns/tri_transition.h"
#undef pattern_ring_param
#undef pattern_edge_point
#undef pattern_rows
#undef pattern_row
#undef pattern_row_point
#undef pattern_vertex_count
#undef pattern_primitives
#undef CLTESS_PATTERNS_LAYOUT_H  /* layout.h again below, for this pattern's own names */
#undef PATTERN_EDGE_POINTS
#undef PATTERN_UNIFORM_ROWS

#define SD2_CULLED 0
#define SD2_FAN 1        /* two equal factors: the SD-2 pattern */
#define SD2_GRID 2       /* three equal */
#define SD2_TRANSITION 3 /* three different */

/* Ring points of edge e: its segments (the ring holds points k = 0 .. n_e - 1). */
inline int sd2_segments(int4 f, int e) { return odd_segments(factor_of(f, e)); }

#define PATTERN_EDGE_POINTS(f, e) sd2_segments(f, e)
#define PATTERN_UNIFORM_ROWS 0  /* rows at fractional points: stage 4 evaluates them directly */

inline int4 sd2_whole(int4 f) { return (int4)(sd2_segments(f, 0), sd2_segments(f, 1), sd2_segments(f, 2), 0); }

/* The shape of a patch and, for SD2_FAN, its tip: the corner c where edges c-1 and c meet (edge
 * e runs from corner e to corner e+1). */
inline int sd2_shape(int4 f, int *tip)
{
    *tip = 0;
    if (f.s0 <= 0)
        return SD2_CULLED;
    if (f.s0 == f.s1 && f.s1 == f.s2)
        return SD2_GRID;
    if (f.s2 == f.s0)
        return SD2_FAN;
    *tip = f.s0 == f.s1 ? 1 : 2;
    return f.s1 == f.s2 || f.s0 == f.s1 ? SD2_FAN : SD2_TRANSITION;
}

/* Location of point i of an edge of factor fixed, from its start. */
inline float sd2_location(int fixed, int i)
{
    edge_param t = {i, odd_segments(fixed), fixed};
    return edge_location(t);
}

/* Barycentric tip + t (base(s) - tip): tip corner c, base from corner c+1 to corner c+2. */
inline float3 sd2_point(int c, float t, float s)
{
    float w[3];
    w[c] = 1.0f - t;
    w[(c + 1) % 3] = t * (1.0f - s);
    w[(c + 2) % 3] = t * s;
    return (float3)(w[0], w[1], w[2]);
}

/* --- the vertex layout ------------------------------------------------------------------------ */

inline edge_param pattern_ring_param(int4 f, int e, int k)
{
    edge_param t = {k, sd2_segments(f, e), factor_of(f, e)};
    return t;
}

inline float3 pattern_edge_point(int e, edge_param t) { return tri_edge_point(e, t); }

/* SD2_FAN: rows i = 1 .. a-1 (parallel to the base), b steps each; SD2_GRID: rows i = 2 .. n-1,
 * i steps each (row j of the layout is i = j + 1). */
inline int pattern_rows(int4 f)
{
    int tip, shape = sd2_shape(f, &tip);
    return shape == SD2_FAN ? sd2_segments(f, tip) - 1
         : shape == SD2_GRID ? max(sd2_segments(f, 0) - 2, 0)
         : shape == SD2_TRANSITION ? transition_rows(sd2_whole(f)) : 0;
}

inline int pattern_row(int4 f, int j)
{
    int tip, shape = sd2_shape(f, &tip);
    return shape == SD2_FAN ? sd2_segments(f, (tip + 1) % 3)
         : shape == SD2_GRID ? j + 1 : transition_row(sd2_whole(f), j);
}

inline float3 pattern_row_point(int4 f, int j, int i)
{
    int tip, shape = sd2_shape(f, &tip);
    if (shape == SD2_FAN)
        return sd2_point(tip, sd2_location(factor_of(f, tip), j), sd2_location(factor_of(f, (tip + 1) % 3), i));
    if (shape == SD2_GRID)
        return sd2_point(0, sd2_location(f.s0, j + 1), (float)i / (float)(j + 1));
    return transition_row_point(sd2_whole(f), j, i);
}

#include "patterns/layout.h"

/* --- strips and triangles --------------------------------------------------------------------- */

/* Where a walk writes: strips (each followed by STRIP_RESTART) and/or their triangles (winding
 * rule of cltess/strips.py: triangle m of a strip is (s[m], s[m+1], s[m+2]), the first two
 * swapped for odd m), both counted; null pointers: count only. */
typedef struct {
    __global uint *strips, *triangles;
    uint base, strip_count, triangle_count, a, b;
    int length;
} strip_writer;

inline void strip_put(__private strip_writer *w, uint v)
{
    if (w->strips)
        w->strips[w->strip_count] = w->base + v;
    ++w->strip_count;
    if (w->length >= 2) {
        int odd = w->length & 1;
        put_triangle(w->triangles, &w->triangle_count, w->base, odd ? w->b : w->a, odd ? w->a : w->b, v);
    }
    w->a = w->b;
    w->b = v;
    ++w->length;
}

inline void strip_end(__private strip_writer *w)
{
    if (w->strips)
        w->strips[w->strip_count] = STRIP_RESTART;
    ++w->strip_count;
    w->length = 0;
}

inline uint sd2_ring(int4 n, int e, int k) { return ring_index(n, e % 3, k); }

/* Local number of SD-2 vertex (i, j): parallel line i from the tip c, radial line j. */
inline uint sd2_vertex(int4 n, int c, int i, int j)
{
    int a = factor_of(n, c), b = factor_of(n, (c + 1) % 3);
    if (i == 0) return sd2_ring(n, c, 0);
    if (j == 0) return sd2_ring(n, c, i);
    if (i == a) return sd2_ring(n, c + 1, j);
    if (j == b) return sd2_ring(n, c + 2, a - i);
    return (uint)(n.s0 + n.s1 + n.s2 + (i - 1) * (b - 1) + (j - 1));
}

/* Local number of grid vertex (i, j): row i (i + 1 points) parallel to edge 1, point j from edge 0. */
inline uint grid_vertex(int4 n, int i, int j)
{
    int m = n.s0;
    if (i == 0) return sd2_ring(n, 0, 0);
    if (j == 0) return sd2_ring(n, 0, i);
    if (i == m) return sd2_ring(n, 1, j);
    if (j == i) return sd2_ring(n, 2, m - i);
    return (uint)(n.s0 + n.s1 + n.s2 + (i - 2) * (i - 1) / 2 + (j - 1));
}

/* The walk: SD2_FAN one strip per pair of radial lines, [tip, (1,j), (1,j+1), ..., (a,j),
 * (a,j+1)]; SD2_GRID one strip per band between rows i and i+1, from edge 2's side; the
 * transition pattern's triangles, one strip each. */
inline void sd2_walk(int4 f, int collapsed, __private strip_writer *w)
{
    int tip, shape = sd2_shape(f, &tip);
    int4 n = sd2_whole(f);
    if (shape == SD2_FAN) {
        int a = factor_of(n, tip), b = factor_of(n, (tip + 1) % 3);
        for (int j = 0; j < b; ++j) {
            strip_put(w, sd2_vertex(n, tip, 0, 0));
            for (int i = 1; i <= a; ++i) {
                strip_put(w, sd2_vertex(n, tip, i, j));
                strip_put(w, sd2_vertex(n, tip, i, j + 1));
            }
            strip_end(w);
        }
    } else if (shape == SD2_GRID) {
        for (int i = 0; i < n.s0; ++i) {
            for (int j = i + 1; j > 0; --j) {
                strip_put(w, grid_vertex(n, i + 1, j));
                strip_put(w, grid_vertex(n, i, j - 1));
            }
            strip_put(w, grid_vertex(n, i + 1, 0));
            strip_end(w);
        }
    } else if (shape == SD2_TRANSITION) {
        /* its triangles written where they go, or where the strips go, then spread out to one
         * strip each from the back (strip t at 4t, after its triangle at 3t: nothing unread is
         * overwritten) */
        __global uint *out = w->triangles ? w->triangles : w->strips;
        uint count = transition_primitives(n, collapsed, out, w->base);
        if (w->strips && !w->triangles)
            for (int t = (int)count - 1; t >= 0; --t) {
                uint x = out[3 * t], y = out[3 * t + 1], z = out[3 * t + 2];
                out[4 * t] = x;
                out[4 * t + 1] = y;
                out[4 * t + 2] = z;
                out[4 * t + 3] = STRIP_RESTART;
            }
        w->triangle_count += count;
        w->strip_count += 4 * count;
    }
}

/* Count mode of the fan and the grid in closed form (docs/sd2.md section 3; the walk's own
 * counts, as tests/test_sd2_pipeline.py checks): *triangles and *strip_indices; 0 for the
 * transition fallback and culled patches, which the walk counts. */
inline int sd2_closed_counts(int4 f, uint *triangles, uint *strip_indices)
{
    int tip, shape = sd2_shape(f, &tip);
    if (shape == SD2_FAN) {
        uint a = (uint)sd2_segments(f, tip), b = (uint)sd2_segments(f, (tip + 1) % 3);
        *triangles = b * (2 * a - 1);
        *strip_indices = b * (2 * a + 2);
        return 1;
    }
    if (shape == SD2_GRID) {
        uint n = (uint)sd2_segments(f, 0);
        *triangles = n * n;
        *strip_indices = n * n + 3 * n;
        return 1;
    }
    return 0;
}

/* Triangles ("count" mode when out == 0, "emit" otherwise): the strips expanded. */
inline uint pattern_primitives(int4 f, int collapsed, __global uint *out, uint base)
{
    uint triangles, strip_indices;
    if (!out && sd2_closed_counts(f, &triangles, &strip_indices))
        return triangles;
    strip_writer w = {0, out, base, 0, 0, 0, 0, 0};
    sd2_walk(f, collapsed, &w);
    return w.triangle_count;
}

/* Strip indices, each strip followed by STRIP_RESTART (count mode when out == 0). */
inline uint pattern_strips(int4 f, int collapsed, __global uint *out, uint base)
{
    uint triangles, strip_indices;
    if (!out && sd2_closed_counts(f, &triangles, &strip_indices))
        return strip_indices;
    strip_writer w = {out, 0, base, 0, 0, 0, 0, 0};
    sd2_walk(f, collapsed, &w);
    return w.strip_count;
}

#endif
