/* Silhouette refinement, per frame: each patch edge's fractional level s_e = M alpha_e (section
 * 5; criteria/silhouette.h silhouette_edge_level) and the semi-uniform record the pattern reads:
 * 2^ceil(s_e) per edge (snap: the dyadic levels of Dyken et al. 2009, watertight), or with
 * snap = 0 the patch level 2^m on every edge, m = max_e ceil(s_e) (the paper's hanging nodes).
 * bound: the plan's crack-free dyadic records (0: no output; negative: a collapsed edge, kept
 * negated).  One work-item per patch of one kind (edges per patch), scene numbers first_patch.. */
#include "criteria/silhouette.h"

__kernel void silhouette_levels(__global const float *alpha, __global const int *group_of,
                                __global const int *bound, uint first_patch, uint num_patches, int edges,
                                float max_level, int use_bound, int snap,
                                __global float *levels, __global int *records)
{
    if (get_global_id(0) >= num_patches)
        return;
    uint p = first_patch + (uint)get_global_id(0);
    int q[FACTOR_SLOTS], m = 0;
    for (int e = 0; e < FACTOR_SLOTS; ++e) {
        levels[FACTOR_SLOTS * p + e] = 0.0f;
        records[FACTOR_SLOTS * p + e] = 0;
    }
    if (bound[FACTOR_SLOTS * p] == 0)
        return;
    for (int e = 0; e < edges; ++e) {
        float s = silhouette_edge_level(alpha[group_of[FACTOR_SLOTS * p + e]], max_level,
                                        bound[FACTOR_SLOTS * p + e], use_bound);
        levels[FACTOR_SLOTS * p + e] = s;
        q[e] = (int)ceil(s);
        m = max(m, q[e]);
    }
    for (int e = 0; e < edges; ++e) {
        int record = 1 << (snap ? q[e] : m);
        records[FACTOR_SLOTS * p + e] = bound[FACTOR_SLOTS * p + e] < 0 ? -record : record;
    }
}
