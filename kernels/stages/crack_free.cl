/* Stage 2: crack-free factors by the crack policy (kernels/crack/), over the edge groups of
 * cltess/crack/adjacency.py as CSR lists.  One work-item per patch edge. */
__kernel void crack_free(__global const int *factors, __global const int *group_of,
                         __global const int *group_start, __global const int *members,
                         uint num_edges, __global int *final_factors)
{
    uint edge = get_global_id(0);
    if (edge >= num_edges)
        return;
    final_factors[edge] = crack_free_factor(factors, edge, group_of, group_start, members);
}
