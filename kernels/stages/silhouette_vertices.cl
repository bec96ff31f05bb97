/* Silhouette refinement, per frame: stage 4 with blended levels (Dyken, Reimers and Seland 2008,
 * section 5, eq. 9-11) on the semi-uniform pattern's layout (patterns/semi_uniform.h; records
 * from stages/silhouette_levels.cl and the crack-free max, docs/design.md "Silhouette
 * refinement").
 *
 * A patch's surface is the paper's: piecewise linear over P^m, m = ceil(s_max) (its topological
 * level), with vertex values
 *
 *   on the open edge e:  S_{s_e}[F](p)                                       (eq. 10, 11)
 *   inside:              (1 - a) G_k(p) + a G_{k+1}(p),  k = floor(s_max), a = s_max - k   (eq. 9)
 *
 * S_L[F] interpolates F linearly over the level-L interval of the boundary curve; G_L
 * interpolates over the level-L triangle of P^L holding p the values F inside and the edges'
 * own values S_{s_e}[F] on the boundary (the paper interpolates F there; taking the edges'
 * values keeps the surface continuous when m changes, docs/design.md).  The record may put the
 * patch on a finer lattice 2^m' (m' >= m: an edge takes the larger level of its two patches, so
 * both sample it at the same points) with each edge snapped to its own level q_e >= m: every
 * vertex then takes the value of that surface at its point (interpolated over the P^m triangle
 * holding it), and every snapped triangle lies inside one triangle of P^m, so the mesh is the
 * same surface whichever lattice and snap it has.  Edge values interpolate the kind's symmetric
 * boundary points with exact dyadic weights r/d and 1 - r/d: the neighbour, walking the edge the
 * other way, forms the same products and sums them the other way round: the same bits.  At
 * integer levels on one lattice (a = 0, m' = m) every vertex is F(p) computed exactly as
 * stages/vertices.cl computes it without forward differencing.  blend = 0 (the ablation): every
 * vertex is F(p).  lod: s(p) per vertex (s_e on the ring, s_max inside). */
#include "criteria/silhouette.h"

inline float level_of(float4 s, int e) { return e == 0 ? s.s0 : e == 1 ? s.s1 : e == 2 ? s.s2 : s.s3; }

/* F at point k of f on edge e, bitwise the neighbour's: the end (k = f) is the next edge's
 * start, the corner exactly. */
ALWAYS_INLINE float3 silhouette_edge_point(__private const kind_patch *patch, int e, int k, int f)
{
    edge_param t = {k, f};
    if (k == f) {
        e = (e + 1) % PATTERN_EDGES;
        t.k = 0;
    }
    return kind_boundary_point(patch, e, t);
}

/* S_level[F] and S_level[N] at point k of f = 2^q on edge e (level <= q). */
ALWAYS_INLINE void silhouette_edge_sample(__private const kind_patch *patch, int e, int k, int f, int level,
                                          __private float3 *position, __private float3 *normal)
{
    int d = f >> level, i = k / d, r = k % d;
    edge_param t = {k, f};
    if (r == 0) {
        kind_eval(patch, pattern_edge_point(e, t), 0, normal);
        *position = silhouette_edge_point(patch, e, k, f);
        return;
    }
    edge_param ta = {i * d, f}, tb = {(i + 1) * d, f};
    float3 na, nb;
    kind_eval(patch, pattern_edge_point(e, ta), 0, &na);
    kind_eval(patch, pattern_edge_point(e, tb), 0, &nb);
    float w = (float)r / (float)d;
    *position = (1.0f - w) * silhouette_edge_point(patch, e, i * d, f) + w * silhouette_edge_point(patch, e, (i + 1) * d, f);
    *normal = (1.0f - w) * na + w * nb;
}

/* eq. 9: (1 - a) lo + a hi, the normal renormalised (the finer one where the blend vanishes). */
inline void silhouette_blend(float a, float3 lo, float3 nlo, float3 hi, float3 nhi,
                             __private float3 *position, __private float3 *normal)
{
    *position = (1.0f - a) * lo + a * hi;
    float3 n = unit_or_zero((1.0f - a) * nlo + a * nhi);
    *normal = dot3(n, n) > 0.0f ? n : nhi;
}

/* S_{s}[F] at ring point k of f on edge e: the edge's value (k = 0: the corner, exactly; a
 * collapsed edge: its first corner). */
ALWAYS_INLINE void silhouette_edge_value(__private const kind_patch *patch, int e, int k, int f, float s, int collapsed,
                                         int blend, __private float3 *position, __private float3 *normal)
{
    edge_param t = {k, f};
    if (!blend || k == 0 || collapsed) {
        kind_eval(patch, pattern_edge_point(e, t), 0, normal);
        edge_param corner = {0, f};
        *position = kind_boundary_point(patch, e, collapsed ? corner : t);
        return;
    }
    int level = (int)floor(s), q = 31 - (int)clz(f);
    float a = s - (float)level;
    float3 lo, nlo, hi, nhi;
    silhouette_edge_sample(patch, e, k, f, min(level, q), &lo, &nlo);
    if (a > 0.0f) {
        silhouette_edge_sample(patch, e, k, f, min(level + 1, q), &hi, &nhi);
        silhouette_blend(a, lo, nlo, hi, nhi, position, normal);
    } else {
        *position = lo;
        *normal = level >= q ? nlo : unit_or_zero(nlo);
    }
}

/* Whether lattice point (i, j) of n lies on the boundary: its edge e and parameter a (0 .. n-1,
 * the edge's start corner included, as patterns/semi_uniform.h pattern_template_point). */
inline int silhouette_lattice_edge(int n, int i, int j, __private int *e, __private int *a)
{
#if PATTERN_EDGES == 4
    if (j == 0 && i < n) { *e = 0; *a = i; return 1; }
    if (i == n && j < n) { *e = 1; *a = j; return 1; }
    if (j == n && i > 0) { *e = 2; *a = n - i; return 1; }
    if (i == 0 && j > 0) { *e = 3; *a = n - j; return 1; }
#else
    if (i + j == n && j < n) { *e = 0; *a = j; return 1; }
    if (i == 0 && j > 0) { *e = 1; *a = n - j; return 1; }
    if (j == 0 && i < n) { *e = 2; *a = i; return 1; }
#endif
    return 0;
}

typedef struct {
    __private const kind_patch *patch;
    int4 f;
    int n, m, collapsed, blend;
    float4 s;
    float s_max;
} silhouette_patch;

/* The boundary values at lattice point (i, j): the edge's S_{s_e}[F]; inside: F. */
ALWAYS_INLINE void silhouette_hat(__private const silhouette_patch *sp, int i, int j, __private float3 *position,
                                  __private float3 *normal)
{
    int e, a;
    if (silhouette_lattice_edge(sp->n, i, j, &e, &a)) {
        int fe = factor_of(sp->f, e);
        silhouette_edge_value(sp->patch, e, a / (sp->n / fe), fe, level_of(sp->s, e), (sp->collapsed >> e) & 1,
                              sp->blend, position, normal);
    } else {
        kind_eval(sp->patch, pattern_row_point(sp->f, j, i), position, normal);
    }
}

/* The level-`level` triangle holding lattice point (i, j) of n: its corners and weights (quad
 * cells split along (0,0)-(1,1), triangle cells as P^m); 1 when the point is a corner itself. */
inline int silhouette_cell(int n, int i, int j, int level, __private int ci[3], __private int cj[3],
                           __private float w[3])
{
    int d = n >> level, bi = i / d * d, bj = j / d * d, ri = i % d, rj = j % d;
    ci[0] = i;
    cj[0] = j;
    w[0] = 1.0f;
    if (ri == 0 && rj == 0)
        return 1;
    float x = (float)ri / (float)d, y = (float)rj / (float)d;
#if PATTERN_EDGES == 4
    ci[0] = bi; cj[0] = bj; ci[2] = bi + d; cj[2] = bj + d;
    if (ri >= rj) {
        ci[1] = bi + d; cj[1] = bj;
        w[0] = 1.0f - x; w[1] = x - y; w[2] = y;
    } else {
        ci[1] = bi; cj[1] = bj + d;
        w[0] = 1.0f - y; w[1] = y - x; w[2] = x;
    }
#else
    if (ri + rj <= d) {
        ci[0] = bi; cj[0] = bj; ci[1] = bi + d; cj[1] = bj; ci[2] = bi; cj[2] = bj + d;
        w[0] = 1.0f - x - y; w[1] = x; w[2] = y;
    } else {
        ci[0] = bi + d; cj[0] = bj; ci[1] = bi; cj[1] = bj + d; ci[2] = bi + d; cj[2] = bj + d;
        w[0] = 1.0f - y; w[1] = 1.0f - x; w[2] = x + y - 1.0f;
    }
#endif
    return 3;
}

/* G_level at lattice point (i, j): the boundary values interpolated over the level's triangle. */
ALWAYS_INLINE void silhouette_coarse(__private const silhouette_patch *sp, int i, int j, int level,
                                     __private float3 *position, __private float3 *normal)
{
    int ci[3], cj[3];
    float w[3];
    int corners = silhouette_cell(sp->n, i, j, level, ci, cj, w);
    if (corners == 1) {
        silhouette_hat(sp, i, j, position, normal);
        return;
    }
    *position = (float3)(0.0f);
    *normal = (float3)(0.0f);
    for (int c = 0; c < 3; ++c)
        if (w[c] != 0.0f) {
            float3 p, nrm;
            silhouette_hat(sp, ci[c], cj[c], &p, &nrm);
            *position += w[c] * p;
            *normal += w[c] * nrm;
        }
}

/* The vertex value at a point (i, j) of P^m (eq. 9-11, the header comment). */
ALWAYS_INLINE void silhouette_value(__private const silhouette_patch *sp, int i, int j, __private float3 *position,
                                    __private float3 *normal)
{
    int e, a;
    if (!sp->blend || silhouette_lattice_edge(sp->n, i, j, &e, &a)) {
        silhouette_hat(sp, i, j, position, normal);
        return;
    }
    int level = (int)floor(sp->s_max);
    float blend = sp->s_max - (float)level;
    float3 lo, nlo, hi, nhi;
    silhouette_coarse(sp, i, j, min(level, sp->m), &lo, &nlo);
    if (blend > 0.0f) {
        silhouette_coarse(sp, i, j, min(level + 1, sp->m), &hi, &nhi);
        silhouette_blend(blend, lo, nlo, hi, nhi, position, normal);
    } else {
        *position = lo;
        *normal = level >= sp->m ? nlo : unit_or_zero(nlo);
    }
}

__kernel void silhouette_vertices(__global const float4 *controls, __global const int4 *records,
                                  __global const ulong *vertex_offsets, __global const int *patch_objects,
                                  __global const float4 *levels, uint first_patch, uint num_patches,
                                  uint patch_base, ulong vertex_base, int blend,
                                  __global float *positions, __global float *normals, __global float *uv,
                                  __global int *patch_ids, __global int *object_ids, __global float *lod)
{
    uint p;
    int4 f;
    int collapsed;
    if (!batch_patch(first_patch, num_patches, records, &p, &f, &collapsed))
        return;
    vertex_out out = {positions, normals, uv, patch_ids, object_ids};
    int object = patch_objects[p];
    kind_patch patch;
    kind_load(controls, p - patch_base, &patch);
    ulong at = vertex_offsets[p] - vertex_base;
    silhouette_patch sp;
    sp.patch = &patch;
    sp.f = f;
    sp.n = su_size(f);
    sp.s = levels[p];
    sp.s_max = max(max(sp.s.s0, sp.s.s1), max(sp.s.s2, sp.s.s3));
    sp.m = (int)ceil(sp.s_max);  /* the patch's own level: as silhouette_levels.cl */
    sp.collapsed = collapsed;
    sp.blend = blend;
    float3 position, normal;

    for (int e = 0; e < PATTERN_EDGES; ++e) {
        int fe = factor_of(f, e);
        float s = level_of(sp.s, e);
        for (int k = 0; k < fe; ++k) {
            edge_param t = pattern_ring_param(f, e, k);
            float3 x = pattern_edge_point(e, t);
            silhouette_edge_value(&patch, e, k, fe, s, (collapsed >> e) & 1, blend, &position, &normal);
            put_vertex(out, at, position, normal, x.xy, p, object);
            lod[at++] = s;
        }
    }

    int rows = pattern_rows(f), n_level = 31 - (int)clz(sp.n);
    for (int j = 1; j <= rows; ++j) {
        int steps = pattern_row(f, j);
        for (int i = 1; i < steps; ++i) {
            float3 x = pattern_row_point(f, j, i);
            if (!blend) {
                kind_eval(&patch, x, &position, &normal);
            } else {
                /* the surface over P^m: the P^m triangle holding the point (itself when m' = m) */
                int ci[3], cj[3];
                float w[3];
                int corners = silhouette_cell(sp.n, i, j, min(sp.m, n_level), ci, cj, w);
                if (corners == 1) {
                    silhouette_value(&sp, i, j, &position, &normal);
                } else {
                    float3 sum = (float3)(0.0f), nsum = (float3)(0.0f);
                    for (int c = 0; c < 3; ++c)
                        if (w[c] != 0.0f) {
                            silhouette_value(&sp, ci[c], cj[c], &position, &normal);
                            sum += w[c] * position;
                            nsum += w[c] * normal;
                        }
                    position = sum;
                    normal = unit_or_zero(nsum);
                }
            }
            put_vertex(out, at, position, normal, x.xy, p, object);
            lod[at++] = sp.s_max;
        }
    }
}
