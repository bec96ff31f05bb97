/* The integral form of the interpolation remainder as a per-triangle bound (issue 9;
 * docs/rational-bound.md, "The integral-form bound in the engine").  NumPy mirror:
 * cltess/criteria/integral.py (pyramid_query, lemma1_box, upper_sum, triangle_bound).
 *
 * For a triangle with corners x_i, barycentric l_i(x), h_i = x_i - x:
 *   |p(x) - l(x)| <= sum_i l_i(x) int_0^1 (1 - t) |D^2 p(x + t h_i)[h_i, h_i]| dt,
 * |D^2 p(xi)[h, h]| <= m_uu h_u^2 + 2 m_uv |h_u h_v| + m_vv h_v^2 with m_ab the hull bound (Lemma 2)
 * of the subpatches meeting a box around xi, read from the patch's majorant pyramid (finest level
 * S x S first, then each coarser level the max of four cells; one float4 (m_uu, m_uv, m_vv, 0) per
 * cell, rows along u).  Upper sums: K^2 sub-triangles P, [0, 1] cut in T = 4K/3 intervals; on
 * P x [t0, t1] l_i <= its max at P's corners, |h_i| <= its max at P's corners per axis, and
 * x + t h_i lies in the box of the six points (1 - t_e) q_a + t_e x_i. */
#ifndef INTEGRAL_BOUND_H
#define INTEGRAL_BOUND_H

#define INTEGRAL_BOX_WIDENING 1e-6f  /* integral.BOX_WIDENING: float32 rounding of a box's corners */
#define INTEGRAL_QUERY_SPAN 4        /* integral.QUERY_SPAN: cells per side looked at, at most */
#define INTEGRAL_BOUND_SAFETY 1.0001f  /* integral.BOUND_SAFETY: the float32 sums' rounding */
#define INTEGRAL_GRADED_SPAN 8       /* integral.GRADED_SPAN: graded cells per side looked at, fewer than */

/* The graded cell holding x: the largest k in [0, count) with breaks[k] <= x (breaks[0] = 0). */
inline int integral_graded_cell(__global const float *breaks, int count, float x)
{
    int lo = 0, hi = count - 1;
    while (lo < hi) {
        int mid = (lo + hi + 1) >> 1;
        if (breaks[mid] <= x)
            lo = mid;
        else
            hi = mid - 1;
    }
    return lo;
}

/* max of (m_uu, m_uv, m_vv) over the cells of a patch's table (integral.patch_table: its pyramid,
 * then count x count graded cells on the breakpoints `breaks`) that the box [lo, hi] meets: the
 * graded cells when it comes within 4/S of an edge and meets fewer than INTEGRAL_GRADED_SPAN of
 * them per side, else the pyramid at the
 * finest level where it spans at most INTEGRAL_QUERY_SPAN cells per side. */
inline float3 integral_query(__global const float4 *pyramid, int levels, __global const float *breaks, int count,
                             float2 lo, float2 hi)
{
    /* the graded cells are finer than the finest subpatches only within 4/S of an edge */
    float edge = 4.0f / (float)(1 << levels);
    int near_edge = fmin(lo.x, lo.y) - INTEGRAL_BOX_WIDENING < edge
                 || fmax(hi.x, hi.y) + INTEGRAL_BOX_WIDENING > 1.0f - edge;
    int gi0 = 0, gj0 = 0, gi1 = count, gj1 = count;
    if (near_edge) {
        gi0 = integral_graded_cell(breaks, count, lo.x - INTEGRAL_BOX_WIDENING);
        gj0 = integral_graded_cell(breaks, count, lo.y - INTEGRAL_BOX_WIDENING);
        gi1 = integral_graded_cell(breaks, count, hi.x + INTEGRAL_BOX_WIDENING);
        gj1 = integral_graded_cell(breaks, count, hi.y + INTEGRAL_BOX_WIDENING);
    }
    if (gi1 - gi0 < INTEGRAL_GRADED_SPAN && gj1 - gj0 < INTEGRAL_GRADED_SPAN) {
        __global const float4 *graded = pyramid + ((1 << (2 * levels + 2)) - 1) / 3;
        float3 g = (float3)(0.0f);
        for (int j = gj0; j <= gj1; ++j)
            for (int i = gi0; i <= gi1; ++i)
                g = fmax(g, graded[j * count + i].xyz);
        return g;
    }
    float side = (float)(1 << levels);
    int top = (1 << levels) - 1;
    int i0 = clamp((int)floor((lo.x - INTEGRAL_BOX_WIDENING) * side), 0, top);
    int j0 = clamp((int)floor((lo.y - INTEGRAL_BOX_WIDENING) * side), 0, top);
    int i1 = clamp((int)floor((hi.x + INTEGRAL_BOX_WIDENING) * side), 0, top);
    int j1 = clamp((int)floor((hi.y + INTEGRAL_BOX_WIDENING) * side), 0, top);
    int offset = 0, n = 1 << levels;
    while (n > 1 && (i1 - i0 >= INTEGRAL_QUERY_SPAN || j1 - j0 >= INTEGRAL_QUERY_SPAN)) {
        offset += n * n;
        n >>= 1;
        i0 >>= 1; i1 >>= 1; j0 >>= 1; j1 >>= 1;
    }
    float3 m = (float3)(0.0f);
    for (int j = j0; j <= j1; ++j)
        for (int i = i0; i <= i1; ++i)
            m = fmax(m, pyramid[offset + j * n + i].xyz);
    return m;
}

/* Lemma 1 with the majorant of the triangle's bounding box. */
inline float integral_lemma1_box(__global const float4 *pyramid, int levels, __global const float *breaks,
                                 int count, float2 x0, float2 x1, float2 x2)
{
    float2 lo = fmin(fmin(x0, x1), x2), hi = fmax(fmax(x0, x1), x2);
    float3 m = integral_query(pyramid, levels, breaks, count, lo, hi);
    float du = hi.x - lo.x + 2.0f * INTEGRAL_BOX_WIDENING, dv = hi.y - lo.y + 2.0f * INTEGRAL_BOX_WIDENING;
    return (m.x * du * du + 2.0f * m.y * du * dv + m.z * dv * dv) / 8.0f;
}

/* One sub-triangle's part: corner x_i's term of the upper sum (q0, q1, q2 the corners of P, lam
 * the max of l_i over them).  Plain variables, no private array: the Intel CPU compiler's
 * vectoriser gave wrong, run-to-run different results with a float2 q[3] here. */
inline float integral_corner_term(__global const float4 *pyramid, int levels, __global const float *breaks,
                                  int count, float2 q0, float2 q1, float2 q2,
                                  float2 x_i, float lam, int t_count)
{
    /* |h_i| at P's corners, plus the widening: the float32 corners q_a are within a few ulp of P's */
    float2 h = fmax(fmax(fabs(x_i - q0), fabs(x_i - q1)), fabs(x_i - q2)) + INTEGRAL_BOX_WIDENING;
    float total = 0.0f;
    for (int s = 0; s < t_count; ++s) {
        float t0 = (float)s / (float)t_count, t1 = (float)(s + 1) / (float)t_count;
        float weight = (t1 - t0) - (t1 * t1 - t0 * t0) / 2.0f;  /* int_t0^t1 (1 - t) dt */
        float2 a0 = (1.0f - t0) * q0 + t0 * x_i, a1 = (1.0f - t1) * q0 + t1 * x_i;
        float2 b0 = (1.0f - t0) * q1 + t0 * x_i, b1 = (1.0f - t1) * q1 + t1 * x_i;
        float2 c0 = (1.0f - t0) * q2 + t0 * x_i, c1 = (1.0f - t1) * q2 + t1 * x_i;
        float2 lo = fmin(fmin(fmin(a0, a1), fmin(b0, b1)), fmin(c0, c1));
        float2 hi = fmax(fmax(fmax(a0, a1), fmax(b0, b1)), fmax(c0, c1));
        float3 m = integral_query(pyramid, levels, breaks, count, lo, hi);
        total += lam * weight * (m.x * h.x * h.x + 2.0f * m.y * h.x * h.y + m.z * h.y * h.y);
    }
    return total;
}

inline float2 integral_sub_corner(int3 c, int k, float2 x0, float2 x1, float2 x2)
{
    return ((float)c.x * x0 + (float)c.y * x1 + (float)c.z * x2) / (float)k;
}

inline float integral_sub_triangle(__global const float4 *pyramid, int levels, __global const float *breaks,
                                   int count, int3 c0, int3 c1, int3 c2, int k,
                                   float2 x0, float2 x1, float2 x2)
{
    float2 q0 = integral_sub_corner(c0, k, x0, x1, x2), q1 = integral_sub_corner(c1, k, x0, x1, x2);
    float2 q2 = integral_sub_corner(c2, k, x0, x1, x2);
    int t_count = 4 * k / 3;
    int3 most = max(max(c0, c1), c2);
    return integral_corner_term(pyramid, levels, breaks, count, q0, q1, q2, x0, (float)most.x / (float)k, t_count)
         + integral_corner_term(pyramid, levels, breaks, count, q0, q1, q2, x1, (float)most.y / (float)k, t_count)
         + integral_corner_term(pyramid, levels, breaks, count, q0, q1, q2, x2, (float)most.z / (float)k, t_count);
}

/* The upper sum over K^2 sub-triangles (row i, then j; the upright one, then the inverted one):
 * their max. */
inline float integral_upper_sum(__global const float4 *pyramid, int levels, __global const float *breaks, int count,
                                int k, float2 x0, float2 x1, float2 x2)
{
    float worst = 0.0f;
    for (int i = 0; i < k; ++i)
        for (int j = 0; j < k - i; ++j) {
            int3 a = (int3)(i, j, k - i - j), b = (int3)(i + 1, j, k - i - j - 1), c = (int3)(i, j + 1, k - i - j - 1);
            worst = fmax(worst, integral_sub_triangle(pyramid, levels, breaks, count, a, b, c, k, x0, x1, x2));
            if (i + j < k - 1) {
                int3 d = (int3)(i + 1, j + 1, k - i - j - 2);
                worst = fmax(worst, integral_sub_triangle(pyramid, levels, breaks, count, b, c, d, k, x0, x1, x2));
            }
        }
    return worst;
}

/* bound * INTEGRAL_BOUND_SAFETY / tolerance: Lemma 1 with the box's majorant, then the upper sums
 * for K = k_first, 2 k_first, ... up to k_last until one is <= tolerance (the smallest found). */
inline float integral_triangle_ratio(__global const float4 *pyramid, int levels, __global const float *breaks,
                                     int count, float2 x0, float2 x1, float2 x2,
                                     float tolerance, int k_first, int k_last)
{
    float best = integral_lemma1_box(pyramid, levels, breaks, count, x0, x1, x2) * INTEGRAL_BOUND_SAFETY;
    for (int k = k_first; k <= k_last && best > tolerance; k *= 2)
        best = fmin(best, integral_upper_sum(pyramid, levels, breaks, count, k, x0, x1, x2) * INTEGRAL_BOUND_SAFETY);
    return best / tolerance;
}

#endif
