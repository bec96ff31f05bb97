/* The semi-uniform pattern on the quad domain (patterns/semi_uniform.h; mirror
 * cltess/patterns/semi_uniform.py, QUAD_SEMI_UNIFORM). */
#define PATTERN_EDGES 4
#include "patterns/semi_uniform.h"
