/* glint — line plots as SVG text and as PNG drawn by cairo, from one layout. */
#define _POSIX_C_SOURCE 200809L
#include "plot.h"

#include <cairo.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "metrics.h"

/* Geometry shared by both outputs: the figure, the plot area inside it, the legend to its right. */
enum { FIG_W = 860, FIG_H = 500, AREA_X0 = 80, AREA_X1 = 580, AREA_Y0 = 40, AREA_Y1 = 430, LEGEND_X = 600 };

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

/* The vertical reading's label goes right of its line, or left of it where it would run out of the
 * plot into the legend (the last budget often sits at the axis' end). 6 px a character: a little
 * more than sans-serif's average at 11 px, as the SVG cannot measure its text. */
static int mark_label_left(double X, const char *label) {
    return label && X + 4.0 + 6.0 * (double)strlen(label) > AREA_X1;
}

/* ---- SVG ------------------------------------------------------------------------------------- */

static void xml_text(FILE *f, const char *s) {
    for (; s && *s; s++) {
        if (*s == '<')
            fputs("&lt;", f);
        else if (*s == '>')
            fputs("&gt;", f);
        else if (*s == '&')
            fputs("&amp;", f);
        else if (*s == '"')
            fputs("&quot;", f);
        else
            fputc(*s, f);
    }
}

int plot_save_svg(const plot_desc *p, const char *path, write_mode mode, char *err, size_t errlen) {
    layout l;
    layout_make(p, &l);
    char *buf = NULL;
    size_t size = 0;
    FILE *f = open_memstream(&buf, &size);
    if (!f) {
        snprintf(err, errlen, "%s: out of memory", path);
        return -1;
    }
    fprintf(f,
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" viewBox=\"0 0 %d %d\" "
            "font-family=\"sans-serif\" font-size=\"12\">\n",
            FIG_W, FIG_H, FIG_W, FIG_H);
    fprintf(f, "<rect width=\"%d\" height=\"%d\" fill=\"white\"/>\n", FIG_W, FIG_H);
    /* grid and ticks */
    for (int k = 0; k < l.x.num_minor; k++) {
        double X = px(&l, pow(10.0, l.x.minor[k]));
        fprintf(f, "<line x1=\"%.1f\" y1=\"%d\" x2=\"%.1f\" y2=\"%d\" stroke=\"#f0f0f0\"/>\n", X, AREA_Y0, X, AREA_Y1);
    }
    for (int k = 0; k < l.y.num_minor; k++) {
        double Y = py(&l, pow(10.0, l.y.minor[k]));
        fprintf(f, "<line x1=\"%d\" y1=\"%.1f\" x2=\"%d\" y2=\"%.1f\" stroke=\"#f0f0f0\"/>\n", AREA_X0, Y, AREA_X1, Y);
    }
    char t[64];
    for (int k = 0; k < l.x.num_ticks; k++) {
        double X = px(&l, tick_value(&l.x, l.x.ticks[k]));
        tick_text(&l.x, l.x.ticks[k], t, sizeof t);
        fprintf(f, "<line x1=\"%.1f\" y1=\"%d\" x2=\"%.1f\" y2=\"%d\" stroke=\"#d8d8d8\"/>\n", X, AREA_Y0, X, AREA_Y1);
        fprintf(f, "<line x1=\"%.1f\" y1=\"%d\" x2=\"%.1f\" y2=\"%d\" stroke=\"black\"/>\n", X, AREA_Y1, X,
                AREA_Y1 + 5);
        fprintf(f, "<text x=\"%.1f\" y=\"%d\" text-anchor=\"middle\">%s</text>\n", X, AREA_Y1 + 19, t);
    }
    for (int k = 0; k < l.y.num_ticks; k++) {
        double Y = py(&l, tick_value(&l.y, l.y.ticks[k]));
        tick_text(&l.y, l.y.ticks[k], t, sizeof t);
        fprintf(f, "<line x1=\"%d\" y1=\"%.1f\" x2=\"%d\" y2=\"%.1f\" stroke=\"#d8d8d8\"/>\n", AREA_X0, Y, AREA_X1, Y);
        fprintf(f, "<line x1=\"%d\" y1=\"%.1f\" x2=\"%d\" y2=\"%.1f\" stroke=\"black\"/>\n", AREA_X0 - 5, Y, AREA_X0,
                Y);
        fprintf(f, "<text x=\"%d\" y=\"%.1f\" text-anchor=\"end\">%s</text>\n", AREA_X0 - 8, Y + 4, t);
    }
    fprintf(f, "<rect x=\"%d\" y=\"%d\" width=\"%d\" height=\"%d\" fill=\"none\" stroke=\"black\"/>\n", AREA_X0,
            AREA_Y0, AREA_X1 - AREA_X0, AREA_Y1 - AREA_Y0);
    fprintf(f, "<text x=\"%d\" y=\"%d\" text-anchor=\"middle\">", (AREA_X0 + AREA_X1) / 2, AREA_Y1 + 42);
    xml_text(f, p->x_label);
    fprintf(f, "</text>\n<text transform=\"translate(22 %d) rotate(-90)\" text-anchor=\"middle\">",
            (AREA_Y0 + AREA_Y1) / 2);
    xml_text(f, p->y_label);
    fprintf(f, "</text>\n<text x=\"%d\" y=\"24\" text-anchor=\"middle\" font-size=\"14\">", (AREA_X0 + AREA_X1) / 2);
    xml_text(f, p->title);
    fputs("</text>\n", f);

    /* the readings: dashed lines, labelled */
    if (in_area(&l, p->mark_x, tick_value(&l.y, l.y.lo))) {
        double X = px(&l, p->mark_x);
        fprintf(f, "<line x1=\"%.1f\" y1=\"%d\" x2=\"%.1f\" y2=\"%d\" stroke=\"#555\" stroke-dasharray=\"6 4\"/>\n", X,
                AREA_Y0, X, AREA_Y1);
        int left = mark_label_left(X, p->mark_x_label);
        fprintf(f, "<text x=\"%.1f\" y=\"%d\" font-size=\"11\" fill=\"#555\"%s>", left ? X - 4 : X + 4, AREA_Y0 + 12,
                left ? " text-anchor=\"end\"" : "");
        xml_text(f, p->mark_x_label);
        fputs("</text>\n", f);
    }
    if (in_area(&l, tick_value(&l.x, l.x.lo), p->mark_y)) {
        double Y = py(&l, p->mark_y);
        fprintf(f, "<line x1=\"%d\" y1=\"%.1f\" x2=\"%d\" y2=\"%.1f\" stroke=\"#555\" stroke-dasharray=\"2 3\"/>\n",
                AREA_X0, Y, AREA_X1, Y);
        fprintf(f, "<text x=\"%d\" y=\"%.1f\" font-size=\"11\" fill=\"#555\">", AREA_X0 + 4, Y - 4);
        xml_text(f, p->mark_y_label);
        fputs("</text>\n", f);
    }

    /* the bands first, under every curve */
    for (int s = 0; s < p->num_series; s++) {
        const plot_series *se = &p->series[s];
        if (!se->lo || !se->hi) continue;
        const uint8_t *c = palette[s % 10];
        fprintf(f, "<polygon fill=\"#%02x%02x%02x\" fill-opacity=\"0.15\" stroke=\"none\" points=\"", c[0], c[1], c[2]);
        for (int i = 0; i < se->n; i++)
            if (in_area(&l, se->x[i], se->lo[i]) && in_area(&l, se->x[i], se->hi[i]))
                fprintf(f, "%.1f,%.1f ", px(&l, se->x[i]), py(&l, se->lo[i]));
        for (int i = se->n - 1; i >= 0; i--)
            if (in_area(&l, se->x[i], se->lo[i]) && in_area(&l, se->x[i], se->hi[i]))
                fprintf(f, "%.1f,%.1f ", px(&l, se->x[i]), py(&l, se->hi[i]));
        fputs("\"/>\n", f);
    }
    for (int s = 0; s < p->num_series; s++) {
        const plot_series *se = &p->series[s];
        const uint8_t *c = palette[s % 10];
        char col[16];
        snprintf(col, sizeof col, "#%02x%02x%02x", c[0], c[1], c[2]);
        fprintf(f, "<polyline fill=\"none\" stroke=\"%s\" stroke-width=\"2\" points=\"", col);
        for (int i = 0; i < se->n; i++)
            if (in_area(&l, se->x[i], se->y[i])) fprintf(f, "%.1f,%.1f ", px(&l, se->x[i]), py(&l, se->y[i]));
        fputs("\"/>\n", f);
        for (int i = 0; i < se->n; i++)
            if (in_area(&l, se->x[i], se->y[i]))
                fprintf(f, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"3\" fill=\"%s\"/>\n", px(&l, se->x[i]),
                        py(&l, se->y[i]), col);
        double yx = cross_x(se, p->mark_x), xy = cross_y(se, p->mark_y);
        if (in_area(&l, p->mark_x, yx))
            fprintf(f,
                    "<rect x=\"%.1f\" y=\"%.1f\" width=\"9\" height=\"9\" fill=\"white\" stroke=\"%s\" "
                    "stroke-width=\"2\"/>\n",
                    px(&l, p->mark_x) - 4.5, py(&l, yx) - 4.5, col);
        if (in_area(&l, xy, p->mark_y)) {
            double X = px(&l, xy), Y = py(&l, p->mark_y);
            fprintf(f,
                    "<polygon points=\"%.1f,%.1f %.1f,%.1f %.1f,%.1f %.1f,%.1f\" fill=\"white\" stroke=\"%s\" "
                    "stroke-width=\"2\"/>\n",
                    X, Y - 6, X + 6, Y, X, Y + 6, X - 6, Y, col);
        }
        /* legend entry */
        int ly = AREA_Y0 + 10 + 20 * s;
        fprintf(f, "<line x1=\"%d\" y1=\"%d\" x2=\"%d\" y2=\"%d\" stroke=\"%s\" stroke-width=\"2\"/>", LEGEND_X, ly,
                LEGEND_X + 24, ly, col);
        fprintf(f, "<circle cx=\"%d\" cy=\"%d\" r=\"3\" fill=\"%s\"/>", LEGEND_X + 12, ly, col);
        fprintf(f, "<text x=\"%d\" y=\"%d\">", LEGEND_X + 30, ly + 4);
        xml_text(f, se->label);
        fputs("</text>\n", f);
    }
    int ly = AREA_Y0 + 10 + 20 * p->num_series + 10;
    if (isfinite(p->mark_x))
        fprintf(f,
                "<rect x=\"%d\" y=\"%d\" width=\"9\" height=\"9\" fill=\"white\" stroke=\"#555\" stroke-width=\"2\"/>"
                "<text x=\"%d\" y=\"%d\" fill=\"#555\">equal time</text>\n",
                LEGEND_X + 8, ly - 4, LEGEND_X + 30, ly + 4),
            ly += 20;
    if (isfinite(p->mark_y))
        fprintf(f,
                "<polygon points=\"%d,%d %d,%d %d,%d %d,%d\" fill=\"white\" stroke=\"#555\" stroke-width=\"2\"/>"
                "<text x=\"%d\" y=\"%d\" fill=\"#555\">equal error</text>\n",
                LEGEND_X + 12, ly - 6, LEGEND_X + 18, ly, LEGEND_X + 12, ly + 6, LEGEND_X + 6, ly, LEGEND_X + 30,
                ly + 4);
    fputs("</svg>\n", f);
    fclose(f);
    int status = write_file_atomic(path, buf, size, mode, err, errlen);
    free(buf);
    return status;
}

/* ---- PNG: the same figure drawn by cairo ------------------------------------------------------ */

#define TAU 6.28318530717958647692 /* a full turn, for cairo_arc */

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

/* Text with its baseline at y, starting at x (align 0), centred on it (0.5) or ending there (1). */
static void words(cairo_t *cr, double x, double y, const char *s, double align) {
    if (!s || !*s) return;
    cairo_text_extents_t e;
    cairo_text_extents(cr, s, &e);
    cairo_move_to(cr, x - align * e.x_advance, y);
    cairo_show_text(cr, s);
}

static void square_marker(cairo_t *cr, double cx, double cy, const uint8_t col[3]) {
    static const uint8_t white[3] = {255, 255, 255};
    cairo_rectangle(cr, cx - 4.5, cy - 4.5, 9, 9);
    colour(cr, white, 1.0);
    cairo_fill_preserve(cr);
    colour(cr, col, 1.0);
    cairo_stroke(cr);
}

static void diamond_marker(cairo_t *cr, double cx, double cy, const uint8_t col[3]) {
    static const uint8_t white[3] = {255, 255, 255};
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

/* The SVG's figure, element for element at its coordinates and sizes. */
static void draw(cairo_t *cr, const plot_desc *p, const layout *l) {
    static const uint8_t white[3] = {255, 255, 255}, minor[3] = {240, 240, 240}, grid[3] = {216, 216, 216},
                         black[3] = {0, 0, 0}, grey[3] = {85, 85, 85};
    colour(cr, white, 1.0);
    cairo_paint(cr);
    cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, 12);
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
    char t[64];
    for (int k = 0; k < l->x.num_ticks; k++) {
        double X = crisp(px(l, tick_value(&l->x, l->x.ticks[k])));
        colour(cr, grid, 1.0);
        line(cr, X, AREA_Y0, X, AREA_Y1);
        colour(cr, black, 1.0);
        line(cr, X, AREA_Y1, X, AREA_Y1 + 5);
        tick_text(&l->x, l->x.ticks[k], t, sizeof t);
        words(cr, X, AREA_Y1 + 19, t, 0.5);
    }
    for (int k = 0; k < l->y.num_ticks; k++) {
        double Y = crisp(py(l, tick_value(&l->y, l->y.ticks[k])));
        colour(cr, grid, 1.0);
        line(cr, AREA_X0, Y, AREA_X1, Y);
        colour(cr, black, 1.0);
        line(cr, AREA_X0 - 5, Y, AREA_X0, Y);
        tick_text(&l->y, l->y.ticks[k], t, sizeof t);
        words(cr, AREA_X0 - 8, Y + 4, t, 1.0);
    }
    cairo_rectangle(cr, AREA_X0 + 0.5, AREA_Y0 + 0.5, AREA_X1 - AREA_X0, AREA_Y1 - AREA_Y0);
    cairo_stroke(cr);
    words(cr, (AREA_X0 + AREA_X1) / 2, AREA_Y1 + 42, p->x_label, 0.5);
    cairo_save(cr);
    cairo_translate(cr, 22, (AREA_Y0 + AREA_Y1) / 2);
    cairo_rotate(cr, -0.25 * TAU);
    words(cr, 0, 0, p->y_label, 0.5);
    cairo_restore(cr);
    cairo_set_font_size(cr, 14);
    words(cr, (AREA_X0 + AREA_X1) / 2, 24, p->title, 0.5);

    /* the readings: dashed lines, labelled */
    cairo_set_font_size(cr, 11);
    colour(cr, grey, 1.0);
    if (in_area(l, p->mark_x, tick_value(&l->y, l->y.lo))) {
        double X = crisp(px(l, p->mark_x)), dash[2] = {6, 4};
        cairo_set_dash(cr, dash, 2, 0);
        line(cr, X, AREA_Y0, X, AREA_Y1);
        int left = mark_label_left(X, p->mark_x_label);
        words(cr, left ? X - 4 : X + 4, AREA_Y0 + 12, p->mark_x_label, left ? 1.0 : 0.0);
    }
    if (in_area(l, tick_value(&l->x, l->x.lo), p->mark_y)) {
        double Y = crisp(py(l, p->mark_y)), dash[2] = {2, 3};
        cairo_set_dash(cr, dash, 2, 0);
        line(cr, AREA_X0, Y, AREA_X1, Y);
        words(cr, AREA_X0 + 4, Y - 4, p->mark_y_label, 0.0);
    }
    cairo_set_dash(cr, NULL, 0, 0);
    cairo_set_font_size(cr, 12);

    /* the bands first, under every curve */
    for (int s = 0; s < p->num_series; s++) {
        const plot_series *se = &p->series[s];
        if (!se->lo || !se->hi) continue;
        cairo_new_path(cr); /* cairo_show_text leaves a current point, which the path would start at */
        for (int i = 0; i < se->n; i++)
            if (in_area(l, se->x[i], se->lo[i]) && in_area(l, se->x[i], se->hi[i]))
                cairo_line_to(cr, px(l, se->x[i]), py(l, se->lo[i]));
        for (int i = se->n - 1; i >= 0; i--)
            if (in_area(l, se->x[i], se->lo[i]) && in_area(l, se->x[i], se->hi[i]))
                cairo_line_to(cr, px(l, se->x[i]), py(l, se->hi[i]));
        colour(cr, palette[s % 10], 0.15);
        cairo_fill(cr);
    }
    cairo_set_line_width(cr, 2.0);
    cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
    for (int s = 0; s < p->num_series; s++) {
        const plot_series *se = &p->series[s];
        const uint8_t *col = palette[s % 10];
        colour(cr, col, 1.0);
        cairo_new_path(cr);
        for (int i = 0; i < se->n; i++)
            if (in_area(l, se->x[i], se->y[i])) cairo_line_to(cr, px(l, se->x[i]), py(l, se->y[i]));
        cairo_stroke(cr);
        for (int i = 0; i < se->n; i++)
            if (in_area(l, se->x[i], se->y[i])) {
                cairo_new_sub_path(cr);
                cairo_arc(cr, px(l, se->x[i]), py(l, se->y[i]), 3.0, 0.0, TAU);
            }
        cairo_fill(cr);
        double yx = cross_x(se, p->mark_x), xy = cross_y(se, p->mark_y);
        if (in_area(l, p->mark_x, yx)) square_marker(cr, px(l, p->mark_x), py(l, yx), col);
        if (in_area(l, xy, p->mark_y)) diamond_marker(cr, px(l, xy), py(l, p->mark_y), col);
        /* legend entry */
        int ly = AREA_Y0 + 10 + 20 * s;
        colour(cr, col, 1.0);
        line(cr, LEGEND_X, ly, LEGEND_X + 24, ly);
        cairo_arc(cr, LEGEND_X + 12, ly, 3.0, 0.0, TAU);
        cairo_fill(cr);
        colour(cr, black, 1.0);
        words(cr, LEGEND_X + 30, ly + 4, se->label, 0.0);
    }
    int ly = AREA_Y0 + 10 + 20 * p->num_series + 10;
    if (isfinite(p->mark_x)) {
        square_marker(cr, LEGEND_X + 12.5, ly + 0.5, grey);
        words(cr, LEGEND_X + 30, ly + 4, "equal time", 0.0);
        ly += 20;
    }
    if (isfinite(p->mark_y)) {
        diamond_marker(cr, LEGEND_X + 12, ly, grey);
        words(cr, LEGEND_X + 30, ly + 4, "equal error", 0.0);
    }
}

int plot_save_png(const plot_desc *p, const char *path, write_mode mode, char *err, size_t errlen) {
    layout l;
    layout_make(p, &l);
    /* cairo draws into its own image surface (xRGB, 32 bits a pixel); its pixels go out through
     * png_save_rgb8, the atomic writer every glint export uses. */
    cairo_surface_t *surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, FIG_W, FIG_H);
    cairo_t *cr = cairo_create(surface);
    draw(cr, p, &l);
    cairo_status_t st = cairo_status(cr);
    cairo_destroy(cr);
    cairo_surface_flush(surface);
    unsigned char *rgb = st == CAIRO_STATUS_SUCCESS ? malloc((size_t)FIG_W * FIG_H * 3) : NULL;
    if (!rgb) {
        cairo_surface_destroy(surface);
        snprintf(err, errlen, "%s: cannot draw the plot: %s", path,
                 cairo_status_to_string(st != CAIRO_STATUS_SUCCESS ? st : CAIRO_STATUS_NO_MEMORY));
        return -1;
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
