/* glint — line plots for glint bench: one description drawn two ways, as SVG text and as a PNG
 * drawn by cairo, the same figure with its title, axis and tick labels and legend. Log or linear
 * axes; decade ticks on log axes. */
#ifndef GLINT_PLOT_H
#define GLINT_PLOT_H

#include <stddef.h>

#include "image_io.h"

typedef struct {
    const char *label;
    int n;
    const double *x, *y;   /* points with a non-positive or non-finite coordinate on a log axis are skipped */
    const double *lo, *hi; /* optional: a light band from lo to hi at each x; NULL for none */
} plot_series;

/* A reading marked on the plot: a dashed line at x (vertical) or y (horizontal) with a marker
 * where each series crosses it (log-log interpolation). NAN: none. */
typedef struct {
    const char *title, *x_label, *y_label;
    int log_x, log_y;
    const plot_series *series;
    int num_series;
    double mark_x, mark_y;
    const char *mark_x_label, *mark_y_label;
} plot_desc;

/* Atomic writes (image_io.h). Return 0, or -1 with err = "PATH: problem". */
int plot_save_svg(const plot_desc *p, const char *path, write_mode mode, char *err, size_t errlen);
int plot_save_png(const plot_desc *p, const char *path, write_mode mode, char *err, size_t errlen);

#endif
