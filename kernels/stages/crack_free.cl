/* Stage 2: crack-free factors by the crack policy (kernels/crack/), over the edge groups of
 * cltess/crack/adjacency.py as CSR lists.  One work-item per patch edge.  A collapsed edge
 * (EdgeGroups.collapsed_edges: its control points are one point, e.g. a sphere's pole) is
 * stored negated: stages 3-5 read it with patch_factors (common.h), which gives the pattern the
 * factor and the collapsed edges; all its points are its first corner, and the pattern emits no
 * triangle between two of them. */
__kernel void crack_free(__global const int *factors, __global const int *group_of,
                         __global const int *group_start, __global const int *members,
                         __global const int *collapsed_edges, uint num_edges, __global int *final_factors)
{
    uint edge = get_global_id(0);
    if (edge >= num_edges)
        return;
    int factor = crack_free_factor(factors, edge, group_of, group_start, members);
    final_factors[edge] = collapsed_edges[edge] ? -factor : factor;
}
