/* st_tensions.c: the tension sigma of each fluid pair and free surface. */
#include <math.h>

#include "surface_tension.h"
#include "mf_error.h"
#include "mf_scene.h"

typedef struct pair_settings {
    double sigma;
} pair_settings;

static const mf_param pair_params[] = {
    {"sigma", MF_PARAM_SCALAR, NULL, 0, 1e6, NULL, offsetof(pair_settings, sigma),
     "tension of the interface, N/m"},
};
static const char *const pair_extra[] = {"fluids", NULL};

static int read_interface(st_data *d, const mf_sim *sim, const mf_entry *e)
{
    char where[512];
    if (e->n != 1 || e->items[0]->kind != MF_VAL_DICT)
        return MF_ERROR(MF_ERR_INPUT,
                        "%s: interface '%s' must be a sub-dictionary { fluids (a b); sigma s; }",
                        mf_loc_str(e->loc, where, sizeof where), e->key);
    const mf_dict *id = e->items[0]->dict;
    pair_settings ps;
    MF_CALL(mf_params_apply(pair_params, 1, id, pair_extra, &ps, NULL));
    mf_entry *fe = mf_dict_find(id, "fluids");
    if (!fe || fe->n != 1 || fe->items[0]->kind != MF_VAL_LIST || fe->items[0]->n != 2)
        return MF_ERROR(MF_ERR_INPUT, "%s: interface '%s': 'fluids' takes two fluid names, e.g. "
                        "fluids (oil water);",
                        mf_loc_str(fe ? fe->loc : id->loc, where, sizeof where), e->key);
    fe->used = true;
    int k[2];
    for (int q = 0; q < 2; q++) {
        const mf_value *v = fe->items[0]->items[q];
        if (v->kind != MF_VAL_WORD && v->kind != MF_VAL_STRING)
            return MF_ERROR(MF_ERR_INPUT, "%s: interface '%s': a fluid name is expected",
                            mf_loc_str(v->loc, where, sizeof where), e->key);
        if (mf_scene_fluid_index(sim, v->text, &k[q]) != 0)
            return MF_ERROR(MF_ERR_INPUT, "%s: interface '%s': %s",
                            mf_loc_str(v->loc, where, sizeof where), e->key,
                            mf_error_message());
    }
    if (k[0] == k[1])
        return MF_ERROR(MF_ERR_INPUT, "%s: interface '%s' names fluid '%s' twice (its free "
                        "surface takes sigma from constant/fluids)",
                        mf_loc_str(fe->loc, where, sizeof where), e->key,
                        sim->fluid[k[0]].name);
    d->sigma[k[0]][k[1]] = d->sigma[k[1]][k[0]] = ps.sigma;
    return 0;
}

int st_setup_tensions(st_data *d, const mf_sim *sim)
{
    d->nfluids = sim->nfluids;
    for (int x = 0; x < sim->nfluids; x++)
        for (int y = 0; y < sim->nfluids; y++)
            d->sigma[x][y] = x == y ? sim->fluid[x].sigma
                                    : fabs(sim->fluid[x].sigma - sim->fluid[y].sigma);
    for (size_t k = 0; d->s.interfaces && k < d->s.interfaces->n; k++) {
        mf_entry *e = d->s.interfaces->entries[k];
        e->used = true;
        MF_CALL(read_interface(d, sim, e));
    }
    d->any = false;
    for (int x = 0; x < sim->nfluids; x++)
        for (int y = 0; y < sim->nfluids; y++)
            d->any = d->any || d->sigma[x][y] > 0;
    return 0;
}
