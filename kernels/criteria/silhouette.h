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

/* alpha of one edge group seen from eye: f = (d.n_s)(d.n_t), d the unit direction from the eye
 * to the edge midpoint (0 at the midpoint itself), then eq. 2 with beta > 0. */
inline float edge_silhouetteness(float3 midpoint, float3 n_s, float3 n_t, float beta, int rule, float3 eye)
{
    if (rule == SILHOUETTE_RULE_ALWAYS)
        return 1.0f;
    if (rule == SILHOUETTE_RULE_NEVER)
        return 0.0f;
    float3 d = unit_or_zero(midpoint - eye);
    float f = dot3(d, n_s) * dot3(d, n_t);
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
