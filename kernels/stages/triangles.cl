/* Stage 5 a work-item per output triangle (issue 15, for GPUs): consecutive work-items write
 * consecutive triangles (coalesced stores).  As stages/vertex_points.cl: a work-group of G
 * work-items owns G * per_item consecutive triangles of the batch, in step k its work-item l
 * writes triangles 2 (k G + l) and 2 (k G + l) + 1 of them, and it finds a triangle's patch over
 * index_offsets only when the patch changes (64-bit divisions by 3 only then): its first by
 * patch_of (common.h), the next ones by patch_after, galloping from the patch it leaves.  A pattern with
 * random access to a regular patch's triangles (PATTERN_TRIANGLE_AT, pattern_triangle_at) gives
 * triangle t directly; any other patch is emitted whole by the work-item of its triangle 0 with
 * pattern_primitives, as stages/indices.cl does.  Either way the bits of stages/indices.cl.
 * That work-item holds its warp while it walks the patch: on the H100, uniform level 16 on 32,000
 * teapot patches took 0.64 ms here while the quad grids with a collapsed edge (the teapot's lid
 * and bottom) were walked, 0.25 ms since pattern_triangle_at covers them (bench/RESULTS.md,
 * "Stage 5 by triangle"), 0.136 ms with its corners by uniform_grid_index and patch_after.
 * Staging a step's triangles in local memory and writing them as consecutive words (whole
 * sectors) was slower there: 0.184 ms, 0.205 with a run of 16 consecutive triangles per
 * work-item (bench/RESULTS.md, "Issue 15: stage 5's triangle math").  Stage 5 is issue-bound
 * (Nsight Compute on the H200: 77% of issue slots, 207 warp instructions per 32 triangles), so
 * a work-item now takes two consecutive triangles, a cell's (a, b, c) and (a, c, d) from one
 * pattern_triangle_pair where they are one cell's (else each alone); a patch's grid and row layout
 * are made once per patch (pattern_triangles_of), the row by a float reciprocal, and a group's
 * triangles are numbered in 32 bits: 133 instructions per 32 triangles, 0.133 -> 0.115 ms on the
 * H200 at uniform level 16 (bench/RESULTS.md, "Issue 15: stage 4's write-out and stage 5's
 * instructions (session 10, branch gpu15i)").  A cell's pair goes as three 8-byte stores where
 * the launch's output is 8-byte aligned (half the store instructions, each of a warp's over the
 * same 24 sectors): 0.115-0.116 -> 0.105-0.106 ms there (bench/RESULTS.md, "Session 19, lead").
 * The batch is patches first_patch .. first_patch + num_patches - 1; work-items past its last
 * triangle stop. */
__kernel void triangles(__global const int4 *factors, __global const ulong *vertex_offsets,
                        __global const ulong *index_offsets, uint first_patch, uint num_patches,
                        ulong index_base, ulong capacity, uint per_item, __global uint *indices)
{
    uint last = first_patch + num_patches;
    if (!batch_fits(index_offsets, last, index_base, capacity))
        return;
    /* A work-group's triangles are numbered from its first, `start`, in 32 bits (a group's
     * G * per_item triangles), and a patch's bounds relative to it (patch_start modulo 2^32: a
     * patch may begin before the group); 64-bit numbers only where a patch is sought. */
    uint group = (uint)get_local_size(0);
    ulong end = index_offsets[last] / 3;
    ulong start = index_offsets[first_patch] / 3 + (ulong)get_group_id(0) * group * per_item;
    if (start >= end)
        return;
    uint stop = (uint)min(end - start, (ulong)group * per_item);
    __global uint *out = indices + 3 * (start - index_base / 3);
    /* Where out is 8-byte aligned, so is an even r's triangle (12 r bytes on): a cell's two
     * triangles, 24 bytes, then go as three 8-byte stores instead of six 4-byte ones. */
    int words = ((ulong)out & 7) == 0;
    uint p = first_patch, base = 0, patch_start = 0, patch_end = 0;  /* the patch's triangles; none found yet */
    int4 f = (int4)(0);
    int collapsed = 0, direct = 0;
#ifdef PATTERN_TRIANGLE_AT
    pattern_triangles grid;
#endif
    for (uint r0 = 2 * (uint)get_local_id(0); r0 < stop; r0 += 2 * group) {
        for (uint r = r0; r < r0 + 2 && r < stop; ++r) {  /* triangles r0 and r0 + 1 */
            if (r >= patch_end) {  /* patch_end >= 1 once found (the patch ends after a triangle >= start) */
                ulong at = start + r;
                p = patch_end ? patch_after(index_offsets, p, last, 3 * at) : patch_of(index_offsets, p, last, 3 * at);
                patch_start = (uint)(index_offsets[p] / 3) - (uint)start;
                patch_end = (uint)min(index_offsets[p + 1] / 3 - start, (ulong)stop);
                f = patch_factors(factors[p], &collapsed);
                base = (uint)vertex_offsets[p];
#ifdef PATTERN_TRIANGLE_AT
                direct = pattern_triangles_of(f, collapsed, &grid);
#endif
            }
            uint t = r - patch_start;
#ifdef PATTERN_TRIANGLE_AT
            if (direct) {
                int pairs;
                uint d;
                uint3 triangle = pattern_triangle_pair(&grid, t, &pairs, &d) + base;
                d += base;
                if (r == r0 && pairs && r + 1 < stop) {  /* and t + 1: (a, c, d) of the same cell */
                    if (words) {
                        __global uint2 *to = (__global uint2 *)(out + 3 * r);
                        to[0] = (uint2)(triangle.x, triangle.y);
                        to[1] = (uint2)(triangle.z, triangle.x);
                        to[2] = (uint2)(triangle.z, d);
                    } else {
                        vstore3(triangle, r, out);
                        vstore3((uint3)(triangle.x, triangle.z, d), r + 1, out);
                    }
                    break;
                }
                vstore3(triangle, r, out);
                continue;
            }
#endif
            if (t == 0)
                pattern_primitives(f, collapsed, out + (size_t)3 * r, base);
        }
    }
}
