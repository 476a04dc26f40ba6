/* timetext.c: times without rounding noise (mf_timetext.h). */
#include "mf_timetext.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

const char *mf_time_text(double t, char *buf, size_t len)
{
    if (!isfinite(t)) {
        snprintf(buf, len, "%g", t);
        return buf;
    }
    const double tol = MF_TIME_TOLERANCE * (fabs(t) > 1e-300 ? fabs(t) : 1e-300);
    for (int digits = 1; digits <= 17; digits++) {
        snprintf(buf, len, "%.*g", digits, t);
        if (fabs(strtod(buf, NULL) - t) <= tol)
            break;
    }
    return buf;
}

double mf_time_round(double t)
{
    char buf[40];
    return strtod(mf_time_text(t, buf, sizeof buf), NULL);
}
