/* The semi-uniform pattern on the triangle domain (patterns/semi_uniform.h; mirror
 * cltess/patterns/semi_uniform.py, TRI_SEMI_UNIFORM). */
#define PATTERN_EDGES 3
#include "patterns/semi_uniform.h"
