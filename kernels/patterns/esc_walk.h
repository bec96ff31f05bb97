/* ESC as before the tables of patterns/esc_counts.h: stage 3's counts and stage 5's triangles and
 * strips all from the band-by-band walk (esc_coarse_triangle).  esc.py ESC_WALK, not registered:
 * bench/esc.py --stages measures against it, tests/test_esc_counts.py checks the tables equal it. */
#define ESC_WALK 1
#include "patterns/esc.h"
