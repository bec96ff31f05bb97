/* Rational bicubic Bezier patches: the device side of the kind "bezier" (docs/design.md
 * section 2; host cltess/kinds/bezier.py, NumPy mirror cltess/surfaces/bezier.py).
 *
 * Layout: 16 float4 homogeneous control points b[4*j + i] = (w*x, w*y, w*z, w), i along u, j
 * along v.  Domain: the unit square (u, v); edges counter-clockwise 0: v=0, 1: u=1, 2: v=1,
 * 3: u=0 (quad_edge_point).  Stage 1 reads the patches (controls, as stage 4 does) and their
 * bound's constants (source: one float4 per patch, made by stage 1 on first use and kept with
 * the scene; PatchKind.per_patch_constants). */
#ifndef CLTESS_KINDS_BEZIER_H
#define CLTESS_KINDS_BEZIER_H
#include "common.h"
#include "criteria/tolerance.h"
#include "criteria/zs.h"

#define KIND_DOMAIN_EDGES 4

/* --- rational patch evaluation ----------------------------------------------------------------- */

/* The patch moved so that its control points' bounding box is centred on the origin:
 * t[k] = (b.xyz - b.w c, b.w).  Returns c.  Tangents t = B_u.xyz - B_u.w p cancel in float32 when
 * |p| is large against the patch; about its own centre they do not (a sphere at (20, 20, 20)
 * had 1% of its normals flipped near the poles before this). */
inline float3 centred_patch(const float4 b[16], float4 t[16])
{
    float3 lo = b[0].xyz / b[0].w, hi = lo;
    for (int k = 1; k < 16; ++k) {
        lo = min(lo, b[k].xyz / b[k].w);
        hi = max(hi, b[k].xyz / b[k].w);
    }
    float3 centre = 0.5f * (lo + hi);
    for (int k = 0; k < 16; ++k)
        t[k] = (float4)(b[k].xyz - b[k].w * centre, b[k].w);
    return centre;
}

/* Collapse the patch to the row v = const: cubic controls c[i] of B(., v) and d[i] of B_v(., v).
 * Derivatives use differences of control points, so a collapsed edge gives exactly zero. */
inline void row_controls(const float4 b[16], float v, float4 c[4], float4 d[4])
{
    float bv[4], dv[3];
    bernstein3(v, bv);
    bernstein2(v, dv);
    for (int i = 0; i < 4; ++i) {
        c[i] = bv[0] * b[i] + bv[1] * b[4 + i] + bv[2] * b[8 + i] + bv[3] * b[12 + i];
        d[i] = 3.0f * (dv[0] * (b[4 + i] - b[i]) + dv[1] * (b[8 + i] - b[4 + i])
                       + dv[2] * (b[12 + i] - b[8 + i]));
    }
}

/* B, B_u, B_v at (u, v) by the tensor-product Bernstein form. */
inline void surface_eval(const float4 b[16], float u, float v, float4 *s, float4 *s_u, float4 *s_v)
{
    float4 c[4], d[4];
    float bu[4], du[3];
    row_controls(b, v, c, d);
    bernstein3(u, bu);
    bernstein2(u, du);
    *s = bu[0] * c[0] + bu[1] * c[1] + bu[2] * c[2] + bu[3] * c[3];
    *s_u = 3.0f * (du[0] * (c[1] - c[0]) + du[1] * (c[2] - c[1]) + du[2] * (c[3] - c[2]));
    *s_v = bu[0] * d[0] + bu[1] * d[1] + bu[2] * d[2] + bu[3] * d[3];
}

/* The point h.xyz / h.w of a homogeneous h, without the three divisions where h.w is exactly 1,
 * and bitwise the same: for x not a NaN, the exact quotient x / 1 is x, representable, so the
 * correctly rounded division returns x itself, with x's sign (-0 stays -0, an infinity stays
 * itself).  programs.py builds with correctly rounded division where the device offers it (NVIDIA,
 * PoCL); where not (Oclgrind), OpenCL would allow x / 1 within 2.5 ulp, but a division by 1 there
 * (the host's) is exact too.  (A NaN gives a NaN either way, its payload perhaps not; a device
 * flushing subnormals reads a subnormal x as the zero that x / 1 would flush it to.)
 * h.w is exactly 1 on a polynomial patch (every weight 1, as the teapot's) at its boundary points
 * (boundary_point's lerps of weights 1: 1 + s (1 - 1) = 1), and inside where the Bernstein values
 * of u and v sum to 1 exactly, e.g. at k / 2^n (the uniform power-of-two levels; along such a row
 * the weight's forward differences are then 1, 0, 0, 0 and stay so).  A warp whose points all have
 * weight 1 skips the divisions: stage 4 of uniform level 16 on the H100 0.469-0.484 ms against
 * 0.498-0.513 (bench/RESULTS.md "Issue 15: exact shortcuts in stage 4 (session 9, branch gpu15g)"). */
inline float3 projected(float4 h)
{
    if (h.w == 1.0f)
        return h.xyz;
    return h.xyz / h.w;
}

/* Unnormalised t_u x t_v with t = (B_d.xyz - B_d.w p) / B.w (the 1/B.w is dropped: same
 * direction), p = B.xyz / B.w (projected).  Sets *ok when it is not (nearly) vanishing. */
inline float3 tangent_cross(float3 p, float4 s_u, float4 s_v, int *ok)
{
    float3 t_u = s_u.xyz - s_u.w * p;
    float3 t_v = s_v.xyz - s_v.w * p;
    float3 n = cross3(t_u, t_v);  /* cross, dot (inline on PoCL: common.h) */
    float scale = dot3f(t_u, t_u) + dot3f(t_v, t_v);
    *ok = dot3f(n, n) > NORMAL_DEGENERATE * NORMAL_DEGENERATE * scale * scale;
    return n;
}

/* Second derivatives B_uu, B_uv, B_vv at (u, v), from second differences of the controls. */
inline void surface_second(const float4 b[16], float u, float v, float4 *s_uu, float4 *s_uv, float4 *s_vv)
{
    float4 c[4], d[4], e[4];
    float bu[4], du[3], bv[2];
    row_controls(b, v, c, d);
    bernstein3(u, bu);
    bernstein2(u, du);
    bv[0] = 1.0f - v;
    bv[1] = v;
    for (int i = 0; i < 4; ++i)  /* controls of B_vv along the row */
        e[i] = 6.0f * (bv[0] * (b[8 + i] - 2.0f * b[4 + i] + b[i])
                       + bv[1] * (b[12 + i] - 2.0f * b[8 + i] + b[4 + i]));
    *s_uu = 6.0f * ((1.0f - u) * (c[2] - 2.0f * c[1] + c[0]) + u * (c[3] - 2.0f * c[2] + c[1]));
    *s_uv = 3.0f * (du[0] * (d[1] - d[0]) + du[1] * (d[2] - d[1]) + du[2] * (d[3] - d[2]));
    *s_vv = bu[0] * e[0] + bu[1] * e[1] + bu[2] * e[2] + bu[3] * e[3];
}

/* Where t_u x t_v vanishes (a collapsed edge), the normal is its first-order term towards the
 * domain centre, d = (1/2 - u, 1/2 - v): D_d(T_u x T_v) = D_d T_u x T_v + T_u x D_d T_v with
 * T = B_d.xyz - B_d.w p and D_d p = (d_u T_u + d_v T_v) / B.w (docs/design.md section 2: "the
 * next-order term").  Second derivatives, not a step inwards: the edge's own float32 noise
 * (its control points are only nearly equal once far from the origin) stays negligible. */
inline float3 limit_normal(const float4 b[16], float u, float v, float4 s, float3 p, float4 s_u, float4 s_v)
{
    float4 s_uu, s_uv, s_vv;
    surface_second(b, u, v, &s_uu, &s_uv, &s_vv);
    float d_u = 0.5f - u, d_v = 0.5f - v;
    float3 t_u = s_u.xyz - s_u.w * p, t_v = s_v.xyz - s_v.w * p;
    float3 dp = (d_u * t_u + d_v * t_v) / s.w;
    float4 ds_u = d_u * s_uu + d_v * s_uv, ds_v = d_u * s_uv + d_v * s_vv;
    float3 dt_u = ds_u.xyz - ds_u.w * p - s_u.w * dp;
    float3 dt_v = ds_v.xyz - ds_v.w * p - s_v.w * dp;
    return cross3(dt_u, t_v) + cross3(t_u, dt_v);
}

/* Unit normal at (u, v), given B, p = B.xyz / B.w (projected), B_u, B_v there: t_u x t_v, or at
 * a collapsed edge its limit (limit_normal); if that vanishes too, a step towards the centre; else
 * +z.
 * ALWAYS_INLINE works around Intel's CPU OpenCL runtime (2026.22): in ESC's stage 4 (only there)
 * its vectoriser left this float3-returning call to a vector variant and read lane k's result
 * 12 bytes (a packed float3) after lane k-1's where it was written 16 bytes (a float3's size)
 * after: lane k got floats 3k .. 3k+2 of the padded results, so every patch but one in 8 had
 * scrambled normals (docs/esc.md, "Normals on Intel's CPU runtime";
 * tests/test_pattern_normals.py).  Returning a float4 also avoided it. */
ALWAYS_INLINE float3 surface_normal(const float4 b[16], float u, float v, float4 s, float3 p, float4 s_u,
                                    float4 s_v)
{
    int ok;
    float3 n = tangent_cross(p, s_u, s_v, &ok);
    if (!ok) {
        float3 limit = limit_normal(b, u, v, s, p, s_u, s_v);
        if (dot3f(limit, limit) > dot3f(n, n)) {
            n = limit;
        } else {
            surface_eval(b, u + NORMAL_SHIFT * (0.5f - u), v + NORMAL_SHIFT * (0.5f - v), &s, &s_u, &s_v);
            n = tangent_cross(projected(s), s_u, s_v, &ok);
        }
    }
    return unit_or(n, (float3)(0.0f, 0.0f, 1.0f));  /* n / length(n), or +z (common.h: no zero divided) */
}

/* The 4 control points of edge e, counter-clockwise (cltess/scene.py, boundary_curves). */
inline void edge_controls(const float4 b[16], int e, float4 c[4])
{
    for (int k = 0; k < 4; ++k) {
        int idx = e == 0 ? k : e == 1 ? 4 * k + 3 : e == 2 ? 15 - k : 12 - 4 * k;
        c[k] = b[idx];
    }
}

/* What the factors of a patch may spend, at its control points' bounding box (criteria/tolerance.h
 * patch_tolerance less the rounding allowance, factor_tolerance; the convex hull holds the
 * patch); *culled when the box is out of view. */
ALWAYS_INLINE float bezier_tolerance(__private const float4 b[16], tolerance_args tol, __private int *culled)
{
    float3 lo = b[0].xyz / b[0].w, hi = lo;
    for (int k = 1; k < 16; ++k) {
        float3 point = b[k].xyz / b[k].w;
        lo = min(lo, point);
        hi = max(hi, point);
    }
    return factor_tolerance(patch_tolerance(lo, hi, tol, culled), lo, hi);
}

/* --- the kind contract (docs/extending.md) ----------------------------------------------------- */

/* Stage 1: factors (m, n, m, n) by edge from the Zheng-Sederberg bound; *flags as FLAG_*.
 * source[p]: the constants of the patch's bound (criteria/zs.h zs_constants), which depend on the
 * patch alone and are kept with the scene (PatchKind.per_patch_constants, Tessellator.upload):
 * .x < 0 marks them not yet made, and the first call that sees the patch (not culled) makes and
 * stores them, so later calls evaluate only zs_constant_steps.  Work-item p writes only
 * source[p]. */
inline int4 kind_factors(__global float4 *source, __global float4 *controls, uint p,
                         tolerance_args tol, int max_factor, int *flags)
{
    float4 b[16];
    load_patch(controls, p, b);
    int culled;
    float eps = bezier_tolerance(b, tol, &culled);
    if (culled) {
        *flags = FLAG_CULLED;
        return (int4)(0);
    }
    float4 constants = source[p];
    if (constants.x < 0.0f) {  /* not made yet for this scene */
        constants = zs_constants(b);
        source[p] = constants;
    }
    float2 inverse = zs_constant_steps(constants, eps);  /* docs/rational-bound.md */
    int saturated = 0;
    int m = edge_factor(inverse.x, max_factor, &saturated);
    int n = edge_factor(inverse.y, max_factor, &saturated);
    *flags = saturated;
    return (int4)(m, n, m, n);
}

/* Stages 4: the patch as evaluated, about its own centre (centred_patch). */
typedef struct {
    float4 edges[4][4];  /* its boundary curves as given: points on them bitwise like the neighbour's */
    float4 t[16];        /* the patch moved to its centre: normals and interior points */
    float3 centre;
} kind_patch;

ALWAYS_INLINE void kind_load(__global const float4 *controls, uint p, __private kind_patch *patch)
{
    float4 b[16];
    load_patch(controls, p, b);
    for (int e = 0; e < 4; ++e)
        edge_controls(b, e, patch->edges[e]);
    patch->centre = centred_patch(b, patch->t);
}

/* Position of point t of edge e, canonical from the edge's own control points. */
ALWAYS_INLINE float3 kind_boundary_point(__private const kind_patch *patch, int e, edge_param t)
{
    return projected(boundary_point(patch->edges[e], t));
}

/* Direct evaluation at x = (u, v, 0) (position 0: the normal only). */
ALWAYS_INLINE void kind_eval(__private const kind_patch *patch, float3 x, __private float3 *position, __private float3 *normal)
{
    float4 s, s_u, s_v;
    surface_eval(patch->t, x.x, x.y, &s, &s_u, &s_v);
    float3 p = projected(s);
    if (position)
        *position = p + patch->centre;
    *normal = surface_normal(patch->t, x.x, x.y, s, p, s_u, s_v);
}

/* Forward differencing along a row v = start.y from u = 0 to 1 in `steps` steps: B is a cubic in
 * u with controls c, B_v one with controls d, and B_u the derivative of B (docs/design.md
 * section 6). */
typedef struct {
    float4 s[4], s_u[4], s_v[4];
} kind_row;

ALWAYS_INLINE void kind_row_begin(__private const kind_patch *patch, float3 start, float3 end, int steps, __private kind_row *row)
{
    float h = 1.0f / (float)steps;
    float4 c[4], d[4], a[4], av[4];
    row_controls(patch->t, start.y, c, d);
    power_form(c, a);
    power_form(d, av);
    cubic_differences(a[0], a[1], a[2], a[3], h, row->s);
    cubic_differences(a[1], 2.0f * a[2], 3.0f * a[3], (float4)(0.0f), h, row->s_u);
    cubic_differences(av[0], av[1], av[2], av[3], h, row->s_v);
}

/* `count` steps of a row with no point made (kind_row_next makes each point after one). */
ALWAYS_INLINE void kind_row_skip(__private kind_row *row, int count)
{
    for (int k = 0; k < count; ++k) {
        step_differences(row->s);
        step_differences(row->s_u);
        step_differences(row->s_v);
    }
}

/* The row's next point, x its domain point (for the normal's fall-backs). */
ALWAYS_INLINE void kind_row_next(__private const kind_patch *patch, __private kind_row *row, float3 x, __private float3 *position, __private float3 *normal)
{
    kind_row_skip(row, 1);
    float4 value = row->s[0];
    float3 p = projected(value);
    *position = p + patch->centre;
    *normal = surface_normal(patch->t, x.x, x.y, value, p, row->s_u[0], row->s_v[0]);
}

#if CLTESS_LANES
/* Where CLTESS_LANES (common.h: Intel's CPU runtime, PoCL on x86-64), stage 4 makes KIND_LANES
 * points at once (stages/rows.h): a row's points (forward differencing) and a ring edge's normals
 * (kind_eval).  Each lane is computed with float8 arithmetic, component by component the same
 * operations in the same order as the scalar functions (FP_CONTRACT is off: common.h), and the
 * builtins in the runtime's own forms (common.h lanes_cross_term, lanes_dot, lanes_length), so
 * the same bits.  unit_or's shortcut gives the same bits without its branch (a zero component
 * divided by len > 0 is itself); projected's (h.xyz / h.w where h.w is 1 is h.xyz) is taken where
 * every lane's h.w is 1.  A lane whose t_u x t_v is (nearly) vanishing, or whose length
 * is not its plain value (lanes_length_plain: PoCL's scaled branches) or not positive, is not
 * "plain": stages/rows.h then makes the eight points one by one by the scalar functions
 * (put_row_lanes, put_ring_lanes).  The kind's side of the contract: KIND_LANES,
 * kind_row_next_lanes, kind_row_skip, kind_eval_lanes, kind_rows, kind_rows_begin, kind_rows_next
 * (docs/extending.md). */
#define KIND_LANES 8

/* bernstein3 / bernstein2 of eight lanes (common.h: the same body). */
ALWAYS_INLINE void bernstein3_lanes(float8 t, float8 b[4]) BERNSTEIN3_OF(float8)

ALWAYS_INLINE void bernstein2_lanes(float8 t, float8 b[3]) BERNSTEIN2_OF(float8)

/* row_controls' component k at eight v, given bernstein3 / bernstein2 of them (bv, dv). */
ALWAYS_INLINE void row_controls_lanes(const float4 b[16], const float8 bv[4], const float8 dv[3], int k,
                                      float8 c[4], float8 d[4])
{
    for (int i = 0; i < 4; ++i) {
        c[i] = bv[0] * b[i][k] + bv[1] * b[4 + i][k] + bv[2] * b[8 + i][k] + bv[3] * b[12 + i][k];
        d[i] = 3.0f * (dv[0] * (b[4 + i][k] - b[i][k]) + dv[1] * (b[8 + i][k] - b[4 + i][k])
                       + dv[2] * (b[12 + i][k] - b[8 + i][k]));
    }
}

/* surface_eval at eight points (u, v): B, B_u, B_v by component (s[c] is component c's lanes).
 * Where the eight share their v bitwise (a ring edge along u), row_controls is made once, its
 * components copied to every lane: the same operations as each lane's. */
ALWAYS_INLINE void surface_eval_lanes(const float4 b[16], float8 u, float8 v, float8 s[4], float8 s_u[4],
                                      float8 s_v[4])
{
    float8 bu[4], du[3], controls[4][4], v_controls[4][4];  /* [k][i]: component k of row control i */
    bernstein3_lanes(u, bu);
    bernstein2_lanes(u, du);
    if (every_lane(as_int8(v) == (int8)(as_int(v.s0)))) {
        float4 one_c[4], one_d[4];
        row_controls(b, v.s0, one_c, one_d);
        __attribute__((opencl_unroll_hint))
        for (int k = 0; k < 4; ++k)
            for (int i = 0; i < 4; ++i) {
                controls[k][i] = (float8)(one_c[i][k]);
                v_controls[k][i] = (float8)(one_d[i][k]);
            }
    } else {
        float8 bv[4], dv[3];
        bernstein3_lanes(v, bv);
        bernstein2_lanes(v, dv);
        __attribute__((opencl_unroll_hint))
        for (int k = 0; k < 4; ++k)
            row_controls_lanes(b, bv, dv, k, controls[k], v_controls[k]);
    }
    for (int k = 0; k < 4; ++k) {  /* the point, component k */
        const float8 *c = controls[k], *d = v_controls[k];
        s[k] = bu[0] * c[0] + bu[1] * c[1] + bu[2] * c[2] + bu[3] * c[3];
        s_u[k] = 3.0f * (du[0] * (c[1] - c[0]) + du[1] * (c[2] - c[1]) + du[2] * (c[3] - c[2]));
        s_v[k] = bu[0] * d[0] + bu[1] * d[1] + bu[2] * d[2] + bu[3] * d[3];
    }
}

/* projected(B) into p[3] and surface_normal's plain case into normal[3], at eight points; *plain
 * nonzero where that case is the one surface_normal takes (tangent_cross's ok, then
 * normal_length's plain value, and positive, so that unit_or divides). */
ALWAYS_INLINE void normal_lanes(const float8 s[4], const float8 s_u[4], const float8 s_v[4], float8 p[3],
                                float8 normal[3], __private int8 *plain)
{
    /* projected's shortcut where every lane's h.w is 1 (polynomial patches): h.xyz / 1 is h.xyz, and
     * three divisions fewer for the divider that the normal's sqrt and divisions keep busy (Intel's
     * runtime 88-89 -> 86, PoCL 93-95 -> 91-92 CPU ms of stage 4 on uniform level 16: bench/RESULTS.md,
     * "Session 17, lead") */
    float8 px = s[0], py = s[1], pz = s[2];
    if (!every_lane(s[3] == 1.0f)) {
        px = s[0] / s[3];
        py = s[1] / s[3];
        pz = s[2] / s[3];
    }
    p[0] = px;
    p[1] = py;
    p[2] = pz;
    float8 tux = s_u[0] - s_u[3] * px, tuy = s_u[1] - s_u[3] * py, tuz = s_u[2] - s_u[3] * pz;
    float8 tvx = s_v[0] - s_v[3] * px, tvy = s_v[1] - s_v[3] * py, tvz = s_v[2] - s_v[3] * pz;
    float8 nx = lanes_cross_term(tuy, tvz, tuz, tvy), ny = lanes_cross_term(tuz, tvx, tux, tvz),
           nz = lanes_cross_term(tux, tvy, tuy, tvx);  /* cross3 */
    float8 scale = lanes_dot(tux, tuy, tuz, tux, tuy, tuz) + lanes_dot(tvx, tvy, tvz, tvx, tvy, tvz);
    float8 nn = lanes_dot(nx, ny, nz, nx, ny, nz);
    int8 ok = nn > NORMAL_DEGENERATE * NORMAL_DEGENERATE * scale * scale;  /* tangent_cross */
    float8 len = lanes_length(nx, ny, nz);  /* normal_length */
    *plain = ok & lanes_length_plain(nn) & (len > 0.0f);  /* unit_or's quotients */
    normal[0] = nx / len;
    normal[1] = ny / len;
    normal[2] = nz / len;
}

/* kind_eval's normals at eight domain points (u, v); *plain as normal_lanes. */
ALWAYS_INLINE void kind_eval_lanes(__private const kind_patch *patch, float8 u, float8 v, float8 normal[3],
                                   __private int8 *plain)
{
    float8 s[4], s_u[4], s_v[4], p[3];
    surface_eval_lanes(patch->t, u, v, s, s_u, s_v);
    normal_lanes(s, s_u, s_v, p, normal, plain);
}

/* The next KIND_LANES points of a row, stepped as kind_row_next steps them: their positions and
 * normals by component (a lane a point), *plain as normal_lanes. */
ALWAYS_INLINE void kind_row_next_lanes(__private const kind_patch *patch, __private kind_row *row,
                                       float8 position[3], float8 normal[3], __private int8 *plain)
{
    float4 value[KIND_LANES], d_u[KIND_LANES], d_v[KIND_LANES];
    __attribute__((opencl_unroll_hint))
    for (int k = 0; k < KIND_LANES; ++k) {
        kind_row_skip(row, 1);
        value[k] = row->s[0];
        d_u[k] = row->s_u[0];
        d_v[k] = row->s_v[0];
    }
    float8 s[4], s_u[4], s_v[4], p[3];
    lanes_of(value, s);
    lanes_of(d_u, s_u);
    lanes_of(d_v, s_v);
    normal_lanes(s, s_u, s_v, p, normal, plain);
    position[0] = p[0] + patch->centre.x;  /* kind_row_next's p + centre */
    position[1] = p[1] + patch->centre.y;
    position[2] = p[2] + patch->centre.z;
}

/* KIND_LANES rows at once, a row a lane (stages/rows.h put_row_block): each lane kind_row_begin'd
 * and stepped as kind_row, component by component; s[k] holds component k's differences. */
typedef struct {
    float8 s[4][4], s_u[4][4], s_v[4][4];
} kind_rows;

/* kind_row_begin of the rows v (a lane each), all in `steps` steps. */
ALWAYS_INLINE void kind_rows_begin(__private const kind_patch *patch, float8 v, int steps, __private kind_rows *rows)
{
    float h = 1.0f / (float)steps;
    float8 bv[4], dv[3];
    bernstein3_lanes(v, bv);
    bernstein2_lanes(v, dv);
    __attribute__((opencl_unroll_hint))
    for (int k = 0; k < 4; ++k) {
        float8 c[4], d[4], a[4], av[4];
        row_controls_lanes(patch->t, bv, dv, k, c, d);
        power_form_lanes(c, a);
        power_form_lanes(d, av);
        cubic_differences_lanes(a[0], a[1], a[2], a[3], h, rows->s[k]);
        cubic_differences_lanes(a[1], 2.0f * a[2], 3.0f * a[3], (float8)(0.0f), h, rows->s_u[k]);
        cubic_differences_lanes(av[0], av[1], av[2], av[3], h, rows->s_v[k]);
    }
}

/* kind_row_next of every row: each row's next point, positions and normals by component (a lane a
 * row), *plain as normal_lanes. */
ALWAYS_INLINE void kind_rows_next(__private const kind_patch *patch, __private kind_rows *rows, float8 position[3],
                                  float8 normal[3], __private int8 *plain)
{
    float8 s[4], s_u[4], s_v[4], p[3];
    __attribute__((opencl_unroll_hint))
    for (int k = 0; k < 4; ++k) {  /* kind_row_skip's step, component k */
        step_differences_lanes(rows->s[k]);
        step_differences_lanes(rows->s_u[k]);
        step_differences_lanes(rows->s_v[k]);
        s[k] = rows->s[k][0];
        s_u[k] = rows->s_u[k][0];
        s_v[k] = rows->s_v[k][0];
    }
    normal_lanes(s, s_u, s_v, p, normal, plain);
    position[0] = p[0] + patch->centre.x;
    position[1] = p[1] + patch->centre.y;
    position[2] = p[2] + patch->centre.z;
}

#endif

#endif
