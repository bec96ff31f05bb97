/* The Filip bound for PN triangles (docs/design.md section 3; CudaTess section 4; host mirror
 * cltess/criteria/filip.py, pn_second_derivative_bounds and pn_inverse_steps). */
#ifndef CLTESS_CRITERIA_FILIP_H
#define CLTESS_CRITERIA_FILIP_H
#include "common.h"

/* Index of the cubic control point b_ijk (k = 3-i-j) and of the quadratic normal control n_ijk
 * (k = 2-i-j) in the 16-float4 PN layout (kinds/pn.h). */
__constant int PN_CUBIC[16] = {2, 6, 5, 1, 7, 9, 4, -1, 8, 3, -1, -1, 0, -1, -1, -1};
__constant int PN_QUADRATIC[9] = {12, 14, 11, 15, 13, -1, 10, -1, -1};

/* Bounds of the second directional derivatives |D_{d_a} D_{d_b} b| over the triangle, d_e the
 * domain direction of edge e (corner e to corner e+1): D_{da,db} b = 6 sum_{|I|=1}
 * (Delta_a Delta_b b)_I B1_I with Delta_e b_I = b_{I+e_{e+1}} - b_{I+e_e}, bounded by the
 * largest of its three control points (docs/design.md section 3).  Returns d[3 * a + b]. */
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

/* 1 / delta_e for each edge e from (1/8) (D_ee + max(D_e,e+1, D_e,e+2)) delta_e^2 <= tol / 2. */
inline void filip_inverse_steps(const float4 b[16], float tol, float inverse[3])
{
    float d[9];
    pn_second_derivative_bounds(b, d);
    for (int e = 0; e < 3; ++e) {
        float curvature = d[4 * e] + max(d[3 * e + (e + 1) % 3], d[3 * e + (e + 2) % 3]);
        inverse[e] = sqrt(curvature / (4.0f * tol));
    }
}

#endif
