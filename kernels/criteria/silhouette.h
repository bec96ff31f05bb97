/* Silhouetteness (Dyken, Reimers and Seland, CGF 2008, section 3, eq. 1-2) and the blended
 * evaluation of fractional levels (section 5, eq. 9-11).  NumPy mirrors:
 * cltess/criteria/silhouette.py (alpha, edge levels) and cltess/patterns/silhouette.py (the
 * blended vertices).  Stages: stages/silhouette_alpha.cl, silhouette_levels.cl,
 * silhouette_vertices.cl. */
#ifndef CLTESS_CRITERIA_SILHOUETTE_H
#define CLTESS_CRITERIA_SILHOUETTE_H
#include "common.h"

/* cltess.criteria.silhouette.RULE_*: what an edge group is tested by. */
#define SILHOUETTE_RULE_PAIR 0    /* two faces: eq. 1-2 */
#define SILHOUETTE_RULE_ALWAYS 1  /* an open boundary or a non-manifold edge: alpha = 1 */
#define SILHOUETTE_RULE_NEVER 2   /* a collapsed edge or an unused factor slot: alpha = 0 */

/* alpha of one edge group seen from the eye (x, y, z): f = (d.n_s)(d.n_t), d the unit direction
 * from the eye to the edge midpoint (0 at the midpoint itself), then eq. 2 with beta > 0.  In
 * scalars: Oclgrind's uninitialised-value plugin takes the padding lane of a float3 built from
 * kernel arguments for uninitialised. */
inline float edge_silhouetteness(float4 midpoint_beta, float4 n_s, float4 n_t, int rule, float eye_x, float eye_y,
                                 float eye_z)
{
    if (rule == SILHOUETTE_RULE_ALWAYS)
        return 1.0f;
    if (rule == SILHOUETTE_RULE_NEVER)
        return 0.0f;
    float dx = midpoint_beta.x - eye_x, dy = midpoint_beta.y - eye_y, dz = midpoint_beta.z - eye_z;
    float length = sqrt(dx * dx + dy * dy + dz * dz);
    if (length > 0.0f) {
        dx /= length;
        dy /= length;
        dz /= length;
    }
    float f = (dx * n_s.x + dy * n_s.y + dz * n_s.z) * (dx * n_t.x + dy * n_t.y + dz * n_t.z);
    float beta = midpoint_beta.w;
    if (f <= 0.0f)
        return 1.0f;
    return f <= beta ? 1.0f - f / beta : 0.0f;
}

/* Edge level s_e = M alpha (with the error bound: at least the bound's level log2 |b|), at most M. */
inline float silhouette_edge_level(float alpha, float max_level, int bound, int use_bound)
{
    float s = max_level * alpha;
    if (use_bound && bound != 0)
        s = max(s, (float)(31 - (int)clz(abs(bound))));
    return min(s, max_level);
}

#endif
