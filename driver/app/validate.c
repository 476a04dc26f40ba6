/* validate.c: `mpsflow validate -case DIR` runs the metric named in the
 * case's validation/metric on its snapshots. */
#include <stdlib.h>
#include <string.h>

#include "mf_dictio.h"
#include "mf_error.h"
#include "mf_app.h"
#include "mf_post.h"

extern const mf_metric mf_metric_scalar_advection; /* metric_scalar.c */
extern const mf_metric mf_metric_volume_flux;      /* metric_scalar.c */
extern const mf_metric mf_metric_poiseuille;       /* metric_poiseuille.c */

/* metric_droplet.c: the multi-fluid cases */
extern const mf_metric mf_metric_laplace, mf_metric_oscillation, mf_metric_layering,
    mf_metric_rayleigh_taylor, mf_metric_fluid_surge_front;

static const mf_metric *const metrics[] = {
    &mf_metric_surge_front,
    &mf_metric_hydrostatic,
    &mf_metric_scalar_advection,
    &mf_metric_volume_flux,
    &mf_metric_laplace,
    &mf_metric_oscillation,
    &mf_metric_layering,
    &mf_metric_rayleigh_taylor,
    &mf_metric_fluid_surge_front,
    &mf_metric_poiseuille,
};
#define NMETRICS (sizeof metrics / sizeof metrics[0])

const mf_metric *const *mf_metric_list(size_t *n)
{
    *n = NMETRICS;
    return metrics;
}

int mf_cmd_validate(const char *case_dir, double *error)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/validation/metric", case_dir);
    mf_dict *d = NULL;
    MF_CALL(mf_dict_parse_file(path, &d));
    const char *name = NULL;
    int rc = mf_dict_get_word(d, "metric", &name);
    const mf_metric *m = NULL;
    for (size_t k = 0; rc == 0 && k < NMETRICS; k++)
        if (strcmp(metrics[k]->name, name) == 0)
            m = metrics[k];
    if (rc == 0 && !m) {
        const char *names[NMETRICS];
        for (size_t k = 0; k < NMETRICS; k++)
            names[k] = metrics[k]->name;
        const char *hint = mf_did_you_mean(name, names, NMETRICS);
        rc = MF_ERROR(MF_ERR_INPUT, "%s: unknown metric '%s'%s%s%s; known: surgeFront, "
                      "hydrostaticPressure, scalarAdvection, volumeFlux, laplacePressure, "
                      "oscillationPeriod, layering, rayleighTaylor, fluidSurgeFront, poiseuille",
                      path, name, hint ? " (did you mean '" : "", hint ? hint : "",
                      hint ? "'?)" : "");
    }
    if (rc == 0)
        rc = m->evaluate(case_dir, d, error);
    if (rc == 0)
        printf("error %s = %.6g\n", m->name, *error);
    mf_dict_free(d);
    return rc;
}
