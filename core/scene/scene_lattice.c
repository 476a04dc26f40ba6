/* scene_lattice.c: the box check shared by the scene builders. */
#include "scene_lattice.h"

#include "mf_error.h"

int mf_lattice_check_box(const char *what, const char *name, const mf_dict *d, const double *mn,
                         const double *mx, int dim)
{
    char where[512];
    for (int a = 0; a < dim; a++)
        if (!(mx[a] > mn[a]))
            return MF_ERROR(MF_ERR_INPUT, "%s: %s '%s': max must exceed min on every axis",
                            mf_loc_str(d->loc, where, sizeof where), what, name);
    return 0;
}
