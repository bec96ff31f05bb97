/* Zheng-Sederberg steps for rational bicubic patches (docs/design.md section 2; host mirror
 * cltess/criteria/zheng_sederberg.py, zs_inverse_steps and zs_steps). */
#ifndef CLTESS_CRITERIA_ZS_H
#define CLTESS_CRITERIA_ZS_H
#include "common.h"

/* Steps with d_uu du^2 + 2 d_uv du dv + d_vv dv^2 <= c and du*dv largest, at most 1
 * (zs_steps: the optimum du/dv = sqrt(d_vv/d_uu), written with s = sqrt(d_uu),
 * t = sqrt(d_vv) so that no 0 * inf appears; inputs scaled by their max; NaN -> 0 = saturated). */
inline float2 zs_steps(float d_uu, float d_uv, float d_vv, float c)
{
    float scale = max(max(d_uu, d_uv), d_vv);
    if (!(scale > 0.0f))
        return (float2)(1.0f, 1.0f);
    float a = d_uu / scale, d = d_uv / scale, b = d_vv / scale;
    c /= scale;
    float du, dv;
    if (a > 0.0f && b > 0.0f) {
        float s = sqrt(a), t = sqrt(b);
        du = s * (s * t + d) > 0.0f ? sqrt(c * t / (2.0f * s * (s * t + d))) : INFINITY;
        dv = t * (s * t + d) > 0.0f ? sqrt(c * s / (2.0f * t * (s * t + d))) : INFINITY;
    } else if (a > 0.0f) {
        dv = 1.0f;
        du = c / (d + sqrt(d * d + a * c));
    } else if (b > 0.0f) {
        du = 1.0f;
        dv = c / (d + sqrt(d * d + b * c));
    } else {
        du = dv = sqrt(c / (2.0f * d));
    }
    du = isnan(du) ? 0.0f : min(du, 1.0f);
    dv = isnan(dv) ? 0.0f : min(dv, 1.0f);
    return (float2)(du, dv);
}

/* (1/du, 1/dv) for the patch t moved to its box centre (t[k] = (X - w c, w)), r = max |P - c|,
 * min_w its smallest weight, tol the tolerance: maxima of |difference of X| and of |difference
 * of w| over the control net (.x = X part, .y = w part), combined as zs_inverse_steps derives. */
inline float2 zs_inverse_steps(const float4 t[16], float r, float min_w, float tol)
{
    float2 uu = 0.0f, vv = 0.0f, uv = 0.0f, u1 = 0.0f, v1 = 0.0f;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 2; ++i) {
            float4 d = t[4 * j + i + 2] - 2.0f * t[4 * j + i + 1] + t[4 * j + i];
            uu = max(uu, (float2)(length(d.xyz), fabs(d.w)));
            float4 e = t[4 * (i + 2) + j] - 2.0f * t[4 * (i + 1) + j] + t[4 * i + j];
            vv = max(vv, (float2)(length(e.xyz), fabs(e.w)));
        }
    for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i) {
            float4 d = t[4 * (j + 1) + i + 1] - t[4 * (j + 1) + i] - t[4 * j + i + 1] + t[4 * j + i];
            uv = max(uv, (float2)(length(d.xyz), fabs(d.w)));
        }
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 3; ++i) {
            float4 d = t[4 * j + i + 1] - t[4 * j + i];
            u1 = max(u1, (float2)(length(d.xyz), fabs(d.w)));
            float4 e = t[4 * (i + 1) + j] - t[4 * i + j];
            v1 = max(v1, (float2)(length(e.xyz), fabs(e.w)));
        }
    float w_u = 3.0f * u1.y, w_v = 3.0f * v1.y;
    float slope_u = (3.0f * u1.x + r * w_u) / min_w;  /* bounds |p_u|, hence |l_u| */
    float slope_v = (3.0f * v1.x + r * w_v) / min_w;
    float d_uu = 6.0f * uu.x + r * 6.0f * uu.y + 2.0f * w_u * slope_u;
    float d_vv = 6.0f * vv.x + r * 6.0f * vv.y + 2.0f * w_v * slope_v;
    float d_uv = 9.0f * uv.x + r * 9.0f * uv.y + w_u * slope_v + w_v * slope_u;
    float2 step = zs_steps(d_uu, d_uv, d_vv, 8.0f * tol * min_w);
    return 1.0f / step;
}

#endif
