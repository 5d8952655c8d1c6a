/* glint — line plots as SVG and as rasterised PNG, from one layout. */
#define _POSIX_C_SOURCE 200809L
#include "plot.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "metrics.h"

/* Geometry shared by both outputs: the figure, the plot area inside it, the legend to its right. */
enum { FIG_W = 860, FIG_H = 500, AREA_X0 = 80, AREA_X1 = 580, AREA_Y0 = 40, AREA_Y1 = 430, LEGEND_X = 600 };

/* Tableau 10: distinct on white, and for the common kinds of colour blindness. */
static const uint8_t palette[10][3] = {{31, 119, 180}, {255, 127, 14}, {44, 160, 44},  {214, 39, 40},
                                       {148, 103, 189}, {140, 86, 75}, {227, 119, 194}, {127, 127, 127},
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
                if ((m == 1 || (few && (m == 2 || m == 5))) && a->num_ticks < 64) a->ticks[a->num_ticks++] = t;
                else if (a->num_minor < 256) a->minor[a->num_minor++] = t;
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
        if (raw / mag > 5.0) step = 10.0 * mag;
        else if (raw / mag > 2.0) step = 5.0 * mag;
        else if (raw / mag > 1.0) step = 2.0 * mag;
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

/* ---- SVG ------------------------------------------------------------------------------------- */

static void xml_text(FILE *f, const char *s) {
    for (; s && *s; s++) {
        if (*s == '<') fputs("&lt;", f);
        else if (*s == '>') fputs("&gt;", f);
        else if (*s == '&') fputs("&amp;", f);
        else if (*s == '"') fputs("&quot;", f);
        else fputc(*s, f);
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
    fprintf(f, "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" viewBox=\"0 0 %d %d\" "
               "font-family=\"sans-serif\" font-size=\"12\">\n", FIG_W, FIG_H, FIG_W, FIG_H);
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
        fprintf(f, "<line x1=\"%.1f\" y1=\"%d\" x2=\"%.1f\" y2=\"%d\" stroke=\"black\"/>\n", X, AREA_Y1, X, AREA_Y1 + 5);
        fprintf(f, "<text x=\"%.1f\" y=\"%d\" text-anchor=\"middle\">%s</text>\n", X, AREA_Y1 + 19, t);
    }
    for (int k = 0; k < l.y.num_ticks; k++) {
        double Y = py(&l, tick_value(&l.y, l.y.ticks[k]));
        tick_text(&l.y, l.y.ticks[k], t, sizeof t);
        fprintf(f, "<line x1=\"%d\" y1=\"%.1f\" x2=\"%d\" y2=\"%.1f\" stroke=\"#d8d8d8\"/>\n", AREA_X0, Y, AREA_X1, Y);
        fprintf(f, "<line x1=\"%d\" y1=\"%.1f\" x2=\"%d\" y2=\"%.1f\" stroke=\"black\"/>\n", AREA_X0 - 5, Y, AREA_X0, Y);
        fprintf(f, "<text x=\"%d\" y=\"%.1f\" text-anchor=\"end\">%s</text>\n", AREA_X0 - 8, Y + 4, t);
    }
    fprintf(f, "<rect x=\"%d\" y=\"%d\" width=\"%d\" height=\"%d\" fill=\"none\" stroke=\"black\"/>\n", AREA_X0,
            AREA_Y0, AREA_X1 - AREA_X0, AREA_Y1 - AREA_Y0);
    fprintf(f, "<text x=\"%d\" y=\"%d\" text-anchor=\"middle\">", (AREA_X0 + AREA_X1) / 2, AREA_Y1 + 42);
    xml_text(f, p->x_label);
    fprintf(f, "</text>\n<text transform=\"translate(22 %d) rotate(-90)\" text-anchor=\"middle\">", (AREA_Y0 + AREA_Y1) / 2);
    xml_text(f, p->y_label);
    fprintf(f, "</text>\n<text x=\"%d\" y=\"24\" text-anchor=\"middle\" font-size=\"14\">", (AREA_X0 + AREA_X1) / 2);
    xml_text(f, p->title);
    fputs("</text>\n", f);

    /* the readings: dashed lines, labelled */
    if (in_area(&l, p->mark_x, tick_value(&l.y, l.y.lo))) {
        double X = px(&l, p->mark_x);
        fprintf(f, "<line x1=\"%.1f\" y1=\"%d\" x2=\"%.1f\" y2=\"%d\" stroke=\"#555\" stroke-dasharray=\"6 4\"/>\n", X,
                AREA_Y0, X, AREA_Y1);
        fprintf(f, "<text x=\"%.1f\" y=\"%d\" font-size=\"11\" fill=\"#555\">", X + 4, AREA_Y0 + 12);
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
                fprintf(f, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"3\" fill=\"%s\"/>\n", px(&l, se->x[i]), py(&l, se->y[i]),
                        col);
        double yx = cross_x(se, p->mark_x), xy = cross_y(se, p->mark_y);
        if (in_area(&l, p->mark_x, yx))
            fprintf(f, "<rect x=\"%.1f\" y=\"%.1f\" width=\"9\" height=\"9\" fill=\"white\" stroke=\"%s\" "
                       "stroke-width=\"2\"/>\n", px(&l, p->mark_x) - 4.5, py(&l, yx) - 4.5, col);
        if (in_area(&l, xy, p->mark_y)) {
            double X = px(&l, xy), Y = py(&l, p->mark_y);
            fprintf(f, "<polygon points=\"%.1f,%.1f %.1f,%.1f %.1f,%.1f %.1f,%.1f\" fill=\"white\" stroke=\"%s\" "
                       "stroke-width=\"2\"/>\n", X, Y - 6, X + 6, Y, X, Y + 6, X - 6, Y, col);
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
        fprintf(f, "<rect x=\"%d\" y=\"%d\" width=\"9\" height=\"9\" fill=\"white\" stroke=\"#555\" stroke-width=\"2\"/>"
                   "<text x=\"%d\" y=\"%d\" fill=\"#555\">equal time</text>\n", LEGEND_X + 8, ly - 4, LEGEND_X + 30, ly + 4),
            ly += 20;
    if (isfinite(p->mark_y))
        fprintf(f, "<polygon points=\"%d,%d %d,%d %d,%d %d,%d\" fill=\"white\" stroke=\"#555\" stroke-width=\"2\"/>"
                   "<text x=\"%d\" y=\"%d\" fill=\"#555\">equal error</text>\n", LEGEND_X + 12, ly - 6, LEGEND_X + 18, ly,
                LEGEND_X + 12, ly + 6, LEGEND_X + 6, ly, LEGEND_X + 30, ly + 4);
    fputs("</svg>\n", f);
    fclose(f);
    int status = write_file_atomic(path, buf, size, mode, err, errlen);
    free(buf);
    return status;
}

/* ---- PNG: a small anti-aliased rasteriser ------------------------------------------------------ */

typedef struct {
    uint8_t *px;
    int w, h;
} canvas;

static void blend(canvas *c, int x, int y, const uint8_t col[3], double a) {
    if (x < 0 || y < 0 || x >= c->w || y >= c->h || !(a > 0.0)) return;
    if (a > 1.0) a = 1.0;
    uint8_t *q = c->px + 3 * ((size_t)y * (size_t)c->w + (size_t)x);
    for (int k = 0; k < 3; k++) q[k] = (uint8_t)lround((double)q[k] + a * ((double)col[k] - (double)q[k]));
}

/* A segment of width w: each pixel covered by its distance to the segment (1 px of ramp). */
static void seg(canvas *c, double x0, double y0, double x1, double y1, double w, const uint8_t col[3]) {
    double r = 0.5 * w + 1.0;
    int xa = (int)floor(fmin(x0, x1) - r), xb = (int)ceil(fmax(x0, x1) + r);
    int ya = (int)floor(fmin(y0, y1) - r), yb = (int)ceil(fmax(y0, y1) + r);
    double dx = x1 - x0, dy = y1 - y0, len2 = dx * dx + dy * dy;
    for (int y = ya; y <= yb; y++)
        for (int x = xa; x <= xb; x++) {
            double qx = x + 0.5 - x0, qy = y + 0.5 - y0;
            double t = len2 > 0.0 ? fmin(fmax((qx * dx + qy * dy) / len2, 0.0), 1.0) : 0.0;
            double ex = qx - t * dx, ey = qy - t * dy;
            blend(c, x, y, col, 0.5 * w + 0.5 - sqrt(ex * ex + ey * ey));
        }
}

static void dashed(canvas *c, double x0, double y0, double x1, double y1, double on, double off, const uint8_t col[3]) {
    double len = hypot(x1 - x0, y1 - y0);
    for (double s = 0.0; s < len; s += on + off) {
        double e = fmin(s + on, len);
        seg(c, x0 + (x1 - x0) * s / len, y0 + (y1 - y0) * s / len, x0 + (x1 - x0) * e / len, y0 + (y1 - y0) * e / len,
            1.0, col);
    }
}

static void disc(canvas *c, double cx, double cy, double r, const uint8_t col[3]) {
    for (int y = (int)floor(cy - r - 1); y <= (int)ceil(cy + r + 1); y++)
        for (int x = (int)floor(cx - r - 1); x <= (int)ceil(cx + r + 1); x++)
            blend(c, x, y, col, r + 0.5 - hypot(x + 0.5 - cx, y + 0.5 - cy));
}

static void square(canvas *c, double cx, double cy, double h, const uint8_t col[3]) {
    static const uint8_t white[3] = {255, 255, 255};
    for (int y = (int)lround(cy - h); y < (int)lround(cy + h); y++)
        for (int x = (int)lround(cx - h); x < (int)lround(cx + h); x++) blend(c, x, y, white, 1.0);
    seg(c, cx - h, cy - h, cx + h, cy - h, 2.0, col);
    seg(c, cx + h, cy - h, cx + h, cy + h, 2.0, col);
    seg(c, cx + h, cy + h, cx - h, cy + h, 2.0, col);
    seg(c, cx - h, cy + h, cx - h, cy - h, 2.0, col);
}

static void diamond(canvas *c, double cx, double cy, double h, const uint8_t col[3]) {
    static const uint8_t white[3] = {255, 255, 255};
    for (int y = (int)floor(cy - h); y <= (int)ceil(cy + h); y++)
        for (int x = (int)floor(cx - h); x <= (int)ceil(cx + h); x++)
            if (fabs(x + 0.5 - cx) + fabs(y + 0.5 - cy) < h) blend(c, x, y, white, 1.0);
    seg(c, cx, cy - h, cx + h, cy, 2.0, col);
    seg(c, cx + h, cy, cx, cy + h, 2.0, col);
    seg(c, cx, cy + h, cx - h, cy, 2.0, col);
    seg(c, cx - h, cy, cx, cy - h, 2.0, col);
}

/* Tick labels only: digits and the few signs %g prints, 3x5 cells drawn 2x. */
static const char glyph_chars[] = "0123456789.-+e";
static const uint8_t glyphs[][5] = {
    {7, 5, 5, 5, 7}, {2, 6, 2, 2, 7}, {7, 1, 7, 4, 7}, {7, 1, 7, 1, 7}, {5, 5, 7, 1, 1}, {7, 4, 7, 1, 7}, {7, 4, 7, 5, 7},
    {7, 1, 1, 1, 1}, {7, 5, 7, 5, 7}, {7, 5, 7, 1, 7}, {0, 0, 0, 0, 2}, {0, 0, 7, 0, 0}, {0, 2, 7, 2, 0}, {0, 7, 7, 4, 7}};

static void text(canvas *c, double x, double y, const char *s, int align_right_or_centre) {
    static const uint8_t ink[3] = {40, 40, 40};
    int width = 8 * (int)strlen(s) - 2;
    int x0 = (int)lround(align_right_or_centre > 0 ? x - width : align_right_or_centre < 0 ? x - width / 2 : x);
    int y0 = (int)lround(y - 5);
    for (const char *p = s; *p; p++, x0 += 8) {
        const char *g = strchr(glyph_chars, *p);
        if (!g || !*p) continue;
        const uint8_t *rows = glyphs[g - glyph_chars];
        for (int r = 0; r < 5; r++)
            for (int b = 0; b < 3; b++)
                if (rows[r] & (4 >> b))
                    for (int dy = 0; dy < 2; dy++)
                        for (int dx = 0; dx < 2; dx++) blend(c, x0 + 2 * b + dx, y0 + 2 * r + dy, ink, 1.0);
    }
}

int plot_save_png(const plot_desc *p, const char *path, write_mode mode, char *err, size_t errlen) {
    layout l;
    layout_make(p, &l);
    canvas c = {malloc((size_t)FIG_W * FIG_H * 3), FIG_W, FIG_H};
    if (!c.px) {
        snprintf(err, errlen, "%s: out of memory", path);
        return -1;
    }
    memset(c.px, 255, (size_t)FIG_W * FIG_H * 3);
    static const uint8_t minor[3] = {240, 240, 240}, grid[3] = {216, 216, 216}, black[3] = {0, 0, 0},
                         grey[3] = {85, 85, 85};
    for (int k = 0; k < l.x.num_minor; k++) {
        double X = px(&l, pow(10.0, l.x.minor[k]));
        seg(&c, X, AREA_Y0, X, AREA_Y1, 1.0, minor);
    }
    for (int k = 0; k < l.y.num_minor; k++) {
        double Y = py(&l, pow(10.0, l.y.minor[k]));
        seg(&c, AREA_X0, Y, AREA_X1, Y, 1.0, minor);
    }
    char t[64];
    for (int k = 0; k < l.x.num_ticks; k++) {
        double X = px(&l, tick_value(&l.x, l.x.ticks[k]));
        seg(&c, X, AREA_Y0, X, AREA_Y1, 1.0, grid);
        seg(&c, X, AREA_Y1, X, AREA_Y1 + 5, 1.0, black);
        tick_text(&l.x, l.x.ticks[k], t, sizeof t);
        text(&c, X, AREA_Y1 + 16, t, -1);
    }
    for (int k = 0; k < l.y.num_ticks; k++) {
        double Y = py(&l, tick_value(&l.y, l.y.ticks[k]));
        seg(&c, AREA_X0, Y, AREA_X1, Y, 1.0, grid);
        seg(&c, AREA_X0 - 5, Y, AREA_X0, Y, 1.0, black);
        tick_text(&l.y, l.y.ticks[k], t, sizeof t);
        text(&c, AREA_X0 - 9, Y, t, 1);
    }
    seg(&c, AREA_X0, AREA_Y0, AREA_X1, AREA_Y0, 1.0, black);
    seg(&c, AREA_X1, AREA_Y0, AREA_X1, AREA_Y1, 1.0, black);
    seg(&c, AREA_X1, AREA_Y1, AREA_X0, AREA_Y1, 1.0, black);
    seg(&c, AREA_X0, AREA_Y1, AREA_X0, AREA_Y0, 1.0, black);
    if (in_area(&l, p->mark_x, tick_value(&l.y, l.y.lo)))
        dashed(&c, px(&l, p->mark_x), AREA_Y0, px(&l, p->mark_x), AREA_Y1, 6, 4, grey);
    if (in_area(&l, tick_value(&l.x, l.x.lo), p->mark_y))
        dashed(&c, AREA_X0, py(&l, p->mark_y), AREA_X1, py(&l, p->mark_y), 2, 3, grey);
    for (int s = 0; s < p->num_series; s++) {
        const plot_series *se = &p->series[s];
        const uint8_t *col = palette[s % 10];
        double lx = NAN, ly = NAN;
        for (int i = 0; i < se->n; i++) {
            if (!in_area(&l, se->x[i], se->y[i])) continue;
            double X = px(&l, se->x[i]), Y = py(&l, se->y[i]);
            if (isfinite(lx)) seg(&c, lx, ly, X, Y, 2.0, col);
            lx = X, ly = Y;
        }
        for (int i = 0; i < se->n; i++)
            if (in_area(&l, se->x[i], se->y[i])) disc(&c, px(&l, se->x[i]), py(&l, se->y[i]), 3.0, col);
        double yx = cross_x(se, p->mark_x), xy = cross_y(se, p->mark_y);
        if (in_area(&l, p->mark_x, yx)) square(&c, px(&l, p->mark_x), py(&l, yx), 4.5, col);
        if (in_area(&l, xy, p->mark_y)) diamond(&c, px(&l, xy), py(&l, p->mark_y), 6.0, col);
        /* legend swatch, in the SVG's order (the PNG has no words) */
        int y = AREA_Y0 + 10 + 20 * s;
        seg(&c, LEGEND_X, y, LEGEND_X + 24, y, 2.0, col);
        disc(&c, LEGEND_X + 12, y, 3.0, col);
        snprintf(t, sizeof t, "%d", s + 1);
        text(&c, LEGEND_X + 32, y, t, 0);
    }
    int status = png_save_rgb8(path, FIG_W, FIG_H, c.px, mode, err, errlen);
    free(c.px);
    return status;
}
