/* Session 19, H200 calls 1-2: the first two-phase form, staged_points (work="staged-prep" then),
 * as it was appended to kernels/stages/prepared_points.cl; with staged_rows.patch's kinds/bezier.h
 * and common.h parts (kind_row_begin_part, kind_eval_part, kind_boundary_part, kind_staged_point
 * then taking a __local kind_patch) and a host launch of STAGED_GROUP work-items per group.
 * Bitwise prepared_rows' output on the H200 (35 tests), Intel's CPU runtime and PoCL. Not kept. */
#ifdef KIND_STAGED
#define STAGED_GROUP 128
#define STAGED_MAX_FACTOR 64
#define STAGED_POINTS (PATTERN_EDGES * STAGED_MAX_FACTOR + STAGED_MAX_FACTOR)  /* a ring and a row */
#define STAGED_PITCH (STAGED_POINTS + 8)  /* a component's row: the 4 components of a point in 4 banks */
#define STAGED_ROWS (STAGED_GROUP / 4)    /* rows per round: a work-item per (row, component) */

#ifdef STAGED_NO_REQD
__kernel
#else
__kernel __attribute__((reqd_work_group_size(STAGED_GROUP, 1, 1)))
#endif
void staged_points(__global const kind_patch *restrict prepared, __global const int4 *factors,
                   __global const ulong *vertex_offsets, __global const int *patch_objects,
                   uint first_patch, uint num_patches, ulong vertex_base,
                   int forward_differencing, ulong capacity, uint patches_per_group,
                   __global float *positions, __global float *normals, __global float *uv,
                   __global int *patch_ids, __global int *object_ids)
{
    __local kind_patch patch;
    __local float made[16][STAGED_PITCH];  /* B, B_u, B_v by component (0-11); a ring point's boundary point (12-15) */
    __local int row_first[STAGED_ROWS + 1];
#if !PATTERN_UNIFORM_ROWS
    forward_differencing = 0;
#endif
    uint last = first_patch + num_patches;
    if (!batch_fits(vertex_offsets, last, vertex_base, capacity))
        return;
    vertex_out out = {positions, normals, uv, patch_ids, object_ids};
    uint item = (uint)get_local_id(0), group_first = first_patch + (uint)get_group_id(0) * patches_per_group;
    uint patches = min(patches_per_group, last - group_first);
    for (uint q = 0; q < patches; ++q) {
        uint p = group_first + q;
        ulong at = vertex_offsets[p];
        if (vertex_offsets[p + 1] == at)
            continue;
        at -= vertex_base;
        int collapsed, object = patch_objects[p];
        int4 f = patch_factors(factors[p], &collapsed);
        __global const float4 *from = (__global const float4 *)(prepared + (p - first_patch));
        for (uint k = item; k < (uint)(sizeof(kind_patch) / 16); k += STAGED_GROUP)
            ((__local float4 *)&patch)[k] = from[k];
        int ring = 0, rows = pattern_rows(f), row = 1;
        for (int e = 0; e < PATTERN_EDGES; ++e)
            ring += PATTERN_EDGE_POINTS(f, e);
        for (int ring_points = ring; ring_points || row <= rows; ring_points = 0) {
            int first_row = row, points = ring_points, alike = 1, length = 0;
            while (row <= rows && row - first_row < STAGED_ROWS) {
                int steps = pattern_row(f, row);
                if (points + steps - 1 > STAGED_POINTS)
                    break;
                alike &= row == first_row || steps - 1 == length;
                length = steps - 1;
                points += steps - 1;
                ++row;
            }
            if (points > STAGED_POINTS || (!ring_points && row == first_row))
                break;
            barrier(CLK_LOCAL_MEM_FENCE);
            if (item == 0) {
                row_first[0] = ring_points;
                for (int j = first_row; j < row; ++j)
                    row_first[j - first_row + 1] = row_first[j - first_row] + pattern_row(f, j) - 1;
            }
            int row_parts = 4 * (row - first_row), c = (int)(item & 3);
            if ((int)item < row_parts) {
                int r = (int)(item >> 2), j = first_row + r, steps = pattern_row(f, j), slot = ring_points - 1;
                for (int before = first_row; before < j; ++before)
                    slot += pattern_row(f, before) - 1;
                if (forward_differencing) {
                    float s[4], s_u[4], s_v[4];
                    kind_row_begin_part(&patch, c, pattern_row_point(f, j, 0).y, steps, s, s_u, s_v);
                    for (int i = 1; i < steps; ++i) {
                        step_differences_part(s);
                        step_differences_part(s_u);
                        step_differences_part(s_v);
                        made[c][slot + i] = s[0];
                        made[4 + c][slot + i] = s_u[0];
                        made[8 + c][slot + i] = s_v[0];
                    }
                } else {
                    for (int i = 1; i < steps; ++i) {
                        float3 x = pattern_row_point(f, j, i);
                        float s, s_u, s_v;
                        kind_eval_part(&patch, c, x.x, x.y, &s, &s_u, &s_v);
                        made[c][slot + i] = s;
                        made[4 + c][slot + i] = s_u;
                        made[8 + c][slot + i] = s_v;
                    }
                }
            }
            int ring_from = row_parts <= STAGED_GROUP - 32 ? row_parts : 0;
            for (int task = (int)item - ring_from; task < 4 * ring_points; task += STAGED_GROUP - ring_from) {
                if (task < 0)
                    continue;
                int k = task >> 2, e = 0, point = k;
                while (point >= PATTERN_EDGE_POINTS(f, e)) {
                    point -= PATTERN_EDGE_POINTS(f, e);
                    ++e;
                }
                int part = task & 3;
                edge_param t = pattern_ring_param(f, e, point), corner = {0, t.f};
                float3 x = pattern_edge_point(e, t);
                float s, s_u, s_v;
                made[12 + part][k] = kind_boundary_part(&patch, part, e, (collapsed >> e) & 1 ? corner : t);
                kind_eval_part(&patch, part, x.x, x.y, &s, &s_u, &s_v);
                made[part][k] = s;
                made[4 + part][k] = s_u;
                made[8 + part][k] = s_v;
            }
            barrier(CLK_LOCAL_MEM_FENCE);
            for (int k = (int)item; k < points; k += STAGED_GROUP) {
                float3 x, position, normal;
                int on_ring = k < ring_points;
                if (on_ring) {
                    int e = 0, point = k;
                    while (point >= PATTERN_EDGE_POINTS(f, e)) {
                        point -= PATTERN_EDGE_POINTS(f, e);
                        ++e;
                    }
                    x = pattern_edge_point(e, pattern_ring_param(f, e, point));
                    position = projected((float4)(made[12][k], made[13][k], made[14][k], made[15][k]));
                } else {
                    int r = 0;
                    if (alike) {
                        r = (k - ring_points) / length;
                    } else {
                        while (row_first[r + 1] <= k)
                            ++r;
                    }
                    x = pattern_row_point(f, first_row + r, k - row_first[r] + 1);
                }
                kind_staged_point(&patch, x, (float4)(made[0][k], made[1][k], made[2][k], made[3][k]),
                                  (float4)(made[4][k], made[5][k], made[6][k], made[7][k]),
                                  (float4)(made[8][k], made[9][k], made[10][k], made[11][k]), on_ring, &position,
                                  &normal);
                put_vertex(out, at + (ulong)k, position, normal, x.xy, (int)p, object);
            }
            at += (ulong)points;
        }
        barrier(CLK_LOCAL_MEM_FENCE);
    }
}
#endif
