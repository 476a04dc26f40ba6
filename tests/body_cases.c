/* body_cases.c: the rigid-body case test_bodies and test_mpi share
 * (body_cases.h). */
#include "body_cases.h"

#include <stdio.h>

void tc_momentum_geometry(char *out, size_t len, double l0, double u)
{
    snprintf(out, len,
             "dimension 2;\nparticleSpacing %g;\n"
             "fluidBlocks {\n"
             " a { type box; min (0.1 0.1 0); max (0.17 0.3 0); fluid water; }\n"
             " b { type box; min (0.23 0.1 0); max (0.3 0.3 0); fluid water; }\n"
             " c { type box; min (0.17 0.1 0); max (0.23 0.17 0); fluid water; }\n"
             " d { type box; min (0.17 0.23 0); max (0.23 0.3 0); fluid water; }\n}\n"
             "walls { tank { type box; min (0 0 0); max (0.4 0.4 0); } }\n"
             "obstacles { body { type box; min (0.17 0.17 0); max (0.23 0.23 0);\n"
             " motion { type rigid; density 1000; g (0 0 0); velocity (%g 0 0); } } }\n",
             l0, u);
}
