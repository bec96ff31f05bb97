/* Silhouette refinement, per frame: stage 4 with blended levels (Dyken, Reimers and Seland 2008,
 * section 5, eq. 9-11) on the semi-uniform pattern's layout (patterns/semi_uniform.h; the
 * records come from stages/silhouette_levels.cl).  A vertex p with geometric level s(p) (s_e on
 * the open edge e, the patch's largest s_e inside, eq. 10) is
 *
 *     v = (1 - a) S_k[F](p) + a S_{k+1}[F](p),   k = floor(s(p)), a = s(p) - k    (eq. 9, 11)
 *
 * where S_L[F] interpolates F linearly over the level-L triangle of P^L holding p (on an edge:
 * over the level-L interval of the boundary curve; the patterns are nested, so p is a point of
 * P^ceil(s)).  Normals are blended alike and normalised.  At a = 0 and on the finest level the
 * vertex is F(p) computed exactly as stages/vertices.cl computes it without forward
 * differencing (kind_boundary_point on the ring, kind_eval inside): integer levels give the
 * semi-uniform pattern's vertices bit for bit.  Edge samples interpolate the kind's symmetric
 * boundary points with weights r/d and 1 - r/d, both exact dyadic numbers, so the neighbour,
 * walking the edge the other way, forms the same products and sums them in the other order:
 * the same bits.  blend = 0 (the ablation): v = F(p).  lod: s(p) per vertex. */
#include "criteria/silhouette.h"

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

/* F and N at lattice point (i, j) of the patch's 2^m lattice, accumulated with weight w. */
ALWAYS_INLINE void silhouette_add(__private const kind_patch *patch, int4 f, int i, int j, float w,
                                  __private float3 *position, __private float3 *normal)
{
    if (w == 0.0f)
        return;
    float3 x = pattern_row_point(f, j, i), p, n;
    kind_eval(patch, x, &p, &n);
    *position += w * p;
    *normal += w * n;
}

/* S_level[F] and S_level[N] at interior lattice point (i, j) of n = 2^m (level <= m): over the
 * level's triangle holding it (quad cells split along (0,0)-(1,1), triangle cells as P^m). */
ALWAYS_INLINE void silhouette_interior_sample(__private const kind_patch *patch, int4 f, int n, int i, int j,
                                              int level, __private float3 *position, __private float3 *normal)
{
    int d = n >> level, ci = i / d * d, cj = j / d * d, ri = i % d, rj = j % d;
    if (ri == 0 && rj == 0) {
        kind_eval(patch, pattern_row_point(f, j, i), position, normal);
        return;
    }
    float x = (float)ri / (float)d, y = (float)rj / (float)d;
    *position = (float3)(0.0f);
    *normal = (float3)(0.0f);
#if PATTERN_EDGES == 4
    if (ri >= rj) {
        silhouette_add(patch, f, ci, cj, 1.0f - x, position, normal);
        silhouette_add(patch, f, ci + d, cj, x - y, position, normal);
    } else {
        silhouette_add(patch, f, ci, cj, 1.0f - y, position, normal);
        silhouette_add(patch, f, ci, cj + d, y - x, position, normal);
    }
    silhouette_add(patch, f, ci + d, cj + d, ri >= rj ? y : x, position, normal);
#else
    if (ri + rj <= d) {
        silhouette_add(patch, f, ci, cj, 1.0f - x - y, position, normal);
        silhouette_add(patch, f, ci + d, cj, x, position, normal);
        silhouette_add(patch, f, ci, cj + d, y, position, normal);
    } else {
        silhouette_add(patch, f, ci + d, cj, 1.0f - y, position, normal);
        silhouette_add(patch, f, ci, cj + d, 1.0f - x, position, normal);
        silhouette_add(patch, f, ci + d, cj + d, x + y - 1.0f, position, normal);
    }
#endif
}

/* eq. 9: (1 - a) lo + a hi; the normal renormalised (the finer one where the blend vanishes). */
inline void silhouette_blend(float a, float3 lo, float3 nlo, float3 hi, float3 nhi,
                             __private float3 *position, __private float3 *normal)
{
    *position = (1.0f - a) * lo + a * hi;
    float3 n = unit_or_zero((1.0f - a) * nlo + a * nhi);
    *normal = dot3(n, n) > 0.0f ? n : nhi;
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
    float4 s4 = levels[p];
    float s_edge[4] = {s4.s0, s4.s1, s4.s2, s4.s3};
    float s_max = max(max(s4.s0, s4.s1), max(s4.s2, s4.s3));
    int n = su_size(f);
    float3 position, normal, lo, nlo, hi, nhi;

    for (int e = 0; e < PATTERN_EDGES; ++e) {
        int fe = factor_of(f, e);
        float s = s_edge[e];
        int k_level = (int)floor(s), q = 31 - (int)clz(fe);
        float a = s - (float)k_level;
        for (int k = 0; k < fe; ++k) {
            edge_param t = pattern_ring_param(f, e, k);
            float3 x = pattern_edge_point(e, t);
            if (!blend || k == 0 || ((collapsed >> e) & 1)) {  /* F(p): corners are exact at every level */
                kind_eval(&patch, x, 0, &normal);
                edge_param corner = {0, t.f};
                position = kind_boundary_point(&patch, e, (collapsed >> e) & 1 ? corner : t);
            } else {
                silhouette_edge_sample(&patch, e, k, fe, min(k_level, q), &lo, &nlo);
                if (a > 0.0f) {
                    silhouette_edge_sample(&patch, e, k, fe, min(k_level + 1, q), &hi, &nhi);
                    silhouette_blend(a, lo, nlo, hi, nhi, &position, &normal);
                } else {
                    position = lo;
                    normal = k_level >= q ? nlo : unit_or_zero(nlo);
                }
            }
            put_vertex(out, at, position, normal, x.xy, p, object);
            lod[at++] = s;
        }
    }

    int m = 31 - (int)clz(n), k_level = (int)floor(s_max);
    float a = s_max - (float)k_level;
    int rows = pattern_rows(f);
    for (int j = 1; j <= rows; ++j) {
        int steps = pattern_row(f, j);
        for (int i = 1; i < steps; ++i) {
            float3 x = pattern_row_point(f, j, i);
            if (!blend) {
                kind_eval(&patch, x, &position, &normal);
            } else {
                silhouette_interior_sample(&patch, f, n, i, j, min(k_level, m), &lo, &nlo);
                if (a > 0.0f) {
                    silhouette_interior_sample(&patch, f, n, i, j, min(k_level + 1, m), &hi, &nhi);
                    silhouette_blend(a, lo, nlo, hi, nhi, &position, &normal);
                } else {
                    position = lo;
                    normal = k_level >= m ? nlo : unit_or_zero(nlo);
                }
            }
            put_vertex(out, at, position, normal, x.xy, p, object);
            lod[at++] = s_max;
        }
    }
}
