/* Stage 5 a work-item per output triangle (issue 15, for GPUs).  A work-group of TRIANGLE_GROUP
 * work-items owns TRIANGLE_GROUP * per_item consecutive triangles of the batch.  A work-item
 * finds a triangle's patch by patch_of (common.h) over index_offsets only when the patch changes
 * (64-bit divisions by 3 only then).  Either way below, the bits of stages/indices.cl.
 *
 * A pattern with random access to a regular patch's triangles (PATTERN_TRIANGLE_AT: a cursor,
 * patterns/quad_transition.h): in steps, work-item l takes a run of `run` = min(per_item,
 * TRIANGLE_RUN) consecutive triangles, the step's l-th; it seeks its first triangle (one
 * division) and steps the cursor to the next ones (no division), writing them to local memory;
 * then the work-group writes the step's indices as consecutive 4-byte words, consecutive
 * work-items on consecutive words (whole 32-byte sectors per warp store).  On the H100 a
 * work-item per triangle that sought every triangle and stored it itself (vstore3: a 12-byte
 * stride between work-items, each store touching 12 sectors for 128 bytes) took 0.146 ms on
 * uniform level 16, 0.216 with ring_index's "% ring" (bench/RESULTS.md, "Issue 15: stage 5 in
 * runs").
 *
 * Any other patch is emitted whole by one work-item with pattern_primitives, as
 * stages/indices.cl does: in a second pass, a work-item per triangle in steps (in step k
 * work-item l takes triangle k TRIANGLE_GROUP + l of the group's), the work-item of the patch's
 * triangle 0; so that neighbouring patches are walked side by side and no step of the staged
 * pass waits for a walk.  It runs only in a work-group that holds such a triangle 0.
 * The batch is patches first_patch .. first_patch + num_patches - 1; work-items past its last
 * triangle stop. */

#define TRIANGLE_GROUP 64  /* work-items per work-group: the host's WORK_GROUP (tests/test_triangles_staged.py) */
#define TRIANGLE_RUN 16    /* at most this many consecutive triangles per work-item and step */

__kernel void triangle_constants(__global uint *constants)
{
    constants[0] = TRIANGLE_GROUP;
    constants[1] = TRIANGLE_RUN;
}

/* The patch of the triangles a work-item is at: found by patch_of when `at` passes its end. */
typedef struct {
    uint p, base;                /* scene patch number; its first vertex */
    ulong start, end;            /* its triangles, numbered in the whole mesh */
    int4 f;
    int collapsed;
} triangle_patch;

inline int find_triangle_patch(__global const int4 *factors, __global const ulong *vertex_offsets,
                               __global const ulong *index_offsets, uint last, ulong at,
                               __private triangle_patch *q)
{
    if (at < q->end)
        return 0;
    q->p = patch_of(index_offsets, q->p, last, 3 * at);
    q->start = index_offsets[q->p] / 3;
    q->end = index_offsets[q->p + 1] / 3;
    q->f = patch_factors(factors[q->p], &q->collapsed);
    q->base = (uint)vertex_offsets[q->p];
    return 1;
}

__kernel __attribute__((reqd_work_group_size(TRIANGLE_GROUP, 1, 1)))
void triangles(__global const int4 *factors, __global const ulong *vertex_offsets,
               __global const ulong *index_offsets, uint first_patch, uint num_patches,
               ulong index_base, ulong capacity, uint per_item, __global uint *indices)
{
    uint last = first_patch + num_patches, lane = get_local_id(0);
    if (!batch_fits(index_offsets, last, index_base, capacity))
        return;
    ulong end = index_offsets[last] / 3, first_triangle = index_base / 3;
    ulong group_first = index_offsets[first_patch] / 3 + (ulong)get_group_id(0) * TRIANGLE_GROUP * per_item;
    ulong group_end = min(group_first + (ulong)TRIANGLE_GROUP * per_item, end);
    triangle_patch q = {first_patch, 0, 0, 0, (int4)(0), 0};  /* no patch found yet */
#ifdef PATTERN_TRIANGLE_AT
    __local uint staged[TRIANGLE_GROUP * (3 * TRIANGLE_RUN + 1)];  /* work-item l's run at l * stride */
    __local uchar kept[TRIANGLE_GROUP * TRIANGLE_RUN];  /* triangle n of run l staged: kept[l * run + n] */
    __local int walks;  /* whether the group holds a triangle 0 of a patch without random access */
    uint run = min(per_item, (uint)TRIANGLE_RUN), words = 3 * run;
    uint stride = words | 1;  /* odd: the runs' n-th words fall in different banks */
    if (lane == 0)
        walks = 0;
    barrier(CLK_LOCAL_MEM_FENCE);
    for (ulong step = group_first; step < group_end; step += TRIANGLE_GROUP * run) {  /* the same for the whole group */
        ulong at = step + lane * run, stop = min(at + run, group_end);
        triangle_cursor cursor;
        int placed = 0;  /* whether the cursor is on triangle at - 1 of patch q */
        for (uint n = 0; n < run; ++n, ++at) {
            int staged_here = 0;
            if (at < stop) {
                if (find_triangle_patch(factors, vertex_offsets, index_offsets, last, at, &q))
                    placed = 0;
                uint t = (uint)(at - q.start);
                if (placed)
                    pattern_triangle_next(&cursor);
                else
                    placed = pattern_triangle_seek(q.f, q.collapsed, t, &cursor);
                if (placed)
                    vstore3(pattern_cursor_triangle(&cursor) + q.base, 0, staged + lane * stride + 3 * n);
                else if (t == 0)
                    walks = 1;
                staged_here = placed;
            }
            kept[lane * run + n] = staged_here;
        }
        barrier(CLK_LOCAL_MEM_FENCE);
        /* word w of the step: word w % words of run w / words, followed without a division */
        uint count = 3 * (uint)min((ulong)TRIANGLE_GROUP * run, group_end - step);
        uint owner = lane / words, offset = lane % words;
        __global uint *out = indices + 3 * (step - first_triangle);
        for (uint w = lane; w < count; w += TRIANGLE_GROUP) {
            if (kept[owner * run + offset / 3])
                out[w] = staged[owner * stride + offset];
            for (offset += TRIANGLE_GROUP; offset >= words; offset -= words)
                ++owner;
        }
        barrier(CLK_LOCAL_MEM_FENCE);
    }
    if (!walks)
        return;
    q.p = first_patch;
    q.end = 0;
#endif
    ulong at = group_first + lane;
    for (uint k = 0; k < per_item && at < group_end; ++k, at += TRIANGLE_GROUP) {
        find_triangle_patch(factors, vertex_offsets, index_offsets, last, at, &q);
        if (at != q.start)
            continue;
#ifdef PATTERN_TRIANGLE_AT
        uint3 triangle;
        if (pattern_triangle_at(q.f, q.collapsed, 0, &triangle))  /* random access: staged above */
            continue;
#endif
        pattern_primitives(q.f, q.collapsed, indices + 3 * (at - first_triangle), q.base);
    }
}
