/* report.c: CSV and PNG reports. */
#include "mf_report.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

#include "mf_error.h"
#include "mf_fs.h"

int mf_report_csv(const char *path, const char *comment, const char *header, size_t ncols,
                  const double *const *columns, size_t nrows)
{
    mf_replace out;
    MF_CALL(mf_replace_open(&out, path, "w"));
    FILE *f = out.f;
    if (comment) {
        const char *s = comment;
        while (*s) {
            size_t n = strcspn(s, "\n");
            fprintf(f, "# %.*s\n", (int)n, s);
            s += n + (s[n] == '\n');
        }
    }
    fprintf(f, "%s\n", header);
    for (size_t r = 0; r < nrows; r++)
        for (size_t c = 0; c < ncols; c++)
            fprintf(f, "%.10g%s", columns[c][r], c + 1 < ncols ? "," : "\n");
    MF_CALL(mf_replace_commit(&out, 0));
    return 0;
}

/* gnuplot strings are single-quoted: drop quotes rather than escape. */
static void put_quoted(FILE *g, const char *s)
{
    fputc('\'', g);
    for (; s && *s; s++)
        if (*s != '\'')
            fputc(*s, g);
    fputc('\'', g);
}

int mf_report_plot(const char *png, const mf_plot *plot, const mf_series *series, size_t nseries)
{
    char tmp[4200];
    snprintf(tmp, sizeof tmp, "%s.tmp", png);
    FILE *g = popen("gnuplot 2>&1", "w");
    if (!g)
        return MF_ERROR(MF_ERR_IO, "cannot start gnuplot (%s): install it with "
                        "apt-get install gnuplot-nox", strerror(errno));
    /* noenhanced: names such as MPS_plain are not subscripts. */
    fprintf(g, "set terminal pngcairo noenhanced size 900,600 font 'sans,11'\nset output ");
    put_quoted(g, tmp);
    fprintf(g, "\nset title ");
    put_quoted(g, plot->title);
    fprintf(g, "\nset xlabel ");
    put_quoted(g, plot->xlabel);
    fprintf(g, "\nset ylabel ");
    put_quoted(g, plot->ylabel);
    fprintf(g, "\nset grid\nset key left top\n");
    if (plot->logx) fprintf(g, "set logscale x\n");
    if (plot->logy) fprintf(g, "set logscale y\n");
    if (plot->extra) fprintf(g, "%s\n", plot->extra);
    fprintf(g, "plot ");
    for (size_t s = 0; s < nseries; s++) {
        fprintf(g, "%s'-' using 1:2 with %s title ", s ? ", " : "",
                series[s].style ? series[s].style : "linespoints");
        put_quoted(g, series[s].title);
        if (series[s].labels)
            fprintf(g, ", '-' using 1:2:3 with labels offset 0,1.2 font ',8' notitle");
    }
    fprintf(g, "\n");
    for (size_t s = 0; s < nseries; s++) {
        for (size_t i = 0; i < series[s].n; i++)
            fprintf(g, "%.10g %.10g\n", series[s].x[i], series[s].y[i]);
        fprintf(g, "e\n");
        if (series[s].labels) {
            for (size_t i = 0; i < series[s].n; i++)
                fprintf(g, "%.10g %.10g \"%s\"\n", series[s].x[i], series[s].y[i],
                        series[s].labels[i]);
            fprintf(g, "e\n");
        }
    }
    int status = pclose(g);
    if (status == -1 || !WIFEXITED(status) || WEXITSTATUS(status) == 127)
        return MF_ERROR(MF_ERR_IO, "gnuplot is not available: install it with "
                        "apt-get install gnuplot-nox");
    if (WEXITSTATUS(status) != 0)
        return MF_ERROR(MF_ERR_IO, "gnuplot failed drawing %s", png);
    if (rename(tmp, png) != 0)
        return MF_ERROR(MF_ERR_IO, "%s: cannot rename (%s)", png, strerror(errno));
    return 0;
}
