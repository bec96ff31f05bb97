/* Silhouette refinement, per frame: alpha of every edge group (criteria/silhouette.h), one
 * work-item per group, so the two patches at an edge read the same value (one per edge). 
 * midpoints: (G, 4), beta in w; normals (G, 2, 4): n_s, n_t; rules (G,). */
#include "criteria/silhouette.h"

__kernel void silhouette_alpha(__global const float4 *midpoints, __global const float4 *normals,
                               __global const int *rules, uint num_groups, float4 eye,
                               __global float *alpha)
{
    uint g = get_global_id(0);
    if (g >= num_groups)
        return;
    float4 m = midpoints[g];
    alpha[g] = edge_silhouetteness(m.xyz, normals[2 * g].xyz, normals[2 * g + 1].xyz, m.w, rules[g], eye.xyz);
}
