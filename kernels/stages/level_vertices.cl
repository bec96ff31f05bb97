/* Stage 4 by level, for a pattern with a template (the semi-uniform one: patterns/semi_uniform.h
 * pattern_template_point): the paper's per-level instanced draws (Dyken et al. 2009, section
 * 4.2) as one launch per level over (queue slot, template point).  queue[queue_start ..
 * queue_start + queue_size - 1]: the scene numbers of the patches of level `level`
 * (cltess/backends/opencl/levels.py level_scan); points: the level's template, lattice points
 * (i, j) of P^level (cltess/patterns/semi_uniform.py point_template).  Each vertex goes where
 * stages/vertices.cl puts it (less vertex_base, as there) and is computed as it computes it with
 * direct evaluation (kind_boundary_point on the ring, kind_eval inside), so the output is
 * bitwise that of the patch-parallel stage 4 without forward differencing. */
__kernel void level_vertices(__global const float4 *controls, __global const int4 *factors,
                             __global const ulong *vertex_offsets, __global const int *patch_objects,
                             __global const uint *queue, uint queue_start, uint queue_size,
                             __global const int2 *points, uint template_size, int level, uint patch_base,
                             ulong vertex_base,
                             __global float *positions, __global float *normals, __global float *uv,
                             __global int *patch_ids, __global int *object_ids)
{
    ulong id = get_global_id(0);
    if (id >= (ulong)queue_size * template_size)
        return;
    uint p = queue[queue_start + (uint)(id / template_size)];
    int2 ij = points[id % template_size];
    int collapsed;
    int4 f = patch_factors(factors[p], &collapsed);
    template_point point = pattern_template_point(f, level, ij.x, ij.y);
    if (point.vertex < 0)
        return;  /* snapped away */
    vertex_out out = {positions, normals, uv, patch_ids, object_ids};
    kind_patch patch;
    kind_load(controls, p - patch_base, &patch);
    ulong at = vertex_offsets[p] - vertex_base + (ulong)point.vertex;
    /* One kind_eval for ring and interior points alike (the work-items of a vector run both
     * sides of a branch): the normal, and the position of an interior point; a ring point's
     * position is then the edge's (kind_boundary_point), as stages/vertices.cl computes them. */
    int on_ring = point.edge >= 0, e = max(point.edge, 0);
    edge_param t = pattern_ring_param(f, e, point.k);
    float3 x = on_ring ? pattern_edge_point(e, t) : pattern_row_point(f, ij.y, ij.x);
    float3 position, normal;
    kind_eval(&patch, x, &position, &normal);
    if (on_ring) {
        edge_param corner = {0, t.f};  /* a collapsed edge: every point is its first corner */
        position = kind_boundary_point(&patch, e, (collapsed >> e) & 1 ? corner : t);
    }
    put_vertex(out, at, position, normal, x.xy, p, patch_objects[p]);
}
