/* body_cases.c: the rigid-body case test_bodies and test_mpi share
 * (body_cases.h). */
#include "body_cases.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

bool tc_body_csv_row(const char *line, double c[20])
{
    int k = 0;
    for (const char *s = line; k < 20; k++) {
        char *e;
        c[k] = strtod(s, &e);
        if (e == s || (*e != ',' && k < 19))
            break;
        s = e + 1;
    }
    return k >= 19;
}

void tc_body_track_free(tc_body_track *tr)
{
    free(tr->t);
    free(tr->x);
    free(tr->v);
    free(tr->f);
}

int tc_body_track_read(const char *dir, const char *body, tc_body_track *tr)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/postProcessing/%s/bodyState.csv", dir, body);
    memset(tr, 0, sizeof *tr);
    FILE *f = fopen(path, "r");
    if (!f)
        return -1;
    size_t cap = 0;
    char line[4096];
    while (fgets(line, sizeof line, f)) {
        if (line[0] == '#') {
            const char *m = strstr(line, "mass ");
            if (m)
                tr->mass = atof(m + 5);
            continue;
        }
        double c[20];
        if (!tc_body_csv_row(line, c))
            continue;
        if (tr->n == cap) {
            cap = cap ? 2 * cap : 256;
            tr->t = realloc(tr->t, cap * sizeof *tr->t);
            tr->x = realloc(tr->x, 3 * cap * sizeof *tr->x);
            tr->v = realloc(tr->v, 3 * cap * sizeof *tr->v);
            tr->f = realloc(tr->f, 3 * cap * sizeof *tr->f);
            if (!tr->t || !tr->x || !tr->v || !tr->f) {
                fclose(f);
                return -1;
            }
        }
        tr->t[tr->n] = c[0];
        for (int a = 0; a < 3; a++) {
            tr->x[3 * tr->n + a] = c[1 + a];
            tr->v[3 * tr->n + a] = c[8 + a];
            tr->f[3 * tr->n + a] = c[14 + a];
        }
        tr->n++;
    }
    fclose(f);
    return tr->n > 1 && tr->mass > 0 ? 0 : -1;
}

