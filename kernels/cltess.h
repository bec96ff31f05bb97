/* Shared device math of the cltess pipeline: Bernstein bases, rational patch evaluation,
 * Zheng-Sederberg steps and the quad tessellation pattern; PN triangles (control points,
 * evaluation, Filip bounds) and the triangle pattern.  Every stage includes this file;
 * cltess/reference.py is the NumPy mirror of each routine (same names).
 *
 * Quad patch layout: 16 float4 homogeneous control points b[4*j + i] = (w*x, w*y, w*z, w),
 * i along u, j along v.  Edges counter-clockwise: 0: v=0, 1: u=1, 2: v=1, 3: u=0.
 *
 * PN triangle layout (the stage-1 output, also 16 float4; reference.pn_control_points):
 * b[0..9] = b300 b030 b003 b210 b120 b021 b012 b102 b201 b111 (w = 1), b[10..15] = n200 n020
 * n002 n110 n011 n101 (w = 0).  Domain: barycentric (u, v, w = 1-u-v) weighting corners P1, P2,
 * P3; edge e runs from corner e to corner e+1 (0: P1->P2, w=0; 1: P2->P3, u=0; 2: P3->P1, v=0).
 */
#ifndef CLTESS_H
#define CLTESS_H

/* No fused multiply-add: neighbouring patches must evaluate shared boundary points with the
 * same roundings whatever code path (vector lanes or scalar tail) the compiler gives them. */
#pragma OPENCL FP_CONTRACT OFF

#define NORMAL_SHIFT 1.0e-3f     /* reference.NORMAL_SHIFT */
#define NORMAL_DEGENERATE 1.0e-3f /* reference.NORMAL_DEGENERATE */
#define PN_NORMAL_VANISHES 1.0e-5f /* reference.PN_NORMAL_VANISHES */

/* --- Bernstein bases ------------------------------------------------------------------------ */

inline void bernstein3(float t, float b[4])
{
    float s = 1.0f - t;
    b[0] = s * s * s;
    b[1] = 3.0f * t * s * s;
    b[2] = 3.0f * t * t * s;
    b[3] = t * t * t;
}

inline void bernstein2(float t, float b[3])
{
    float s = 1.0f - t;
    b[0] = s * s;
    b[1] = 2.0f * t * s;
    b[2] = t * t;
}

inline void load_patch(__global const float4 *patches, uint p, float4 b[16])
{
    for (int k = 0; k < 16; ++k)
        b[k] = patches[16 * p + k];
}

/* Stages 4 and 5 run on one batch of patches, first_patch .. first_patch + num_patches - 1
 * (scene numbering).  Sets this work-item's patch p and its factors f; 0 when it has nothing
 * to emit (past the batch's end, or culled). */
inline int batch_patch(uint first_patch, uint num_patches, __global const int4 *factors, uint *p, int4 *f)
{
    if (get_global_id(0) >= num_patches)
        return 0;
    *p = first_patch + (uint)get_global_id(0);
    *f = factors[*p];
    return f->s0 > 0;
}

/* --- rational patch evaluation (DESIGN.md section 2) ----------------------------------------- */

/* The patch moved so that its control points' bounding box is centred on the origin:
 * t[k] = (b.xyz - b.w c, b.w).  Returns c.  Tangents t = B_u.xyz - B_u.w p cancel in float32 when
 * |p| is large against the patch; about its own centre they do not (a sphere at (20, 20, 20)
 * had 1% of its normals flipped near the poles before this). */
inline float3 centred_patch(const float4 b[16], float4 t[16])
{
    float3 lo = b[0].xyz / b[0].w, hi = lo;
    for (int k = 1; k < 16; ++k) {
        lo = min(lo, b[k].xyz / b[k].w);
        hi = max(hi, b[k].xyz / b[k].w);
    }
    float3 centre = 0.5f * (lo + hi);
    for (int k = 0; k < 16; ++k)
        t[k] = (float4)(b[k].xyz - b[k].w * centre, b[k].w);
    return centre;
}

/* Collapse the patch to the row v = const: cubic controls c[i] of B(., v) and d[i] of B_v(., v).
 * Derivatives use differences of control points, so a collapsed edge gives exactly zero. */
inline void row_controls(const float4 b[16], float v, float4 c[4], float4 d[4])
{
    float bv[4], dv[3];
    bernstein3(v, bv);
    bernstein2(v, dv);
    for (int i = 0; i < 4; ++i) {
        c[i] = bv[0] * b[i] + bv[1] * b[4 + i] + bv[2] * b[8 + i] + bv[3] * b[12 + i];
        d[i] = 3.0f * (dv[0] * (b[4 + i] - b[i]) + dv[1] * (b[8 + i] - b[4 + i])
                       + dv[2] * (b[12 + i] - b[8 + i]));
    }
}

/* B, B_u, B_v at (u, v) by the tensor-product Bernstein form. */
inline void surface_eval(const float4 b[16], float u, float v, float4 *s, float4 *s_u, float4 *s_v)
{
    float4 c[4], d[4];
    float bu[4], du[3];
    row_controls(b, v, c, d);
    bernstein3(u, bu);
    bernstein2(u, du);
    *s = bu[0] * c[0] + bu[1] * c[1] + bu[2] * c[2] + bu[3] * c[3];
    *s_u = 3.0f * (du[0] * (c[1] - c[0]) + du[1] * (c[2] - c[1]) + du[2] * (c[3] - c[2]));
    *s_v = bu[0] * d[0] + bu[1] * d[1] + bu[2] * d[2] + bu[3] * d[3];
}

/* Unnormalised t_u x t_v with t = (B_d.xyz - B_d.w p) / B.w (the 1/B.w is dropped: same
 * direction).  Sets *ok when it is not (nearly) vanishing. */
inline float3 tangent_cross(float4 s, float4 s_u, float4 s_v, int *ok)
{
    float3 p = s.xyz / s.w;
    float3 t_u = s_u.xyz - s_u.w * p;
    float3 t_v = s_v.xyz - s_v.w * p;
    float3 n = cross(t_u, t_v);
    float scale = dot(t_u, t_u) + dot(t_v, t_v);
    *ok = dot(n, n) > NORMAL_DEGENERATE * NORMAL_DEGENERATE * scale * scale;
    return n;
}

/* Second derivatives B_uu, B_uv, B_vv at (u, v), from second differences of the controls. */
inline void surface_second(const float4 b[16], float u, float v, float4 *s_uu, float4 *s_uv, float4 *s_vv)
{
    float4 c[4], d[4], e[4];
    float bu[4], du[3], bv[2];
    row_controls(b, v, c, d);
    bernstein3(u, bu);
    bernstein2(u, du);
    bv[0] = 1.0f - v;
    bv[1] = v;
    for (int i = 0; i < 4; ++i)  /* controls of B_vv along the row */
        e[i] = 6.0f * (bv[0] * (b[8 + i] - 2.0f * b[4 + i] + b[i])
                       + bv[1] * (b[12 + i] - 2.0f * b[8 + i] + b[4 + i]));
    *s_uu = 6.0f * ((1.0f - u) * (c[2] - 2.0f * c[1] + c[0]) + u * (c[3] - 2.0f * c[2] + c[1]));
    *s_uv = 3.0f * (du[0] * (d[1] - d[0]) + du[1] * (d[2] - d[1]) + du[2] * (d[3] - d[2]));
    *s_vv = bu[0] * e[0] + bu[1] * e[1] + bu[2] * e[2] + bu[3] * e[3];
}

/* Where t_u x t_v vanishes (a collapsed edge), the normal is its first-order term towards the
 * domain centre, d = (1/2 - u, 1/2 - v): D_d(T_u x T_v) = D_d T_u x T_v + T_u x D_d T_v with
 * T = B_d.xyz - B_d.w p and D_d p = (d_u T_u + d_v T_v) / B.w (DESIGN.md section 2: "the
 * next-order term").  Second derivatives, not a step inwards: the edge's own float32 noise
 * (its control points are only nearly equal once far from the origin) stays negligible. */
inline float3 limit_normal(const float4 b[16], float u, float v, float4 s, float4 s_u, float4 s_v)
{
    float4 s_uu, s_uv, s_vv;
    surface_second(b, u, v, &s_uu, &s_uv, &s_vv);
    float d_u = 0.5f - u, d_v = 0.5f - v;
    float3 p = s.xyz / s.w;
    float3 t_u = s_u.xyz - s_u.w * p, t_v = s_v.xyz - s_v.w * p;
    float3 dp = (d_u * t_u + d_v * t_v) / s.w;
    float4 ds_u = d_u * s_uu + d_v * s_uv, ds_v = d_u * s_uv + d_v * s_vv;
    float3 dt_u = ds_u.xyz - ds_u.w * p - s_u.w * dp;
    float3 dt_v = ds_v.xyz - ds_v.w * p - s_v.w * dp;
    return cross(dt_u, t_v) + cross(t_u, dt_v);
}

/* Unit normal at (u, v), given B, B_u, B_v there: t_u x t_v, or at a collapsed edge its limit
 * (limit_normal); if that vanishes too, a step towards the centre; else +z. */
inline float3 surface_normal(const float4 b[16], float u, float v, float4 s, float4 s_u, float4 s_v)
{
    int ok;
    float3 n = tangent_cross(s, s_u, s_v, &ok);
    if (!ok) {
        float3 limit = limit_normal(b, u, v, s, s_u, s_v);
        if (dot(limit, limit) > dot(n, n)) {
            n = limit;
        } else {
            surface_eval(b, u + NORMAL_SHIFT * (0.5f - u), v + NORMAL_SHIFT * (0.5f - v), &s, &s_u, &s_v);
            n = tangent_cross(s, s_u, s_v, &ok);
        }
    }
    float len = length(n);
    return len > 0.0f ? n / len : (float3)(0.0f, 0.0f, 1.0f);
}

/* The 4 control points of edge e, counter-clockwise (cltess/scene.py, boundary_curves). */
inline void edge_controls(const float4 b[16], int e, float4 c[4])
{
    for (int k = 0; k < 4; ++k) {
        int idx = e == 0 ? k : e == 1 ? 4 * k + 3 : e == 2 ? 15 - k : 12 - 4 * k;
        c[k] = b[idx];
    }
}

inline float4 lerp4(float4 a, float4 b, float t) { return a + t * (b - a); }

/* Point k of f on a boundary curve, placed symmetrically about the midpoint: de Casteljau
 * from the nearer end, and at the midpoint the commutative (a + b) / 2.  A neighbour walking
 * the shared curve the other way gets bitwise the same point (Mesa's tessellator does the
 * same for D3D11 patterns).  k = 0 returns the end control point exactly. */
inline float4 boundary_point(const float4 c[4], int k, int f)
{
    /* The corner itself, bit for bit: c0 + 0 * (c1 - c0) turns a -0.0 of c0 into +0.0 or not
     * depending on c1, which differs between the patches meeting there. */
    if (k == 0)
        return c[0];
    float4 q[4];
    int forward = 2 * k < f;
    for (int i = 0; i < 4; ++i)
        q[i] = forward ? c[i] : c[3 - i];
    if (2 * k == f) {
        for (int level = 3; level > 0; --level)
            for (int i = 0; i < level; ++i)
                q[i] = (q[i] + q[i + 1]) * 0.5f;
    } else {
        float t = (float)min(k, f - k) / (float)f;
        for (int level = 3; level > 0; --level)
            for (int i = 0; i < level; ++i)
                q[i] = lerp4(q[i], q[i + 1], t);
    }
    return q[0];
}

/* Domain parameters of point k of f on edge e. */
inline float2 edge_uv(int e, int k, int f)
{
    float t = (float)k / (float)f;
    return e == 0 ? (float2)(t, 0.0f) : e == 1 ? (float2)(1.0f, t)
         : e == 2 ? (float2)(1.0f - t, 1.0f) : (float2)(0.0f, 1.0f - t);
}

/* --- Zheng-Sederberg steps (DESIGN.md section 2) ---------------------------------------------- */

/* Largest x with quadratic x^2 + 2 linear x + offset <= c (a stable root; offset < c). */
inline float largest_step(float quadratic, float linear, float offset, float c)
{
    return (c - offset) / (linear + sqrt(linear * linear + quadratic * (c - offset)));
}

/* Steps with d_uu du^2 + 2 d_uv du dv + d_vv dv^2 <= c and du*dv largest, at most 1
 * (reference.zs_steps): (1, 1) when it meets the bound; else the optimum du/dv = sqrt(d_vv/d_uu),
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

/* --- Zheng-Sederberg steps from bounds of p = X / w itself (reference.zs_inverse_steps) ----- */

/* The nets below are kept in the scaled Bernstein basis C(n, i) C(n, j) B_i(u) B_j(v): there a
 * product of polynomials is a plain convolution of the coefficients (Farin), and the ratio N_k / W_k
 * of two (9, 9) nets is the same as in the plain basis (both carry C(9, i) C(9, j)). */

/* d/dt of a cubic written again as a cubic, in the scaled basis: C(3, k) CUBIC_DERIVATIVE[k][m] /
 * C(3, m) (reference.CUBIC_DERIVATIVE), row k of the matrix. */
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

/* out += (a.w b.xyz - b.w a.xyz, 0) for scaled (3, 3) nets, out (6, 6). */
inline void convolve_wedge(const float4 a[16], const float4 b[16], float4 out[49])
{
    for (int k1 = 0; k1 < 16; ++k1)
        for (int k2 = 0; k2 < 16; ++k2) {
            float4 x = a[k1], y = b[k2];
            out[(k1 / 4 + k2 / 4) * 7 + k1 % 4 + k2 % 4] += (float4)(x.w * y.xyz - y.w * x.xyz, 0.0f);
        }
}

/* The steps' inverses (1/du, 1/dv) for a patch and tolerance eps (reference.zs_inverse_steps,
 * docs/rational-bound.md).  Equal weights: Lemma 1 with 6, 9, 6 times the largest second
 * differences of the points (polynomial Zheng-Sederberg).  Rational: the hull points
 * H_k = (N_uu, N_uv, N_vv)_k / W_k of (p_uu, p_uv, p_vv) (Lemma 2: w^3 p_uu = w A_uu - 2 w_u B_u,
 * w^3 p_uv = w A_uv - w_u B_v - w_v B_u, w^3 p_vv likewise, A_ab = w X_ab - w_ab X,
 * B_a = w X_a - w_a X, all (9, 9) Bernstein nets); steps from Lemma 1 with M_ab = max |H_k.ab|,
 * or from Lemma 3 (alpha h_u^2 + gamma h_v^2 majorises every |H_k[h, h]|) when those are larger. */
inline float2 zs_inverse_steps(const float4 b[16], float eps)
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
        return 1.0f / zs_steps(6.0f * m.x, 9.0f * m.y, 6.0f * m.z, 8.0f * eps);
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
    float cube[100];
    for (int k = 0; k < 49; ++k)
        b_u[k] = b_v[k] = a[k] = 0.0f;
    for (int k = 0; k < 100; ++k)
        hull[0][k] = 0.0f;
    convolve_scaled(h, 3, h, 3, 1.0f, a);        /* w^2 in .w */
    convolve_scaled(h, 3, a, 6, 1.0f, hull[0]);  /* w^3 in .w */
    for (int k = 0; k < 100; ++k) {
        cube[k] = hull[0][k].w;
        hull[0][k] = hull[1][k] = hull[2][k] = 0.0f;
    }
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
    float2 step = zs_steps(m.x, m.y, m.z, 8.0f * eps);  /* Lemma 1 */

    if (m.x > 0.0f && m.z > 0.0f) {  /* Lemma 3 (reference.diagonal_majorant), rho = M_vv / M_uu */
        float rho = m.z / m.x, root_rho = sqrt(rho), alpha = 0.0f;
        for (int k = 0; k < 100; ++k) {
            float3 p = 0.5f * (hull[0][k].xyz + hull[2][k].xyz / rho);
            float3 q = 0.5f * (hull[0][k].xyz - hull[2][k].xyz / rho);
            float3 r = hull[1][k].xyz / root_rho;
            float qq = dot(q, q), rr = dot(r, r), qr = dot(q, r), pq = dot(p, q), pr = dot(p, r);
            float s2 = 0.5f * (qq + rr) + sqrt(0.25f * (qq - rr) * (qq - rr) + qr * qr);
            alpha = max(alpha, sqrt(dot(p, p) + 2.0f * sqrt(pq * pq + pr * pr) + s2));
        }
        float2 diagonal = (float2)(min(sqrt(4.0f * eps / alpha), 1.0f), min(sqrt(4.0f * eps / (rho * alpha)), 1.0f));
        if (diagonal.x * diagonal.y > step.x * step.y)
            step = diagonal;
    }
    return 1.0f / step;
}

/* --- the quad pattern (DESIGN.md section 5, reference.quad_pattern) ---------------------------- */

/* Core grid factors: the regular grid when uniform, else the inner grid of the ring pattern. */
inline int2 quad_core(int4 f, int *uniform)
{
    *uniform = f.s0 == f.s2 && f.s1 == f.s3;
    if (*uniform)
        return (int2)(f.s0, f.s1);
    return (int2)(max(min(f.s0, f.s2), 2), max(min(f.s1, f.s3), 2));
}

inline int factor_of(int4 f, int e) { return e == 0 ? f.s0 : e == 1 ? f.s1 : e == 2 ? f.s2 : f.s3; }

inline uint quad_vertex_count(int4 f)
{
    int uniform;
    if (f.s0 <= 0)
        return 0;
    int2 core = quad_core(f, &uniform);
    return (uint)(f.s0 + f.s1 + f.s2 + f.s3 + (core.x - 1) * (core.y - 1));
}

/* Local vertex numbers: the boundary ring first, then the inner grid row by row. */
inline uint ring_index(int4 f, int e, int k)
{
    int ring = f.s0 + f.s1 + f.s2 + f.s3;
    int base = e == 0 ? 0 : e == 1 ? f.s0 : e == 2 ? f.s0 + f.s1 : f.s0 + f.s1 + f.s2;
    return (uint)((base + k) % ring);
}

inline uint inner_index(int4 f, int2 core, int i, int j)
{
    return (uint)(f.s0 + f.s1 + f.s2 + f.s3 + (j - 1) * (core.x - 1) + (i - 1));
}

inline uint grid_index(int4 f, int2 core, int i, int j)
{
    if (j == 0) return ring_index(f, 0, i);
    if (i == core.x) return ring_index(f, 1, j);
    if (j == core.y) return ring_index(f, 2, core.x - i);
    if (i == 0) return ring_index(f, 3, core.y - j);
    return inner_index(f, core, i, j);
}

/* Point k of the inner polyline that faces edge e, counter-clockwise. */
inline uint inner_edge_index(int4 f, int2 core, int e, int k)
{
    int a = core.x, b = core.y;
    return e == 0 ? inner_index(f, core, 1 + k, 1)
         : e == 1 ? inner_index(f, core, a - 1, 1 + k)
         : e == 2 ? inner_index(f, core, a - 1 - k, b - 1)
         : inner_index(f, core, 1, b - 1 - k);
}

/* One triangle: written when out is not null, always counted. */
inline void put_triangle(__global uint *out, uint *count, uint base, uint a, uint b, uint c)
{
    if (out) {
        out[3 * *count + 0] = base + a;
        out[3 * *count + 1] = base + b;
        out[3 * *count + 2] = base + c;
    }
    ++*count;
}

inline void grid_cells(__global uint *out, uint *count, uint base, int4 f, int2 core,
                       int i0, int i1, int j0, int j1)
{
    for (int j = j0; j < j1; ++j)
        for (int i = i0; i < i1; ++i) {
            uint a = grid_index(f, core, i, j), b = grid_index(f, core, i + 1, j);
            uint c = grid_index(f, core, i + 1, j + 1), d = grid_index(f, core, i, j + 1);
            put_triangle(out, count, base, a, b, c);
            put_triangle(out, count, base, a, c, d);
        }
}

/* The quad pattern's triangles, in "count" mode (out == 0) or "emit" mode (out != 0): one
 * routine, so the counts of stage 3 and the indices of stage 5 cannot disagree.  Returns the
 * number of triangles; vertex numbers are offset by base. */
inline uint quad_triangles(int4 f, __global uint *out, uint base)
{
    uint count = 0;
    int uniform;
    if (f.s0 <= 0)
        return 0;
    int2 core = quad_core(f, &uniform);
    if (uniform) {
        grid_cells(out, &count, base, f, core, 0, core.x, 0, core.y);
        return count;
    }
    grid_cells(out, &count, base, f, core, 1, core.x - 1, 1, core.y - 1);
    /* Transition strips (CudaTess section 3, Moreton 2001): between an edge's f_e segments and
     * the facing inner polyline's core-2 segments, advance the side whose next segment's
     * midpoint comes first: (o + 1/2) / f_e <= (k + 3/2) / core, in integers. */
    for (int e = 0; e < 4; ++e) {
        int outer_n = factor_of(f, e), along = (e % 2 == 0) ? core.x : core.y, inner_n = along - 2;
        int o = 0, k = 0;
        while (o < outer_n || k < inner_n) {
            if (k == inner_n || (o < outer_n && (2 * o + 1) * along <= (2 * k + 3) * outer_n)) {
                put_triangle(out, &count, base, ring_index(f, e, o), ring_index(f, e, o + 1),
                             inner_edge_index(f, core, e, k));
                ++o;
            } else {
                put_triangle(out, &count, base, ring_index(f, e, o), inner_edge_index(f, core, e, k + 1),
                             inner_edge_index(f, core, e, k));
                ++k;
            }
        }
    }
    return count;
}

/* --- PN triangles (DESIGN.md section 3, reference.pn_*) --------------------------------------- */

/* Index of the cubic control point b_ijk (k = 3-i-j) and of the quadratic normal control n_ijk
 * (k = 2-i-j) in the 16-float4 PN layout above. */
__constant int PN_CUBIC[16] = {2, 6, 5, 1, 7, 9, 4, -1, 8, 3, -1, -1, 0, -1, -1, -1};
__constant int PN_QUADRATIC[9] = {12, 14, 11, 15, 13, -1, 10, -1, -1};

inline float dot3(float3 a, float3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

inline float3 unit_or_zero(float3 a)
{
    float len = sqrt(dot3(a, a));
    return len > 0.0f ? a / len : (float3)(0.0f);
}

/* The inner control point of a boundary curve next to its end p_near (Vlachos et al.):
 * (2 p_near + p_far - ((p_far - p_near) . n_near) n_near) / 3.  One expression with the dot
 * product written out, so that the two triangles sharing an edge, which meet it from opposite
 * ends, compute bitwise the same point.  n_near = 0 gives the straight edge's third point. */
inline float3 pn_edge_control(float3 p_near, float3 p_far, float3 n_near)
{
    float w = dot3(p_far - p_near, n_near);
    return (2.0f * p_near + p_far - w * n_near) / 3.0f;
}

/* n_ij of the quadratic normal field: normalize(N_i + N_j - v_ij (P_j - P_i)),
 * v_ij = 2 (P_j - P_i).(N_i + N_j) / |P_j - P_i|^2 (0 on a zero-length edge). */
inline float3 pn_mid_normal(float3 p_i, float3 p_j, float3 n_i, float3 n_j)
{
    float3 d = p_j - p_i;
    float len2 = dot3(d, d);
    float v = len2 > 0.0f ? 2.0f * dot3(d, n_i + n_j) / len2 : 0.0f;
    return unit_or_zero(n_i + n_j - v * d);
}

/* Stage 1's PN control points from one triangle's input (12 float4, Tessellator's PN upload):
 * in[0..2] positions P1 P2 P3, in[3..5] vertex normals N1 N2 N3 (the normal field), in[6..11]
 * the normals each boundary curve uses at its two ends, edge e at in[6 + 2e] (start, corner e)
 * and in[7 + 2e] (end, corner e+1): the vertex normals, or 0 for a straight edge, or the
 * average over the triangles at a sharp edge (cltess/adjacency.py, pn_edge_normals). */
inline void pn_control_points(const float4 in[12], float4 b[16])
{
    for (int c = 0; c < 3; ++c)
        b[c] = (float4)(in[c].xyz, 1.0f);
    float3 sum = (float3)(0.0f);
    __attribute__((opencl_unroll_hint))
    for (int e = 0; e < 3; ++e) {
        float3 p = in[e].xyz, q = in[(e + 1) % 3].xyz;
        float3 near = pn_edge_control(p, q, in[6 + 2 * e].xyz);
        float3 far = pn_edge_control(q, p, in[7 + 2 * e].xyz);
        b[3 + 2 * e] = (float4)(near, 1.0f);
        b[4 + 2 * e] = (float4)(far, 1.0f);
        sum += near + far;
    }
    float3 mean_edge = sum / 6.0f;
    float3 centre = (in[0].xyz + in[1].xyz + in[2].xyz) / 3.0f;
    b[9] = (float4)(mean_edge + (mean_edge - centre) / 2.0f, 1.0f);
    __attribute__((opencl_unroll_hint))
    for (int c = 0; c < 3; ++c) {
        b[10 + c] = (float4)(in[3 + c].xyz, 0.0f);
        b[13 + c] = (float4)(pn_mid_normal(in[c].xyz, in[(c + 1) % 3].xyz, in[3 + c].xyz,
                                           in[3 + (c + 1) % 3].xyz), 0.0f);
    }
}

/* The 4 control points of edge e's boundary curve, from corner e to corner e+1. */
inline void pn_edge_curve(const float4 b[16], int e, float4 c[4])
{
    c[0] = b[e];
    c[1] = b[3 + 2 * e];
    c[2] = b[4 + 2 * e];
    c[3] = b[(e + 1) % 3];
}

/* Bounds of the second directional derivatives |D_{d_a} D_{d_b} b| over the triangle, d_e the
 * domain direction of edge e (corner e to corner e+1): D_{da,db} b = 6 sum_{|I|=1}
 * (Delta_a Delta_b b)_I B1_I with Delta_e b_I = b_{I+e_{e+1}} - b_{I+e_e}, bounded by the
 * largest of its three control points (DESIGN.md section 3).  Returns d[3 * a + b]. */
inline void pn_second_derivative_bounds(const float4 b[16], float d[9])
{
    __attribute__((opencl_unroll_hint))
    for (int a = 0; a < 3; ++a)
        __attribute__((opencl_unroll_hint))
        for (int c = a; c < 3; ++c) {
            float worst = 0.0f;
            __attribute__((opencl_unroll_hint))
            for (int base = 0; base < 3; ++base) {
                float3 sum = (float3)(0.0f);
                __attribute__((opencl_unroll_hint))
                for (int s = 0; s < 4; ++s) {  /* (+e_{a+1} or +e_a) + (+e_{c+1} or +e_c) */
                    int x = (s & 1) ? a : (a + 1) % 3, y = (s & 2) ? c : (c + 1) % 3;
                    int idx[3] = {0, 0, 0};
                    idx[base] += 1;
                    idx[x] += 1;
                    idx[y] += 1;
                    float sign = ((s & 1) ^ ((s >> 1) & 1)) ? -1.0f : 1.0f;
                    sum += sign * b[PN_CUBIC[4 * idx[0] + idx[1]]].xyz;
                }
                worst = max(worst, length(sum));
            }
            d[3 * a + c] = d[3 * c + a] = 6.0f * worst;
        }
}

/* Cubic and quadratic Bernstein-triangle sums at barycentric (u, v, w). */
inline float3 pn_position(const float4 b[16], float3 t)
{
    float u = t.x, v = t.y, w = t.z;
    return u * u * u * b[0].xyz + v * v * v * b[1].xyz + w * w * w * b[2].xyz
         + 3.0f * (u * u * v * b[3].xyz + u * v * v * b[4].xyz + v * v * w * b[5].xyz
                   + v * w * w * b[6].xyz + u * w * w * b[7].xyz + u * u * w * b[8].xyz)
         + 6.0f * u * v * w * b[9].xyz;
}

inline float3 pn_normal_field(const float4 b[16], float3 t)
{
    float u = t.x, v = t.y, w = t.z;
    return u * u * b[10].xyz + v * v * b[11].xyz + w * w * b[12].xyz
         + 2.0f * (u * v * b[13].xyz + v * w * b[14].xyz + u * w * b[15].xyz);
}

/* The unit normal from the normal field; where it vanishes, the flat triangle's normal. */
inline float3 pn_unit_normal(const float4 b[16], float3 n)
{
    if (dot3(n, n) > PN_NORMAL_VANISHES * PN_NORMAL_VANISHES)
        return unit_or_zero(n);
    float3 face = unit_or_zero(cross(b[1].xyz - b[0].xyz, b[2].xyz - b[0].xyz));
    return dot3(face, face) > 0.0f ? face : (float3)(0.0f, 0.0f, 1.0f);
}

/* Blossoms (polar forms) of the cubic and of the normal field at barycentric points: the
 * Bezier controls of the patch restricted to the segment from x to y are B(x,x,x), B(x,x,y),
 * B(x,y,y), B(y,y,y) (forward differencing along rows, DESIGN.md section 6). */
inline float4 pn_blossom3(const float4 b[16], float3 x, float3 y, float3 z)
{
    float4 q[6];  /* quadratic level, |I| = 2, in PN_QUADRATIC order minus 10 */
    for (int i = 0; i <= 2; ++i)
        for (int j = 0; i + j <= 2; ++j)
            q[PN_QUADRATIC[3 * i + j] - 10] = x.x * b[PN_CUBIC[4 * (i + 1) + j]]
                + x.y * b[PN_CUBIC[4 * i + j + 1]] + x.z * b[PN_CUBIC[4 * i + j]];
    float4 l[3];  /* linear level: (1,0,0), (0,1,0), (0,0,1) */
    l[0] = y.x * q[0] + y.y * q[3] + y.z * q[5];
    l[1] = y.x * q[3] + y.y * q[1] + y.z * q[4];
    l[2] = y.x * q[5] + y.y * q[4] + y.z * q[2];
    return z.x * l[0] + z.y * l[1] + z.z * l[2];
}

inline float4 pn_blossom2(const float4 b[16], float3 x, float3 y)
{
    float4 l[3];
    l[0] = x.x * b[10] + x.y * b[13] + x.z * b[15];
    l[1] = x.x * b[13] + x.y * b[11] + x.z * b[14];
    l[2] = x.x * b[15] + x.y * b[14] + x.z * b[12];
    return y.x * l[0] + y.y * l[1] + y.z * l[2];
}

/* --- the triangle pattern (DESIGN.md section 5, reference.tri_pattern) ------------------------ */

/* Core factor N = the largest edge factor (CudaTess section 4).  Vertex layout, boundary
 * first: the ring of f0 + f1 + f2 points counter-clockwise from P1 (edge e, point k at
 * t = k / f_e), then the interior grid points (i/N, j/N), i, j, k >= 1, in rows j = 1..N-2,
 * i = 1..N-1-j.  All of the factor-N grid's interior points are vertices whatever the edges. */
inline int tri_core(int4 f) { return max(max(f.s0, f.s1), f.s2); }

inline uint tri_vertex_count(int4 f)
{
    if (f.s0 <= 0)
        return 0;
    int n = tri_core(f);
    return (uint)(f.s0 + f.s1 + f.s2 + (n - 1) * (n - 2) / 2);
}

inline uint tri_ring_index(int4 f, int e, int k)
{
    int ring = f.s0 + f.s1 + f.s2;
    int base = e == 0 ? 0 : e == 1 ? f.s0 : f.s0 + f.s1;
    return (uint)((base + k) % ring);
}

inline uint tri_interior_index(int4 f, int n, int i, int j)
{
    return (uint)(f.s0 + f.s1 + f.s2 + (j - 1) * (2 * n - 2 - j) / 2 + (i - 1));
}

/* Grid point (i, j, n-i-j) of the factor-n grid: a corner, a point of an edge whose factor is
 * n (the pattern uses no other boundary grid points), or an interior point. */
inline uint tri_grid_index(int4 f, int n, int i, int j)
{
    int k = n - i - j;
    if (i == n) return 0;
    if (j == n) return (uint)f.s0;
    if (k == n) return (uint)(f.s0 + f.s1);
    if (k == 0) return tri_ring_index(f, 0, j);
    if (i == 0) return tri_ring_index(f, 1, k);
    if (j == 0) return tri_ring_index(f, 2, i);
    return tri_interior_index(f, n, i, j);
}

/* Point m (0..n-1, along the edge's direction) of the grid row one step inside edge e. */
inline uint tri_row_index(int4 f, int n, int e, int m)
{
    int c[3];
    c[e] = n - 1 - m;
    c[(e + 1) % 3] = m;
    c[(e + 2) % 3] = 1;
    return tri_grid_index(f, n, c[0], c[1]);
}

/* The triangle pattern's triangles, in "count" mode (out == 0) or "emit" mode (out != 0), like
 * quad_triangles.  The uniform core is the regular factor-N grid less the band along each edge
 * whose factor is below N (a transition edge; at most two, since one edge has N).  Each
 * transition band is stitched between the edge's f_e segments and the grid row inside it,
 * advancing the side whose next segment midpoint comes first, with the row's points placed at
 * (m + 1/2) / N (midway between their two projections onto the edge):
 * (o + 1/2) / f_e <= (m + 1) / N, in integers.  With two transition edges, each row stops
 * where the two rows cross (the paper's modification: the row runs on the extended core grid,
 * less its first, virtual segment).  Factors (1, 1, 1) give the triangle (P1, P2, P3). */
inline uint tri_triangles(int4 f, __global uint *out, uint base)
{
    uint count = 0;
    if (f.s0 <= 0)
        return 0;
    int n = tri_core(f);
    int t[3] = {f.s0 < n, f.s1 < n, f.s2 < n};
    /* The core: the regular grid of factor m on the points whose coordinate (e+2)%3, which is 0
     * on edge e, is at least t[e]; up and down triangles, counter-clockwise. */
    int m = n - t[0] - t[1] - t[2];
    for (int j = 0; j < m; ++j)
        for (int i = 0; i + j < m; ++i) {
            int a = t[1] + i, b = t[2] + j;  /* grid point (a, b, n-a-b) */
            put_triangle(out, &count, base, tri_grid_index(f, n, a + 1, b),
                         tri_grid_index(f, n, a, b + 1), tri_grid_index(f, n, a, b));
            if (i + j < m - 1)
                put_triangle(out, &count, base, tri_grid_index(f, n, a + 1, b),
                             tri_grid_index(f, n, a + 1, b + 1), tri_grid_index(f, n, a, b + 1));
        }
    for (int e = 0; e < 3; ++e) {
        if (!t[e])
            continue;
        int fe = factor_of(f, e), o = 0, k = t[(e + 2) % 3], k_end = n - 1 - t[(e + 1) % 3];
        while (o < fe || k < k_end) {
            if (k == k_end || (o < fe && (2 * o + 1) * n <= 2 * (k + 1) * fe)) {
                put_triangle(out, &count, base, tri_ring_index(f, e, o), tri_ring_index(f, e, o + 1),
                             tri_row_index(f, n, e, k));
                ++o;
            } else {
                put_triangle(out, &count, base, tri_ring_index(f, e, o), tri_row_index(f, n, e, k + 1),
                             tri_row_index(f, n, e, k));
                ++k;
            }
        }
    }
    return count;
}

#endif
