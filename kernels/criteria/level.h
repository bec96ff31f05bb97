/* Level functions of the SD-2 pattern (Amresh and Fünfzig, sections 3.1-3.2; docs/sd2.md
 * section 2; NumPy mirror cltess/levels.py): a value per welded vertex, and each edge's real
 * factor from its two ends' values alone, so that the two patches of an edge compute bitwise the
 * same factor and every triangle has at most two different factors (the two edges at one
 * vertex, the tip, share it).  Factors are 16.16 fixed point (common.h FIXED_ONE). */
#ifndef CLTESS_CRITERIA_LEVEL_H
#define CLTESS_CRITERIA_LEVEL_H
#include "common.h"

/* Pinned to cltess.levels.LEVEL_FUNCTIONS / DEPTH_MAPS by tests/test_sd2_levels.py. */
#define LEVEL_DEPTH 1       /* distance to the eye plane, mapped by g1 or g2 */
#define LEVEL_SILHOUETTE 2  /* signed cosine n . (eye - v) / |eye - v| (front: >= 0); section 2 */
#define LEVEL_BOUND 3       /* the largest error-bound factor of the vertex's edges */
#define LEVEL_MAP_LINEAR 0
#define LEVEL_MAP_QUADRATIC 1

/* The value of a welded vertex at p with normal n, camera at eye looking along forward: its
 * depth, or (silhouette) the cosine between its normal and the direction to the eye, whose sign
 * is the paper's front / back class. */
inline float vertex_level(int function, float3 p, float3 n, float3 eye, float3 forward)
{
    if (function == LEVEL_DEPTH)
        return dot3(p - eye, forward);
    float3 view = eye - p;
    float length = sqrt(dot3(view, view));
    return length > 0.0f ? dot3(n, view) / length : 0.0f;
}

/* The silhouette's factor at cosine distance x from the silhouette: high at 0, falling linearly
 * to low at x = band (docs/sd2.md section 2); band 0: low (the paper's classes). */
inline float silhouette_ramp(float x, float band, float low, float high)
{
    return x < band ? high - (high - low) * (x / band) : low;
}

/* Silhouette: an edge is crossed when its ends' classes differ (cosine >= 0: front). */
inline int silhouette_crossed(float a, float b) { return (a >= 0.0f) != (b >= 0.0f); }

/* g1 (linear) or g2 (quadratic) of section 3.2: depth d in [near, far] onto [high, low],
 * clamped outside.  g2 = (high - low) / (near - far)^2 (d - far)^2 + low. */
inline float depth_factor(float d, int map, float near, float far, float low, float high)
{
    float range = far - near;
    float x = range > 0.0f ? clamp((d - near) / range, 0.0f, 1.0f) : 0.0f;
    float y = 1.0f - x;
    return map == LEVEL_MAP_QUADRATIC ? low + (high - low) * (y * y) : high * y + low * x;
}

inline int fixed_factor(float r) { return max((int)rint(r * (float)FIXED_ONE), FIXED_ONE); }

/* The per-corner factor phi (fixed point) of corner c of a triangle whose corners have values
 * value[0..2]: every edge's factor is the larger of its two ends' phi (depth: g of the depth;
 * bound: the odd whole bound; silhouette: high at the corner whose class is the odd one, else
 * the ramp of its own |cosine|, range = (band, -, low, high)). */
inline int level_vertex_factor(int function, const float *value, int c, int map, float4 range)
{
    float a = value[c];
    if (function == LEVEL_DEPTH)
        return fixed_factor(depth_factor(a, map, range.s0, range.s1, range.s2, range.s3));
    if (function == LEVEL_SILHOUETTE) {
        int odd = silhouette_crossed(a, value[(c + 1) % 3]) && silhouette_crossed(a, value[(c + 2) % 3]);
        return fixed_factor(odd ? range.s3 : silhouette_ramp(fabs(a), range.s0, range.s2, range.s3));
    }
    return (int)a * FIXED_ONE;
}

/* The SD-2 pattern's hint for a triangle (patterns/sd2.h sd2_hint; docs/sd2.md section 5):
 * (phi_m << 2) | m, m the corner of the smallest phi (the first such); 0 without phi. */
inline int level_hint(int function, const float *value, int map, float4 range)
{
    int phi[3], m = 0;
    for (int c = 0; c < 3; ++c)
        phi[c] = level_vertex_factor(function, value, c, map, range);
    for (int c = 1; c < 3; ++c)
        if (phi[c] < phi[m])
            m = c;
    return phi[m] > 0 && phi[m] < (1 << 29) ? (phi[m] << 2) | m : 0;
}

/* Edge factor (fixed point) from its ends' values a, b (levels, or odd whole bound factors).
 * depth: g(min(a, b)) = max(g(a), g(b)), g falling; silhouette: high where the classes differ,
 * else the ramp of the smaller |cosine| (continuous: the ramp is high at 0), range.s0 the band. */
inline int level_edge_factor(int function, float a, float b, int map, float4 range)
{
    float near = range.s0, far = range.s1, low = range.s2, high = range.s3;
    if (function == LEVEL_DEPTH)
        return max(fixed_factor(depth_factor(a, map, near, far, low, high)),
                   fixed_factor(depth_factor(b, map, near, far, low, high)));
    if (function == LEVEL_SILHOUETTE)
        return fixed_factor(silhouette_crossed(a, b) ? high
                            : silhouette_ramp(fmin(fabs(a), fabs(b)), range.s0, low, high));
    return (int)fmax(a, b) * FIXED_ONE;
}

#endif
