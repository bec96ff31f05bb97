/* Zheng-Sederberg steps for rational bicubic patches (docs/design.md section 2, with the rational
 * second-derivative bounds of docs/rational-bound.md; host mirror cltess/criteria/zheng_sederberg.py,
 * zs_inverse_steps and zs_steps). */
#ifndef CLTESS_CRITERIA_ZS_H
#define CLTESS_CRITERIA_ZS_H
#include "common.h"

/* Largest x with quadratic x^2 + 2 linear x + offset <= c (a stable root; offset < c). */
inline float largest_step(float quadratic, float linear, float offset, float c)
{
    return (c - offset) / (linear + sqrt(linear * linear + quadratic * (c - offset)));
}

/* Steps with d_uu du^2 + 2 d_uv du dv + d_vv dv^2 <= c and du*dv largest, at most 1
 * (criteria/zheng_sederberg.py, zs_steps): (1, 1) when it meets the bound; else the optimum du/dv = sqrt(d_vv/d_uu),
 * written with s = sqrt(d_uu), t = sqrt(d_vv) so that no 0 * inf appears, and where it lies
 * beyond du = 1 (dv = 1) that step is 1 and the other the largest the bound allows; inputs
 * scaled by their max; NaN -> 0 = saturated. */
inline float2 zs_steps(float d_uu, float d_uv, float d_vv, float c)
{
    if (d_uu + 2.0f * d_uv + d_vv <= c)
        return (float2)(1.0f, 1.0f);
    float scale = max(max(d_uu, d_uv), d_vv);
    float a = d_uu / scale, d = d_uv / scale, b = d_vv / scale;
    c /= scale;
    float du, dv;
    if (a > 0.0f && b > 0.0f) {
        float s = sqrt(a), t = sqrt(b);
        du = sqrt(c * t / (2.0f * s * (s * t + d)));
        dv = sqrt(c * s / (2.0f * t * (s * t + d)));
        if (du > 1.0f) {
            du = 1.0f;
            dv = largest_step(b, d, a, c);
        } else if (dv > 1.0f) {
            du = largest_step(a, d, b, c);
            dv = 1.0f;
        }
    } else if (a > 0.0f) {
        du = largest_step(a, d, 0.0f, c);
        dv = 1.0f;
    } else if (b > 0.0f) {
        du = 1.0f;
        dv = largest_step(b, d, 0.0f, c);
    } else {
        du = dv = sqrt(c / (2.0f * d));
    }
    du = isnan(du) ? 0.0f : min(du, 1.0f);
    dv = isnan(dv) ? 0.0f : min(dv, 1.0f);
    return (float2)(du, dv);
}

/* --- Zheng-Sederberg steps from bounds of p = X / w itself (criteria/zheng_sederberg.py, zs_inverse_steps) ----- */

/* The nets below are kept in the scaled Bernstein basis C(n, i) C(n, j) B_i(u) B_j(v): there a
 * product of polynomials is a plain convolution of the coefficients (Farin), and the ratio N_k / W_k
 * of two (9, 9) nets is the same as in the plain basis (both carry C(9, i) C(9, j)). */

/* d/dt of a cubic written again as a cubic, in the scaled basis: C(3, k) CUBIC_DERIVATIVE[k][m] /
 * C(3, m) (zheng_sederberg.CUBIC_DERIVATIVE), row k of the matrix. */
__constant float SCALED_CUBIC_DERIVATIVE[16] = {-3, 1, 0, 0, -3, -1, 2, 0, 0, -2, 1, 3, 0, 0, -1, 3};

/* out = d/du (along_u) or d/dv of the scaled (3, 3) net a, as a scaled (3, 3) net. */
inline void cubic_derivative(const float4 a[16], int along_u, float4 out[16])
{
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            float4 sum = 0.0f;
            for (int k = 0; k < 4; ++k)
                sum += along_u ? SCALED_CUBIC_DERIVATIVE[4 * i + k] * a[4 * j + k]
                               : SCALED_CUBIC_DERIVATIVE[4 * j + k] * a[4 * k + i];
            out[4 * j + i] = sum;
        }
}

/* out += coef a.w b: scaled nets a of degree (na, na) and b of degree (nb, nb), [j][i] row-major. */
inline void convolve_scaled(const float4 *a, int na, const float4 *b, int nb, float coef, float4 *out)
{
    int stride = na + nb + 1;
    for (int j1 = 0; j1 <= na; ++j1)
        for (int i1 = 0; i1 <= na; ++i1) {
            float x = coef * a[j1 * (na + 1) + i1].w;
            for (int j2 = 0; j2 <= nb; ++j2)
                for (int i2 = 0; i2 <= nb; ++i2)
                    out[(j1 + j2) * stride + i1 + i2] += x * b[j2 * (nb + 1) + i2];
        }
}

/* out += a b for scalar scaled nets a of degree (na, na) and b of degree (nb, nb) (the weights'
 * powers: convolve_scaled's .w alone, in the same order). */
inline void convolve_weights(const float *a, int na, const float *b, int nb, float *out)
{
    int stride = na + nb + 1;
    for (int j1 = 0; j1 <= na; ++j1)
        for (int i1 = 0; i1 <= na; ++i1) {
            float x = a[j1 * (na + 1) + i1];
            for (int j2 = 0; j2 <= nb; ++j2)
                for (int i2 = 0; i2 <= nb; ++i2)
                    out[(j1 + j2) * stride + i1 + i2] += x * b[j2 * (nb + 1) + i2];
        }
}

/* out += (a.w b.xyz - b.w a.xyz, 0) for scaled (3, 3) nets, out (6, 6). */
inline void convolve_wedge(const float4 a[16], const float4 b[16], float4 out[49])
{
    for (int k1 = 0; k1 < 16; ++k1)
        for (int k2 = 0; k2 < 16; ++k2) {
            float4 x = a[k1], y = b[k2];
            out[(k1 / 4 + k2 / 4) * 7 + k1 % 4 + k2 % 4] += (float4)(x.w * y.xyz - y.w * x.xyz, 0.0f);
        }
}

/* The bound's constants of a patch, which depend on the patch alone (criteria/zheng_sederberg.py,
 * zs_constants; docs/rational-bound.md): (M_uu, M_uv, M_vv, alpha).  Equal weights: Lemma 1's
 * M's are 6, 9, 6 times the largest second differences of the points (polynomial
 * Zheng-Sederberg) and alpha = 0 (no Lemma 3).  Rational: the hull points
 * H_k = (N_uu, N_uv, N_vv)_k / W_k of (p_uu, p_uv, p_vv) (Lemma 2: w^3 p_uu = w A_uu - 2 w_u B_u,
 * w^3 p_uv = w A_uv - w_u B_v - w_v B_u, w^3 p_vv likewise, A_ab = w X_ab - w_ab X,
 * B_a = w X_a - w_a X, all (9, 9) Bernstein nets); M_ab = max |H_k.ab|, and Lemma 3's alpha for
 * rho = M_vv / M_uu (0 when M_uu or M_vv is 0).  About 8,000 float4 multiply-adds per rational
 * patch: stage 1 calls it once per patch and scene and keeps the result (kinds/bezier.h). */
inline float4 zs_constants(const float4 b[16])
{
    float3 lo = b[0].xyz / b[0].w, hi = lo;
    int equal_weights = 1;
    for (int k = 1; k < 16; ++k) {
        lo = min(lo, b[k].xyz / b[k].w);
        hi = max(hi, b[k].xyz / b[k].w);
        equal_weights &= b[k].w == b[0].w;
    }
    if (equal_weights) {
        float3 m = 0.0f;  /* .x uu, .y uv, .z vv, of the points */
        float inv_w = 1.0f / b[0].w;
        for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 2; ++i) {
                m.x = max(m.x, length((b[4 * j + i + 2].xyz - 2.0f * b[4 * j + i + 1].xyz + b[4 * j + i].xyz) * inv_w));
                m.z = max(m.z, length((b[4 * (i + 2) + j].xyz - 2.0f * b[4 * (i + 1) + j].xyz + b[4 * i + j].xyz) * inv_w));
            }
        for (int j = 0; j < 3; ++j)
            for (int i = 0; i < 3; ++i)
                m.y = max(m.y, length((b[4 * (j + 1) + i + 1].xyz - b[4 * (j + 1) + i].xyz
                                       - b[4 * j + i + 1].xyz + b[4 * j + i].xyz) * inv_w));
        return (float4)(6.0f * m.x, 9.0f * m.y, 6.0f * m.z, 0.0f);
    }

    float3 centre = 0.5f * (lo + hi);  /* the numerators are translation-invariant: keep X small */
    float4 h[16], h_u[16], h_v[16], second[16];
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {  /* scaled by C(3, i) C(3, j) */
            float binomial = ((i == 1 || i == 2) ? 3.0f : 1.0f) * ((j == 1 || j == 2) ? 3.0f : 1.0f);
            float4 x = b[4 * j + i];
            h[4 * j + i] = binomial * (float4)(x.xyz - x.w * centre, x.w);
        }
    cubic_derivative(h, 1, h_u);
    cubic_derivative(h, 0, h_v);

    float4 b_u[49], b_v[49], a[49], hull[3][100];
    float weight[16], square[49], cube[100];
    for (int k = 0; k < 16; ++k)
        weight[k] = h[k].w;
    for (int k = 0; k < 49; ++k) {
        b_u[k] = b_v[k] = a[k] = 0.0f;
        square[k] = 0.0f;
    }
    for (int k = 0; k < 100; ++k) {
        cube[k] = 0.0f;
        hull[0][k] = hull[1][k] = hull[2][k] = 0.0f;
    }
    convolve_weights(weight, 3, weight, 3, square);  /* w^2 */
    convolve_weights(weight, 3, square, 6, cube);    /* w^3 */
    convolve_wedge(h, h_u, b_u);
    convolve_wedge(h, h_v, b_v);

    float3 m = 0.0f;  /* .x uu, .y uv, .z vv */
    for (int which = 0; which < 3; ++which) {
        float4 *n = hull[which];
        cubic_derivative(which == 2 ? h_v : h_u, which == 0, second);
        for (int k = 0; k < 49; ++k)
            a[k] = 0.0f;
        convolve_wedge(h, second, a);  /* A = w X_ab - w_ab X */
        convolve_scaled(h, 3, a, 6, 1.0f, n);
        if (which != 2)
            convolve_scaled(h_u, 3, which == 0 ? b_u : b_v, 6, which == 0 ? -2.0f : -1.0f, n);
        if (which != 0)
            convolve_scaled(h_v, 3, which == 2 ? b_v : b_u, 6, which == 2 ? -2.0f : -1.0f, n);
        float worst = 0.0f;
        for (int k = 0; k < 100; ++k) {
            n[k] /= cube[k];
            worst = max(worst, length(n[k].xyz));
        }
        if (which == 0) m.x = worst; else if (which == 1) m.y = worst; else m.z = worst;
    }

    float alpha = 0.0f;
    if (m.x > 0.0f && m.z > 0.0f) {  /* Lemma 3 (zheng_sederberg.diagonal_majorant), rho = M_vv / M_uu */
        float rho = m.z / m.x, root_rho = sqrt(rho);
        for (int k = 0; k < 100; ++k) {
            float3 p = 0.5f * (hull[0][k].xyz + hull[2][k].xyz / rho);
            float3 q = 0.5f * (hull[0][k].xyz - hull[2][k].xyz / rho);
            float3 r = hull[1][k].xyz / root_rho;
            float qq = dot(q, q), rr = dot(r, r), qr = dot(q, r), pq = dot(p, q), pr = dot(p, r);
            float s2 = 0.5f * (qq + rr) + sqrt(0.25f * (qq - rr) * (qq - rr) + qr * qr);
            alpha = max(alpha, sqrt(dot(p, p) + 2.0f * sqrt(pq * pq + pr * pr) + s2));
        }
    }
    return (float4)(m, alpha);
}

/* The steps' inverses (1/du, 1/dv) from a patch's constants bound = zs_constants(b) and the
 * tolerance eps (criteria/zheng_sederberg.py, zs_constant_steps): Lemma 1,
 * zs_steps(M_uu, M_uv, M_vv, 8 eps), or, where alpha > 0 and its du*dv is larger, Lemma 3 with
 * rho = M_vv / M_uu: du = sqrt(4 eps / alpha), dv = sqrt(4 eps / (rho alpha)), each at most 1.
 * The part of the bound stage 1 evaluates per tolerance. */
inline float2 zs_constant_steps(float4 bound, float eps)
{
    float2 step = zs_steps(bound.x, bound.y, bound.z, 8.0f * eps);  /* Lemma 1 */
    if (bound.w > 0.0f) {  /* Lemma 3 */
        float rho = bound.z / bound.x, alpha = bound.w;
        float2 diagonal = (float2)(min(sqrt(4.0f * eps / alpha), 1.0f), min(sqrt(4.0f * eps / (rho * alpha)), 1.0f));
        if (diagonal.x * diagonal.y > step.x * step.y)
            step = diagonal;
    }
    return 1.0f / step;
}

#endif
