/* Crack policy "or_masks" (ESC, patterns/esc.h): every patch edge takes the bitwise OR of the
 * candidate masks stored for its curve by all patch edges of its group; the rest of its record
 * (interior masks, level, its REVERSED flag) stays its own.  Each side stored its boundary bits
 * in the curve's canonical direction (criteria/esc_distance.h), which is the bit order reversed on
 * the flipped side, so the OR needs no flip here; a candidate inserted by either side is inserted
 * by both even where their tolerances differ (screen space) or their arithmetic did.  Records
 * without ESC_ALIVE (another pattern's factors in the same scene, e.g. PN triangles) take the
 * largest factor, as crack/max.h.  Culled patches stay 0.  Mirror: cltess/crack/or_masks.py. */
#ifndef CLTESS_CRACK_OR_MASKS_H
#define CLTESS_CRACK_OR_MASKS_H
#include "patterns/esc.h"

inline int crack_free_factor(__global const int *factors, uint edge, __global const int *group_of,
                             __global const int *group_start, __global const int *members)
{
    int own = factors[edge];
    if (own <= 0)
        return own;
    int group = group_of[edge];
    int esc = (own & ESC_ALIVE) != 0;
    for (int k = group_start[group]; k < group_start[group + 1]; ++k) {
        int other = factors[members[k]];
        if (esc)
            own |= other > 0 ? other & ESC_BOUNDARY_BITS : 0;
        else
            own = max(own, other);
    }
    return own;
}

#endif
