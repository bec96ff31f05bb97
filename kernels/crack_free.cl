/* Stage 2: crack-free factors.  Every patch edge takes the max factor over the patch edges
 * that share its curve (DESIGN.md section 4); culled patches stay 0.  The groups come from
 * cltess/adjacency.py as CSR lists.  Mirror: reference.crack_free_factors.
 * One work-item per patch edge. */
#include "cltess.h"

__kernel void crack_free_factors(__global const int *factors, __global const int *group_of,
                                 __global const int *group_start, __global const int *members,
                                 uint num_edges, __global int *final_factors)
{
    uint edge = get_global_id(0);
    if (edge >= num_edges)
        return;
    int own = factors[edge];
    if (own > 0) {
        int group = group_of[edge];
        for (int k = group_start[group]; k < group_start[group + 1]; ++k)
            own = max(own, factors[members[k]]);
    }
    final_factors[edge] = own;
}
