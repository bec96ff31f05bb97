/* Stage 4 a work-item per output vertex from prepared patches (issue 15, for GPUs;
 * Tessellator(work="vertex-prep" / "point-prep")).  stages/vertex_points.cl runs kind_load
 * every time a work-item's next vertex lies in another patch, which with the group's stride is
 * about once per vertex: for a Bezier patch 16 float4 loads, its 4 boundary curves and
 * centred_patch with 48 divisions.  Here that is done once per patch and frame:
 *
 *   prepare_patches   a work-item per patch of the batch: kind_load, and the kind_patch stored
 *                     to prepared[p - first_patch], float4 by float4 with its unused lanes (a
 *                     float3's fourth) zeroed, so no undefined byte is stored (Oclgrind's
 *                     uninitialised-value pass); a patch without vertices is skipped, unless
 *                     `every` (a Session keeps a scene's prepared patches for all its frames:
 *                     a patch culled now may have vertices in a later frame);
 *   prepared_points   as vertex_points, the patch copied from prepared[] (no arithmetic; the
 *                     lanes of a warp mostly read the same patch: cached) instead of kind_load;
 *   kind_patch_size   sizeof(kind_patch), for the host's scratch buffer.
 *
 * The kind's kind_patch holds everything kind_load made, so the copy is bitwise the struct that
 * vertex_points builds in private memory, and the vertices bitwise its (put_point, stages/rows.h;
 * forward differencing replayed as there).  The kind contract is unchanged (docs/extending.md):
 * its functions still take a __private kind_patch.  Built against a kind and a pattern header. */
#include "stages/rows.h"

__kernel void kind_patch_size(__global uint *size)
{
    size[0] = (uint)sizeof(kind_patch);
}

__kernel void prepare_patches(__global const float4 *controls, __global const ulong *vertex_offsets,
                              uint first_patch, uint num_patches, uint patch_base,
                              __global float4 *prepared,  /* kind_patch records, written word by word */
                              int every)
{
    uint slot = (uint)get_global_id(0), p = first_patch + slot;
    if (slot >= num_patches || (!every && vertex_offsets[p + 1] == vertex_offsets[p]))
        return;  /* past the batch, or no vertex (culled, folded): never read */
    union {
        kind_patch patch;
        float4 words[(sizeof(kind_patch) + 15) / 16];
    } made;
    for (uint k = 0; k < (uint)(sizeof(made.words) / 16); ++k)  /* the float3s' unused lanes: 0 */
        made.words[k] = (float4)(0.0f);
    kind_load(controls, p - patch_base, &made.patch);
    __global float4 *to = prepared + (size_t)slot * (sizeof(kind_patch) / 16);
    for (uint k = 0; k < (uint)(sizeof(kind_patch) / 16); ++k)  /* word by word (sizeof: a multiple of 16) */
        to[k] = made.words[k];
}

/* As stages/vertex_points.cl (put_points, stages/rows.h), with the patch from prepared[]. */
__kernel void prepared_points(__global const kind_patch *restrict prepared, __global const int4 *factors,
                              __global const ulong *vertex_offsets, __global const int *patch_objects,
                              uint first_patch, uint num_patches, ulong vertex_base,
                              int forward_differencing, ulong capacity, uint per_item,
                              __global float *positions, __global float *normals, __global float *uv,
                              __global int *patch_ids, __global int *object_ids)
{
    vertex_out out = {positions, normals, uv, patch_ids, object_ids};
    put_points(0, 0, 1, prepared, factors, vertex_offsets, patch_objects, first_patch, num_patches, vertex_base,
               forward_differencing, capacity, per_item, out);
}

/* Stage 4 a work-item per line (an interior row or a ring edge) from prepared patches (issue 15,
 * for GPUs; Tessellator(work="rows-prep")).  prepared_points replays a row's forward
 * differencing from the row's start for every point (kind_row_begin and up to steps - 1 steps:
 * about 1,300 operations per point on the H100 against 600 for a direct evaluation) and runs
 * put_point's edge loop for every ring point; here a work-item walks its line's points in order
 * as put_rows / put_ring do (one kind_row_begin per row), so each point is one step.
 *
 * A work-group of LINE_GROUP work-items owns patches_per_group consecutive patches of the batch.
 * Its lines are numbered rows first (patch by patch: row_first[q] is patch q's first), then the
 * edges edge-major (line rows + e * patches + q), so that a warp's lanes mostly walk rows alone
 * or one edge alone (one path per warp).  In rounds of LINE_GROUP lines, each work-item takes
 * one, and its points go LINE_CHUNK at a time to local memory (staged[component][item][point],
 * a row of LINE_CHUNK + 1 floats per work-item: the stores of a warp fall in distinct banks);
 * then the work-group writes the staged points out, consecutive work-items the consecutive
 * points of a line (a patch's rows, and its ring's edges, are side by side in the output), so
 * that the global stores of a warp fall side by side, where a work-item writing its own line
 * (stages/vertex_rows.cl) spreads them over the lines.  Each point is edge_point's or
 * row_point's (stages/rows.h): bitwise what stages/vertices.cl writes.  Patches without
 * vertices (culled) have no lines and are never read from prepared[] (prepare_patches skips
 * them); a batch of more than `capacity` vertices writes none (batch_fits: the whole launch
 * returns).  Needs patches_per_group <= LINE_MAX_PATCHES and the work-group size LINE_GROUP (the
 * host's constants, checked by a test).  On the H100, uniform level 16: stage 4 0.505 ms against
 * prepared_points' 1.07 (bench/RESULTS.md, "Issue 15: stage 4 a work-item per row or ring edge"). */
#define LINE_GROUP 32
#ifndef LINE_CHUNK  /* points per line staged at a time (a build option may set it: bench/gpu_stage45.py) */
#define LINE_CHUNK 16
#endif
#define LINE_MAX_PATCHES 64
#define LINE_STAGED (LINE_GROUP * (LINE_CHUNK + 1))

/* A point's position, normal and uv (its domain point's u, v) to the staging slot. */
inline void stage_point(__local float (*staged)[LINE_STAGED], uint slot, float3 position, float3 normal, float3 x)
{
    staged[0][slot] = position.x;
    staged[1][slot] = position.y;
    staged[2][slot] = position.z;
    staged[3][slot] = normal.x;
    staged[4][slot] = normal.y;
    staged[5][slot] = normal.z;
    staged[6][slot] = x.x;
    staged[7][slot] = x.y;
}

__kernel void line_constants(__global uint *constants)
{
    constants[0] = LINE_GROUP;
    constants[1] = LINE_CHUNK;
    constants[2] = LINE_MAX_PATCHES;
}

__kernel __attribute__((reqd_work_group_size(LINE_GROUP, 1, 1)))
void prepared_rows(__global const kind_patch *restrict prepared, __global const int4 *factors,
                   __global const ulong *vertex_offsets, __global const int *patch_objects,
                   uint first_patch, uint num_patches, ulong vertex_base,
                   int forward_differencing, ulong capacity, uint patches_per_group,
                   __global float *positions, __global float *normals, __global float *uv,
                   __global int *patch_ids, __global int *object_ids)
{
    __local uint row_first[LINE_MAX_PATCHES + 1];
    __local float staged[8][LINE_STAGED];  /* position, normal, uv of each staged point */
    __local ulong line_at[LINE_GROUP];     /* output slot of each work-item's first staged point */
    __local int line_count[LINE_GROUP], line_patch[LINE_GROUP], line_object[LINE_GROUP];
    __local int round_length;
    /* each patch's factors, first output slot, object, rows, and whether it has vertices */
    __local int4 group_factors[LINE_MAX_PATCHES];
    __local ulong group_vertex[LINE_MAX_PATCHES];
    __local int group_object[LINE_MAX_PATCHES], group_rows[LINE_MAX_PATCHES], group_has[LINE_MAX_PATCHES];
#if !PATTERN_UNIFORM_ROWS
    forward_differencing = 0;  /* the rows' points are not equally spaced (patterns/layout.h) */
#endif
    uint last = first_patch + num_patches;
    if (!batch_fits(vertex_offsets, last, vertex_base, capacity))
        return;
    vertex_out out = {positions, normals, uv, patch_ids, object_ids};
    uint item = (uint)get_local_id(0), group_first = first_patch + (uint)get_group_id(0) * patches_per_group;
    uint patches = min(patches_per_group, last - group_first);  /* the host launches no group past the batch */
    /* The group's patches, a work-item each, to local memory: a round's lines read them there, not
     * from global memory after the round's first local read (Nsight Compute on the H200: those
     * dependent loads held 13% of the warps' sampled time; bench/RESULTS.md, "Issue 15: stage 4
     * under Nsight Compute on the H200"). */
    for (uint q = item; q < patches; q += LINE_GROUP) {
        uint p = group_first + q;
        ulong from = vertex_offsets[p], to = vertex_offsets[p + 1];
        int4 raw = factors[p];
        int collapsed;
        group_factors[q] = raw;
        group_vertex[q] = from - vertex_base;
        group_object[q] = patch_objects[p];
        group_has[q] = to > from;
        group_rows[q] = to > from ? pattern_rows(patch_factors(raw, &collapsed)) : 0;
    }
    barrier(CLK_LOCAL_MEM_FENCE);
    if (item == 0) {  /* the group's rows, patch by patch (none for a patch without vertices) */
        uint rows = 0;
        for (uint q = 0; q < patches; ++q) {
            row_first[q] = rows;
            rows += (uint)group_rows[q];
        }
        row_first[patches] = rows;
    }
    barrier(CLK_LOCAL_MEM_FENCE);
    uint rows = row_first[patches], lines = rows + PATTERN_EDGES * patches;
    for (uint first_line = 0; first_line < lines; first_line += LINE_GROUP) {
        uint line = first_line + item, q = 0;
        int edge = -1, row = 0, count = 0;
        if (line < rows) {  /* row `row` of patch q */
            while (row_first[q + 1] <= line)
                ++q;
            row = (int)(line - row_first[q]) + 1;
        } else if (line < lines) {  /* edge `edge` of patch q */
            edge = (int)((line - rows) / patches);
            q = (line - rows) % patches;
        }
        uint p = group_first + q;
        int collapsed = 0;
        int4 f = patch_factors(group_factors[q], &collapsed);
        ulong at = 0;
        if (line < lines && group_has[q])
            at = group_vertex[q] + line_start(f, edge, row, &count);
        kind_row walk;
        kind_patch patch;
        if (count > 0 && edge < 0 && forward_differencing) {
            patch = prepared[p - first_patch];
            int steps = pattern_row(f, row);
            kind_row_begin(&patch, pattern_row_point(f, row, 0), pattern_row_point(f, row, steps), steps, &walk);
        }
        if (item == 0)
            round_length = 0;
        barrier(CLK_LOCAL_MEM_FENCE);
        atomic_max(&round_length, count);
        barrier(CLK_LOCAL_MEM_FENCE);
        int length = round_length;
        barrier(CLK_LOCAL_MEM_FENCE);  /* read by all before the next round resets it */
        for (int k = 0; k < length; k += LINE_CHUNK) {
            int staging = clamp(count - k, 0, LINE_CHUNK);
            uint own = item * (LINE_CHUNK + 1);  /* this work-item's staging slots */
            float3 x, position, normal;
            /* Two loops, each reading only the part of the patch that its points use.  (The copy is
             * the same in every step, and NVIDIA's compiler loads it once before the loop: 255
             * registers, bench/RESULTS.md.) */
            if (edge >= 0) {
                for (int s = 0; s < staging; ++s) {
                    patch = prepared[p - first_patch];
                    edge_point(&patch, f, collapsed, edge, k + s, &x, &position, &normal);
                    stage_point(staged, own + (uint)s, position, normal, x);
                }
            } else {
                for (int s = 0; s < staging; ++s) {
                    patch = prepared[p - first_patch];
                    row_point(&patch, f, collapsed, row, k + s, forward_differencing, &walk, &x, &position, &normal);
                    stage_point(staged, own + (uint)s, position, normal, x);
                }
            }
            line_at[item] = at + (ulong)k;
            line_count[item] = staging;
            line_patch[item] = (int)p;
            line_object[item] = staging ? group_object[q] : 0;
            barrier(CLK_LOCAL_MEM_FENCE);
            for (uint t = item; t < LINE_GROUP * LINE_CHUNK; t += LINE_GROUP) {  /* consecutive t: one line's points */
                uint from = t / LINE_CHUNK, s = t % LINE_CHUNK, slot = from * (LINE_CHUNK + 1) + s;
                if ((int)s < line_count[from])
                    put_vertex(out, line_at[from] + s,
                               (float3)(staged[0][slot], staged[1][slot], staged[2][slot]),
                               (float3)(staged[3][slot], staged[4][slot], staged[5][slot]),
                               (float2)(staged[6][slot], staged[7][slot]), line_patch[from], line_object[from]);
            }
            barrier(CLK_LOCAL_MEM_FENCE);
        }
    }
}
