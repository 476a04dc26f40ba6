/* convection.h: schemes of the MPS-MAFL Eulerian phase (module kind
 * "convection", mf_convection_ops in mf_modules.h), so that a plugin can add
 * one.
 *
 * Each scheme advances one point of a 1-D directional grid (section 3.3):
 * f[0..3] = f_{i-2}, f_{i-1}, f_i, f_{i+1} with spacing dr, the flow from
 * i-1 towards i, and q = |u^a| dt / dr (0 <= q <= 1). The new f_i is the
 * value a distance q dr upstream of point i (eq. 21).
 *
 *   upwind   eq. 24: f_i - q (f_i - f_{i-1}); first order.
 *   QUICK    eq. 25: f_i - q (3/8 f_{i+1} + 3/8 f_i - 7/8 f_{i-1} + 1/8 f_{i-2}),
 *            plus (by default) Leonard's streaming terms, see quick.c.
 *
 * Both take `filter` (eq. 26): clip the new value to [min, max] of the grid
 * values the scheme used, so that no new extremum appears.
 */
#ifndef MF_CONVECTION_H
#define MF_CONVECTION_H

#include <stdbool.h>

#include "mf_modules.h"

extern const mf_convection_ops mf_convection_upwind;
extern const mf_convection_ops mf_convection_QUICK;

/* eq. 26: x clipped to [min, max] of f[first .. 3]. */
static inline double mf_convection_clip(double x, const double f[4], int first)
{
    double lo = f[first], hi = f[first];
    for (int k = first + 1; k < 4; k++) {
        lo = f[k] < lo ? f[k] : lo;
        hi = f[k] > hi ? f[k] : hi;
    }
    return x < lo ? lo : (x > hi ? hi : x);
}

#endif
