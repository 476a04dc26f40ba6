/* test_water_entry_metric.c: the waterEntryDepth metric's comparison with an
 * experiment (validation/<reference>, T = t sqrt(g/D), H = h/D) on a
 * synthetic trajectory, through `mpsflow validate`:
 *
 *   - a body that sinks at a constant 1.5 m/s (h linear in t, so the
 *     metric's linear interpolation in time is exact) against reference
 *     points set off from that line by known amounts: the error is the RMS
 *     of those offsets over the points with 0 < T inside the run (the point
 *     at T = 0 and the one after the run's end are left out), and
 *     result_experiment.csv has the run's H at each reference T;
 *   - without `reference` the error is the model's (von Karman) RMS, which
 *     differs, and no result_experiment.csv is written;
 *   - a malformed reference line fails with the file and line named.
 *
 * argv[1]: the mpsflow executable. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "case_util.h"
#include "mf_test.h"

#define R 0.055
#define LEVEL 0.25
#define SPEED 1.5 /* m/s, the synthetic body's constant sinking speed */

static const char metric_head[] = "FoamFile { version 2.0; format ascii; class dictionary; "
                                  "object metric; }\n"
                                  "metric waterEntryDepth;\nbody cylinder;\nradius 0.055;\n"
                                  "surface 0.25;\nrho 1000;\ngravity 9.81;\nendTime 0.03;\n";

/* bodyState.csv of a body whose lowest point touches the level at t = 0 and
 * sinks at SPEED: rows every 1 ms to 0.1 s, the columns mpsflow writes. */
static int write_trajectory(const tc_case *c)
{
    size_t cap = 1 << 16, len = 0;
    char *text = malloc(cap);
    if (!text)
        return -1;
    len += (size_t)snprintf(text + len, cap - len,
                            "# rigid body 'cylinder': mass 4.75165889 (2-D: per metre), centre of "
                            "mass, ...\ntime,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz,Fx,Fy,Fz,Tx,Ty,"
                            "Tz\n");
    for (int k = 0; k <= 100; k++) {
        const double t = 1e-3 * k, y = LEVEL + R - SPEED * t;
        len += (size_t)snprintf(text + len, cap - len,
                                "%.10g,0.25,%.12g,0,1,0,0,0,0,%g,0,0,0,0,0,0,0,0,0,0\n", t, y,
                                -SPEED);
    }
    const int rc = tc_case_write(c, "postProcessing/cylinder/bodyState.csv", text);
    free(text);
    return rc;
}

/* The last error validate printed ("error waterEntryDepth = X"), NAN if none. */
static double printed_error(const tc_case *c)
{
    char path[600];
    snprintf(path, sizeof path, "%s/log", c->dir);
    char *log = tc_read_text(path);
    const char *key = "error waterEntryDepth = ";
    double e = NAN;
    for (const char *at = log ? strstr(log, key) : NULL; at; at = strstr(at + 1, key))
        e = atof(at + strlen(key));
    free(log);
    return e;
}

/* The RMS against the reference in result.csv's comment ("... points: X;"). */
static double reported_rms(const tc_case *c, char *count, size_t len)
{
    char path[600];
    snprintf(path, sizeof path, "%s/validation/result.csv", c->dir);
    char *text = tc_read_text(path);
    double e = NAN;
    const char *at = text ? strstr(text, "RMS of (h - h_ref)/D over ") : NULL;
    const char *colon = at ? strstr(at, "points: ") : NULL;
    if (colon) {
        e = atof(colon + strlen("points: "));
        const char *n = at + strlen("RMS of (h - h_ref)/D over ");
        snprintf(count, len, "%.*s", (int)(colon - n), n);
    }
    free(text);
    return e;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: test_water_entry_metric MPSFLOW\n");
        return 2;
    }
    const double D = 2 * R, tscale = sqrt(9.81 / D);
    /* Reference points: T = 0 (left out), three inside the run with
     * offsets, one after its end (t = 0.1 s, T = 0.944; left out). */
    const double T[5] = {0, 0.1, 0.4, 0.8, 1.2}, off[5] = {0.5, 0.02, -0.04, 0.01, 0.3};
    char ref[1024];
    size_t len = (size_t)snprintf(ref, sizeof ref, "# synthetic\nT,H\n");
    for (int i = 0; i < 5; i++)
        len += (size_t)snprintf(ref + len, sizeof ref - len, "%.12g,%.12g\n", T[i],
                                SPEED * T[i] / tscale / D + off[i]);
    const double expected = sqrt((off[1] * off[1] + off[2] * off[2] + off[3] * off[3]) / 3);

    tc_case c;
    CHECK_OK(tc_case_create(&c, argv[1], "water-entry-metric"));
    const char *dirs[3] = {"output", "postProcessing", "postProcessing/cylinder"};
    for (int k = 0; k < 3; k++) {
        char dir[700];
        snprintf(dir, sizeof dir, "%s/%s", c.dir, dirs[k]);
        CHECK_OK(mkdir(dir, 0755));
    }
    CHECK_OK(write_trajectory(&c));
    CHECK_OK(tc_case_write(&c, "output/runSummary", "status completed;\n"));
    CHECK_OK(tc_case_write(&c, "validation/ref.csv", ref));
    char metric[1200];
    snprintf(metric, sizeof metric, "%sreference \"ref.csv\";\n", metric_head);
    CHECK_OK(tc_case_write(&c, TC_METRIC, metric));

    int status = tc_case_run(&c, "validate", NULL);
    CHECK_MSG(status == 0, "validate with a reference exited with %d", status);
    const double with_ref = printed_error(&c);
    char count[64] = "";
    const double rms = reported_rms(&c, count, sizeof count);
    printf("water entry metric: error %.9g (printed %.6g) over %s, expected %.9g\n", rms,
           with_ref, count, expected);
    CHECK(fabs(rms - expected) < 1e-8 * expected);
    CHECK(fabs(with_ref - expected) < 1e-5 * expected); /* printed to 6 digits */
    CHECK_MSG(!strcmp(count, "3 of 5 "), "compared over '%s' points, expected 3 of 5", count);
    /* result_experiment.csv: the run's H at the reference's T, nan outside. */
    char path[700];
    snprintf(path, sizeof path, "%s/validation/result_experiment.csv", c.dir);
    FILE *f = fopen(path, "r");
    CHECK_MSG(f != NULL, "no %s", path);
    char line[512];
    int row = 0;
    while (f && fgets(line, sizeof line, f)) {
        double t_ref, h_ref, h_run;
        if (line[0] == '#' || line[0] == 'T')
            continue;
        char run_text[64] = "";
        if (sscanf(line, "%lf,%lf,%63s", &t_ref, &h_ref, run_text) != 3) {
            CHECK_MSG(0, "result_experiment.csv: bad row '%s'", line);
            continue;
        }
        h_run = strtod(run_text, NULL);
        if (row < 5) {
            const bool inside = row >= 1 && row <= 3;
            CHECK_MSG(fabs(t_ref - T[row]) < 1e-9, "row %d: T %g, expected %g", row, t_ref, T[row]);
            if (inside)
                CHECK_MSG(fabs(h_run - SPEED * T[row] / tscale / D) < 1e-8,
                          "row %d: H_run %.9g, expected %.9g", row, h_run,
                          SPEED * T[row] / tscale / D);
            else
                CHECK_MSG(isnan(h_run), "row %d: H_run %g where the run has no value", row, h_run);
        }
        row++;
    }
    if (f)
        fclose(f);
    CHECK_MSG(row == 5, "result_experiment.csv has %d rows, expected 5", row);

    /* Without a reference: the model's RMS, and no experiment report. */
    remove(path);
    CHECK_OK(tc_case_write(&c, TC_METRIC, metric_head));
    status = tc_case_run(&c, "validate", NULL);
    CHECK_MSG(status == 0, "validate without a reference exited with %d", status);
    const double without = printed_error(&c);
    CHECK(isfinite(without) && fabs(without - with_ref) > 1e-3);
    f = fopen(path, "r");
    CHECK_MSG(f == NULL, "%s written without a reference", path);
    if (f)
        fclose(f);

    /* A malformed reference line: the file and the line are named. */
    CHECK_OK(tc_case_write(&c, "validation/ref.csv", "T,H\n0.1,0.2\n0.3;0.4\n"));
    CHECK_OK(tc_case_write(&c, TC_METRIC, metric));
    status = tc_case_run(&c, "validate", NULL);
    CHECK_MSG(status != 0, "validate accepted a malformed reference");
    CHECK(tc_case_log_contains(&c, "validation/ref.csv:3: expected two numbers"));
    tc_case_destroy(&c);
    return mf_test_summary("water_entry_metric");
}
