/* The tolerance field: how much error a patch may have, and whether it is culled
 * (docs/design.md section 7; host mirror cltess/criteria/tolerance.py).  Built with
 * -D TOLERANCE_SCREEN for the screen-space tolerance, else object space. */
#ifndef CLTESS_CRITERIA_TOLERANCE_H
#define CLTESS_CRITERIA_TOLERANCE_H
#include "common.h"

/* What stage 1 reads (ObjectSpace / ScreenSpace.kernel_args on the host): eps (object space),
 * or the camera: view (row-major 4x4), frustum (tan_x, tan_y, near, far), pixels and the pixel
 * size at depth 1. */
typedef struct {
    float eps;
    float16 view;
    float4 frustum;
    float pixels;
    float pixel_size;
} tolerance_args;

/* No patch gets a tolerance below this many float32 steps at its largest coordinate
 * (cltess.criteria.tolerance.FLOAT32_TOLERANCE_STEPS; docs/design.md section 7): the output's
 * float32 coordinates cannot hold a finer one, and below about one step neighbouring vertices
 * round to one point (degenerate, non-manifold welds far from the origin).  It is the rounding
 * allowance below plus the 2 steps the factors kept at least before the allowance. */
#define FLOAT32_TOLERANCE_STEPS 6.0f

/* Float32 steps of a patch's tolerance that its factors leave to rounding
 * (cltess.criteria.tolerance.FLOAT32_ROUNDING_STEPS; docs/design.md section 7): the control
 * points rounded to float32, the move to the patch's centre and the output's rounding each
 * move a point by up to sqrt(3)/2 step; the sphere at +1e5 measured 2.4 steps. */
#define FLOAT32_ROUNDING_STEPS 4.0f

/* One float32 step (ulp) at the largest |coordinate| of the box lo..hi. */
inline float float32_step(float3 lo, float3 hi)
{
    float3 extent = max(fabs(lo), fabs(hi));
    float largest = max(max(extent.x, extent.y), extent.z);
    return nextafter(largest, INFINITY) - largest;
}

inline float float32_tolerance_floor(float3 lo, float3 hi)
{
    return FLOAT32_TOLERANCE_STEPS * float32_step(lo, hi);
}

/* What a patch's factors may spend of its tolerance eps (patch_tolerance): eps less the
 * rounding allowance, so that the output, rounding included, stays within eps. */
inline float factor_tolerance(float eps, float3 lo, float3 hi)
{
    return eps - FLOAT32_ROUNDING_STEPS * float32_step(lo, hi);
}

/* Object-space tolerance of the patch whose control points lie in the box lo..hi, and whether
 * it is culled.  Object space: every patch gets eps.  Screen space: eps = pixels * nearest
 * depth * pixel_size, and a box entirely outside one frustum plane is culled.  Either is raised
 * to float32_tolerance_floor(lo, hi) where it is below. */
inline float patch_tolerance(float3 lo, float3 hi, tolerance_args tol, int *culled)
{
    *culled = 0;
    float floor = float32_tolerance_floor(lo, hi);
#ifndef TOLERANCE_SCREEN
    return max(tol.eps, floor);
#else
    float16 view = tol.view;
    float tan_x = tol.frustum.s0, tan_y = tol.frustum.s1, near = tol.frustum.s2, far = tol.frustum.s3;
    int out_mask = 0x3f;  /* bit per plane: set while every corner so far is outside it */
    float nearest = INFINITY;
    for (int c = 0; c < 8; ++c) {
        float3 w = (float3)((c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z);
        float x = dot(view.s012, w) + view.s3;
        float y = dot(view.s456, w) + view.s7;
        float depth = -(dot(view.s89a, w) + view.sb);
        int outside = (depth < near) | (depth > far) << 1 | (x > tan_x * depth) << 2
                    | (x < -tan_x * depth) << 3 | (y > tan_y * depth) << 4 | (y < -tan_y * depth) << 5;
        out_mask &= outside;
        nearest = min(nearest, depth);
    }
    *culled = out_mask != 0;
    return max(tol.pixels * max(nearest, near) * tol.pixel_size, floor);
#endif
}

#endif
