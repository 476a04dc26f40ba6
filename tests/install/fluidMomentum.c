/* fluidMomentum.c: a function object built outside the tree, against an
 * installed mpsflow (tests/test_install.sh):
 *   cc $(pkg-config --cflags mpsflow) -shared -fPIC -o libfluidMomentum.so fluidMomentum.c
 *   functions { momentum { type fluidMomentum; libs ("libfluidMomentum.so"); } }
 * Writes postProcessing/<name>/momentum.dat: time and the fluid's mean
 * velocity (x y z) after every step. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "mf_error.h"
#include "mf_modules.h"

typedef struct momentum {
    FILE *out;
} momentum;

static int momentum_create(const void *settings, const mf_sim *sim, const char *out_dir,
                           void **data)
{
    (void)settings;
    (void)sim;
    char path[4200];
    snprintf(path, sizeof path, "%s", out_dir);
    for (char *s = path + 1; *s; s++) /* mkdir -p */
        if (*s == '/') {
            *s = '\0';
            mkdir(path, 0777);
            *s = '/';
        }
    if (mkdir(path, 0777) != 0 && errno != EEXIST)
        return MF_ERROR(MF_ERR_IO, "%s: cannot create (%s)", path, strerror(errno));
    momentum *m = calloc(1, sizeof *m);
    if (!m)
        return MF_ERROR(MF_ERR_MEMORY, "fluidMomentum: out of memory");
    snprintf(path, sizeof path, "%s/momentum.dat", out_dir);
    m->out = fopen(path, "w");
    if (!m->out) {
        free(m);
        return MF_ERROR(MF_ERR_IO, "%s: cannot write (%s)", path, strerror(errno));
    }
    fprintf(m->out, "# time mean_ux mean_uy mean_uz [m/s]\n");
    *data = m;
    return 0;
}

static int momentum_execute(void *data, const mf_sim *sim)
{
    momentum *m = data;
    double u[3] = {0, 0, 0};
    size_t n = 0;
    for (size_t i = 0; i < sim->p->n_owned; i++)
        if (sim->p->kind[i] == MF_FLUID) {
            for (int c = 0; c < 3; c++)
                u[c] += sim->p->vel[3 * i + c];
            n++;
        }
    if (n > 0)
        fprintf(m->out, "%.10g %.10g %.10g %.10g\n", sim->time, u[0] / n, u[1] / n, u[2] / n);
    return 0;
}

static void momentum_destroy(void *data)
{
    momentum *m = data;
    fclose(m->out);
    free(m);
}

static const mf_function_object_ops fluid_momentum_ops = {
    .info = {MF_ABI_VERSION, MF_KIND_FUNCTION_OBJECT, "fluidMomentum",
             "the fluid's mean velocity each step (out-of-tree plugin example)", NULL, 0, 0},
    .create = momentum_create,
    .execute = momentum_execute,
    .destroy = momentum_destroy,
};

int mf_plugin_register_fluidMomentum(mf_registry *reg);
int mf_plugin_register_fluidMomentum(mf_registry *reg)
{
    return mf_registry_add(reg, &fluid_momentum_ops.info);
}
