/* mf_report.h: CSV tables and PNG plots (through gnuplot's pngcairo
 * terminal: a well-kept plotting program from Debian, driven by a pipe). */
#ifndef MF_REPORT_H
#define MF_REPORT_H

#include <stdbool.h>
#include <stddef.h>

typedef struct mf_series {
    const char *title;
    const double *x, *y;
    size_t n;
    const char *style;          /* gnuplot style: "lines", "points", "linespoints" */
    const char *const *labels;  /* optional per-point labels (NULL: none) */
} mf_series;

typedef struct mf_plot {
    const char *title, *xlabel, *ylabel;
    bool logx, logy;
    const char *extra; /* further gnuplot commands before `plot` (may be NULL) */
} mf_plot;

/* Write a CSV file (temp + rename): a '#' comment block (may be NULL), a
 * header line, then nrows rows of ncols numbers from columns[c][r]. */
int mf_report_csv(const char *path, const char *comment, const char *header, size_t ncols,
                  const double *const *columns, size_t nrows);

/* Draw the series into a PNG (temp + rename). MF_ERR_IO with a hint if
 * gnuplot is missing. */
int mf_report_plot(const char *png, const mf_plot *plot, const mf_series *series, size_t nseries);

#endif
