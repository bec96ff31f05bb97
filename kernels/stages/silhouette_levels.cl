/* Silhouette refinement, per frame: each patch edge's fractional level s_e = M alpha_e (section
 * 5; criteria/silhouette.h silhouette_edge_level), and the patch's topological level m =
 * ceil(max_e s_e), written as the record 2^m on each of its edges.  With the snap the host then
 * runs the crack-free max over the edge groups (stages/crack_free.cl), so an edge takes the
 * larger level of its two patches and both sample it at the same points (the semi-uniform
 * pattern snaps the patch's other edges to their own levels); without it (the paper's hanging
 * nodes, an ablation) the records stay 2^m, a collapsed edge's negated here (the crack-free
 * pass negates them otherwise).  bound: the plan's crack-free dyadic records (0: no output;
 * negative: a collapsed edge).  One work-item per patch of one kind (edges per patch), scene
 * numbers first_patch .. */
#include "criteria/silhouette.h"

__kernel void silhouette_levels(__global const float *alpha, __global const int *group_of,
                                __global const int *bound, uint first_patch, uint num_patches, int edges,
                                float max_level, int use_bound, int snap,
                                __global float *levels, __global int *records)
{
    if (get_global_id(0) >= num_patches)
        return;
    uint p = first_patch + (uint)get_global_id(0);
    for (int e = 0; e < FACTOR_SLOTS; ++e) {
        levels[FACTOR_SLOTS * p + e] = 0.0f;
        records[FACTOR_SLOTS * p + e] = 0;
    }
    if (bound[FACTOR_SLOTS * p] == 0)
        return;
    float s_max = 0.0f;
    for (int e = 0; e < edges; ++e) {
        float s = silhouette_edge_level(alpha[group_of[FACTOR_SLOTS * p + e]], max_level,
                                        bound[FACTOR_SLOTS * p + e], use_bound);
        levels[FACTOR_SLOTS * p + e] = s;
        s_max = max(s_max, s);
    }
    int record = 1 << (int)ceil(s_max);
    for (int e = 0; e < edges; ++e)
        records[FACTOR_SLOTS * p + e] = !snap && bound[FACTOR_SLOTS * p + e] < 0 ? -record : record;
}
