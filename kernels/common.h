/* What every kind, pattern and stage of the cltess pipeline shares: float rules, constants,
 * Bernstein and forward-difference helpers, the symmetric boundary point, the domains' edge
 * points, and the writers of vertices and triangles (docs/design.md section 1; the device
 * contract of kinds, patterns and criteria is in docs/extending.md).
 *
 * A program is composed per (kind, pattern, tolerance): cltess/backends/opencl/programs.py
 * prepends #includes of the kind's and the pattern's headers and -D TOLERANCE_... to one of
 * the generic stage kernels in stages/. */
#ifndef CLTESS_COMMON_H
#define CLTESS_COMMON_H

/* No fused multiply-add: neighbouring patches must evaluate shared boundary points with the
 * same roundings whatever code path (vector lanes or scalar tail) the compiler gives them. */
#pragma OPENCL FP_CONTRACT OFF

/* Pinned to the Python constants of the same name by tests/contracts/test_constants.py. */
#define NORMAL_SHIFT 1.0e-3f      /* cltess.surfaces.bezier.NORMAL_SHIFT */
#define NORMAL_DEGENERATE 1.0e-3f /* cltess.surfaces.bezier.NORMAL_DEGENERATE */
#define PN_NORMAL_VANISHES 1.0e-5f /* cltess.surfaces.pn.PN_NORMAL_VANISHES */
#define FACTOR_SLOTS 4            /* cltess.kinds.base.FACTOR_SLOTS: int4 factors per patch */

/* For the kind functions stage 4 calls per vertex: inlined into the generic stage, as their code
 * sat inside each kind's own kernel before (PoCL's cost model otherwise keeps kind_eval and
 * kind_row_begin out of line, and the patch and row state in memory: PN vertices 15-50% slower). */
#define ALWAYS_INLINE inline __attribute__((always_inline))

/* --- Bernstein bases and power form ---------------------------------------------------------- */

/* Written once for float and for float8 lanes (kinds/bezier.h bernstein3_lanes): a lane must do
 * the same operations in the same order. */
#define BERNSTEIN3_OF(T)                                                                             \
    {                                                                                                \
        T s = 1.0f - t;                                                                              \
        b[0] = s * s * s;                                                                            \
        b[1] = 3.0f * t * s * s;                                                                     \
        b[2] = 3.0f * t * t * s;                                                                     \
        b[3] = t * t * t;                                                                            \
    }
#define BERNSTEIN2_OF(T)                                                                             \
    {                                                                                                \
        T s = 1.0f - t;                                                                              \
        b[0] = s * s;                                                                                \
        b[1] = 2.0f * t * s;                                                                         \
        b[2] = t * t;                                                                                \
    }

inline void bernstein3(float t, float b[4]) BERNSTEIN3_OF(float)

inline void bernstein2(float t, float b[3]) BERNSTEIN2_OF(float)

inline float4 lerp4(float4 a, float4 b, float t) { return a + t * (b - a); }

ALWAYS_INLINE float dot3(float3 a, float3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

/* --- PoCL's builtins inline (issue 15, the CPU line) ---------------------------------------------
 * PoCL 3.0 on x86-64 (LLVM 14; it defines POCL_DEVICE_ADDRESS_BITS) keeps cross, dot, length,
 * vstore3 and vstore2 of float3/float2 out of line: in stage 4 (stages/vertices.cl) every vertex
 * made 8 calls, each a handful of instructions, and, every xmm register being the caller's to save
 * on x86-64, each call spilled the live float4s to the stack around it.  Sampled by perf, the
 * builtins' own bodies held a quarter of stage 4's CPU time and the spills and reloads around the
 * calls much of the rest (bench/RESULTS.md, "Issue 15: stage 4 on the CPU under perf (session 10,
 * branch `cpu15f`)").  Here they are spelled out as PoCL's library computes them (its code in the
 * kernels' shared objects: the same operations in the same order, so the same bits;
 * tests/test_unit_normal.py compares them with the builtins bit for bit on every device), so
 * that the compiler inlines them.  Elsewhere they are the builtins, as before.  Stage 4's hot
 * path uses them (kinds/bezier.h tangent_cross, unit_or's length, put_vertex's stores). */
#if defined(POCL_DEVICE_ADDRESS_BITS) && defined(__x86_64__) && !defined(CLTESS_BUILTIN_FORMS)
#define CLTESS_POCL_FORMS 1
/* PoCL's dot(float3) is (a.x b.x + a.y b.y) + a.z b.z: dot3 above */
#define dot3f dot3
/* PoCL's cross(float3), component by component */
ALWAYS_INLINE float3 cross3(float3 a, float3 b)
{
    return (float3)(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
/* PoCL's length(float3): sqrt of the dot, the vector scaled by 2^86 first (and the root by 2^-86
 * after) where the dot is below FLT_MIN, by 2^-65 (and 2^65) where it is +inf.  The root is
 * clang's __builtin_sqrtf, the correctly rounded vsqrtss that PoCL's length and sqrt run, inline
 * (PoCL's sqrt is out of line too). */
ALWAYS_INLINE float length3(float3 a)
{
    float s = dot3f(a, a);
    if (s < FLT_MIN) {
        float3 b = a * 0x1.0p86f;
        return __builtin_sqrtf(dot3f(b, b)) * 0x1.0p-86f;
    }
    if (s == INFINITY) {
        float3 b = a * 0x1.0p-65f;
        return __builtin_sqrtf(dot3f(b, b)) * 0x1.0p65f;
    }
    return __builtin_sqrtf(s);
}
/* vstore3 / vstore2: the components stored one by one */
ALWAYS_INLINE void store3(float3 v, ulong at, __global float *out)
{
    out[3 * at] = v.x;
    out[3 * at + 1] = v.y;
    out[3 * at + 2] = v.z;
}
ALWAYS_INLINE void store2(float2 v, ulong at, __global float *out)
{
    out[2 * at] = v.x;
    out[2 * at + 1] = v.y;
}
/* sqrt(float), int min and int max, also out of line on PoCL 3.0 (PN triangles' unit_or_zero in
 * stage 4, the patterns' row and cell code in stage 5): PoCL's own bodies are vsqrtss, and
 * `a > b ? b : a` / `a < b ? b : a` by cmovg / cmovl (bench/RESULTS.md, "Issue 15: PoCL's other
 * out-of-line calls (session 10, branch `cpu15g`)"). */
ALWAYS_INLINE float sqrt1f(float a) { return __builtin_sqrtf(a); }
ALWAYS_INLINE int imin(int a, int b) { return a > b ? b : a; }
ALWAYS_INLINE int imax(int a, int b) { return a < b ? b : a; }
/* a helper PoCL keeps out of line and that gains inline there (patterns/stitch.h stitch_strip,
 * patterns/quad_transition.h grid_cell and grid_cells); elsewhere plain inline, as before */
#define POCL_INLINE ALWAYS_INLINE
#else
#define CLTESS_POCL_FORMS 0
#define dot3f dot
#define cross3 cross
#define length3 length
#define store3 vstore3
#define store2 vstore2
#define sqrt1f sqrt
#define imin min
#define imax max
#define POCL_INLINE inline
#endif

/* --- eight lanes (issue 15, the CPU line) -----------------------------------------------------
 * Stage 4's rows and ring edges KIND_LANES points at once (stages/rows.h, kinds/bezier.h): by
 * default on the two CPU runtimes cltess installs, Intel's and PoCL (x86-64), where the
 * per-patch stage 4 of uniform level 16 takes 0.6x the CPU time (bench/RESULTS.md, "Session 13,
 * lead"); -D CLTESS_LANES=1 forces it anywhere (Oclgrind's scenarios: tests/oclgrind_scenarios.py
 * LANES), =0 turns it off.  The lanes are written without vload8, vstore8, shuffle, sqrt(float8)
 * and all, which PoCL keeps out of line; the unaligned vector type is Clang's extension, which
 * every runtime here builds with. */
/* Intel's CPU runtime (2026.2 defines cl_intel_vec_len_hint, its vectoriser's hint, as a macro). */
#if defined(cl_intel_vec_len_hint) && !defined(CLTESS_BUILTIN_FORMS)
#define CLTESS_INTEL_FORMS 1
#else
#define CLTESS_INTEL_FORMS 0
#endif
#ifndef CLTESS_LANES
#define CLTESS_LANES (CLTESS_POCL_FORMS || CLTESS_INTEL_FORMS)
#endif
#if CLTESS_LANES
/* The builtins that stage 4's normals use, over eight lanes, as each runtime computes them, so
 * that every lane is bitwise the scalar builtin (tests/test_unit_normal.py checks them against
 * the builtins, special values included).  Intel's CPU runtime (its scalar code, 2026.2:
 * bench/kernels/cpu_stage4_probe.cl, session 4) computes cross and length in double (products
 * of floats are exact there, then one rounding) and dot by dpps, (p0 + p1) + (p2 + +0); PoCL's
 * are those spelled out above.  lanes_length_plain(squared), squared the lanes_dot of the vector
 * with itself: where length's value is the plain one that lanes_length gives (PoCL's length
 * takes scaled branches below FLT_MIN and at infinity). */
#if CLTESS_INTEL_FORMS
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
ALWAYS_INLINE float8 lanes_dot(float8 ax, float8 ay, float8 az, float8 bx, float8 by, float8 bz)
{
    return (ax * bx + ay * by) + (az * bz + 0.0f);
}
ALWAYS_INLINE float8 lanes_cross_term(float8 a1, float8 b2, float8 a2, float8 b1)  /* a1 b2 - a2 b1 */
{
    return convert_float8(convert_double8(a1) * convert_double8(b2) - convert_double8(a2) * convert_double8(b1));
}
ALWAYS_INLINE float8 lanes_length(float8 x, float8 y, float8 z)
{
    double8 dx = convert_double8(x), dy = convert_double8(y), dz = convert_double8(z);
    return convert_float8(sqrt((dx * dx + dy * dy) + dz * dz));
}
ALWAYS_INLINE int8 lanes_length_plain(float8 squared) { return (int8)(-1); }  /* no branches */
#else
ALWAYS_INLINE float8 lanes_dot(float8 ax, float8 ay, float8 az, float8 bx, float8 by, float8 bz)
{
    return ax * bx + ay * by + az * bz;  /* dot3 */
}
ALWAYS_INLINE float8 lanes_cross_term(float8 a1, float8 b2, float8 a2, float8 b1) { return a1 * b2 - a2 * b1; }
ALWAYS_INLINE float8 lanes_length(float8 x, float8 y, float8 z)
{
    float8 s = lanes_dot(x, y, z, x, y, z);
    return (float8)(sqrt1f(s.s0), sqrt1f(s.s1), sqrt1f(s.s2), sqrt1f(s.s3), sqrt1f(s.s4), sqrt1f(s.s5),
                    sqrt1f(s.s6), sqrt1f(s.s7));  /* one vsqrtps on PoCL, where sqrt(float8) is a call */
}
ALWAYS_INLINE int8 lanes_length_plain(float8 squared) { return (squared >= FLT_MIN) & (squared != INFINITY); }
#endif
/* Vectors of 8 that may sit at any float or int (vmovups). */
typedef float float8_at_float __attribute__((ext_vector_type(8), aligned(4)));
typedef int int8_at_int __attribute__((ext_vector_type(8), aligned(4)));
/* Eight float4 as their four components' lanes: c[0] = (v[0].x, .., v[7].x), .. c[3] the .w. */
ALWAYS_INLINE void lanes_of(const float4 v[8], float8 c[4])
{
    c[0] = (float8)(v[0].x, v[1].x, v[2].x, v[3].x, v[4].x, v[5].x, v[6].x, v[7].x);
    c[1] = (float8)(v[0].y, v[1].y, v[2].y, v[3].y, v[4].y, v[5].y, v[6].y, v[7].y);
    c[2] = (float8)(v[0].z, v[1].z, v[2].z, v[3].z, v[4].z, v[5].z, v[6].z, v[7].z);
    c[3] = (float8)(v[0].w, v[1].w, v[2].w, v[3].w, v[4].w, v[5].w, v[6].w, v[7].w);
}
/* Eight float3 as their components' lanes. */
ALWAYS_INLINE void lanes_of3(const float3 v[8], float8 c[3])
{
    c[0] = (float8)(v[0].x, v[1].x, v[2].x, v[3].x, v[4].x, v[5].x, v[6].x, v[7].x);
    c[1] = (float8)(v[0].y, v[1].y, v[2].y, v[3].y, v[4].y, v[5].y, v[6].y, v[7].y);
    c[2] = (float8)(v[0].z, v[1].z, v[2].z, v[3].z, v[4].z, v[5].z, v[6].z, v[7].z);
}
/* store3 of eight lanes' (x, y, z) to records at .. at + 7, as three vector stores. */
ALWAYS_INLINE void store3_lanes(float8 x, float8 y, float8 z, ulong at, __global float *out)
{
    __global float8_at_float *to = (__global float8_at_float *)(out + 3 * at);
    to[0] = (float8)(x.s0, y.s0, z.s0, x.s1, y.s1, z.s1, x.s2, y.s2);
    to[1] = (float8)(z.s2, x.s3, y.s3, z.s3, x.s4, y.s4, z.s4, x.s5);
    to[2] = (float8)(y.s5, z.s5, x.s6, y.s6, z.s6, x.s7, y.s7, z.s7);
}
/* store2 of eight lanes' (x, y). */
ALWAYS_INLINE void store2_lanes(float8 x, float8 y, ulong at, __global float *out)
{
    __global float8_at_float *to = (__global float8_at_float *)(out + 2 * at);
    to[0] = (float8)(x.s0, y.s0, x.s1, y.s1, x.s2, y.s2, x.s3, y.s3);
    to[1] = (float8)(x.s4, y.s4, x.s5, y.s5, x.s6, y.s6, x.s7, y.s7);
}
/* The 8 x 8 transpose: t[r] lane c is m[c] lane r. */
ALWAYS_INLINE void transposed_lanes(const float8 m[8], float8 t[8])
{
    t[0] = (float8)(m[0].s0, m[1].s0, m[2].s0, m[3].s0, m[4].s0, m[5].s0, m[6].s0, m[7].s0);
    t[1] = (float8)(m[0].s1, m[1].s1, m[2].s1, m[3].s1, m[4].s1, m[5].s1, m[6].s1, m[7].s1);
    t[2] = (float8)(m[0].s2, m[1].s2, m[2].s2, m[3].s2, m[4].s2, m[5].s2, m[6].s2, m[7].s2);
    t[3] = (float8)(m[0].s3, m[1].s3, m[2].s3, m[3].s3, m[4].s3, m[5].s3, m[6].s3, m[7].s3);
    t[4] = (float8)(m[0].s4, m[1].s4, m[2].s4, m[3].s4, m[4].s4, m[5].s4, m[6].s4, m[7].s4);
    t[5] = (float8)(m[0].s5, m[1].s5, m[2].s5, m[3].s5, m[4].s5, m[5].s5, m[6].s5, m[7].s5);
    t[6] = (float8)(m[0].s6, m[1].s6, m[2].s6, m[3].s6, m[4].s6, m[5].s6, m[6].s6, m[7].s6);
    t[7] = (float8)(m[0].s7, m[1].s7, m[2].s7, m[3].s7, m[4].s7, m[5].s7, m[6].s7, m[7].s7);
}
/* Whether every one of eight lanes is nonzero (all() is a call on PoCL).  Any nonzero: on Oclgrind
 * a vector comparison's true came out 1 after an &, where OpenCL says -1. */
ALWAYS_INLINE int every_lane(int8 a)
{
    int4 b = a.lo & a.hi;
    int2 c = b.lo & b.hi;
    return (c.x & c.y) != 0;
}
#endif

/* a / |a| where |a| > 0, else 0 (PN triangles' normals; silhouette vertices).  The root as sqrt
 * (inline on PoCL: sqrt1f above). */
inline float3 unit_or_zero(float3 a)
{
    float len = sqrt1f(dot3(a, a));
    return len > 0.0f ? a / len : (float3)(0.0f);
}

/* --- division without a zero dividend (issue 15, NVIDIA) ---------------------------------------
 * NVIDIA's correctly rounded division (div.rn.f32: MUFU.RCP, a refinement and FCHK) calls a slow
 * path, out of line, wherever FCHK finds an operand outside its fast range: a zero dividend is
 * one.  A teapot's normals have exact zero components (its symmetry planes), so in stage 4's
 * prepared_rows at uniform level 16 on the H200 that subroutine held 9% of the warps' sampled
 * time, its call sites about 5% more, a call on every point in some lane (Nsight Compute,
 * bench/RESULTS.md, "Issue 15: stage 4 under Nsight Compute on the H200").  These give the same
 * bits without dividing a zero. */

/* a / b for b > 0 (+inf included): a zero a (either sign) is its own quotient exactly, and the
 * division, made with the dividend 1 there, is not used.  The dividend's zero test is on a's bits
 * (shifted past the sign), unlike the result's: NVIDIA's compiler folded `a == 0 ? 1 : a` inside
 * `a == 0 ? a : ...` back to a, so the slow path stayed (H200, run 2).  (A device that flushed
 * subnormals in the comparison `a == 0.0f` but not in a select would differ on a subnormal a; the
 * three runtimes the tests run compare them as nonzero: tests/test_unit_normal.py's +-1e-40.) */
inline float quotient_by_positive(float a, float b)
{
    float q = ((as_uint(a) << 1) == 0u ? 1.0f : a) / b;
    return a == 0.0f ? a : q;
}

#if defined(cl_nv_pragma_unroll) && !defined(CLTESS_BUILTIN_LENGTH)
/* NVIDIA's OpenCL compiler (it defines cl_nv_pragma_unroll): length(n) spelled out as it expands
 * length(float3) (its PTX, driver 580): m the largest of |x|, |y|, |z| (compared in that order);
 * 0 where m is 0; +inf where a component is infinite; else m * sqrt((|x| / m)^2 + (|y| / m)^2 +
 * (|z| / m)^2), the first square a product and the next two fused, every division and the root
 * correctly rounded (the programs' -cl-fp32-correctly-rounded-divide-sqrt).  Here a zero
 * component's quotient is 0 without the division: |c| / m is +0 exactly for m > 0 finite, and
 * where m is a NaN another component is one, whose quotient makes the sum a NaN either way
 * (tests/test_unit_normal.py compares it with length() bit for bit on the device). */
#define CLTESS_SPELLED_LENGTH 1
inline float normal_length(float3 n)
{
    float a = fabs(n.x), b = fabs(n.y), c = fabs(n.z);
    float m = a < b ? b : a;
    m = m < c ? c : m;
    if (m == 0.0f)
        return 0.0f;
    if (a == INFINITY || b == INFINITY || c == INFINITY)
        return INFINITY;
    float qa = quotient_by_positive(a, m), qb = quotient_by_positive(b, m), qc = quotient_by_positive(c, m);
    float sum = fma(qc, qc, fma(qb, qb, qa * qa));
    return m * sqrt(sum);
}
#elif CLTESS_POCL_FORMS
#define CLTESS_SPELLED_LENGTH 2
inline float normal_length(float3 n) { return length3(n); }
#else
#define CLTESS_SPELLED_LENGTH 0
inline float normal_length(float3 n) { return length(n); }
#endif

/* n / length(n) where that is > 0, else `otherwise`: bitwise what that expression gives (the
 * length as length(), the quotients as /), without dividing a zero. */
inline float3 unit_or(float3 n, float3 otherwise)
{
    float len = normal_length(n);
    if (!(len > 0.0f))
        return otherwise;
#if CLTESS_POCL_FORMS
    /* On PoCL x86-64 the three quotients as one vector division (PoCL made x a vdivss and y, z a
     * vdivps): each lane the same correctly rounded quotient, a zero dividend (either sign) its own
     * quotient as in quotient_by_positive, so the same bits; stage 4 -4.7%.  By the vector ?:, not
     * select(), which PoCL keeps out of line (with select() stage 4 was 11% slower: bench/RESULTS.md,
     * "Issue 15: PoCL's other out-of-line calls (session 10, branch `cpu15g`)"). */
    float4 d = (float4)(n, 1.0f);
    int4 zero = (as_int4(d) << 1) == 0;
    float4 q = (zero ? (float4)(1.0f) : d) / len;
    return (zero ? d : q).xyz;
#else
    return (float3)(quotient_by_positive(n.x, len), quotient_by_positive(n.y, len), quotient_by_positive(n.z, len));
#endif
}

/* Power-form coefficients of the cubic Bernstein polynomial with controls c.  (One body for float4
 * and for float8 lanes, power_form_lanes: a lane must do the same operations in the same order.) */
#define POWER_FORM_BODY                                                                              \
    {                                                                                                \
        a[0] = c[0];                                                                                 \
        a[1] = 3.0f * (c[1] - c[0]);                                                                 \
        a[2] = 3.0f * (c[2] - 2.0f * c[1] + c[0]);                                                   \
        a[3] = c[3] - 3.0f * c[2] + 3.0f * c[1] - c[0];                                              \
    }
inline void power_form(const float4 c[4], float4 a[4]) POWER_FORM_BODY

/* Forward differences of a cubic a0 + a1 u + a2 u^2 + a3 u^3 at u = 0, step h (Wallace 1990):
 * value, first, second, third difference (docs/design.md section 6).  (One body, as above.) */
#define CUBIC_DIFFERENCES_BODY                                                                       \
    {                                                                                                \
        float h2 = h * h, h3 = h2 * h;                                                               \
        d[0] = a0;                                                                                   \
        d[1] = a1 * h + a2 * h2 + a3 * h3;                                                           \
        d[2] = 2.0f * a2 * h2 + 6.0f * a3 * h3;                                                      \
        d[3] = 6.0f * a3 * h3;                                                                       \
    }
inline void cubic_differences(float4 a0, float4 a1, float4 a2, float4 a3, float h, float4 d[4])
    CUBIC_DIFFERENCES_BODY

#if CLTESS_LANES
ALWAYS_INLINE void power_form_lanes(const float8 c[4], float8 a[4]) POWER_FORM_BODY

ALWAYS_INLINE void cubic_differences_lanes(float8 a0, float8 a1, float8 a2, float8 a3, float h, float8 d[4])
    CUBIC_DIFFERENCES_BODY
#endif

/* One step of forward differences d (one body for float4 and for float8 lanes, as above). */
#define STEP_DIFFERENCES_BODY                                                                        \
    {                                                                                                \
        d[0] += d[1];                                                                                \
        d[1] += d[2];                                                                                \
        d[2] += d[3];                                                                                \
    }
inline void step_differences(float4 d[4]) STEP_DIFFERENCES_BODY

#if CLTESS_LANES
ALWAYS_INLINE void step_differences_lanes(float8 d[4]) STEP_DIFFERENCES_BODY
#endif

/* --- boundary points (docs/design.md section 4) ---------------------------------------------- */

/* Point k of f on an edge: the pattern says which (pattern_ring_param), the kind places it
 * (kind_boundary_point) and the domain gives its parameters (quad_edge_point, tri_edge_point). */
typedef struct {
    int k;
    int f;
    int fixed;  /* 0: point k of f whole segments at k / f; else a fractional pattern's real factor in
                 * 16.16 fixed point, f = odd_segments(fixed), points by fractional_location */
} edge_param;

/* --- fractional factors: D3D11 fractional_odd spacing (docs/sd2.md section 1) ----------------- */

/* 1.0 of the 16.16 fixed-point real factors (cltess.patterns.fractional.FIXED_ONE). */
#define FIXED_ONE 65536

/* Segments of an edge of real factor fixed / 2^16 (>= 1): the smallest odd number >= it. */
inline int odd_segments(int fixed)
{
    int twice_half = fixed + FIXED_ONE;  /* (r + 1) / 2 in 15.17 fixed point, exactly */
    return 2 * ((twice_half + 2 * FIXED_ONE - 1) >> 17) - 1;
}

/* Location from its nearer end of point i < (n + 1) / 2 of an edge of real factor fixed / 2^16:
 * its place on the floor odd factor lerped to its place on the ceiling one by the fraction of
 * (r + 1) / 2; past the split point (D3D's splitPointOnFloorHalfTessFactor) a point sits one
 * index lower on the floor factor, so a new pair of points grows out of one point.  Continuous
 * in r, k / r at odd whole r.  Mirror: cltess/patterns/fractional.py near_location. */
inline float fractional_location(int fixed, int i)
{
    int twice_half = fixed + FIXED_ONE;  /* (r + 1) / 2 in 15.17 fixed point, exactly */
    int floor_half = twice_half >> 17, ceil_half = (twice_half + 2 * FIXED_ONE - 1) >> 17;
    int split = floor_half == ceil_half ? ceil_half + 1
              : floor_half == 1 ? 0
              : (((floor_half - 1) - (1 << (31 - (int)clz(floor_half - 1)))) << 1) + 1;  /* remove the MSB */
    int on_floor = i > split ? i - 1 : i;
    float a = (float)on_floor / (float)(2 * floor_half - 1);
    float b = (float)i / (float)(2 * ceil_half - 1);
    float t = (float)(twice_half & (2 * FIXED_ONE - 1)) * (0.5f / (float)FIXED_ONE);
    return a + t * (b - a);
}

/* Where point t of an edge lies, as the fraction from its nearer end (*from_end: the far end,
 * i.e. the location is 1 - it); a midpoint (2k == f, whole factors only) is 0.5 exactly. */
inline float edge_near_fraction(edge_param t, int *from_end)
{
    int near = imin(t.k, t.f - t.k);
    *from_end = near != t.k;
    return t.fixed ? fractional_location(t.fixed, near) : (float)near / (float)t.f;
}

/* The location of point t along its edge, from its start, in [0, 1]. */
inline float edge_location(edge_param t)
{
    if (!t.fixed)
        return (float)t.k / (float)t.f;
    int from_end;
    float near = edge_near_fraction(t, &from_end);
    return from_end ? 1.0f - near : near;
}

/* Point t of a cubic boundary curve with controls c, placed symmetrically about the midpoint:
 * de Casteljau from the nearer end, and at the midpoint the commutative (a + b) / 2.  A
 * neighbour walking the shared curve the other way gets bitwise the same point (Mesa's
 * tessellator does the same for D3D11 patterns).  k = 0 returns the end control point exactly. */
inline float4 boundary_point(const float4 c[4], edge_param t)
{
    int k = t.k, f = t.f;
    /* The corner itself, bit for bit: c0 + 0 * (c1 - c0) turns a -0.0 of c0 into +0.0 or not
     * depending on c1, which differs between the patches meeting there. */
    if (k == 0)
        return c[0];
    float4 q[4];
    int forward = 2 * k < f;
    __attribute__((opencl_unroll_hint))  /* unrolled, q stays in registers (PoCL left it in memory) */
    for (int i = 0; i < 4; ++i)
        q[i] = forward ? c[i] : c[3 - i];
    if (2 * k == f) {
        __attribute__((opencl_unroll_hint))
        for (int level = 3; level > 0; --level)
            __attribute__((opencl_unroll_hint))
            for (int i = 0; i < level; ++i)
                q[i] = (q[i] + q[i + 1]) * 0.5f;
    } else {
        int from_end;
        float s = edge_near_fraction(t, &from_end);  /* whole factors: min(k, f - k) / f */
        __attribute__((opencl_unroll_hint))
        for (int level = 3; level > 0; --level)
            __attribute__((opencl_unroll_hint))
            for (int i = 0; i < level; ++i)
                q[i] = lerp4(q[i], q[i + 1], s);
    }
    return q[0];
}

/* --- domains: the point of an edge parameter, (u, v, w) with uv = .xy ------------------------- */

/* Quad (u, v, 0); edges counter-clockwise 0: v=0, 1: u=1, 2: v=1, 3: u=0. */
inline float3 quad_edge_point(int e, edge_param p)
{
    float t = edge_location(p);
    return e == 0 ? (float3)(t, 0.0f, 0.0f) : e == 1 ? (float3)(1.0f, t, 0.0f)
         : e == 2 ? (float3)(1.0f - t, 1.0f, 0.0f) : (float3)(0.0f, 1.0f - t, 0.0f);
}

/* Triangle, barycentric (u, v, w) weighting corners P1, P2, P3; edge e runs from corner e to
 * corner e+1 (0: P1->P2, w=0; 1: P2->P3, u=0; 2: P3->P1, v=0). */
inline float3 tri_edge_point(int e, edge_param p)
{
    float t = edge_location(p), s = p.fixed ? 1.0f - t : (float)(p.f - p.k) / (float)p.f;
    return e == 0 ? (float3)(s, t, 0.0f) : e == 1 ? (float3)(0.0f, s, t) : (float3)(t, 0.0f, s);
}

/* Point i of row j of the uniform triangle grid of n steps: (i / n, j / n, (n - i - j) / n). */
inline float3 tri_grid_point(int n, int j, int i)
{
    return (float3)((float)i / (float)n, (float)j / (float)n, (float)(n - i - j) / (float)n);
}

/* --- factors ------------------------------------------------------------------------------- */

inline int factor_of(int4 f, int e) { return e == 0 ? f.s0 : e == 1 ? f.s1 : e == 2 ? f.s2 : f.s3; }

/* The factor for a step of 1/inverse: ceil, at least 1; above max_factor it is clamped and
 * *saturated set (the bound is not met there). */
inline int edge_factor(float inverse, int max_factor, int *saturated)
{
    if (inverse <= (float)max_factor)
        return imax((int)ceil(inverse), 1);
    *saturated = 1;
    return max_factor;
}

/* The record of a dyadic pattern (semi-uniform, Dyken et al. 2009): each factor f rounded up to
 * 2^p, p = min(ceil(log2 f), max_level), exactly (ceil(log2 f) = 32 - clz(f - 1) for f > 1); 0
 * stays 0 (culled).  Where the cap lowers a factor the bound is not met: *saturated.  Monotone,
 * so it commutes with the crack-free max over an edge group.  max_level is an input per call, so
 * a criterion may set an edge's level otherwise (e.g. by silhouette). */
inline int dyadic_factor(int f, int max_level, int *saturated)
{
    if (f <= 0)
        return 0;
    int level = f > 1 ? 32 - (int)clz(f - 1) : 0;
    if (level > max_level)
        *saturated = 1;
    return 1 << imin(level, max_level);
}

inline int4 dyadic_factors(int4 f, int max_level, int *saturated)
{
    return (int4)(dyadic_factor(f.s0, max_level, saturated), dyadic_factor(f.s1, max_level, saturated),
                  dyadic_factor(f.s2, max_level, saturated), dyadic_factor(f.s3, max_level, saturated));
}

/* Why a patch has no output, in stage 1's flags (bit 0 is "saturated"). */
#define FLAG_SATURATED 1
#define FLAG_CULLED 2
#define FLAG_FOLDED 4

/* Primitive-restart marker between triangle strips (cltess/strips.py STRIP_RESTART). */
#define STRIP_RESTART 0xFFFFFFFFu

/* The factors of a patch as stage 2 stores them: a collapsed edge (its control points one
 * point, e.g. a sphere's pole) negated.  Returns the factors; *collapsed: bit e set for a
 * collapsed edge e (its points all at its first corner; no triangle joins two of them). */
inline int4 patch_factors(int4 stored, int *collapsed)
{
    *collapsed = (stored.s0 < 0) | (stored.s1 < 0) << 1 | (stored.s2 < 0) << 2 | (stored.s3 < 0) << 3;
    return as_int4(abs(stored));  /* abs of an int4 is a uint4 */
}

/* Stages 4 and 5 run on one batch of patches, first_patch .. first_patch + num_patches - 1
 * (scene numbering).  Sets this work-item's patch p, its factors f and collapsed edges
 * (patch_factors); 0 when it has nothing to emit (past the batch's end, or culled). */
inline int batch_patch(uint first_patch, uint num_patches, __global const int4 *factors, uint *p, int4 *f,
                       int *collapsed)
{
    if (get_global_id(0) >= num_patches)
        return 0;
    *p = first_patch + (uint)get_global_id(0);
    *f = patch_factors(factors[*p], collapsed);
    return f->s0 > 0;
}

/* Whether the batch's output fits its buffer: its records (vertices or indices) run from
 * offsets[first_patch] - base to offsets[last] - base, and the buffer holds `capacity` of them.
 * A Session frame launches stages 4-5 before the host has read stage 3's totals (on the
 * buffers' capacity: docs/design.md section 11); a batch that does not fit writes nothing,
 * and the host, reading the totals later, grows the buffers and runs stages 4-5 again. */
inline int batch_fits(__global const ulong *offsets, uint last, ulong base, ulong capacity)
{
    return offsets[last] - base <= capacity;
}

/* The patch owning output slot `at` (a vertex, or an index; global numbering) among patches
 * lo .. hi - 1 whose slots start at offsets[p] (stage 3's scan): the last p with offsets[p] <= at
 * (binary search; a culled patch owns no slot, so the one found is never culled).  Needs
 * offsets[lo] <= at < offsets[hi].  Stages 4-5 a work-item per vertex or triangle. */
inline uint patch_of(__global const ulong *offsets, uint lo, uint hi, ulong at)
{
    while (hi - lo > 1) {
        uint mid = lo + (hi - lo) / 2;
        if (offsets[mid] <= at)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

/* patch_of for a work-item moving on from its patch lo to a later slot `at` (offsets[lo] <= at):
 * galloping (lo + 1, lo + 2, lo + 4, ... while offsets[lo + step] <= at), then patch_of within the
 * last stride: the same patch in about 2 log2(distance) loads instead of log2(hi - lo), where the
 * next patch is usually lo + 1.  Stage 5 by triangle: 0.136 ms against 0.146 on uniform level 16 on
 * the H100 (bench/RESULTS.md, "Issue 15: stage 5's triangle math (session 8, branch gpu15f)"). */
inline uint patch_after(__global const ulong *offsets, uint lo, uint hi, ulong at)
{
    uint step = 1;
    while (lo + step < hi && offsets[lo + step] <= at) {
        lo += step;
        step *= 2;
    }
    return patch_of(offsets, lo, min(hi, lo + step), at);
}

inline void load_patch(__global const float4 *patches, uint p, float4 b[16])
{
    for (int k = 0; k < 16; ++k)
        b[k] = patches[16 * p + k];
}

/* --- output records -------------------------------------------------------------------------- */

/* The vertex record, one array per field (cltess.tessellation.VERTEX_RECORD, in this order). */
typedef struct {
    __global float *positions;   /* (V, 3) */
    __global float *normals;     /* (V, 3) */
    __global float *uv;          /* (V, 2) */
    __global int *patch_ids;     /* (V,) */
    __global int *object_ids;    /* (V,) */
} vertex_out;

inline void put_vertex(vertex_out out, ulong at, float3 position, float3 normal, float2 uv,
                       int patch, int object)
{
    store3(position, at, out.positions);  /* vstore3, vstore2 (inline on PoCL: above) */
    store3(normal, at, out.normals);
    store2(uv, at, out.uv);
    out.patch_ids[at] = patch;
    out.object_ids[at] = object;
}

#if CLTESS_LANES
/* put_vertex of eight lanes to records at .. at + 7: the same bytes, a field's eight at once. */
ALWAYS_INLINE void put_vertex_lanes(vertex_out out, ulong at, const float8 position[3], const float8 normal[3],
                                    float8 u, float8 v, int patch, int object)
{
    store3_lanes(position[0], position[1], position[2], at, out.positions);
    store3_lanes(normal[0], normal[1], normal[2], at, out.normals);
    store2_lanes(u, v, at, out.uv);
    *(__global int8_at_int *)(out.patch_ids + at) = (int8)(patch);
    *(__global int8_at_int *)(out.object_ids + at) = (int8)(object);
}
#endif

/* One triangle: written when out is not null, always counted ("count" and "emit" modes of
 * pattern_primitives). */
inline void put_triangle(__global uint *out, uint *count, uint base, uint a, uint b, uint c)
{
    if (out) {
        out[3 * *count + 0] = base + a;
        out[3 * *count + 1] = base + b;
        out[3 * *count + 2] = base + c;
    }
    ++*count;
}

/* Local number of ring point k of edge e: the ring (f_0 + ... points, counter-clockwise, edge
 * e's points at f_0 + ... + f_{e-1}) comes first in every pattern's vertex layout.  Unused
 * factor slots are 0. */
inline uint ring_index(int4 f, int e, int k)
{
    int ring = f.s0 + f.s1 + f.s2 + f.s3;
    int base = e == 0 ? 0 : e == 1 ? f.s0 : e == 2 ? f.s0 + f.s1 : f.s0 + f.s1 + f.s2;
    return (uint)((base + k) % ring);
}

#endif
