/* Stage 6, on request (--verify): the actual error of a tessellation, measured.  For each
 * sampled output triangle, the surface S (kind_eval) against the mesh at equal domain points:
 * at the barycentric points (i, j, order - i - j) / order of the triangle (its corners and
 * edges included), the mesh point is the same combination of its vertices' positions and the
 * domain point the same combination of their (u, v) (the third domain coordinate: 0 on the
 * quad, w = 1 - u - v on the triangle).  Writes max |S(x) - mesh(x)| / tolerance of the patch
 * per triangle (cltess.bound.worst_bound_ratio is the float64 host mirror).  One work-item per
 * sampled triangle first + stride * gid, all of one kind (scene patch p is the kind's
 * p - patch_base). */
/* Vertex v's domain point from its (u, v): (u, v, 0) on the quad, (u, v, 1 - u - v) on the
 * triangle.  Scalar loads: Oclgrind's uninitialised-value pass (-O0) crashed on a float2 widened
 * to a float3. */
inline float3 verify_domain(__global const float *uv, uint v)
{
    float u = uv[2 * v], w = uv[2 * v + 1];
    return (float3)(u, w, KIND_DOMAIN_EDGES == 3 ? 1.0f - u - w : 0.0f);
}

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
    uint a = triangles[3 * t], b = triangles[3 * t + 1], c = triangles[3 * t + 2];
    uint p = (uint)patch_ids[a];
    kind_patch patch;
    kind_load(controls, p - patch_base, &patch);
    float3 position_a = vload3(a, positions), position_b = vload3(b, positions), position_c = vload3(c, positions);
    float3 domain_a = verify_domain(uv, a), domain_b = verify_domain(uv, b), domain_c = verify_domain(uv, c);
    float worst = 0.0f;
    for (int i = 0; i <= order; ++i)
        for (int j = 0; j <= order - i; ++j) {
            float wa = (float)i / (float)order, wb = (float)j / (float)order;
            float wc = (float)(order - i - j) / (float)order;
            float3 mesh = wa * position_a + wb * position_b + wc * position_c;
            float3 x = wa * domain_a + wb * domain_b + wc * domain_c;
            float3 surface, normal;
            kind_eval(&patch, x, &surface, &normal);
            worst = fmax(worst, length(surface - mesh));
        }
    ratios[gid] = worst / tolerances[p];
}
