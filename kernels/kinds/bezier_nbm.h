/* ESC's evaluator (Hu et al. 2014, eq. 8): the power-basis matrix NBM = N B N^T of a bicubic
 * patch, computed once per patch, and Q(u, v) = U . NBM . V^T by Horner (U = (1, u, u^2, u^3)).
 * Its own header, beside kinds/bezier.h.  Mirror: cltess/surfaces/nbm.py; docs/esc.md section 1.
 * b[4 j + i]: control point of row j (v), column i (u), homogeneous; m[4 a + b] multiplies
 * u^a v^b. */
#ifndef CLTESS_KINDS_BEZIER_NBM_H
#define CLTESS_KINDS_BEZIER_NBM_H
#include "common.h"

/* Cubic Bernstein -> power basis, N[a][i] (cltess/surfaces/nbm.py POWER_BASIS). */
__constant float NBM_N[4][4] = {{1.0f, 0.0f, 0.0f, 0.0f}, {-3.0f, 3.0f, 0.0f, 0.0f},
                                {3.0f, -6.0f, 3.0f, 0.0f}, {-1.0f, 3.0f, -3.0f, 1.0f}};

/* NBM = N B N^T: m[4a + b] = sum_{i,j} N[a][i] N[b][j] b[4 j + i]. */
ALWAYS_INLINE void nbm_matrix(__private const float4 b[16], __private float4 m[16])
{
    float4 partial[16];  /* partial[4 a + j] = sum_i N[a][i] b[4 j + i] */
    for (int a = 0; a < 4; ++a)
        for (int j = 0; j < 4; ++j) {
            float4 s = (float4)(0.0f);
            for (int i = 0; i <= a; ++i)  /* N is lower triangular */
                s += NBM_N[a][i] * b[4 * j + i];
            partial[4 * a + j] = s;
        }
    for (int a = 0; a < 4; ++a)
        for (int c = 0; c < 4; ++c) {
            float4 s = (float4)(0.0f);
            for (int j = 0; j <= c; ++j)
                s += NBM_N[c][j] * partial[4 * a + j];
            m[4 * a + c] = s;
        }
}

/* Homogeneous Q, Q_u, Q_v at (u, v): Horner in v for each power of u, then in u. */
ALWAYS_INLINE void nbm_eval(__private const float4 m[16], float u, float v, __private float4 *q,
                            __private float4 *q_u, __private float4 *q_v)
{
    float4 row[4], row_v[4];
    for (int a = 0; a < 4; ++a) {
        float4 r = m[4 * a + 3], r_v = (float4)(0.0f);
        for (int c = 2; c >= 0; --c) {
            r_v = r_v * v + r;
            r = r * v + m[4 * a + c];
        }
        row[a] = r;
        row_v[a] = r_v;
    }
    float4 s = row[3], s_u = (float4)(0.0f), s_v = row_v[3];
    for (int a = 2; a >= 0; --a) {
        s_u = s_u * u + s;
        s = s * u + row[a];
        s_v = s_v * u + row_v[a];
    }
    *q = s;
    *q_u = s_u;
    *q_v = s_v;
}

/* The position alone (the distance test's V_B): Horner on the point, no derivatives. */
ALWAYS_INLINE float3 nbm_position(__private const float4 m[16], float u, float v)
{
    float4 s = (float4)(0.0f);
    for (int a = 3; a >= 0; --a) {
        float4 r = m[4 * a + 3];
        for (int c = 2; c >= 0; --c)
            r = r * v + m[4 * a + c];
        s = s * u + r;
    }
    return s.xyz / s.w;
}

#endif
