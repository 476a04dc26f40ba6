/* st_module.c: the surfaceTension module: create, destroy, its work arrays,
 * the fields it writes and its ops table. */
#include <stdlib.h>
#include <string.h>

#include "surface_tension.h"
#include "mf_alloc.h"
#include "mf_error.h"

static void st_destroy(void *data)
{
    st_data *d = data;
    if (!d)
        return;
    free(d->n1);
    free(d->nall);
    free(d->kappa);
    free(d->kappa_s);
    free(d->fdir);
    free(d->nrm);
    free(d->p_surface);
    free(d->kappa_out);
    free(d->accel_out);
    free(d);
}

static int st_create_data(const st_settings *s, mf_sim *sim, st_data *d)
{
    d->s = *s;
    d->paper = strcmp(s->curvature, "paper") == 0;
    d->normal = strcmp(s->curvature, "normal") == 0;
    d->pressure_mode = strcmp(s->free_surface, "pressure") == 0;
    d->dim = sim->dim;
    d->l0 = sim->l0;
    d->r = s->radius * sim->l0;
    /* Shared: the solver's lists where they reach r_st (their order, too). */
    MF_CALL(mf_neighbours_request(sim->neighbours, d->r, 0, &d->pairs));
    st_lattice_counts(d);
    st_exact_table(d);
    MF_CALL(st_setup_tensions(d, sim));
    MF_CALL(mf_particles_request_field(sim->p, "Curvature", 1, MF_FIELD_DOUBLE, true,
                                       &d->f_curvature));
    MF_CALL(mf_particles_request_field(sim->p, "SurfaceTension", 3, MF_FIELD_DOUBLE, true,
                                       &d->f_accel));
    mf_log_printf(sim->log, MF_LOG_NORMAL,
                  "surfaceTension: r_st = %g l0, N_full = %g, n0^st = %g (flat interface), "
                  "curvature %s, free surfaces by %s\n",
                  s->radius, d->n_full, d->n0st, s->curvature,
                  d->pressure_mode ? "pressure (p = sigma kappa, eq. 18; no force there)"
                                   : "force (eq. 33)");
    for (int x = 0; x < sim->nfluids; x++)
        for (int y = x; y < sim->nfluids; y++)
            if (d->sigma[x][y] > 0) {
                if (x == y)
                    mf_log_printf(sim->log, MF_LOG_NORMAL,
                                  "surfaceTension: free surface of %s: sigma = %g N/m\n",
                                  sim->fluid[x].name, d->sigma[x][y]);
                else
                    mf_log_printf(sim->log, MF_LOG_NORMAL,
                                  "surfaceTension: interface %s/%s: sigma = %g N/m\n",
                                  sim->fluid[x].name, sim->fluid[y].name, d->sigma[x][y]);
            }
    if (!d->any)
        mf_log_printf(sim->log, MF_LOG_NORMAL,
                      "surfaceTension: every sigma is 0 (constant/fluids): no force\n");
    return 0;
}

static int st_create(const void *settings, mf_sim *sim, void **data)
{
    st_data *d = calloc(1, sizeof *d);
    if (!d)
        return MF_ERROR(MF_ERR_MEMORY, "out of memory");
    int rc = st_create_data(settings, sim, d);
    if (rc != 0) {
        st_destroy(d);
        return mf_error_trace(rc, __FILE__, __LINE__, __func__);
    }
    *data = d;
    return 0;
}

/* Work arrays, one entry per particle. */
int st_reserve(st_data *d, size_t n)
{
    if (n <= d->cap)
        return 0;
    size_t cap = n + n / 4 + 64;
    if (mf_resize(&d->n1, cap, sizeof *d->n1) || mf_resize(&d->nall, cap, sizeof *d->nall) ||
        mf_resize(&d->kappa, cap, sizeof *d->kappa) ||
        mf_resize(&d->kappa_s, cap, sizeof *d->kappa_s) ||
        mf_resize(&d->fdir, 3 * cap, sizeof *d->fdir) ||
        mf_resize(&d->nrm, 3 * cap, sizeof *d->nrm) ||
        mf_resize(&d->p_surface, cap, sizeof *d->p_surface) ||
        mf_resize(&d->kappa_out, cap, sizeof *d->kappa_out) ||
        mf_resize(&d->accel_out, 3 * cap, sizeof *d->accel_out))
        return MF_ERROR(MF_ERR_MEMORY, "out of memory for %zu particles", n);
    d->cap = cap;
    return 0;
}

/* The Curvature and SurfaceTension fields from the last accumulate. */
static int st_write_fields(void *data, mf_sim *sim)
{
    const st_data *d = data;
    const mf_particles *p = sim->p;
    double *kappa = mf_particles_fd(p, d->f_curvature);
    double *accel = mf_particles_fd(p, d->f_accel);
    const size_t n = d->out_n <= p->n ? d->out_n : 0;
    if (n)
        memcpy(kappa, d->kappa_out, n * sizeof *kappa);
    if (n)
        memcpy(accel, d->accel_out, 3 * n * sizeof *accel);
    memset(kappa + n, 0, (p->n - n) * sizeof *kappa);
    memset(accel + 3 * n, 0, 3 * (p->n - n) * sizeof *accel);
    return 0;
}

const mf_force_ops mf_force_surfaceTension = {
    .info = {MF_ABI_VERSION, MF_KIND_FORCE, "surfaceTension",
             "surface tension sigma kappa delta n, curvature from particle counts (Appendix A, "
             "Nomura et al. 2001)",
             st_params, ST_NPARAMS, sizeof(st_settings)},
    .create = st_create,
    .accumulate = st_accumulate,
    .destroy = st_destroy,
    .flags = MF_FORCE_INTERNAL,
    .stable_dt = st_stable_dt,
    .write_fields = st_write_fields,
    .claim_surface_pressure = st_claim_surface_pressure,
    .surface_pressure = st_surface_pressure,
};
