/* ESC with stage 3's counts walked (esc_coarse_triangle in count mode), as before the table of
 * patterns/esc_counts.h: esc.py ESC_COUNTS_WALK, not registered; bench/esc.py --stages compares it. */
#define ESC_COUNTS_WALK 1
#include "patterns/esc.h"
