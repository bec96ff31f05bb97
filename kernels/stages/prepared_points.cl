/* Stage 4 a work-item per output vertex from prepared patches (issue 15, for GPUs;
 * Tessellator(work="vertex-prep" / "point-prep")).  stages/vertex_points.cl runs kind_load
 * every time a work-item's next vertex lies in another patch, which with the group's stride is
 * about once per vertex: for a Bezier patch 16 float4 loads, its 4 boundary curves and
 * centred_patch with 48 divisions.  Here that is done once per patch and frame:
 *
 *   prepare_patches   a work-item per patch of the batch: kind_load, and the kind_patch stored
 *                     to prepared[p - first_patch], float4 by float4 with its unused lanes (a
 *                     float3's fourth) zeroed, so no undefined byte is stored (Oclgrind's
 *                     uninitialised-value pass); a patch without vertices is skipped;
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
                              __global float4 *prepared)  /* kind_patch records, written word by word */
{
    uint slot = (uint)get_global_id(0), p = first_patch + slot;
    if (slot >= num_patches || vertex_offsets[p + 1] == vertex_offsets[p])
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
