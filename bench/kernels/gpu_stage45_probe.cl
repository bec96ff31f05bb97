/* Stand-alone stage 4 and 5 kernels with the engine's output layout, for bench/gpu_stage45.py:
 * what a GPU does with the same bytes and the simplest work, against which the engine's kernels
 * are measured (issue 15; the lead's session-2 probe was of this form).  Not the engine's bits.
 *
 *   grid_vertices   a work-item per vertex of a uniform (f + 1) x (f + 1) grid per patch: the
 *                   rational bicubic evaluated directly from the global controls (surface_eval
 *                   of kinds/bezier.h), its unit normal t_u x t_v, positions and normals as 3
 *                   floats, uv 2, patch and object id: 40 bytes a vertex;
 *   grid_triangles  a work-item per triangle of the f x f grid: 3 uints.
 * Built against kinds/bezier.h (and common.h), with the engine's division option. */

__kernel void grid_vertices(__global const float4 *controls, uint patches, int f,
                            __global float *positions, __global float *normals, __global float *uv,
                            __global int *patch_ids, __global int *object_ids)
{
    uint per_patch = (uint)((f + 1) * (f + 1)), v = (uint)get_global_id(0);
    if (v >= patches * per_patch)
        return;
    uint p = v / per_patch, local_v = v % per_patch;
    int i = (int)(local_v % (uint)(f + 1)), j = (int)(local_v / (uint)(f + 1));
    float u = (float)i / (float)f, w = (float)j / (float)f;
    float4 b[16];
    load_patch(controls, p, b);
    float4 s, s_u, s_v;
    surface_eval(b, u, w, &s, &s_u, &s_v);
    int ok;
    float3 n = tangent_cross(s.xyz / s.w, s_u, s_v, &ok);  /* p: the division, as before projected */
    float len = length(n);
    n = len > 0.0f ? n / len : (float3)(0.0f, 0.0f, 1.0f);
    put_vertex((vertex_out){positions, normals, uv, patch_ids, object_ids}, v, s.xyz / s.w, n, (float2)(u, w),
               (int)p, 0);
}

__kernel void grid_triangles(uint patches, int f, __global uint *indices)
{
    uint per_patch = (uint)(2 * f * f), t = (uint)get_global_id(0);
    if (t >= patches * per_patch)
        return;
    uint p = t / per_patch, local_t = t % per_patch, cell = local_t >> 1;
    uint i = cell % (uint)f, j = cell / (uint)f, base = p * (uint)((f + 1) * (f + 1));
    uint a = base + j * (uint)(f + 1) + i, d = a + (uint)(f + 1);
    uint3 triangle = (local_t & 1) ? (uint3)(a, d + 1, d) : (uint3)(a, a + 1, d + 1);
    vstore3(triangle, t, indices);
}
