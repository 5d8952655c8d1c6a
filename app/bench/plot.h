/* glint — line plots for glint bench: one description drawn by one cairo routine, to an SVG
 * (cairo's SVG surface; its text as glyph outlines) and to a PNG. Both have the title, axis titles
 * with their units, tick labels and a legend naming every curve, band and reading. Log or linear
 * axes; decade ticks on log axes. */
#ifndef GLINT_PLOT_H
#define GLINT_PLOT_H

#include <stddef.h>

#include "image_io.h"

/* The figure, in pixels of the PNG and user units of the SVG: the data inside the plot area, the
 * legend right of it. */
enum {
    PLOT_WIDTH = 860,
    PLOT_HEIGHT = 500,
    PLOT_AREA_X0 = 80,
    PLOT_AREA_X1 = 580,
    PLOT_AREA_Y0 = 40,
    PLOT_AREA_Y1 = 430,
    PLOT_LEGEND_X = 600,
};

typedef struct {
    const char *label;
    int n;
    const double *x, *y;   /* points with a non-finite coordinate, or a non-positive one on a log
                            * axis, are skipped and break the curve */
    const double *lo, *hi; /* optional: a light band from lo to hi at each x; NULL for none */
} plot_series;

/* A reading marked on the plot: a dashed line at x (vertical) or y (horizontal) with a marker
 * where each series crosses it (log-log interpolation). NAN: none. */
typedef struct {
    const char *title;
    const char *x_label, *x_unit; /* the axis title reads "label (unit)"; unit NULL or "": none */
    const char *y_label, *y_unit;
    int log_x, log_y;
    const plot_series *series;
    int num_series;
    const char *band_label; /* the legend's words for the bands, when a series has one */
    double mark_x, mark_y;
    const char *mark_x_label, *mark_y_label;
} plot_desc;

/* Atomic writes (image_io.h). Return 0, or -1 with err = "PATH: problem". */
int plot_save_svg(const plot_desc *p, const char *path, write_mode mode, char *err, size_t errlen);
int plot_save_png(const plot_desc *p, const char *path, write_mode mode, char *err, size_t errlen);

#endif
