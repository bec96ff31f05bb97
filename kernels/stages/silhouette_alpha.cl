/* Silhouette refinement, per frame: alpha of every edge group (criteria/silhouette.h), one
 * work-item per group, so the two patches at an edge read the same value (one per edge). 
 * midpoints: (G, 4), beta in w; normals (G, 2, 4): n_s, n_t; rules (G,).  The eye comes as three
 * floats (criteria/silhouette.h: Oclgrind's uninitialised-value plugin and float3 padding). */
#include "criteria/silhouette.h"

__kernel void silhouette_alpha(__global const float4 *midpoints, __global const float4 *normals,
                               __global const int *rules, uint num_groups, float eye_x, float eye_y,
                               float eye_z,
                               __global float *alpha)
{
    uint g = get_global_id(0);
    if (g >= num_groups)
        return;
    alpha[g] = edge_silhouetteness(midpoints[g], normals[2 * g], normals[2 * g + 1], rules[g], eye_x, eye_y, eye_z);
}
