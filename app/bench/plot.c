/* glint — line plots: one cairo drawing routine, onto cairo's SVG surface and onto an image
 * surface for the PNG. */
#define _POSIX_C_SOURCE 200809L
#include "plot.h"

#include <cairo-svg.h>
#include <cairo.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "metrics.h"

enum {
    FIG_W = PLOT_WIDTH,
    FIG_H = PLOT_HEIGHT,
    AREA_X0 = PLOT_AREA_X0,
    AREA_X1 = PLOT_AREA_X1,
    AREA_Y0 = PLOT_AREA_Y0,
    AREA_Y1 = PLOT_AREA_Y1,
    LEGEND_X = PLOT_LEGEND_X
};

/* Tableau 10: distinct on white, and for the common kinds of colour blindness. */
static const uint8_t palette[10][3] = {{31, 119, 180},  {255, 127, 14}, {44, 160, 44},   {214, 39, 40},
                                       {148, 103, 189}, {140, 86, 75},  {227, 119, 194}, {127, 127, 127},
                                       {188, 189, 34},  {23, 190, 207}};

typedef struct {
    int log;
    double lo, hi; /* in axis units: log10 of the value on a log axis */
    double ticks[64];
    int num_ticks;
    double minor[256]; /* log axes: 2..9 x each decade */
    int num_minor;
} axis;

static int usable(int log, double v) { return isfinite(v) && (!log || v > 0.0); }
static double to_axis(const axis *a, double v) { return a->log ? log10(v) : v; }

/* The nearest of 1, 2, 5 x 10^k below (dir < 0) or above (dir > 0) the log10 value l. */
static double log_nice(double l, int dir) {
    static const double m[4] = {1.0, 2.0, 5.0, 10.0};
    double d = floor(l);
    if (dir < 0) {
        for (int k = 2; k >= 0; k--)
            if (d + log10(m[k]) <= l + 1e-9) return d + log10(m[k]);
        return d;
    }
    for (int k = 0; k < 4; k++)
        if (d + log10(m[k]) >= l - 1e-9) return d + log10(m[k]);
    return d + 1.0;
}

static void axis_fit(axis *a, int log, double vmin, double vmax) {
    memset(a, 0, sizeof *a);
    a->log = log;
    if (!(vmin <= vmax)) vmin = log ? 1.0 : 0.0, vmax = log ? 10.0 : 1.0;
    if (log) {
        /* The range ends at 1, 2 or 5 x 10^k around the data, not at whole decades, so a curve
         * just above a decade does not waste most of the plot. */
        a->lo = log_nice(log10(vmin), -1);
        a->hi = log_nice(log10(vmax), +1);
        if (a->hi - a->lo < 0.25) a->hi = log_nice(a->lo + 0.25, +1);
        if (a->hi - a->lo > 60) a->lo = a->hi - 60; /* keep the tick arrays bounded */
        /* Decades get labels; within two decades, 2 and 5 times them too. */
        int few = a->hi - a->lo <= 2.0 + 1e-9;
        for (double d = floor(a->lo); d <= a->hi + 1e-9; d += 1.0)
            for (int m = 1; m <= 9; m++) {
                double t = d + log10((double)m);
                if (t < a->lo - 1e-9 || t > a->hi + 1e-9) continue;
                if ((m == 1 || (few && (m == 2 || m == 5))) && a->num_ticks < 64)
                    a->ticks[a->num_ticks++] = t;
                else if (a->num_minor < 256)
                    a->minor[a->num_minor++] = t;
            }
    } else {
        double span = vmax - vmin;
        if (!(span > 0.0)) { /* one value: a range around it */
            double half = fabs(vmax) > 0.0 ? 0.5 * fabs(vmax) : 0.5;
            vmin -= half;
            vmax += half;
            span = vmax - vmin;
        }
        double raw = span / 5.0, mag = pow(10.0, floor(log10(raw))), step = mag;
        if (raw / mag > 5.0)
            step = 10.0 * mag;
        else if (raw / mag > 2.0)
            step = 5.0 * mag;
        else if (raw / mag > 1.0)
            step = 2.0 * mag;
        a->lo = floor(vmin / step) * step;
        a->hi = ceil(vmax / step) * step;
        for (double t = a->lo; t <= a->hi + 0.5 * step && a->num_ticks < 64; t += step) a->ticks[a->num_ticks++] = t;
    }
}

typedef struct {
    axis x, y;
} layout;

static void layout_make(const plot_desc *p, layout *l) {
    double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
    for (int s = 0; s < p->num_series; s++)
        for (int i = 0; i < p->series[s].n; i++) {
            double x = p->series[s].x[i], y = p->series[s].y[i];
            if (!usable(p->log_x, x) || !usable(p->log_y, y)) continue;
            xmin = fmin(xmin, x), xmax = fmax(xmax, x), ymin = fmin(ymin, y), ymax = fmax(ymax, y);
            /* the band too, so it is not cut off at the plot's edge */
            if (p->series[s].lo && usable(p->log_y, p->series[s].lo[i])) ymin = fmin(ymin, p->series[s].lo[i]);
            if (p->series[s].hi && usable(p->log_y, p->series[s].hi[i])) ymax = fmax(ymax, p->series[s].hi[i]);
        }
    /* The readings too: a budget the runs overshot (a loaded machine) still shows where it is. */
    if (xmin <= xmax && usable(p->log_x, p->mark_x)) xmin = fmin(xmin, p->mark_x), xmax = fmax(xmax, p->mark_x);
    if (ymin <= ymax && usable(p->log_y, p->mark_y)) ymin = fmin(ymin, p->mark_y), ymax = fmax(ymax, p->mark_y);
    axis_fit(&l->x, p->log_x, xmin, xmax);
    axis_fit(&l->y, p->log_y, ymin, ymax);
}

static double px(const layout *l, double x) {
    return AREA_X0 + (to_axis(&l->x, x) - l->x.lo) / (l->x.hi - l->x.lo) * (AREA_X1 - AREA_X0);
}
static double py(const layout *l, double y) {
    return AREA_Y1 - (to_axis(&l->y, y) - l->y.lo) / (l->y.hi - l->y.lo) * (AREA_Y1 - AREA_Y0);
}
static double tick_value(const axis *a, double t) { return a->log ? pow(10.0, t) : t; }

static void tick_text(const axis *a, double t, char *out, size_t n) {
    double v = tick_value(a, t);
    if (fabs(v) < 1e-12 * (fabs(a->hi) + fabs(a->lo) + 1.0) && !a->log) v = 0.0;
    snprintf(out, n, "%g", v);
}

/* Where a series crosses the marks (log-log interpolation; NAN when it does not). */
static double cross_x(const plot_series *s, double x) { return metric_loglog_at(s->x, s->y, s->n, x); }
static double cross_y(const plot_series *s, double y) { return metric_loglog_reach(s->x, s->y, s->n, y); }

static int in_area(const layout *l, double x, double y) {
    if (!usable(l->x.log, x) || !usable(l->y.log, y)) return 0;
    double X = px(l, x), Y = py(l, y);
    return X >= AREA_X0 - 0.5 && X <= AREA_X1 + 0.5 && Y >= AREA_Y0 - 0.5 && Y <= AREA_Y1 + 0.5;
}

/* Point i of a series is drawn: its curve point, and with band it the band's ends too. */
static int drawn(const layout *l, const plot_series *s, int i, int band) {
    if (band) return in_area(l, s->x[i], s->lo[i]) && in_area(l, s->x[i], s->hi[i]);
    return in_area(l, s->x[i], s->y[i]);
}

/* ---- drawing: one routine for both surfaces --------------------------------------------------- */

#define TAU 6.28318530717958647692 /* a full turn, for cairo_arc */

static const uint8_t white[3] = {255, 255, 255}, black[3] = {0, 0, 0}, grey[3] = {85, 85, 85};

static void colour(cairo_t *cr, const uint8_t c[3], double alpha) {
    cairo_set_source_rgba(cr, c[0] / 255.0, c[1] / 255.0, c[2] / 255.0, alpha);
}

/* 1 px lines on pixel centres, so grid and frame come out sharp rather than two grey rows. */
static double crisp(double v) { return floor(v) + 0.5; }

static void line(cairo_t *cr, double x0, double y0, double x1, double y1) {
    cairo_move_to(cr, x0, y0);
    cairo_line_to(cr, x1, y1);
    cairo_stroke(cr);
}

static double text_width(cairo_t *cr, const char *s) {
    cairo_text_extents_t e;
    cairo_text_extents(cr, s, &e);
    return e.x_advance;
}

/* Text with its baseline at y, starting at x (align 0), centred on it (0.5) or ending there (1);
 * in a smaller size when wider than max (down to 7 px). */
static void words(cairo_t *cr, double x, double y, const char *s, double align, double max) {
    if (!s || !*s) return;
    cairo_matrix_t m;
    cairo_get_font_matrix(cr, &m); /* a plain scale: rotations go into the transformation */
    double w = text_width(cr, s), size = m.xx;
    if (w > max && w > 0.0) {
        cairo_set_font_size(cr, fmax(7.0, size * max / w));
        w = text_width(cr, s);
    }
    cairo_move_to(cr, x - align * w, y);
    cairo_show_text(cr, s);
    cairo_new_path(cr); /* show_text leaves a current point a later path would start from */
    cairo_set_font_size(cr, size);
}

/* "label (unit)", or the label alone. */
static void axis_title(const char *label, const char *unit, char *out, size_t n) {
    if (unit && *unit)
        snprintf(out, n, "%s (%s)", label ? label : "", unit);
    else
        snprintf(out, n, "%s", label ? label : "");
}

static void square_marker(cairo_t *cr, double cx, double cy, const uint8_t col[3]) {
    cairo_rectangle(cr, cx - 4.5, cy - 4.5, 9, 9);
    colour(cr, white, 1.0);
    cairo_fill_preserve(cr);
    colour(cr, col, 1.0);
    cairo_stroke(cr);
}

static void diamond_marker(cairo_t *cr, double cx, double cy, const uint8_t col[3]) {
    cairo_move_to(cr, cx, cy - 6);
    cairo_line_to(cr, cx + 6, cy);
    cairo_line_to(cr, cx, cy + 6);
    cairo_line_to(cr, cx - 6, cy);
    cairo_close_path(cr);
    colour(cr, white, 1.0);
    cairo_fill_preserve(cr);
    colour(cr, col, 1.0);
    cairo_stroke(cr);
}

static void dot(cairo_t *cr, double x, double y) {
    cairo_new_sub_path(cr);
    cairo_arc(cr, x, y, 3.0, 0.0, TAU);
}

static void draw_axes(cairo_t *cr, const plot_desc *p, const layout *l) {
    static const uint8_t minor[3] = {240, 240, 240}, grid[3] = {216, 216, 216};
    cairo_set_line_width(cr, 1.0);
    colour(cr, minor, 1.0);
    for (int k = 0; k < l->x.num_minor; k++) {
        double X = crisp(px(l, pow(10.0, l->x.minor[k])));
        line(cr, X, AREA_Y0, X, AREA_Y1);
    }
    for (int k = 0; k < l->y.num_minor; k++) {
        double Y = crisp(py(l, pow(10.0, l->y.minor[k])));
        line(cr, AREA_X0, Y, AREA_X1, Y);
    }
    char t[320];
    for (int k = 0; k < l->x.num_ticks; k++) {
        double X = crisp(px(l, tick_value(&l->x, l->x.ticks[k])));
        colour(cr, grid, 1.0);
        line(cr, X, AREA_Y0, X, AREA_Y1);
        colour(cr, black, 1.0);
        line(cr, X, AREA_Y1, X, AREA_Y1 + 5);
        tick_text(&l->x, l->x.ticks[k], t, sizeof t);
        words(cr, X, AREA_Y1 + 19, t, 0.5, 80);
    }
    for (int k = 0; k < l->y.num_ticks; k++) {
        double Y = crisp(py(l, tick_value(&l->y, l->y.ticks[k])));
        colour(cr, grid, 1.0);
        line(cr, AREA_X0, Y, AREA_X1, Y);
        colour(cr, black, 1.0);
        line(cr, AREA_X0 - 5, Y, AREA_X0, Y);
        tick_text(&l->y, l->y.ticks[k], t, sizeof t);
        words(cr, AREA_X0 - 8, Y + 4, t, 1.0, AREA_X0 - 36);
    }
    cairo_rectangle(cr, AREA_X0 + 0.5, AREA_Y0 + 0.5, AREA_X1 - AREA_X0, AREA_Y1 - AREA_Y0);
    cairo_stroke(cr);
    axis_title(p->x_label, p->x_unit, t, sizeof t);
    words(cr, (AREA_X0 + AREA_X1) / 2.0, AREA_Y1 + 42, t, 0.5, AREA_X1 - AREA_X0 + 100);
    axis_title(p->y_label, p->y_unit, t, sizeof t);
    cairo_save(cr);
    cairo_translate(cr, 22, (AREA_Y0 + AREA_Y1) / 2.0);
    cairo_rotate(cr, -0.25 * TAU);
    words(cr, 0, 0, t, 0.5, AREA_Y1 - AREA_Y0 + 60);
    cairo_restore(cr);
    cairo_set_font_size(cr, 14);
    words(cr, (AREA_X0 + AREA_X1) / 2.0, 24, p->title, 0.5, AREA_X1 - AREA_X0 + 100);
    cairo_set_font_size(cr, 12);
}

/* The readings drawn: both lie on the axes' ranges. */
static int shows_x(const plot_desc *p, const layout *l) { return in_area(l, p->mark_x, tick_value(&l->y, l->y.lo)); }
static int shows_y(const plot_desc *p, const layout *l) { return in_area(l, tick_value(&l->x, l->x.lo), p->mark_y); }

/* The readings: dashed lines, labelled. The vertical one's label goes right of its line, or left
 * of it where it would run out of the plot into the legend (the last budget often sits at the
 * axis' end). */
static void draw_readings(cairo_t *cr, const plot_desc *p, const layout *l) {
    cairo_set_font_size(cr, 11);
    colour(cr, grey, 1.0);
    if (shows_x(p, l)) {
        double X = crisp(px(l, p->mark_x)), dash[2] = {6, 4};
        cairo_set_dash(cr, dash, 2, 0);
        line(cr, X, AREA_Y0, X, AREA_Y1);
        const char *s = p->mark_x_label ? p->mark_x_label : "";
        int left = X + 4.0 + text_width(cr, s) > AREA_X1;
        words(cr, left ? X - 4 : X + 4, AREA_Y0 + 12, s, left ? 1.0 : 0.0, AREA_X1 - AREA_X0 - 8);
    }
    if (shows_y(p, l)) {
        double Y = crisp(py(l, p->mark_y)), dash[2] = {2, 3};
        cairo_set_dash(cr, dash, 2, 0);
        line(cr, AREA_X0, Y, AREA_X1, Y);
        words(cr, AREA_X0 + 4, Y - 4, p->mark_y_label, 0.0, AREA_X1 - AREA_X0 - 8);
    }
    cairo_set_dash(cr, NULL, 0, 0);
    cairo_set_font_size(cr, 12);
}

/* The curves over their bands, with their points and their readings' markers. A point not drawn
 * (see drawn) breaks the curve and the band there. */
static void draw_series(cairo_t *cr, const plot_desc *p, const layout *l) {
    for (int s = 0; s < p->num_series; s++) {
        const plot_series *se = &p->series[s];
        if (!se->lo || !se->hi) continue;
        for (int a = 0; a < se->n;) {
            if (!drawn(l, se, a, 1)) {
                a++;
                continue;
            }
            int b = a;
            while (b + 1 < se->n && drawn(l, se, b + 1, 1)) b++;
            cairo_new_path(cr);
            for (int i = a; i <= b; i++) cairo_line_to(cr, px(l, se->x[i]), py(l, se->lo[i]));
            for (int i = b; i >= a; i--) cairo_line_to(cr, px(l, se->x[i]), py(l, se->hi[i]));
            colour(cr, palette[s % 10], 0.15);
            cairo_fill(cr);
            a = b + 1;
        }
    }
    cairo_set_line_width(cr, 2.0);
    cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
    for (int s = 0; s < p->num_series; s++) {
        const plot_series *se = &p->series[s];
        const uint8_t *col = palette[s % 10];
        colour(cr, col, 1.0);
        cairo_new_path(cr);
        for (int i = 0, pen = 0; i < se->n; i++) {
            int in = drawn(l, se, i, 0);
            if (in && pen) cairo_line_to(cr, px(l, se->x[i]), py(l, se->y[i]));
            if (in && !pen) cairo_move_to(cr, px(l, se->x[i]), py(l, se->y[i]));
            pen = in;
        }
        cairo_stroke(cr);
        for (int i = 0; i < se->n; i++)
            if (drawn(l, se, i, 0)) dot(cr, px(l, se->x[i]), py(l, se->y[i]));
        cairo_fill(cr);
        double yx = cross_x(se, p->mark_x), xy = cross_y(se, p->mark_y);
        if (in_area(l, p->mark_x, yx)) square_marker(cr, px(l, p->mark_x), py(l, yx), col);
        if (in_area(l, xy, p->mark_y)) diamond_marker(cr, px(l, xy), py(l, p->mark_y), col);
    }
}

/* The legend, right of the plot: a row per series (its line, point and band), then the band's
 * meaning and the readings' markers. Rows close up when many; those that still do not fit are
 * counted in a last row. */
static void draw_legend(cairo_t *cr, const plot_desc *p, const layout *l) {
    int bands = 0;
    for (int s = 0; s < p->num_series; s++) bands |= p->series[s].lo && p->series[s].hi;
    int extra = (bands && p->band_label && *p->band_label) + shows_x(p, l) + shows_y(p, l);
    double top = AREA_Y0 + 10, room = FIG_H - 8 - top, gap = extra ? 10.0 : 0.0, pitch = 20.0;
    int shown = p->num_series;
    if ((shown + extra) * pitch + gap > room) pitch = fmax(11.0, (room - gap) / (shown + extra));
    if ((shown + extra) * pitch + gap > room) shown = (int)((room - gap) / pitch) - extra - 1;
    double font = fmin(12.0, pitch - 1.0), text_x = LEGEND_X + 30, max = FIG_W - 4 - text_x;
    cairo_set_font_size(cr, font);
    cairo_set_line_width(cr, 2.0);
    double y = top;
    for (int s = 0; s < shown; s++, y += pitch) {
        const uint8_t *col = palette[s % 10];
        if (p->series[s].lo && p->series[s].hi) {
            double h = fmin(10.0, pitch - 2.0);
            cairo_rectangle(cr, LEGEND_X, y - 0.5 * h, 24, h);
            colour(cr, col, 0.15);
            cairo_fill(cr);
        }
        colour(cr, col, 1.0);
        line(cr, LEGEND_X, y, LEGEND_X + 24, y);
        dot(cr, LEGEND_X + 12, y);
        cairo_fill(cr);
        colour(cr, black, 1.0);
        words(cr, text_x, y + font / 3.0, p->series[s].label, 0.0, max);
    }
    if (shown < p->num_series) {
        char more[64];
        snprintf(more, sizeof more, "and %d more", p->num_series - shown);
        colour(cr, grey, 1.0);
        words(cr, text_x, y + font / 3.0, more, 0.0, max);
        y += pitch;
    }
    y += gap;
    if (bands && p->band_label && *p->band_label) {
        cairo_rectangle(cr, LEGEND_X, y - 5, 24, 10);
        colour(cr, grey, 0.15);
        cairo_fill(cr);
        colour(cr, grey, 1.0);
        words(cr, text_x, y + font / 3.0, p->band_label, 0.0, max);
        y += pitch;
    }
    if (shows_x(p, l)) {
        square_marker(cr, LEGEND_X + 12.5, y + 0.5, grey);
        words(cr, text_x, y + font / 3.0, "equal time", 0.0, max);
        y += pitch;
    }
    if (shows_y(p, l)) {
        diamond_marker(cr, LEGEND_X + 12, y, grey);
        words(cr, text_x, y + font / 3.0, "equal error", 0.0, max);
    }
    cairo_set_font_size(cr, 12);
}

/* The figure, on any surface FIG_W x FIG_H. */
static cairo_status_t draw(cairo_surface_t *surface, const plot_desc *p) {
    layout l;
    layout_make(p, &l);
    cairo_t *cr = cairo_create(surface);
    colour(cr, white, 1.0);
    cairo_paint(cr);
    /* Unhinted text on both surfaces: the same glyph positions and widths in the SVG and the PNG,
     * whichever is drawn first (cairo shares fonts between surfaces). */
    cairo_font_options_t *fo = cairo_font_options_create();
    cairo_font_options_set_hint_style(fo, CAIRO_HINT_STYLE_NONE);
    cairo_font_options_set_hint_metrics(fo, CAIRO_HINT_METRICS_OFF);
    cairo_font_options_set_antialias(fo, CAIRO_ANTIALIAS_GRAY);
    cairo_set_font_options(cr, fo);
    cairo_font_options_destroy(fo);
    cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, 12);
    draw_axes(cr, p, &l);
    draw_readings(cr, p, &l);
    draw_series(cr, p, &l);
    draw_legend(cr, p, &l);
    cairo_status_t st = cairo_status(cr);
    cairo_destroy(cr);
    return st;
}

static int draw_failed(const char *path, cairo_status_t st, char *err, size_t errlen) {
    snprintf(err, errlen, "%s: cannot draw the plot: %s", path, cairo_status_to_string(st));
    return -1;
}

/* ---- the two outputs ---------------------------------------------------------------------------- */

typedef struct {
    unsigned char *data;
    size_t size, cap;
} membuf;

static cairo_status_t membuf_write(void *closure, const unsigned char *data, unsigned int n) {
    membuf *b = closure;
    if (n > b->cap - b->size) {
        size_t cap = b->cap ? b->cap : 1 << 16;
        while (cap - b->size < n) cap *= 2;
        unsigned char *q = realloc(b->data, cap);
        if (!q) return CAIRO_STATUS_WRITE_ERROR;
        b->data = q, b->cap = cap;
    }
    memcpy(b->data + b->size, data, n);
    b->size += n;
    return CAIRO_STATUS_SUCCESS;
}

int plot_save_svg(const plot_desc *p, const char *path, write_mode mode, char *err, size_t errlen) {
    /* cairo writes the document into memory; it goes out through the atomic writer. */
    membuf b = {0};
    cairo_surface_t *surface = cairo_svg_surface_create_for_stream(membuf_write, &b, FIG_W, FIG_H);
    cairo_svg_surface_set_document_unit(surface, CAIRO_SVG_UNIT_USER); /* width="860", as the PNG's pixels */
    cairo_status_t st = draw(surface, p);
    cairo_surface_finish(surface);
    if (st == CAIRO_STATUS_SUCCESS) st = cairo_surface_status(surface);
    cairo_surface_destroy(surface);
    int status = st == CAIRO_STATUS_SUCCESS ? write_file_atomic(path, b.data, b.size, mode, err, errlen)
                                            : draw_failed(path, st, err, errlen);
    free(b.data);
    return status;
}

int plot_save_png(const plot_desc *p, const char *path, write_mode mode, char *err, size_t errlen) {
    /* cairo draws into its own image surface (xRGB, 32 bits a pixel); its pixels go out through
     * png_save_rgb8, the atomic writer every glint export uses. */
    cairo_surface_t *surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, FIG_W, FIG_H);
    cairo_status_t st = draw(surface, p);
    cairo_surface_flush(surface);
    unsigned char *rgb = st == CAIRO_STATUS_SUCCESS ? malloc((size_t)FIG_W * FIG_H * 3) : NULL;
    if (!rgb) {
        cairo_surface_destroy(surface);
        return draw_failed(path, st != CAIRO_STATUS_SUCCESS ? st : CAIRO_STATUS_NO_MEMORY, err, errlen);
    }
    const unsigned char *data = cairo_image_surface_get_data(surface);
    int stride = cairo_image_surface_get_stride(surface);
    for (int y = 0; y < FIG_H; y++)
        for (int x = 0; x < FIG_W; x++) {
            uint32_t v;
            memcpy(&v, data + (size_t)y * (size_t)stride + 4 * (size_t)x, sizeof v);
            unsigned char *q = rgb + 3 * ((size_t)y * FIG_W + (size_t)x);
            q[0] = (unsigned char)(v >> 16), q[1] = (unsigned char)(v >> 8), q[2] = (unsigned char)v;
        }
    cairo_surface_destroy(surface);
    int status = png_save_rgb8(path, FIG_W, FIG_H, rgb, mode, err, errlen);
    free(rgb);
    return status;
}
