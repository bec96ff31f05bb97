/* The semi-uniform pattern (Dyken, Reimers and Seland, "Semi-uniform adaptive patch
 * tessellation", CGF 2009, section 3).  Mirror: cltess/patterns/semi_uniform.py (same
 * conventions, layout and triangle order; tests/test_pattern_semi_uniform_device.py).
 *
 * A patch at level m is the uniform pattern P^m on the 2^m lattice (a grid split along the
 * diagonals (i, j)-(i+1, j+1) for a quad, 4^m triangles for a triangle); the boundary points of
 * an edge whose level p_e is below m are snapped to the nearest p_e-dyadic point (eq. 1, applied
 * to the edge parameter alone, so the level-0 midpoint goes to the edge's end instead of the
 * paper's invalid (1, 1, 0)), and the triangles that collapse are dropped.  All in integers.
 *
 * Record: f = the dyadic edge factors 2^p_e (0: culled; a triangle's f.s3 is ignored), so ring
 * point k of edge e is (k, f_e) as for the transition patterns, and 2^m = max_e f_e.
 * Vertex layout: the ring (f_e points per edge, counter-clockwise), then the interior lattice
 * points (i, j) / 2^m row by row, j = 1.., i = 1.. (quad: i < 2^m; tri: i < 2^m - j).
 *
 * The domain: PATTERN_EDGES 4 (quad, default) or 3 (-D PATTERN_EDGES=3: triangle, (u, v) the
 * barycentric weights of corners P1, P2).  The su_* routines take it as an argument (constant
 * folded); the pattern_* contract of ARCHITECTURE.md section 3 passes PATTERN_EDGES.
 *
 * Needs from the common header: edge_param (fields k, f: point k of f on an edge),
 * factor_of(int4, int) and put_triangle(out, &count, base, a, b, c) (written when out != 0,
 * always counted).
 */
#ifndef PATTERNS_SEMI_UNIFORM_H
#define PATTERNS_SEMI_UNIFORM_H

#ifndef PATTERN_EDGES
#define PATTERN_EDGES 4
#endif

/* --- levels ------------------------------------------------------------------------------------ */

/* The record entry of an edge with integer factor f: 2^p, p = min(ceil(log2 f), max_level), exact
 * (ceil(log2 f) = 32 - clz(f - 1) for f > 1); 0 stays 0 (culled).  Monotone, so it commutes with
 * the crack-free max over an edge group. */
inline int su_dyadic_factor(int f, int max_level)
{
    if (f <= 0)
        return 0;
    int level = f > 1 ? 32 - (int)clz(f - 1) : 0;
    return 1 << min(level, max_level);
}

/* 2^m, the patch's lattice size: the largest edge factor. */
inline int su_size(int edges, int4 f)
{
    int n = max(max(f.s0, f.s1), f.s2);
    return edges == 4 ? max(n, f.s3) : n;
}

inline int su_ring_size(int edges, int4 f)
{
    return f.s0 + f.s1 + f.s2 + (edges == 4 ? f.s3 : 0);
}

/* --- the snap function (eq. 1) ------------------------------------------------------------------ */

/* sigma_p on the edge parameter t = a / n: the nearest multiple of d = n / 2^p, ties towards 0
 * when t < 1/2 and towards 1 otherwise: ceil((2a - d) / 2d) = floor((2a + d - 1) / 2d) for t < 1/2,
 * floor((2a + d) / 2d) otherwise; numerators >= 0. */
inline int su_snap(int a, int n, int d)
{
    return (2 * a + d - (2 * a < n ? 1 : 0)) / (2 * d) * d;
}

/* Vertex number of the lattice point of edge e at edge parameter a / n, after the snap. */
inline uint su_ring_vertex(int edges, int4 f, int n, int e, int a)
{
    int base = 0;
    for (int x = 0; x < e; ++x)
        base += factor_of(f, x);
    int d = n / factor_of(f, e);
    return (uint)((base + su_snap(a, n, d) / d) % su_ring_size(edges, f));
}

/* Vertex number of phi(lattice point (i, j)): a boundary point through its edge's snap (corners
 * are kept by either edge), an interior point in its row. */
inline uint su_vertex(int edges, int4 f, int n, int i, int j)
{
    int ring = su_ring_size(edges, f);
    if (edges == 4) {
        if (j == 0) return su_ring_vertex(edges, f, n, 0, i);
        if (i == n) return su_ring_vertex(edges, f, n, 1, j);
        if (j == n) return su_ring_vertex(edges, f, n, 2, n - i);
        if (i == 0) return su_ring_vertex(edges, f, n, 3, n - j);
        return (uint)(ring + (j - 1) * (n - 1) + (i - 1));
    }
    if (i + j == n) return su_ring_vertex(edges, f, n, 0, j);
    if (i == 0) return su_ring_vertex(edges, f, n, 1, n - j);
    if (j == 0) return su_ring_vertex(edges, f, n, 2, i);
    return (uint)(ring + (j - 1) * (2 * n - 2 - j) / 2 + (i - 1));
}

/* --- triangles: one routine for count (out == 0) and emit mode ------------------------------------ */

inline void su_put(__global uint *out, uint *count, uint base, uint a, uint b, uint c)
{
    if (a != b && b != c && c != a)  /* collapsed by the snap: dropped */
        put_triangle(out, count, base, a, b, c);
}

/* The triangles of P^m through phi, degenerate ones dropped, counter-clockwise, in the mirror's
 * order (reference.quad_pattern / tri_pattern's uniform order).  Returns their number. */
inline uint su_primitives(int edges, int4 f, __global uint *out, uint base)
{
    uint count = 0;
    if (f.s0 <= 0)
        return 0;
    int n = su_size(edges, f);
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < (edges == 4 ? n : n - j); ++i) {
            if (edges == 4) {
                uint a = su_vertex(edges, f, n, i, j), b = su_vertex(edges, f, n, i + 1, j);
                uint c = su_vertex(edges, f, n, i + 1, j + 1), d = su_vertex(edges, f, n, i, j + 1);
                su_put(out, &count, base, a, b, c);
                su_put(out, &count, base, a, c, d);
            } else {
                uint a = su_vertex(edges, f, n, i + 1, j), b = su_vertex(edges, f, n, i, j + 1);
                su_put(out, &count, base, a, b, su_vertex(edges, f, n, i, j));
                if (i + j < n - 1)
                    su_put(out, &count, base, a, su_vertex(edges, f, n, i + 1, j + 1), b);
            }
        }
    return count;
}

/* Closed forms (SEEDS.md 1.3): P^m has (n+1)^2 or (n+1)(n+2)/2 points and 2 n^2 or n^2
 * triangles; each boundary point snapped away (n - f_e per edge) removes one of each. */
inline uint su_vertex_count(int edges, int4 f)
{
    if (f.s0 <= 0)
        return 0;
    int n = su_size(edges, f);
    return (uint)(su_ring_size(edges, f) + (edges == 4 ? (n - 1) * (n - 1) : (n - 1) * (n - 2) / 2));
}

inline uint su_triangle_count(int edges, int4 f)
{
    if (f.s0 <= 0)
        return 0;
    int n = su_size(edges, f);
    return (uint)((edges == 4 ? 2 : 1) * n * n - (edges * n - su_ring_size(edges, f)));
}

/* --- the pattern contract (ARCHITECTURE.md section 3) ---------------------------------------------- */

/* Ring point k (0 <= k < f_e) of edge e: t = k / f_e, the p_e-dyadic points. */
inline edge_param pattern_ring_param(int4 f, int e, int k)
{
    edge_param t;
    t.k = k;
    t.f = factor_of(f, e);
    return t;
}

/* Interior rows: lattice rows 1 .. n-1 (quad) or 1 .. n-2 (tri). */
inline int pattern_rows(int4 f)
{
    if (f.s0 <= 0)
        return 0;
    int n = su_size(PATTERN_EDGES, f);
    return PATTERN_EDGES == 4 ? n - 1 : max(n - 2, 0);
}

/* Row j (0-based: lattice row r = j + 1, v = r / n) runs between the boundary points uv0 and uv1,
 * which are not its points; its count points lie evenly between them, point i (0-based) at
 * uv0 + (i + 1) / (count + 1) (uv1 - uv0), exactly pattern_row_point(f, j, i). */
inline int pattern_row(int4 f, int j, float2 *uv0, float2 *uv1)
{
    int n = su_size(PATTERN_EDGES, f), r = j + 1;
    float v = (float)r / (float)n;
    *uv0 = (float2)(0.0f, v);
    *uv1 = (float2)(PATTERN_EDGES == 4 ? 1.0f : (float)(n - r) / (float)n, v);
    return PATTERN_EDGES == 4 ? n - 1 : n - 1 - r;
}

/* Point i of row j, exactly: the lattice point (i + 1, j + 1) / n (dyadic, exact in float). */
inline float2 pattern_row_point(int4 f, int j, int i)
{
    float n = (float)su_size(PATTERN_EDGES, f);
    return (float2)((float)(i + 1) / n, (float)(j + 1) / n);
}

inline uint pattern_vertex_count(int4 f) { return su_vertex_count(PATTERN_EDGES, f); }

inline uint pattern_primitives(int4 f, __global uint *out, uint base)
{
    return su_primitives(PATTERN_EDGES, f, out, base);
}

#endif
