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
#undef PATTERN_CHORD_POINTS

#define SD2_CULLED 0
#define SD2_FAN 1        /* two equal factors: the SD-2 pattern */
#define SD2_GRID 2       /* three equal */
#define SD2_TRANSITION 3 /* three different */

/* Ring points of edge e: its segments (the ring holds points k = 0 .. n_e - 1). */
inline int sd2_segments(int4 f, int e) { return odd_segments(factor_of(f, e)); }

#define PATTERN_EDGE_POINTS(f, e) sd2_segments(f, e)
#define PATTERN_UNIFORM_ROWS 0  /* rows at fractional points: stage 4 evaluates them directly */
#define PATTERN_CHORD_POINTS 1  /* the tie zone's centres: pattern_chord_point, below */

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

/* The hint a level function leaves in the fourth factor slot (docs/sd2.md section 5; mirror
 * cltess/patterns/sd2.py HINT_SHIFT): (phi_m << SD2_HINT_SHIFT) | m, m the corner of the
 * smallest per-vertex factor phi_m; 0: none.  Returns 1 with *m, *phi when there is one. */
#define SD2_HINT_SHIFT 2
inline int sd2_hint(int4 f, int *m, int *phi)
{
    int h = abs(f.s3);  /* stage 2 stores an unused slot negated (common.h patch_factors) */
    *m = h & ((1 << SD2_HINT_SHIFT) - 1);
    *phi = h >> SD2_HINT_SHIFT;
    return h > 0 && *m < 3;
}

/* The distance (16.16) of a fixed-point factor from the nearest odd whole number (mirror
 * odd_distance, the same integer operations). */
inline int sd2_odd_distance(int x)
{
    int r = abs(x - FIXED_ONE) % (2 * FIXED_ONE);
    return min(r, 2 * FIXED_ONE - r);
}

/* kappa, the width in lam over which the zone moves from one tie configuration to the other
 * (docs/sd2.md section 5, "Seventh pass"; mirror _switch_width, the same operations):
 * min(1, max(rho / SD2_SWITCH_REACH, sigma_m / rho)), rho = F - phi_m the distance from the triple
 * tie, sigma_m that of phi_m from the nearest odd whole number: small only near a triple tie at an
 * odd whole number, where the two tie configurations are within O(rho + sigma_m) of one lattice as
 * surfaces and any blend of them stands off both by about the error; 1 elsewhere.  The reach is
 * pinned equal to the mirror's SWITCH_REACH by tests/contracts/test_constants.py. */
#define SD2_SWITCH_REACH 0.125f
inline float sd2_switch_width(int big, int phi_m)
{
    int rho = big - phi_m;
    if (rho <= 0 || phi_m < 2 * FIXED_ONE)  /* the plateau of 1 moves in proportion already */
        return 1.0f;
    float apart = (float)sd2_odd_distance(phi_m) / (float)rho;
    float from_tie = (float)rho * (1.0f / (float)FIXED_ONE) / SD2_SWITCH_REACH;
    return fmin(1.0f, fmax(from_tie, apart));
}

/* lam steepened about 1/2 to width kappa (mirror _sharpen, the same operations):
 * clamp(1/2 + (lam - 1/2) / kappa, 0, 1); kappa = 0: the step, 1 from lam = 1/2 on.  0 and 1 are
 * kept, so ties and plateaus keep their configuration. */
inline float sd2_sharpen(float lam, float kappa)
{
    if (kappa >= 1.0f)
        return lam;
    float d = lam - 0.5f;
    if (kappa <= 0.0f)
        return d >= 0.0f ? 1.0f : 0.0f;
    float x = d / kappa;
    float y = 0.5f + x;
    return fmin(fmax(y, 0.0f), 1.0f);
}

/* The tie zone of the fan with tip c (mirror sd2_morph): 1 when in it, with *w the radial
 * pattern's weight (F - G) / 1.0 and *lam the weight of the tie with partner c+1,
 * min(e2 / e1, 1), e_k = F - phi_k (1 when the base corners tie with each other: a plateau left
 * by the tip starts from one tie configuration, docs/sd2.md section 5), sharpened about 1/2 near a
 * triple tie at an odd whole factor of 3 or more (sd2_sharpen to width sd2_switch_width; section 5,
 * "Seventh pass"). */
inline int sd2_morph(int4 f, int c, float *w, float *lam)
{
    int m, phi_m;
    int big = factor_of(f, c), base = factor_of(f, (c + 1) % 3);
    *w = 1.0f;
    *lam = 1.0f;
    if (!sd2_hint(f, &m, &phi_m) || m == c || phi_m > base || big < base || big - base >= FIXED_ONE)
        return 0;
    int e_m = big - phi_m, e_other = big - base;
    int e1 = m == (c + 1) % 3 ? e_m : e_other, e2 = m == (c + 1) % 3 ? e_other : e_m;
    *w = (float)e_other * (1.0f / (float)FIXED_ONE);
    float ratio = e1 > 0 ? fmin((float)e2 / (float)e1, 1.0f) : 1.0f;
    *lam = sd2_sharpen(ratio, sd2_switch_width(big, phi_m));
    return 1;
}

/* Corner c+2's weight of the zone's fan vertex at row location t, base location s (mirror
 * _fan_z, the same operations): w t s + (1 - w) (lam max(t + s - 1, 0) + (1 - lam) min(s, t)). */
inline float sd2_fan_z(float t, float s, float w, float lam)
{
    float radial = t * s;
    float towards_1 = fmax((t + s) - 1.0f, 0.0f);
    float towards_2 = fmin(s, t);
    float a = lam * towards_1;
    float b = (1.0f - lam) * towards_2;
    float tie = a + b;
    float x = w * radial;
    float y = (1.0f - w) * tie;
    return x + y;
}

/* How far a zone quad's centre has slid on its row from (i, j+1) towards (i, j) (mirror
 * _centre_mu): (1 - w)(1 - lam); 0 at the zone's outer edge and where the partner is c+1. */
inline float sd2_centre_mu(float w, float lam) { return (1.0f - w) * (1.0f - lam); }

/* Barycentric point on the row at location t from corner c with corner c+2 weight z. */
inline float3 sd2_row_point(int c, float t, float z)
{
    float w[3];
    w[c] = 1.0f - t;
    w[(c + 1) % 3] = t - z;
    w[(c + 2) % 3] = z;
    return (float3)(w[0], w[1], w[2]);
}

/* The corner the grid's rows start from: m + 1 with a hint, else 0. */
inline int sd2_grid_corner(int4 f)
{
    int m, phi;
    return sd2_hint(f, &m, &phi) ? (m + 1) % 3 : 0;
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
    float w, lam;
    if (shape == SD2_FAN)  /* in the tie zone, the quads' centres: a - 1 rows more */
        return (sd2_segments(f, tip) - 1) * (sd2_morph(f, tip, &w, &lam) ? 2 : 1);
    return shape == SD2_FAN ? sd2_segments(f, tip) - 1
         : shape == SD2_GRID ? max(sd2_segments(f, 0) - 2, 0)
         : shape == SD2_TRANSITION ? transition_rows(sd2_whole(f)) : 0;
}

inline int pattern_row(int4 f, int j)
{
    int tip, shape = sd2_shape(f, &tip);
    if (shape == SD2_FAN)  /* centre rows (j >= a): b centres, b + 1 steps */
        return sd2_segments(f, (tip + 1) % 3) + (j >= sd2_segments(f, tip) ? 1 : 0);
    return shape == SD2_FAN ? sd2_segments(f, (tip + 1) % 3)
         : shape == SD2_GRID ? j + 1 : transition_row(sd2_whole(f), j);
}

inline float3 pattern_row_point(int4 f, int j, int i)
{
    int tip, shape = sd2_shape(f, &tip);
    if (shape == SD2_FAN) {
        int big = factor_of(f, tip), base = factor_of(f, (tip + 1) % 3);
        float w, lam;
        if (!sd2_morph(f, tip, &w, &lam))
            return sd2_point(tip, sd2_location(big, j), sd2_location(base, i));
        int a = sd2_segments(f, tip);
        if (j < a) {
            float t = sd2_location(big, j);
            return sd2_row_point(tip, t, sd2_fan_z(t, sd2_location(base, i), w, lam));
        }
        /* the centre of quad (r, i - 1), slid on row r from (r, i) to (r, i - 1) by mu (mirror
         * sd2_layout): its domain point; in space it goes on its row's chord (pattern_chord_point) */
        int r = j - (a - 1);
        float t = sd2_location(big, r);
        float mu = sd2_centre_mu(w, lam);
        float keep = 1.0f - mu;
        float right = keep * sd2_fan_z(t, sd2_location(base, i), w, lam);
        float left = mu * sd2_fan_z(t, sd2_location(base, i - 1), w, lam);
        return sd2_row_point(tip, t, right + left);
    }
    if (shape == SD2_GRID) {
        int m, phi;
        if (!sd2_hint(f, &m, &phi))
            return sd2_point(0, sd2_location(f.s0, j + 1), (float)i / (float)(j + 1));
        float t = sd2_location(f.s0, j + 1);  /* the tie configuration (docs/sd2.md section 5) */
        return sd2_row_point((m + 1) % 3, t, t - sd2_location(f.s0, j + 1 - i));
    }
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

/* Local number of the tie zone's centre of the quad between rows i, i+1 and radial lines j, j+1. */
inline uint sd2_centre(int4 n, int c, int i, int j)
{
    int a = factor_of(n, c), b = factor_of(n, (c + 1) % 3);
    return (uint)(n.s0 + n.s1 + n.s2 + (a - 1) * (b - 1) + (i - 1) * b + j);
}

/* Row points that stage 4 places on a chord of the mesh rather than on the surface
 * (stages/rows.h chord_position; mirror sd2_chords): the tie zone's centres.  Returns 1 for row
 * point (j, i) when it is one, with *start and *end the local numbers of its row neighbours
 * (r, i) and (r, i - 1) and *mu: it goes to P_start + mu (P_end - P_start), P_v the position
 * stage 4 gives vertex v.  On the surface a centre stood off its row's chord by up to the row's
 * chord error, a fin that moved the mesh by most of the error at low factors whenever lam moved
 * (docs/sd2.md section 5). */
inline int pattern_chord_point(int4 f, int j, int i, __private uint *start, __private uint *end,
                               __private float *mu)
{
    int tip, shape = sd2_shape(f, &tip);
    float w, lam;
    if (shape != SD2_FAN || !sd2_morph(f, tip, &w, &lam))
        return 0;
    int4 n = sd2_whole(f);
    int a = factor_of(n, tip);
    if (j < a)
        return 0;
    *start = sd2_vertex(n, tip, j - (a - 1), i);
    *end = sd2_vertex(n, tip, j - (a - 1), i - 1);
    *mu = sd2_centre_mu(w, lam);
    return 1;
}

/* Local number of grid vertex (i, j): row i (i + 1 points) parallel to the edge opposite
 * corner g, point j from edge g. */
inline uint grid_vertex(int4 n, int g, int i, int j)
{
    int m = n.s0;
    if (i == 0) return sd2_ring(n, g, 0);
    if (j == 0) return sd2_ring(n, g, i);
    if (i == m) return sd2_ring(n, g + 1, j);
    if (j == i) return sd2_ring(n, g + 2, m - i);
    return (uint)(n.s0 + n.s1 + n.s2 + (i - 2) * (i - 1) / 2 + (j - 1));
}

/* The walk: SD2_FAN one strip per pair of radial lines, [tip, (1,j), (1,j+1), ..., (a,j),
 * (a,j+1)]; SD2_GRID one strip per band between rows i and i+1, from edge 2's side; the
 * transition pattern's triangles, one strip each. */
inline void sd2_walk(int4 f, int collapsed, __private strip_writer *w)
{
    int tip, shape = sd2_shape(f, &tip);
    int4 n = sd2_whole(f);
    float weight, lam;
    if (shape == SD2_FAN && sd2_morph(f, tip, &weight, &lam)) {
        /* the tie zone (mirror _zone_strips): centre C of quad (i, j) is a vertex of row i on both
         * sides, the triangle above split at it, the quad fanning from it to B, C' (the lower
         * row's centre, none on the base) and D: per radial pair [A1, C1, tip, E1], then per
         * quad [A, B, C, C', D] and [C, D, E], or [A, B, C, D, E] on the base's row */
        int a = factor_of(n, tip), b = factor_of(n, (tip + 1) % 3);
        for (int j = 0; j < b; ++j) {
            strip_put(w, sd2_vertex(n, tip, 1, j));
            strip_put(w, sd2_centre(n, tip, 1, j));
            strip_put(w, sd2_vertex(n, tip, 0, 0));
            strip_put(w, sd2_vertex(n, tip, 1, j + 1));
            strip_end(w);
            for (int i = 1; i < a; ++i) {
                uint A = sd2_vertex(n, tip, i, j), B = sd2_vertex(n, tip, i + 1, j);
                uint D = sd2_vertex(n, tip, i + 1, j + 1), E = sd2_vertex(n, tip, i, j + 1);
                uint C = sd2_centre(n, tip, i, j);
                strip_put(w, A);
                strip_put(w, B);
                strip_put(w, C);
                if (i + 1 < a) {
                    strip_put(w, sd2_centre(n, tip, i + 1, j));
                    strip_put(w, D);
                    strip_end(w);
                    strip_put(w, C);
                    strip_put(w, D);
                    strip_put(w, E);
                } else {
                    strip_put(w, D);
                    strip_put(w, E);
                }
                strip_end(w);
            }
        }
    } else if (shape == SD2_FAN) {
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
        int g = sd2_grid_corner(f);
        for (int i = 0; i < n.s0; ++i) {
            for (int j = i + 1; j > 0; --j) {
                strip_put(w, grid_vertex(n, g, i + 1, j));
                strip_put(w, grid_vertex(n, g, i, j - 1));
            }
            strip_put(w, grid_vertex(n, g, i + 1, 0));
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
        float w, lam;
        int zone = sd2_morph(f, tip, &w, &lam);
        *triangles = zone ? b * (4 * a - 3) : b * (2 * a - 1);
        *strip_indices = zone ? b * (10 * a - 9) : b * (2 * a + 2);
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
