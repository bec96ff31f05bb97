/* Crack policy "max": every patch edge takes the largest factor over the patch edges that share
 * its curve (docs/design.md section 4); culled patches stay 0.  Mirror:
 * cltess/crack/adjacency.py crack_free_factors. */
#ifndef CLTESS_CRACK_MAX_H
#define CLTESS_CRACK_MAX_H

inline int crack_free_factor(__global const int *factors, uint edge, __global const int *group_of,
                             __global const int *group_start, __global const int *members)
{
    int own = factors[edge];
    if (own > 0) {
        int group = group_of[edge];
        for (int k = group_start[group]; k < group_start[group + 1]; ++k)
            own = max(own, factors[members[k]]);
    }
    return own;
}

#endif
