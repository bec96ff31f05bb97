/* The error-hull bound of one triangle of a rational bicubic patch (issue 9; docs/rational-bound.md,
 * "The error-hull bound").  NumPy mirror: cltess/criteria/error_hull.py (triangle_ratio).
 *
 * Corners x_i in (u, v), P_i = p(x_i), l the affine interpolant of the P_i.  On a box B of the
 * domain p - l = (X - w l) / w with X, w the patch's numerator and weight, so with R the (3, 3)
 * homogeneous net restricted to B, L_dc the values of l at B's corners (l is bilinear on B) and
 *   E_ba = sum_{j + d = b, i + c = a} alpha_jd^b alpha_ic^a (R_ji.xyz - R_ji.w L_dc),
 *   W_ba = sum alpha alpha R_ji.w      (the (4, 4) nets of X - w l and of w, degree-elevated;
 *                                       alpha_b0^b = (4 - b) / 4, alpha_(b-1)1^b = b / 4),
 * p - l is the convex combination of the E_ba / W_ba with weights B_ba W_ba / w >= 0 (all
 * W_ba > 0), so |p - l| <= max_ba |E_ba| / W_ba on B.  The triangle's bounding box is the first
 * box; a box over the tolerance is cut in four, down to ERROR_HULL_DEPTH, keeping the quarters
 * that meet the triangle.  float32 throughout, with the rounding allowances of
 * docs/rational-bound.md ("float32 rounding of the error hull"): every term is an upper bound of
 * its float64 value. */
#ifndef ERROR_HULL_H
#define ERROR_HULL_H

#define ERROR_HULL_DEPTH 4            /* error_hull.DEPTH: box halvings, at most */
#define ERROR_HULL_UNIT 5.9604645e-8f  /* error_hull.UNIT: 2^-24, float32's unit roundoff */
#define ERROR_HULL_NET_STEPS 64.0f    /* error_hull.NET_STEPS: |E_ba| and W_ba's rounding, units of W_ba (R + |L|) */
#define ERROR_HULL_WEIGHT_STEPS 32.0f  /* error_hull.WEIGHT_STEPS: W_ba's relative rounding, units */
#define ERROR_HULL_POINT_STEPS 96.0f  /* error_hull.POINT_STEPS: p(x_i)'s rounding, units of its radius */
#define ERROR_HULL_MEET_WIDENING 1e-6f  /* error_hull.MEET_WIDENING: a box is dropped only when this much wider misses */
#define ERROR_HULL_CONDITION 1e-2f    /* error_hull.CONDITION: a triangle with det's rounding over this of det fails */
#define ERROR_HULL_STACK (3 * ERROR_HULL_DEPTH + 1)

/* The cubic Bernstein basis at t: every entry within 7 units of its value (relative). */
inline float4 error_hull_basis(float t)
{
    float s = 1.0f - t;
    return (float4)(s * s * s, 3.0f * s * s * t, 3.0f * s * t * t, t * t * t);
}

/* The rows of the matrix that maps a cubic's Bernstein coefficients on [0, 1] to those of its
 * restriction to [a, b]: row k holds the coefficients of (1 - a + a z)^(3 - k) (1 - b + b z)^k
 * (the blossom at a^(3 - k) b^k); non-negative entries within 7 units of their values. */
inline void error_hull_restriction(float a, float b, float4 *row0, float4 *row1, float4 *row2, float4 *row3)
{
    float sa = 1.0f - a, sb = 1.0f - b;
    float3 qa = (float3)(sa * sa, 2.0f * sa * a, a * a), qb = (float3)(sb * sb, 2.0f * sb * b, b * b);
    *row0 = error_hull_basis(a);
    *row1 = (float4)(qa.x * sb, qa.y * sb + qa.x * b, qa.z * sb + qa.y * b, qa.z * b);
    *row2 = (float4)(qb.x * sa, qb.y * sa + qb.x * a, qb.z * sa + qb.y * a, qb.z * a);
    *row3 = error_hull_basis(b);
}

inline float4 error_hull_row(float4 m, float4 n0, float4 n1, float4 n2, float4 n3)
{
    return m.x * n0 + m.y * n1 + m.z * n2 + m.w * n3;
}

/* p(x) from the patch's 16 homogeneous control points (centred: net[4 j + i], i along u), and in
 * *slack the bound of its float32 rounding (POINT_STEPS units of max_k |X_k| / w_k = radius). */
inline float3 error_hull_point(__global const float4 *net, float2 x, float radius, float *slack)
{
    float4 bu = error_hull_basis(x.x), bv = error_hull_basis(x.y);
    float4 h = bv.x * error_hull_row(bu, net[0], net[1], net[2], net[3])
             + bv.y * error_hull_row(bu, net[4], net[5], net[6], net[7])
             + bv.z * error_hull_row(bu, net[8], net[9], net[10], net[11])
             + bv.w * error_hull_row(bu, net[12], net[13], net[14], net[15]);
    *slack = ERROR_HULL_POINT_STEPS * ERROR_HULL_UNIT * radius;
    return h.xyz / h.w;
}

/* Whether the box [lo, hi] lies strictly on the far side of the line a b from c (all four
 * corners; false for a degenerate triangle, whose inside is 0). */
inline int error_hull_beyond_edge(float2 lo, float2 hi, float2 a, float2 b, float2 c)
{
    float2 n = (float2)(a.y - b.y, b.x - a.x);
    float inside = dot(n, c - a);
    float4 side = (float4)(dot(n, (float2)(lo.x, lo.y) - a), dot(n, (float2)(hi.x, lo.y) - a),
                           dot(n, (float2)(lo.x, hi.y) - a), dot(n, (float2)(hi.x, hi.y) - a));
    return (inside > 0.0f && all(side < 0.0f)) || (inside < 0.0f && all(side > 0.0f));
}

/* Whether the box [lo, hi] can meet the triangle: false only when the box widened by
 * MEET_WIDENING lies strictly outside one of its edges (separating axes; the bounding box's
 * axes hold for every box cut from it). */
inline int error_hull_meets(float2 lo, float2 hi, float2 x0, float2 x1, float2 x2)
{
    lo -= ERROR_HULL_MEET_WIDENING;
    hi += ERROR_HULL_MEET_WIDENING;
    return !(error_hull_beyond_edge(lo, hi, x0, x1, x2) || error_hull_beyond_edge(lo, hi, x1, x2, x0)
             || error_hull_beyond_edge(lo, hi, x2, x0, x1));
}

/* l at the point y (barycentric solve by Cramer's rule on float32 differences) and in *slack a
 * bound of |computed - exact| (docs/rational-bound.md: Delta lambda_j, then the combination). */
inline float3 error_hull_affine(float2 y, float2 x0, float2 x1, float2 x2, float3 p0, float3 d1, float3 d2,
                                float *slack)
{
    const float unit = ERROR_HULL_UNIT;
    float2 e1 = x1 - x0, e2 = x2 - x0, r = y - x0;
    float det = e1.x * e2.y - e1.y * e2.x;
    float det_abs = fabs(e1.x * e2.y) + fabs(e1.y * e2.x);
    float lambda1 = (r.x * e2.y - r.y * e2.x) / det, lambda2 = (e1.x * r.y - e1.y * r.x) / det;
    float n1_abs = fabs(r.x * e2.y) + fabs(r.y * e2.x), n2_abs = fabs(e1.x * r.y) + fabs(e1.y * r.x);
    float delta1 = 2.0f * (4.0f * unit * (n1_abs + fabs(lambda1) * det_abs) / fabs(det) + unit * fabs(lambda1));
    float delta2 = 2.0f * (4.0f * unit * (n2_abs + fabs(lambda2) * det_abs) / fabs(det) + unit * fabs(lambda2));
    float size1 = length(d1), size2 = length(d2);
    *slack = 2.0f * (delta1 * size1 + delta2 * size2
                     + 6.0f * unit * (length(p0) + fabs(lambda1) * size1 + fabs(lambda2) * size2));
    return p0 + lambda1 * d1 + lambda2 * d2;
}

/* max_ba |E_ba| / W_ba on the box [lo, hi] plus the rounding allowances: NET_STEPS units of
 * (radius + max |L|) for E's terms (|R_ji.xyz| <= R_ji.w radius), WEIGHT_STEPS for W's, and
 * the corner values' own rounding (l_slack: |L - l| at the corners bounds it on the box). */
inline float error_hull_box(__global const float4 *net, float radius, float2 lo, float2 hi,
                            float2 x0, float2 x1, float2 x2, float3 p0, float3 d1, float3 d2)
{
    const float unit = ERROR_HULL_UNIT;
    float4 mu0, mu1, mu2, mu3, mv0, mv1, mv2, mv3;
    error_hull_restriction(lo.x, hi.x, &mu0, &mu1, &mu2, &mu3);
    error_hull_restriction(lo.y, hi.y, &mv0, &mv1, &mv2, &mv3);
    float4 along_u[16];  /* [j][a]: each row of the net restricted along u */
    for (int j = 0; j < 4; ++j) {
        float4 n0 = net[4 * j], n1 = net[4 * j + 1], n2 = net[4 * j + 2], n3 = net[4 * j + 3];
        along_u[4 * j] = error_hull_row(mu0, n0, n1, n2, n3);
        along_u[4 * j + 1] = error_hull_row(mu1, n0, n1, n2, n3);
        along_u[4 * j + 2] = error_hull_row(mu2, n0, n1, n2, n3);
        along_u[4 * j + 3] = error_hull_row(mu3, n0, n1, n2, n3);
    }
    float4 rows[4] = {mv0, mv1, mv2, mv3};
    float4 restricted[16];  /* [b][a] */
    for (int b = 0; b < 4; ++b)
        for (int a = 0; a < 4; ++a)
            restricted[4 * b + a] = error_hull_row(rows[b], along_u[a], along_u[4 + a], along_u[8 + a], along_u[12 + a]);
    float slack00, slack01, slack10, slack11;
    float3 corner[4];  /* [d][c]: (lo.x, lo.y), (hi.x, lo.y), (lo.x, hi.y), (hi.x, hi.y) */
    corner[0] = error_hull_affine((float2)(lo.x, lo.y), x0, x1, x2, p0, d1, d2, &slack00);
    corner[1] = error_hull_affine((float2)(hi.x, lo.y), x0, x1, x2, p0, d1, d2, &slack01);
    corner[2] = error_hull_affine((float2)(lo.x, hi.y), x0, x1, x2, p0, d1, d2, &slack10);
    corner[3] = error_hull_affine((float2)(hi.x, hi.y), x0, x1, x2, p0, d1, d2, &slack11);
    float corner_max = fmax(fmax(length(corner[0]), length(corner[1])), fmax(length(corner[2]), length(corner[3])));
    float worst = 0.0f;
    for (int b = 0; b < 5; ++b)
        for (int a = 0; a < 5; ++a) {
            float3 e = (float3)(0.0f);
            float w = 0.0f;
            for (int d = 0; d < 2; ++d) {
                int j = b - d;
                if (j < 0 || j > 3)
                    continue;
                float alpha_v = d ? (float)b / 4.0f : (float)(4 - b) / 4.0f;
                for (int c = 0; c < 2; ++c) {
                    int i = a - c;
                    if (i < 0 || i > 3)
                        continue;
                    float alpha = alpha_v * (c ? (float)a / 4.0f : (float)(4 - a) / 4.0f);
                    float4 r = restricted[4 * j + i];
                    e += alpha * (r.xyz - r.w * corner[2 * d + c]);
                    w += alpha * r.w;
                }
            }
            if (!(w > 0.0f))
                return INFINITY;
            worst = fmax(worst, length(e) * (1.0f + ERROR_HULL_WEIGHT_STEPS * unit) / w);
        }
    float l_slack = fmax(fmax(slack00, slack01), fmax(slack10, slack11));
    return worst * (1.0f + 4.0f * unit) + ERROR_HULL_NET_STEPS * unit * (radius + corner_max) + l_slack;
}

/* bound / tolerance of the triangle x0 x1 x2 of the patch `net` (16 centred homogeneous control
 * points, radius = max_k |X_k| / w_k): the largest over the boxes kept, where every box is within
 * the tolerance; else the first box at the depth limit over it (> 1); INFINITY for a triangle
 * too thin to solve in float32 (CONDITION). */
inline float error_hull_ratio(__global const float4 *net, float radius, float2 x0, float2 x1, float2 x2,
                              float tolerance)
{
    const float unit = ERROR_HULL_UNIT;
    float2 e1 = x1 - x0, e2 = x2 - x0;
    float det = e1.x * e2.y - e1.y * e2.x;
    if (!(8.0f * unit * (fabs(e1.x * e2.y) + fabs(e1.y * e2.x)) < ERROR_HULL_CONDITION * fabs(det)))
        return INFINITY;
    float s0, s1, s2;
    float3 p0 = error_hull_point(net, x0, radius, &s0);
    float3 p1 = error_hull_point(net, x1, radius, &s1);
    float3 p2 = error_hull_point(net, x2, radius, &s2);
    float3 d1 = p1 - p0, d2 = p2 - p0;
    float point_slack = fmax(fmax(s0, s1), s2);  /* |l_computed P - l_P| <= it on the triangle */
    /* the boxes to do (lo.x, lo.y, hi.x, hi.y; halvings): scalar arrays, as Oclgrind's
     * uninitialised-value plugin (unoptimised build) crashed on a private float4 array here */
    float stack_u0[ERROR_HULL_STACK], stack_v0[ERROR_HULL_STACK], stack_u1[ERROR_HULL_STACK], stack_v1[ERROR_HULL_STACK];
    int depth[ERROR_HULL_STACK];
    float2 first_lo = fmin(fmin(x0, x1), x2), first_hi = fmax(fmax(x0, x1), x2);
    stack_u0[0] = first_lo.x;
    stack_v0[0] = first_lo.y;
    stack_u1[0] = first_hi.x;
    stack_v1[0] = first_hi.y;
    depth[0] = 0;
    int top = 1;
    float worst = 0.0f;
    while (top > 0) {
        --top;
        float4 box = (float4)(stack_u0[top], stack_v0[top], stack_u1[top], stack_v1[top]);
        int level = depth[top];
        float ratio = (error_hull_box(net, radius, box.xy, box.zw, x0, x1, x2, p0, d1, d2) + point_slack) / tolerance;
        if (ratio <= 1.0f) {
            worst = fmax(worst, ratio);
            continue;
        }
        if (level == ERROR_HULL_DEPTH)
            return ratio;
        float2 mid = (box.xy + box.zw) * 0.5f;
        for (int q = 0; q < 4; ++q) {  /* (lo, lo), (hi, lo), (lo, hi), (hi, hi) halves in (u, v) */
            float4 quarter = (float4)((q & 1) ? mid.x : box.x, (q & 2) ? mid.y : box.y,
                                      (q & 1) ? box.z : mid.x, (q & 2) ? box.w : mid.y);
            if (error_hull_meets(quarter.xy, quarter.zw, x0, x1, x2)) {
                stack_u0[top] = quarter.x;
                stack_v0[top] = quarter.y;
                stack_u1[top] = quarter.z;
                stack_v1[top] = quarter.w;
                depth[top] = level + 1;
                ++top;
            }
        }
    }
    return worst;
}

#endif
