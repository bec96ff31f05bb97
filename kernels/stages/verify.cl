/* Stage 6, on request (--verify): the actual error of a tessellation, measured.  For each
 * sampled output triangle, the surface S (kind_eval) against the mesh at equal domain points:
 * at the barycentric points (i, j, order - i - j) / order of the triangle (its corners and
 * edges included), the mesh point is the same combination of its vertices' positions and the
 * domain point the same combination of their (u, v) (the third domain coordinate: 0 on the
 * quad, w = 1 - u - v on the triangle).  Writes max |S(x) - mesh(x)| / tolerance of the patch
 * per triangle (cltess.bound.worst_bound_ratio is the float64 host mirror).  One work-item per
 * sampled triangle first + stride * gid, all of one kind (scene patch p is the kind's
 * p - patch_base). */
__kernel void verify(__global const float4 *controls, __global const float *positions,
                     __global const float *uv, __global const int *patch_ids,
                     __global const uint *triangles, ulong first, uint stride, uint num_samples,
                     uint patch_base, int order, __global const float *tolerances,
                     __global float *ratios)
{
    uint gid = get_global_id(0);
    if (gid >= num_samples)
        return;
    ulong t = first + (ulong)stride * gid;
    uint corner[3] = {triangles[3 * t], triangles[3 * t + 1], triangles[3 * t + 2]};
    uint p = (uint)patch_ids[corner[0]];
    kind_patch patch;
    kind_load(controls, p - patch_base, &patch);
    float3 position[3], domain[3];
    for (int c = 0; c < 3; ++c) {
        position[c] = vload3(corner[c], positions);
        float2 x = vload2(corner[c], uv);
        domain[c] = (float3)(x, KIND_DOMAIN_EDGES == 3 ? 1.0f - x.x - x.y : 0.0f);
    }
    float worst = 0.0f;
    for (int i = 0; i <= order; ++i)
        for (int j = 0; j <= order - i; ++j) {
            float a = (float)i / (float)order, b = (float)j / (float)order, c = (float)(order - i - j) / (float)order;
            float3 mesh = a * position[0] + b * position[1] + c * position[2];
            float3 x = a * domain[0] + b * domain[1] + c * domain[2];
            float3 surface, normal;
            kind_eval(&patch, x, &surface, &normal);
            worst = fmax(worst, length(surface - mesh));
        }
    ratios[gid] = worst / tolerances[p];
}
