/* Stage 5 a work-item per output triangle (issue 15, for GPUs).  As stages/vertex_points.cl: a
 * work-group of TRIANGLE_GROUP work-items owns TRIANGLE_GROUP * per_item consecutive triangles of
 * the batch, in step k its work-item l handles triangle k TRIANGLE_GROUP + l of them, and it finds
 * a triangle's patch by patch_of (common.h) over index_offsets only when the patch changes
 * (64-bit divisions by 3 only then).  A pattern with random access to a regular patch's
 * triangles (PATTERN_TRIANGLE_AT, pattern_triangle_at) gives triangle t directly; any other patch
 * is emitted whole by the work-item of its triangle 0 with pattern_primitives, as
 * stages/indices.cl does.  Either way the bits of stages/indices.cl.
 *
 * Staged stores (session 8): a step's random-access triangles go to local memory first, and the
 * work-group writes the step's 3 TRIANGLE_GROUP indices as consecutive 4-byte words, consecutive
 * work-items on consecutive words (each warp store fills whole 32-byte sectors).  A work-item
 * storing its own triangle (vstore3) leaves a 12-byte stride between work-items: each of its
 * three stores touches 12 sectors for 128 bytes, three times the L2 write requests of the
 * output.  Whole-patch emissions run after the staged steps (a second pass over the same
 * triangles, only in a work-item that met a triangle 0 of such a patch), so that no work-group
 * waits at a step's barrier for a patch walk; the staged stores skip their triangles.
 * The batch is patches first_patch .. first_patch + num_patches - 1; work-items past its last
 * triangle stop. */

#define TRIANGLE_GROUP 64  /* work-items per work-group: the host's WORK_GROUP (tests/test_triangles_staged.py) */

__kernel void triangle_constants(__global uint *constants)
{
    constants[0] = TRIANGLE_GROUP;
}

/* The patch of the triangles a work-item is at: found by patch_of when `at` passes its end. */
typedef struct {
    uint p, base;                /* scene patch number; its first vertex in the batch */
    ulong start, end;            /* its triangles, numbered in the whole mesh */
    int4 f;
    int collapsed;
} triangle_patch;

inline void find_triangle_patch(__global const int4 *factors, __global const ulong *vertex_offsets,
                                __global const ulong *index_offsets, uint last, ulong at,
                                __private triangle_patch *q)
{
    if (at < q->end)
        return;
    q->p = patch_of(index_offsets, q->p, last, 3 * at);
    q->start = index_offsets[q->p] / 3;
    q->end = index_offsets[q->p + 1] / 3;
    q->f = patch_factors(factors[q->p], &q->collapsed);
    q->base = (uint)vertex_offsets[q->p];
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
    triangle_patch q = {first_patch, 0, 0, 0, (int4)(0), 0};  /* no patch found yet */
    int walks = 1;  /* whether this work-item holds a triangle 0 of a patch without random access */
#ifdef PATTERN_TRIANGLE_AT
    __local uint staged[3 * TRIANGLE_GROUP];  /* the step's triangles, triangle l at 3 l */
    __local int kept[TRIANGLE_GROUP];         /* whether staged triangle l is stored from here */
    walks = 0;
    ulong step = group_first;
    for (uint k = 0; k < per_item && step < end; ++k, step += TRIANGLE_GROUP) {  /* the same for the whole group */
        ulong at = step + lane;
        int random = 0;
        if (at < end) {
            find_triangle_patch(factors, vertex_offsets, index_offsets, last, at, &q);
            uint3 triangle;
            uint t = (uint)(at - q.start);
            random = pattern_triangle_at(q.f, q.collapsed, t, &triangle);
            if (random)
                vstore3(triangle + q.base, lane, staged);
            walks |= !random && t == 0;
        }
        kept[lane] = random;
        barrier(CLK_LOCAL_MEM_FENCE);
        uint words = 3 * (uint)min((ulong)TRIANGLE_GROUP, end - step);
        __global uint *out = indices + 3 * (step - first_triangle);
        for (uint w = lane; w < words; w += TRIANGLE_GROUP)
            if (kept[w / 3])
                out[w] = staged[w];
        barrier(CLK_LOCAL_MEM_FENCE);
    }
    q.p = first_patch;
    q.end = 0;
#endif
    if (!walks)
        return;
    ulong at = group_first + lane;
    for (uint k = 0; k < per_item && at < end; ++k, at += TRIANGLE_GROUP) {
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
