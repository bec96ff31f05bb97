/* ESC's distance test (Hu et al. 2014, eq. 9) as stage 1 of the pattern "esc": for each
 * candidate k/n of each of the 33 coarse edges, insert it when |V_B - V_S| > eps, V_B the
 * surface point, V_S the point at the same parameter on the chord between the coarse edge's end
 * points on the surface (docs/esc.md, decision 1).  Boundary coarse edges are decided from the
 * boundary curve alone (boundary_point on its 4 controls), in its canonical direction (decision
 * 2), so both patches at an edge decide identically; interior ones by NBM-Horner
 * (kinds/bezier_nbm.h).  Writes the record of patterns/esc.h.  Mirror: cltess/esc/masks.py.
 * Per-patch level (decision 5): the record keeps the lattice of L = max_level, and a patch tests
 * only the candidates of its own level L_p, the coarsest level whose candidates lie on that
 * lattice and whose 3 (L_p + 1) segments per side meet the Zheng-Sederberg factor of the patch
 * (kinds/bezier.h kind_factors, in object space or pixels); the others stay 0.
 * Needs kinds/bezier.h (included before it by stages/factors.cl). */
#ifndef CLTESS_CRITERIA_ESC_DISTANCE_H
#define CLTESS_CRITERIA_ESC_DISTANCE_H
#include "common.h"
#include "kinds/bezier_nbm.h"
#include "patterns/esc.h"

/* Does the canonical direction of the edge with controls c run against c (the lexicographically
 * smaller of c0..c3 and c3..c0, by x, y, z, w)?  Both patches at the edge decide alike. */
inline int esc_edge_reversed(__private const float4 c[4])
{
    for (int k = 0; k < 2; ++k) {
        float4 a = c[k], b = c[3 - k];
        if (a.x != b.x) return b.x < a.x;
        if (a.y != b.y) return b.y < a.y;
        if (a.z != b.z) return b.z < a.z;
        if (a.w != b.w) return b.w < a.w;
    }
    return 0;  /* a palindrome: either direction gives the same points */
}

/* Steps per coarse edge of a patch whose bound asks for `factor` segments per side: the fewest d
 * dividing n = L + 1 (the record's lattice; docs/esc.md decision 5) with 3 d >= factor, else n.
 * Its candidates are those k / n with k d a multiple of n (esc_candidate_tested). */
inline int esc_patch_steps(int factor, int n)
{
    for (int d = 1; d < n; ++d)
        if (n % d == 0 && 3 * d >= factor)
            return d;
    return n;
}

inline int esc_candidate_tested(int k, int steps, int n) { return (k * steps) % n == 0; }

/* L bits of a coarse edge from its surface points: ends p0, p1, candidates at k/n; only those of
 * the patch's level (steps per coarse edge) are tested, the others stay 0. */
inline uint esc_chord_bits(float3 p0, float3 p1, __private const float3 candidate[ESC_MAX_LEVEL], int level,
                           int steps, float eps)
{
    uint bits = 0;
    for (int k = 1; k <= level; ++k) {
        if (!esc_candidate_tested(k, steps, level + 1))
            continue;
        float w1 = (float)k / (float)(level + 1), w0 = (float)(level + 1 - k) / (float)(level + 1);
        float3 chord = p0 * w0 + p1 * w1;  /* commutative per component: the same bits both ways */
        if (length(candidate[k - 1] - chord) > eps)
            bits |= 1u << (k - 1);
    }
    return bits;
}

/* source: the Bezier kind's bound constants (kind_factors), controls: the patches. */
inline int4 esc_factors(__global float4 *source, __global float4 *controls, uint p, tolerance_args tol,
                        int max_factor, int max_level, int *flags)
{
    int4 bound = kind_factors(source, controls, p, tol, max_factor, flags);
    if (*flags & FLAG_CULLED)
        return (int4)(0);
    float4 b[16];
    load_patch(controls, p, b);
    int culled;
    float eps = bezier_tolerance(b, tol, &culled);
    int level = clamp(max_level, 0, ESC_MAX_LEVEL), n = level + 1, m = 3 * n;  /* levels above 3: capped */
    int factor = max(bound.s0, bound.s1), steps = esc_patch_steps(factor, n);
    int poles = 0;  /* bit e: patch edge e is a pole (a boundary curve that is one point) */
    for (int e = 0; e < 4; ++e) {
        float4 c[4];
        edge_controls(b, e, c);
        int point = 1;  /* c_k.xyz / c_k.w all equal, compared by (correctly rounded) products */
        for (int k = 1; k < 4; ++k)
            point &= all(c[k].xyz * c[0].w == c[0].xyz * c[k].w);
        poles |= point << e;
    }
    if (poles)
        steps = n;  /* a patch at a pole: the full level */
    uint full = (1u << level) - 1u;  /* the pole rule: a coarse edge into a pole takes every candidate */
#ifdef ESC_ONE_LEVEL
    steps = n;  /* one level per run, every patch at L (esc.py ESC_ONE_LEVEL: bench/esc.py's baseline) */
#endif
    /* saturated: the bound asks for more than the lattice has (or than max_factor) */
    *flags = (*flags & FLAG_SATURATED) | (factor > m ? FLAG_SATURATED : 0);
    int slots[4];
    /* the boundary: each patch edge's 3 coarse edges from its curve, canonical direction */
    for (int e = 0; e < 4; ++e) {
        float4 c[4], canonical[4];
        edge_controls(b, e, c);
        int reversed = esc_edge_reversed(c);
        for (int k = 0; k < 4; ++k)
            canonical[k] = reversed ? c[3 - k] : c[k];
        uint bits = 0;
        for (int s = 0; s < 3; ++s) {
            edge_param t0 = {s * n, m}, t1 = {s * n + n, m};
            float4 h0 = boundary_point(canonical, t0), h1 = boundary_point(canonical, t1);
            float3 candidate[ESC_MAX_LEVEL];
            for (int k = 1; k <= level; ++k) {
                edge_param t = {s * n + k, m};
                float4 h = boundary_point(canonical, t);
                candidate[k - 1] = h.xyz / h.w;
            }
            uint segment = esc_chord_bits(h0.xyz / h0.w, h1.xyz / h1.w, candidate, level, steps, eps);
            if (poles && esc_pole_edge(esc_boundary_coarse(e, reversed ? 2 - s : s), poles))
                segment = full;
            bits |= segment << (s * level);
        }
        slots[e] = (int)bits | (reversed ? ESC_REVERSED : 0);
    }
    /* the 21 interior coarse edges, by NBM-Horner of the centred patch */
    float4 t[16], nbm[16];
    centred_patch(b, t);
    nbm_matrix(t, nbm);
    ulong interior = 0;
    int slot = 0;
    for (int c = 0; c < 33; ++c) {
        int boundary = (c < 3) || (c >= 9 && c < 15) || (c >= 21 && c < 24);
        if (boundary)
            continue;
        int2 start, end;
        esc_coarse_ends(c, &start, &end);
        float3 p0 = nbm_position(nbm, (float)start.x / 3.0f, (float)start.y / 3.0f);
        float3 p1 = nbm_position(nbm, (float)end.x / 3.0f, (float)end.y / 3.0f);
        float3 candidate[ESC_MAX_LEVEL];
        for (int k = 1; k <= level; ++k) {
            int2 x = n * start + k * (end - start);
            candidate[k - 1] = nbm_position(nbm, (float)x.x / (float)m, (float)x.y / (float)m);
        }
        uint bits = poles && esc_pole_edge(c, poles) ? full : esc_chord_bits(p0, p1, candidate, level, steps, eps);
        interior |= (ulong)bits << (slot * level);
        ++slot;
    }
    int4 f;
    for (int e = 0; e < 4; ++e) {
        int value = slots[e] | (int)(((interior >> (ESC_INTERIOR_BITS * e)) & ((1u << ESC_INTERIOR_BITS) - 1u)) << ESC_INTERIOR_SHIFT)
                    | (level << ESC_LEVEL_SHIFT) | ESC_ALIVE;
        if (e == 0) f.s0 = value; else if (e == 1) f.s1 = value; else if (e == 2) f.s2 = value; else f.s3 = value;
    }
    return f;
}

#endif
