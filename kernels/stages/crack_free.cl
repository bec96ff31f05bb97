/* Stage 2: crack-free factors by the crack policy (kernels/crack/), over the edge groups of
 * cltess/crack/adjacency.py as CSR lists.  One work-item per patch edge.  A zero edge
 * (EdgeGroups.zero_edges: collapsed to a point, e.g. a sphere's pole) gets factor 0: no
 * segments, its one point is the next corner, so no triangle joins its coincident corners. */
__kernel void crack_free(__global const int *factors, __global const int *group_of,
                         __global const int *group_start, __global const int *members,
                         __global const int *zero_edges, uint num_edges, __global int *final_factors)
{
    uint edge = get_global_id(0);
    if (edge >= num_edges)
        return;
    final_factors[edge] = zero_edges[edge] ? 0 : crack_free_factor(factors, edge, group_of, group_start, members);
}
