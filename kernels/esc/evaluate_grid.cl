/* The three evaluators of a bicubic patch on an n x n grid (n + 1 points per side), for the
 * accuracy test and the speed bench of docs/esc.md section 1 (cltess/esc/evaluate.py):
 * method 0 direct (kinds/bezier.h kind_eval), 1 NBM by Horner (kinds/bezier_nbm.h, the matrix
 * computed once per patch, of the patch centred as kind_load centres it; 3: of the raw patch), 2 forward differencing along rows (kind_row_begin / kind_row_next).
 * One work-item per patch; positions and normals (P, n+1, n+1, 3). */
__kernel void evaluate_grid(__global const float4 *controls, uint num_patches, int n, int method,
                            __global float *positions, __global float *normals)
{
    uint p = get_global_id(0);
    if (p >= num_patches)
        return;
    ulong at = (ulong)p * (ulong)((n + 1) * (n + 1));
    float h = 1.0f / (float)n;
    if (method == 1 || method == 3) {
        float4 b[16], t[16], m[16];
        load_patch(controls, p, b);
        float3 centre = method == 1 ? centred_patch(b, t) : (float3)(0.0f);  /* as kind_load */
        nbm_matrix(method == 1 ? t : b, m);
        for (int j = 0; j <= n; ++j)
            for (int i = 0; i <= n; ++i) {
                float4 q, q_u, q_v;
                nbm_eval(m, (float)i * h, (float)j * h, &q, &q_u, &q_v);
                float3 position = q.xyz / q.w;
                float3 shifted = position + centre;
                float3 t_u = q_u.xyz - q_u.w * position, t_v = q_v.xyz - q_v.w * position;
                float3 normal = normalize(cross(t_u, t_v));
                vstore3(shifted, at, positions);
                vstore3(normal, at++, normals);
            }
        return;
    }
    kind_patch patch;
    kind_load(controls, p, &patch);
    for (int j = 0; j <= n; ++j) {
        float v = (float)j * h;
        float3 position, normal;
        if (method == 2) {
            kind_row row;
            kind_eval(&patch, (float3)(0.0f, v, 0.0f), &position, &normal);
            vstore3(position, at, positions);
            vstore3(normal, at++, normals);
            kind_row_begin(&patch, (float3)(0.0f, v, 0.0f), (float3)(1.0f, v, 0.0f), n, &row);
            for (int i = 1; i < n; ++i) {
                kind_row_next(&patch, &row, (float3)((float)i * h, v, 0.0f), &position, &normal);
                vstore3(position, at, positions);
                vstore3(normal, at++, normals);
            }
            kind_eval(&patch, (float3)(1.0f, v, 0.0f), &position, &normal);
            vstore3(position, at, positions);
            vstore3(normal, at++, normals);
        } else {
            for (int i = 0; i <= n; ++i) {
                kind_eval(&patch, (float3)((float)i * h, v, 0.0f), &position, &normal);
                vstore3(position, at, positions);
                vstore3(normal, at++, normals);
            }
        }
    }
}
