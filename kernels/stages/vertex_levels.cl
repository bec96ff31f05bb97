/* Level functions, step 1 (criteria/level.h): the value of each welded vertex (depth to the eye
 * plane, or the silhouette's cosine between normal and view) from its position and canonical
 * normal.  One work-item per welded vertex. */
__kernel void vertex_levels(__global const float *positions, __global const float *normals, uint num_vertices,
                            int function, float4 eye, float4 forward, __global float *levels)
{
    uint v = get_global_id(0);
    if (v >= num_vertices)
        return;
    levels[v] = vertex_level(function, vload3(v, positions), vload3(v, normals), eye.xyz, forward.xyz);
}
