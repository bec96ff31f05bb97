/* The integral form of the interpolation remainder as a per-triangle bound (issue 9;
 * docs/rational-bound.md, "The integral-form bound in the engine").  NumPy mirror:
 * cltess/criteria/integral.py (pyramid_query, lemma1_box, upper_sum, triangle_bound).
 *
 * For a triangle with corners x_i, barycentric l_i(x), h_i = x_i - x:
 *   |p(x) - l(x)| <= sum_i l_i(x) int_0^1 (1 - t) |D^2 p(x + t h_i)[h_i, h_i]| dt,
 * |D^2 p(xi)[h, h]| <= m_uu h_u^2 + 2 m_uv |h_u h_v| + m_vv h_v^2 with m_ab the hull bound (Lemma 2)
 * of the subpatches meeting a box around xi, read from the patch's majorant pyramid (finest level
 * S x S first, then each coarser level the max of four cells; one float8 per cell, rows along u:
 * integral.FORM_COLUMNS), and also |D^2 p(xi)[h, h]| <= sqrt(Q) with Q the direction-aware quartic
 * bound (integral_direction_form; docs/rational-bound.md, "The direction-aware form per cell"):
 * each term takes the smaller.  Upper sums: K^2 sub-triangles P, [0, 1] cut in T = 4K/3 intervals; on
 * P x [t0, t1] l_i <= its max at P's corners, |h_i| <= its max at P's corners per axis, and
 * x + t h_i lies in the box of the six points (1 - t_e) q_a + t_e x_i. */
#ifndef INTEGRAL_BOUND_H
#define INTEGRAL_BOUND_H

#define INTEGRAL_BOX_WIDENING 1e-6f  /* integral.BOX_WIDENING: float32 rounding of a box's corners */
#define INTEGRAL_QUERY_SPAN 4        /* integral.QUERY_SPAN: cells per side looked at, at most */
#define INTEGRAL_BOUND_SAFETY 1.0001f  /* integral.BOUND_SAFETY: the float32 sums' rounding */
#define INTEGRAL_GRADED_SPAN 8       /* integral.GRADED_SPAN: graded cells per side looked at, fewer than */
#define INTEGRAL_QUARTIC_SLACK 1e-5f  /* integral.QUARTIC_SLACK: the float32 quartic's rounding, times its size */

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

/* max of each column (integral.FORM_COLUMNS) over the cells of a patch's table (integral.patch_table: its pyramid,
 * then count x count graded cells on the breakpoints `breaks`) that the box [lo, hi] meets: the
 * graded cells when it comes within 4/S of an edge and meets fewer than INTEGRAL_GRADED_SPAN of
 * them per side, else the pyramid at the
 * finest level where it spans at most INTEGRAL_QUERY_SPAN cells per side. */
inline float8 integral_query(__global const float8 *pyramid, int levels, __global const float *breaks, int count,
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
        __global const float8 *graded = pyramid + ((1 << (2 * levels + 2)) - 1) / 3;
        float8 g = graded[gj0 * count + gi0];
        for (int j = gj0; j <= gj1; ++j)
            for (int i = gi0; i <= gi1; ++i)
                g = fmax(g, graded[j * count + i]);
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
    float8 m = pyramid[offset + j0 * n + i0];
    for (int j = j0; j <= j1; ++j)
        for (int i = i0; i <= i1; ++i)
            m = fmax(m, pyramid[offset + j * n + i]);
    return m;
}

/* Lemma 1 with the majorant of the triangle's bounding box. */
inline float integral_lemma1_box(__global const float8 *pyramid, int levels, __global const float *breaks,
                                 int count, float2 x0, float2 x1, float2 x2)
{
    float2 lo = fmin(fmin(x0, x1), x2), hi = fmax(fmax(x0, x1), x2);
    float3 m = integral_query(pyramid, levels, breaks, count, lo, hi).s012;
    float du = hi.x - lo.x + 2.0f * INTEGRAL_BOX_WIDENING, dv = hi.y - lo.y + 2.0f * INTEGRAL_BOX_WIDENING;
    return (m.x * du * du + 2.0f * m.y * du * dv + m.z * dv * dv) / 8.0f;
}

/* The monomials' ranges over the box lo <= h <= hi (integral.monomial_ranges, same order):
 * s0 max h_u^4, s1 max h_v^4, s2 s3 min and max h_u^2 h_v^2, s4 s5 of h_u^3 h_v, s6 s7 of h_u h_v^3. */
inline float8 integral_monomials(float2 lo, float2 hi)
{
    float2 square_max = fmax(lo * lo, hi * hi);
    float2 square_min = select(select((float2)(0.0f), hi * hi, hi < 0.0f), lo * lo, lo > 0.0f);
    float2 cube_lo = lo * lo * lo, cube_hi = hi * hi * hi;
    float4 u3v = (float4)(cube_lo.x * lo.y, cube_lo.x * hi.y, cube_hi.x * lo.y, cube_hi.x * hi.y);
    float4 uv3 = (float4)(lo.x * cube_lo.y, hi.x * cube_lo.y, lo.x * cube_hi.y, hi.x * cube_hi.y);
    return (float8)(square_max.x * square_max.x, square_max.y * square_max.y,
                    square_min.x * square_min.y, square_max.x * square_max.y,
                    fmin(fmin(u3v.x, u3v.y), fmin(u3v.z, u3v.w)), fmax(fmax(u3v.x, u3v.y), fmax(u3v.z, u3v.w)),
                    fmin(fmin(uv3.x, uv3.y), fmin(uv3.z, uv3.w)), fmax(fmax(uv3.x, uv3.y), fmax(uv3.z, uv3.w)));
}

/* sqrt of an upper bound of max_k |H_k[h, h]|^2 over a query's cells (m: its column maxima) and
 * the h whose monomial ranges are `mono` (integral.direction_form): each coefficient's range
 * times its monomial's range, the largest product; plus INTEGRAL_QUARTIC_SLACK times the sum of
 * their sizes for the float32 rounding. */
inline float integral_direction_form(float8 m, float8 mono)
{
    float quartic_uu = m.s0 * m.s0 * mono.s0, quartic_vv = m.s2 * m.s2 * mono.s1;
    float e22 = m.s3 >= 0.0f ? m.s3 * mono.s3 : m.s3 * mono.s2;
    float e31 = fmax(fmax(m.s4 * mono.s5, m.s4 * mono.s4), fmax(-m.s5 * mono.s5, -m.s5 * mono.s4));
    float e13 = fmax(fmax(m.s6 * mono.s7, m.s6 * mono.s6), fmax(-m.s7 * mono.s7, -m.s7 * mono.s6));
    float total = quartic_uu + quartic_vv + e22 + e31 + e13;
    float size = quartic_uu + quartic_vv + fabs(e22) + fabs(e31) + fabs(e13);
    return sqrt(fmax(total + INTEGRAL_QUARTIC_SLACK * size, 0.0f));
}

/* One sub-triangle's part: corner x_i's term of the upper sum (q0, q1, q2 the corners of P, lam
 * the max of l_i over them).  Plain variables, no private array: the Intel CPU compiler's
 * vectoriser gave wrong, run-to-run different results with a float2 q[3] here. */
inline float integral_corner_term(__global const float8 *pyramid, int levels, __global const float *breaks,
                                  int count, float2 q0, float2 q1, float2 q2,
                                  float2 x_i, float lam, int t_count)
{
    /* |h_i| at P's corners, plus the widening: the float32 corners q_a are within a few ulp of P's */
    float2 h = fmax(fmax(fabs(x_i - q0), fabs(x_i - q1)), fabs(x_i - q2)) + INTEGRAL_BOX_WIDENING;
    /* the signed box of h_i = x_i - x over P, widened likewise, for the direction-aware form */
    float8 mono = integral_monomials(fmin(fmin(x_i - q0, x_i - q1), x_i - q2) - INTEGRAL_BOX_WIDENING,
                                     fmax(fmax(x_i - q0, x_i - q1), x_i - q2) + INTEGRAL_BOX_WIDENING);
    float total = 0.0f;
    for (int s = 0; s < t_count; ++s) {
        float t0 = (float)s / (float)t_count, t1 = (float)(s + 1) / (float)t_count;
        float weight = (t1 - t0) - (t1 * t1 - t0 * t0) / 2.0f;  /* int_t0^t1 (1 - t) dt */
        float2 a0 = (1.0f - t0) * q0 + t0 * x_i, a1 = (1.0f - t1) * q0 + t1 * x_i;
        float2 b0 = (1.0f - t0) * q1 + t0 * x_i, b1 = (1.0f - t1) * q1 + t1 * x_i;
        float2 c0 = (1.0f - t0) * q2 + t0 * x_i, c1 = (1.0f - t1) * q2 + t1 * x_i;
        float2 lo = fmin(fmin(fmin(a0, a1), fmin(b0, b1)), fmin(c0, c1));
        float2 hi = fmax(fmax(fmax(a0, a1), fmax(b0, b1)), fmax(c0, c1));
        float8 m = integral_query(pyramid, levels, breaks, count, lo, hi);
        float norms = m.s0 * h.x * h.x + 2.0f * m.s1 * h.x * h.y + m.s2 * h.y * h.y;
        total += lam * weight * fmin(norms, integral_direction_form(m, mono));
    }
    return total;
}

inline float2 integral_sub_corner(int3 c, int k, float2 x0, float2 x1, float2 x2)
{
    return ((float)c.x * x0 + (float)c.y * x1 + (float)c.z * x2) / (float)k;
}

inline float integral_sub_triangle(__global const float8 *pyramid, int levels, __global const float *breaks,
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
inline float integral_upper_sum(__global const float8 *pyramid, int levels, __global const float *breaks, int count,
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
inline float integral_triangle_ratio(__global const float8 *pyramid, int levels, __global const float *breaks,
                                     int count, float2 x0, float2 x1, float2 x2,
                                     float tolerance, int k_first, int k_last)
{
    float best = integral_lemma1_box(pyramid, levels, breaks, count, x0, x1, x2) * INTEGRAL_BOUND_SAFETY;
    for (int k = k_first; k <= k_last && best > tolerance; k *= 2)
        best = fmin(best, integral_upper_sum(pyramid, levels, breaks, count, k, x0, x1, x2) * INTEGRAL_BOUND_SAFETY);
    return best / tolerance;
}

#endif
