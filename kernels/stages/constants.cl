/* Once per scene, before stage 1, for kinds whose bound has per-patch constants
 * (PatchKind.per_patch_constants; the Bézier kind: criteria/zs.h, zs_constants): what depends on
 * the patch alone, one float4 per patch, made here from the controls stage 4 reads and cached on
 * the scene per context (Tessellator.upload); stage 1 then reads it as its source and evaluates
 * only the closed form per tolerance.  One work-item per patch. */
__kernel void constants(__global const float4 *controls, uint num_patches, __global float4 *out)
{
    uint p = get_global_id(0);
    if (p >= num_patches)
        return;
    out[p] = kind_constants(controls, p);
}
