/* Stage 5 by level, for a pattern with a template (the semi-uniform one, patterns/semi_uniform.h),
 * beside stage 4 by level (level_vertices.cl; cltess/backends/opencl/levels.py).  A patch's
 * triangles are its interior ones, then its band's (pattern_primitives): the interior triangles
 * of P^m are never moved nor dropped by the snap, so they come from the level's template, one
 * work-item per (queue slot, template triangle), each writing one triangle at a fixed place
 * (level_interior); the band (O(2^m) triangles with a corner on the boundary, where the snap
 * drops some) is walked by one work-item per queue slot (level_band: pattern_band_primitives, as stage 5
 * walks it).
 * Both number the vertices globally (vertex_offsets[p]) and write at index_offsets[p] -
 * index_base, as stages/indices.cl does, so the output is that of stage 5, bit for bit. */
__kernel void level_interior(__global const int4 *factors, __global const ulong *vertex_offsets,
                             __global const ulong *index_offsets, __global const uint *queue, uint queue_start,
                             uint queue_size, __global const uint *interior, uint template_size, ulong index_base,
                             __global uint *indices)
{
    ulong id = get_global_id(0);
    if (id >= (ulong)queue_size * template_size)
        return;
    uint p = queue[queue_start + (uint)(id / template_size)], t = (uint)(id % template_size);
    int4 f = as_int4(abs(factors[p]));  /* a collapsed edge's sign does not reach the interior */
    uint first = (uint)vertex_offsets[p] + (uint)(f.s0 + f.s1 + f.s2 + f.s3);  /* past the ring */
    __global uint *out = indices + (index_offsets[p] - index_base) + 3 * (ulong)t;
    out[0] = first + interior[3 * t];
    out[1] = first + interior[3 * t + 1];
    out[2] = first + interior[3 * t + 2];
}

__kernel void level_band(__global const int4 *factors, __global const ulong *vertex_offsets,
                         __global const ulong *index_offsets, __global const uint *queue, uint queue_start,
                         uint queue_size, ulong index_base, __global uint *indices)
{
    if (get_global_id(0) >= queue_size)
        return;
    uint p = queue[queue_start + (uint)get_global_id(0)];
    int collapsed;
    int4 f = patch_factors(factors[p], &collapsed);
    pattern_band_primitives(f, collapsed, indices + (index_offsets[p] - index_base), (uint)vertex_offsets[p]);
}
