/* glint tests — the bench's plots (app/bench/plot.c, compiled in): one description saved as SVG and as
 * PNG. The PNG is decoded and the SVG read as XML (well-formed, the figure's size, its paths and
 * glyphs); where the data must land is computed here from the axes' ranges, independently of the
 * plot's code. Both files show each series in one colour at its points, the legend's swatches in
 * that colour, the title, axis titles with units and tick labels; NaN, infinite, zero and negative
 * values on log axes draw nothing outside the plot area; many series fit the legend; existing
 * files are replaced only when asked. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include <stb_image.h>

#include "check.h"
#include "plot.h"
#include "scratch.h"
#include "svg_read.h"

enum { W = PLOT_WIDTH, H = PLOT_HEIGHT, X0 = PLOT_AREA_X0, X1 = PLOT_AREA_X1, Y0 = PLOT_AREA_Y0, Y1 = PLOT_AREA_Y1 };
enum { LEGEND_X = PLOT_LEGEND_X, ROW0 = PLOT_AREA_Y0 + 10, ROW = 20 }; /* legend rows at 50, 70, ... */

/* ---- the PNG ---------------------------------------------------------------------------------- */

typedef struct {
    unsigned char *rgb;
    int w, h;
} image;

static image load_png(const char *path) {
    image im = {0};
    int c;
    im.rgb = stbi_load(path, &im.w, &im.h, &c, 3);
    return im;
}

static const unsigned char *at(const image *im, int x, int y) { return im->rgb + 3 * ((size_t)y * im->w + x); }

static int near_rgb(const unsigned char *q, const double c[3], double tol) {
    return fabs(q[0] - c[0]) <= tol && fabs(q[1] - c[1]) <= tol && fabs(q[2] - c[2]) <= tol;
}

/* A strong colour: not white, grey or black (text, grid, frame). */
static int saturated(const unsigned char *q) {
    int lo = q[0] < q[1] ? q[0] : q[1], hi = q[0] > q[1] ? q[0] : q[1];
    lo = q[2] < lo ? q[2] : lo, hi = q[2] > hi ? q[2] : hi;
    return hi - lo > 60;
}

/* Width and height of the dark pixels (text, frame, ticks) in [x0, x1) x [y0, y1). */
static void ink(const image *im, int x0, int y0, int x1, int y1, int *iw, int *ih) {
    int lx = x1, hx = x0 - 1, ly = y1, hy = y0 - 1;
    for (int y = y0 < 0 ? 0 : y0; y < y1 && y < im->h; y++)
        for (int x = x0 < 0 ? 0 : x0; x < x1 && x < im->w; x++) {
            const unsigned char *q = at(im, x, y);
            if (q[0] < 150 && q[1] < 150 && q[2] < 150)
                lx = x < lx ? x : lx, hx = x > hx ? x : hx, ly = y < ly ? y : ly, hy = y > hy ? y : hy;
        }
    *iw = hx >= lx ? hx - lx + 1 : 0;
    *ih = hy >= ly ? hy - ly + 1 : 0;
}

/* Pixels of colour c (within tol) outside the plot area grown by margin and left of the legend. */
static int stray_pixels(const image *im, const double c[3], double tol, int margin) {
    int n = 0;
    for (int y = 0; y < im->h; y++)
        for (int x = 0; x < LEGEND_X - 2 && x < im->w; x++) {
            int inside = x >= X0 - margin && x <= X1 + margin && y >= Y0 - margin && y <= Y1 + margin;
            if (!inside && near_rgb(at(im, x, y), c, tol) && saturated(at(im, x, y))) n++;
        }
    return n;
}

static char *read_text(const char *path) {
    size_t size = 0;
    unsigned char *b = get_file(path, &size);
    char *s = b ? realloc(b, size + 1) : NULL;
    if (s) s[size] = 0;
    if (!s) free(b);
    return s;
}

/* ---- the checks ------------------------------------------------------------------------------- */

static char png_path[1400], svg_path_name[1400];

/* Saves p as NAME.svg and NAME.png in the scratch directory (replacing); 0 when both were written. */
static int save_both(const plot_desc *p, const char *name) {
    char err[1600], file[256];
    snprintf(file, sizeof file, "%s.svg", name);
    path_in(svg_path_name, sizeof svg_path_name, file);
    int a = plot_save_svg(p, svg_path_name, WRITE_REPLACE, err, sizeof err);
    CHECK(a == 0, "%s: %s", file, err);
    snprintf(file, sizeof file, "%s.png", name);
    path_in(png_path, sizeof png_path, file);
    int b = plot_save_png(p, png_path, WRITE_REPLACE, err, sizeof err);
    CHECK(b == 0, "%s: %s", file, err);
    return a || b ? -1 : 0;
}

/* The SVG just saved, checked to be well-formed and of the figure's size, read into dr. */
static int load_svg(drawing *dr) {
    char *text = read_text(svg_path_name);
    CHECK(text != NULL, "%s: unreadable", svg_path_name);
    if (!text) return -1;
    const char *problem = xml_problem(text);
    CHECK(problem == NULL, "%s is not well-formed XML: %s", svg_path_name, problem);
    read_drawing(text, dr);
    free(text);
    /* In user units (pixels), the PNG's size: not points or millimetres. */
    char size[160];
    snprintf(size, sizeof size, "%s %s %s", dr->width, dr->height, dr->view_box);
    CHECK(strcmp(size, "860 500 0 0 860 500") == 0 || strcmp(size, "860px 500px 0 0 860 500") == 0,
          "the SVG's width, height and viewBox are '%s', not the figure's %dx%d", size, W, H);
    for (int i = 0; i < dr->num_paths; i++) {
        const path_points *pp = &dr->path[i].pts;
        CHECK(!pp->bad, "an SVG path with commands other than M L C Z, or too long");
        for (int k = 0; k < pp->n; k++)
            CHECK(pp->x[k] >= -1 && pp->x[k] <= W + 1 && pp->y[k] >= -1 && pp->y[k] <= H + 1,
                  "an SVG path point (%g, %g) outside the figure", pp->x[k], pp->y[k]);
    }
    return 0;
}

static image load_checked_png(void) {
    image im = load_png(png_path);
    CHECK(im.rgb && im.w == W && im.h == H, "%s: %dx%d, not the figure's %dx%d", png_path, im.w, im.h, W, H);
    if (im.rgb && (im.w != W || im.h != H)) stbi_image_free(im.rgb), im.rgb = NULL;
    return im;
}

/* The colour of legend row k's swatch (its point, at the line's middle). */
static void legend_colour(const image *im, int k, double c[3]) {
    const unsigned char *q = at(im, LEGEND_X + 12, ROW0 + ROW * k);
    c[0] = q[0], c[1] = q[1], c[2] = q[2];
}

/* Any pixel within r of (x, y) within tol of c. */
static int colour_near(const image *im, double x, double y, const double c[3], double tol, int r) {
    for (int dy = -r; dy <= r; dy++)
        for (int dx = -r; dx <= r; dx++) {
            int px = (int)floor(x) + dx, py = (int)floor(y) + dy;
            if (px >= 0 && py >= 0 && px < im->w && py < im->h && near_rgb(at(im, px, py), c, tol)) return 1;
        }
    return 0;
}

/* The SVG's curve of colour c: every stroked path of that colour and width 2 left of the legend
 * lies in the plot area; with joined, each (x[i], y[i]) is on one of them; the legend has a stroke
 * of that colour at row legend_y. Filled paths of colour c have a round sub-path about 6 px across
 * centred on each point (its extent includes the Bezier control points). */
static void check_svg_series(const drawing *dr, const char *name, const double c[3], const double *x, const double *y,
                             int n, int joined, double legend_y) {
    int legend = 0;
    for (int k = 0; k < n; k++) {
        int on_line = 0, dot = 0;
        for (int i = 0; i < dr->num_paths; i++) {
            const svg_path *q = &dr->path[i];
            const path_points *pp = &q->pts;
            if (q->has_stroke && same_colour(q->stroke, c, 2.0) && q->stroke_width == 2.0) {
                int in_legend = pp->n > 0 && pp->x[0] >= LEGEND_X - 1;
                for (int j = 0; j < pp->n; j++)
                    if (in_legend)
                        legend |= k == 0 && fabs(pp->y[j] - legend_y) <= 0.5;
                    else if (k == 0)
                        CHECK(pp->x[j] >= X0 - 0.5 && pp->x[j] <= X1 + 0.5 && pp->y[j] >= Y0 - 0.5 &&
                                  pp->y[j] <= Y1 + 0.5,
                              "%s: the SVG curve has a point (%g, %g) outside the plot area", name, pp->x[j], pp->y[j]);
                if (!in_legend)
                    for (int sub = 0; sub <= pp->sub[pp->n > 0 ? pp->n - 1 : 0]; sub++)
                        on_line |= polyline_distance(pp, sub, x[k], y[k]) <= 0.5;
            }
            if (q->has_fill && same_colour(q->fill, c, 2.0) && q->fill_opacity == 1.0)
                for (int sub = 0; pp->n > 0 && sub <= pp->sub[pp->n - 1]; sub++) {
                    double lx = INFINITY, hx = -INFINITY, ly = INFINITY, hy = -INFINITY;
                    for (int j = 0; j < pp->n; j++)
                        if (pp->sub[j] == sub)
                            lx = fmin(lx, pp->x[j]), hx = fmax(hx, pp->x[j]), ly = fmin(ly, pp->y[j]),
                            hy = fmax(hy, pp->y[j]);
                    dot |= fabs(0.5 * (lx + hx) - x[k]) <= 0.5 && fabs(0.5 * (ly + hy) - y[k]) <= 0.5 && hx - lx >= 5 &&
                           hx - lx <= 9 && hy - ly >= 5 && hy - ly <= 9;
                }
        }
        CHECK(on_line || !joined, "%s: the SVG's curve misses point %d at (%g, %g)", name, k, x[k], y[k]);
        CHECK(dot, "%s: the SVG has no dot at point %d (%g, %g)", name, k, x[k], y[k]);
    }
    CHECK(legend, "%s: the SVG's legend has no line of the curve's colour at y %g", name, legend_y);
}

/* Log axes from decade lo to decade hi over the plot area. */
static double map_x(double x, double lo, double hi) { return X0 + (log10(x) - lo) / (hi - lo) * (X1 - X0); }
static double map_y(double y, double lo, double hi) { return Y1 - (log10(y) - lo) / (hi - lo) * (Y1 - Y0); }

static const char *const x_title = "render time (s)", *const y_title = "relative error (fraction of ‖R‖₂)";

static void test_curves(void) {
    /* The axes fit the data to whole decades here: x 1..100, y 0.01..1. */
    static const double xs[3] = {1, 10, 100}, ya[3] = {1, 0.1, 0.01}, yb[3] = {0.5, 0.05, 0.03};
    static const double lob[3] = {0.3, 0.02, 0.015}, hib[3] = {0.8, 0.1, 0.05};
    const plot_series series[2] = {{"alpha", 3, xs, ya, NULL, NULL}, {"beta", 3, xs, yb, lob, hib}};
    plot_desc p = {.title = "Error against time",
                   .x_label = "render time",
                   .x_unit = "s",
                   .y_label = "relative error",
                   .y_unit = "fraction of ‖R‖₂",
                   .log_x = 1,
                   .log_y = 1,
                   .series = series,
                   .num_series = 2,
                   .band_label = "min–max of 3 seeds",
                   .mark_x = NAN,
                   .mark_y = NAN};
    if (save_both(&p, "curves")) return;
    image im = load_checked_png();
    drawing *dr = calloc(1, sizeof *dr);
    if (!im.rgb || !dr || load_svg(dr)) {
        stbi_image_free(im.rgb), free(dr);
        return;
    }
    const double *ys[2] = {ya, yb};
    double c[2][3];
    for (int s = 0; s < 2; s++) {
        legend_colour(&im, s, c[s]);
        const unsigned char q[3] = {(unsigned char)c[s][0], (unsigned char)c[s][1], (unsigned char)c[s][2]};
        CHECK(saturated(q), "legend row %d's swatch is not a curve's colour (%g %g %g)", s, c[s][0], c[s][1], c[s][2]);
        double X[3], Y[3];
        for (int i = 0; i < 3; i++) {
            X[i] = map_x(xs[i], 0, 2), Y[i] = map_y(ys[s][i], -2, 0);
            CHECK(colour_near(&im, X[i], Y[i], c[s], 12, 0), "series %d point %d: PNG pixel (%g, %g) not its colour", s,
                  i, X[i], Y[i]);
            if (i)
                CHECK(colour_near(&im, 0.5 * (X[i] + X[i - 1]), 0.5 * (Y[i] + Y[i - 1]), c[s], 40, 1),
                      "series %d: no line between points %d and %d in the PNG", s, i - 1, i);
        }
        CHECK(stray_pixels(&im, c[s], 40, 7) == 0, "series %d's colour drawn outside the plot and legend", s);
        check_svg_series(dr, s ? "beta" : "alpha", c[s], X, Y, 3, 1, ROW0 + ROW * s);
    }
    CHECK(!same_colour(c[0], c[1], 60), "the two series share a colour");
    /* The band: 15 % of beta's colour over white, inside it and off both curves. */
    const unsigned char *q = at(&im, 335, 340);
    double tint[3];
    for (int k = 0; k < 3; k++) tint[k] = 255.0 - 0.15 * (255.0 - c[1][k]);
    CHECK(near_rgb(q, tint, 8), "the band's pixel is %d %d %d, not beta's tint %.0f %.0f %.0f", q[0], q[1], q[2],
          tint[0], tint[1], tint[2]);
    int band = 0;
    for (int i = 0; i < dr->num_paths; i++) {
        const svg_path *sp = &dr->path[i];
        if (!sp->has_fill || !same_colour(sp->fill, c[1], 2.0) || fabs(sp->fill_opacity - 0.15) > 0.01) continue;
        int corners = 0;
        for (int k = 0; k < 3; k++)
            for (int j = 0; j < sp->pts.n; j++)
                corners += fabs(sp->pts.x[j] - map_x(xs[k], 0, 2)) <= 0.5 &&
                           (fabs(sp->pts.y[j] - map_y(lob[k], -2, 0)) <= 0.5 ||
                            fabs(sp->pts.y[j] - map_y(hib[k], -2, 0)) <= 0.5);
        band |= corners >= 6;
    }
    CHECK(band, "the SVG has no band through beta's lo and hi points");

    /* Words: the title, the axis titles with their units, the tick labels, the legend's names. */
    int iw, ih;
    ink(&im, X0, 0, X1, Y0 - 6, &iw, &ih);
    CHECK(iw >= 100 && ih >= 8, "the PNG has no title (ink %dx%d)", iw, ih);
    ink(&im, 30, Y0 - 8, X0 - 6, Y1 + 8, &iw, &ih);
    CHECK(iw >= 15 && ih >= 370, "the PNG's y tick labels (ink %dx%d) do not span the axis", iw, ih);
    ink(&im, X0 - 20, Y1 + 8, X1 + 20, Y1 + 24, &iw, &ih);
    CHECK(iw >= 490 && ih >= 6, "the PNG's x tick labels (ink %dx%d) do not span the axis", iw, ih);
    static const char *const names[3] = {"alpha", "beta", "min–max of 3 seeds"};
    static const int rows[3] = {ROW0, ROW0 + ROW, ROW0 + 2 * ROW + 10}, widths[3] = {25, 20, 80};
    for (int k = 0; k < 3; k++) {
        ink(&im, LEGEND_X + 28, rows[k] - 9, W, rows[k] + 7, &iw, &ih);
        CHECK(iw >= widths[k] && ih >= 6, "the PNG's legend lacks '%s' (ink %dx%d)", names[k], iw, ih);
        CHECK(glyphs_in(dr, LEGEND_X + 28, rows[k] - 2, W, rows[k] + 8) >= visible_chars(names[k]),
              "the SVG's legend lacks '%s'", names[k]);
    }
    const unsigned char *sw = at(&im, LEGEND_X + 3, rows[2]);
    CHECK(sw[0] < 250 && sw[0] > 180 && !saturated(sw), "the band's legend swatch is %d %d %d", sw[0], sw[1], sw[2]);
    CHECK(glyphs_in(dr, 0, 0, W, Y0 - 4) >= visible_chars(p.title), "the SVG has no title");
    CHECK(glyphs_in(dr, X0 - 60, Y1 + 30, X1 + 60, H) >= visible_chars(x_title), "the SVG lacks '%s'", x_title);
    CHECK(glyphs_in(dr, 0, Y0, 30, Y1) >= visible_chars(y_title), "the SVG lacks '%s'", y_title);
    CHECK(glyphs_in(dr, X0 - 20, Y1 + 8, X1 + 20, Y1 + 24) >= 6, "the SVG lacks x tick labels 1, 10, 100");
    CHECK(glyphs_in(dr, 30, Y0 - 8, X0 - 6, Y1 + 8) >= 8, "the SVG lacks y tick labels 0.01, 0.1, 1");

    /* The units widen the axis titles: drawn without them, the titles are shorter. */
    int xw, yh, xw0, yh0;
    ink(&im, X0 - 60, Y1 + 26, X1 + 60, H, &xw, &ih);
    ink(&im, 0, Y0, 30, Y1, &iw, &yh);
    stbi_image_free(im.rgb);
    p.x_unit = p.y_unit = NULL;
    if (save_both(&p, "no-units") == 0) {
        im = load_checked_png();
        if (im.rgb) {
            ink(&im, X0 - 60, Y1 + 26, X1 + 60, H, &xw0, &ih);
            ink(&im, 0, Y0, 30, Y1, &iw, &yh0);
            CHECK(xw0 >= 60 && xw >= xw0 + 15, "x title %d px wide with its unit, %d px without", xw, xw0);
            CHECK(yh0 >= 60 && yh >= yh0 + 60, "y title %d px tall with its unit, %d px without", yh, yh0);
        }
        stbi_image_free(im.rgb);
    }
    free(dr);
}

/* Values a log axis cannot show, bands with holes, an empty series and one of only NaN: the files
 * are written, the usable points drawn, nothing of the curves' colours outside the plot area, and
 * the curve broken where points are missing. */
static void test_bad_values(void) {
    static const double xa[7] = {0, 1, NAN, 10, INFINITY, 100, -5}, ya[7] = {1, 0.5, 0.3, -1, 0.1, 0.01, 0.2};
    static const double nan3[3] = {NAN, NAN, NAN}, xd[3] = {1, 10, 100}, yd[3] = {0.2, NAN, 0.05};
    static const double lod[3] = {0.1, 0.05, -1}, hid[3] = {INFINITY, 0.2, 0.1};
    const plot_series series[4] = {{"holes", 7, xa, ya, NULL, NULL},
                                   {"only NaN", 3, nan3, nan3, nan3, nan3},
                                   {NULL, 0, NULL, NULL, NULL, NULL},
                                   {"band with holes", 3, xd, yd, lod, hid}};
    const plot_desc p = {.title = "Bad values",
                         .x_label = "time",
                         .x_unit = "s",
                         .y_label = "error",
                         .log_x = 1,
                         .log_y = 1,
                         .series = series,
                         .num_series = 4,
                         .mark_x = 50,
                         .mark_y = 0.0,
                         .mark_x_label = "at 50",
                         .mark_y_label = "at 0"};
    if (save_both(&p, "bad")) return;
    image im = load_checked_png();
    drawing *dr = calloc(1, sizeof *dr);
    if (!im.rgb || !dr || load_svg(dr)) {
        stbi_image_free(im.rgb), free(dr);
        return;
    }
    /* y spans 0.01 to 0.5: decades -2 to log10(0.5). */
    double hi = log10(0.5), ca[3], cd[3];
    legend_colour(&im, 0, ca);
    legend_colour(&im, 3, cd);
    double X[2] = {map_x(1, 0, 2), map_x(100, 0, 2)}, Y[2] = {map_y(0.5, -2, hi), map_y(0.01, -2, hi)};
    for (int k = 0; k < 2; k++)
        CHECK(colour_near(&im, X[k], Y[k], ca, 12, 0), "the usable point %d is not drawn in the PNG", k);
    CHECK(!colour_near(&im, 0.5 * (X[0] + X[1]), 0.5 * (Y[0] + Y[1]), ca, 40, 2),
          "the PNG joins points across the missing ones");
    check_svg_series(dr, "holes", ca, X, Y, 2, 0, ROW0);
    for (int i = 0; i < dr->num_paths; i++)
        if (dr->path[i].has_stroke && same_colour(dr->path[i].stroke, ca, 2.0))
            for (int sub = 0; dr->path[i].pts.n > 0 && sub <= dr->path[i].pts.sub[dr->path[i].pts.n - 1]; sub++)
                CHECK(polyline_distance(&dr->path[i].pts, sub, 0.5 * (X[0] + X[1]), 0.5 * (Y[0] + Y[1])) > 3,
                      "the SVG joins points across the missing ones");
    CHECK(stray_pixels(&im, ca, 40, 7) == 0 && stray_pixels(&im, cd, 40, 7) == 0,
          "a curve's colour is drawn outside the plot area");
    /* The vertical reading is drawn and in the legend; the one at 0 on a log axis is neither. */
    int iw, ih;
    ink(&im, LEGEND_X + 28, ROW0 + 4 * ROW + 10 - 9, W, ROW0 + 4 * ROW + 10 + 7, &iw, &ih);
    CHECK(iw >= 45, "the legend lacks the reading at 50 (ink %dx%d)", iw, ih);
    ink(&im, LEGEND_X, ROW0 + 5 * ROW + 10 - 9, W, H, &iw, &ih);
    CHECK(iw == 0, "the legend names a reading that is not drawn (ink %dx%d)", iw, ih);
    stbi_image_free(im.rgb);

    /* 600 decades on a log axis (it keeps the top 60) and one x value on a linear one. */
    static const double x1[2] = {5, 5}, y1[2] = {1e-300, 1e300};
    const plot_series wide = {"wide", 2, x1, y1, NULL, NULL};
    const plot_desc q = {.title = "Wide", .log_y = 1, .series = &wide, .num_series = 1, .mark_x = NAN, .mark_y = NAN};
    if (save_both(&q, "wide") == 0 && load_svg(dr) == 0) {
        im = load_checked_png();
        if (im.rgb) {
            double cw[3];
            legend_colour(&im, 0, cw);
            CHECK(stray_pixels(&im, cw, 40, 7) == 0, "the wide curve is drawn outside the plot area");
            CHECK(colour_near(&im, (X0 + X1) / 2.0, Y0, cw, 12, 0), "the wide curve's top point is not drawn");
        }
        stbi_image_free(im.rgb);
    }
    free(dr);
}

/* A linear x axis: 0 to 16 fits 0 to 20 in steps of 5. */
static void test_linear(void) {
    static const double x[2] = {0, 16}, y[2] = {0.2, 0.5};
    const plot_series s = {"lin", 2, x, y, NULL, NULL};
    const plot_desc p = {.title = "Linear",
                         .x_label = "columns",
                         .x_unit = "clusters",
                         .log_y = 1,
                         .series = &s,
                         .num_series = 1,
                         .mark_x = NAN,
                         .mark_y = NAN};
    if (save_both(&p, "linear")) return;
    image im = load_checked_png();
    if (!im.rgb) return;
    double c[3];
    legend_colour(&im, 0, c);
    /* y: 0.2 to 0.5 is the axis' whole range (it ends at 1, 2 or 5 times a power of ten). */
    CHECK(colour_near(&im, X0, Y1, c, 12, 0) && colour_near(&im, X0 + 16.0 / 20.0 * (X1 - X0), Y0, c, 12, 0),
          "the linear plot's points are not where 0 and 16 map on 0..20");
    stbi_image_free(im.rgb);
}

/* More series than legend rows: the legend closes up and stays inside the figure. */
static void test_many(void) {
    enum { N = 60 };
    static double x[2] = {1, 10}, y[N][2];
    static char names[N][16];
    plot_series s[N];
    for (int k = 0; k < N; k++) {
        y[k][0] = 1.0 + k, y[k][1] = 0.5 + k;
        snprintf(names[k], sizeof names[k], "series %d", k);
        s[k] = (plot_series){names[k], 2, x, y[k], NULL, NULL};
    }
    const plot_desc p = {
        .title = "Many", .log_x = 1, .log_y = 1, .series = s, .num_series = N, .mark_x = 2, .mark_y = 5};
    if (save_both(&p, "many")) return;
    image im = load_checked_png();
    if (!im.rgb) return;
    int iw, ih;
    ink(&im, LEGEND_X, 0, W, H, &iw, &ih);
    CHECK(ih >= 380, "the legend (ink %dx%d) does not fill its column", iw, ih);
    ink(&im, LEGEND_X, H - 4, W, H, &iw, &ih);
    CHECK(ih == 0, "the legend runs off the figure's bottom");
    stbi_image_free(im.rgb);
}

static int same_file(const char *path, const unsigned char *data, size_t size) {
    size_t n;
    unsigned char *b = get_file(path, &n);
    int same = b && n == size && memcmp(b, data, size) == 0;
    free(b);
    return same;
}

/* WRITE_NO_REPLACE refuses an existing file and leaves it as it was; WRITE_REPLACE replaces it;
 * a missing directory is an error naming the path; no temporary file is left behind. */
static void test_write_modes(void) {
    static const double x[2] = {1, 2}, y[2] = {1, 2};
    const plot_series s = {"a", 2, x, y, NULL, NULL};
    plot_desc p = {.title = "First", .series = &s, .num_series = 1, .mark_x = NAN, .mark_y = NAN};
    for (int png = 0; png < 2; png++) {
        int (*save)(const plot_desc *, const char *, write_mode, char *, size_t) = png ? plot_save_png : plot_save_svg;
        char path[1400], err[1600];
        path_in(path, sizeof path, png ? "mode.png" : "mode.svg");
        p.title = "First";
        CHECK(save(&p, path, WRITE_NO_REPLACE, err, sizeof err) == 0, "%s: %s", path, err);
        size_t n0 = 0;
        unsigned char *first = get_file(path, &n0);
        p.title = "Second";
        CHECK(save(&p, path, WRITE_NO_REPLACE, err, sizeof err) == -1 && strstr(err, path) && strstr(err, "exists"),
              "%s: replaced without being asked (%s)", path, err);
        CHECK(first && same_file(path, first, n0), "%s: changed by a refused write", path);
        CHECK(save(&p, path, WRITE_REPLACE, err, sizeof err) == 0, "%s: %s", path, err);
        CHECK(first && !same_file(path, first, n0), "%s: not replaced when asked", path);
        free(first);
        path_in(path, sizeof path, png ? "missing/p.png" : "missing/p.svg");
        CHECK(save(&p, path, WRITE_REPLACE, err, sizeof err) == -1 && strncmp(err, path, strlen(path)) == 0, "%s: '%s'",
              path, err);
    }
    CHECK(stray_temp_files(scratch_dir) == 0, "temporary files left");
}

/* The PNG is the same whether or not the process drew an SVG before it (cairo shares fonts between
 * surfaces): each order in a process of its own. */
static void test_order(void) {
    static const double x[2] = {1, 10}, y[2] = {1, 0.1};
    const plot_series s = {"vsl", 2, x, y, NULL, NULL};
    const plot_desc p = {.title = "Relative L2 error against render time",
                         .x_label = "render time",
                         .x_unit = "s",
                         .y_label = "relative L2 error",
                         .log_x = 1,
                         .log_y = 1,
                         .series = &s,
                         .num_series = 1,
                         .mark_x = NAN,
                         .mark_y = NAN};
    char png[2][1400], svg[1400], err[1600];
    path_in(png[0], sizeof png[0], "alone.png");
    path_in(png[1], sizeof png[1], "after-svg.png");
    path_in(svg, sizeof svg, "before.svg");
    for (int k = 0; k < 2; k++) {
        fflush(NULL);
        pid_t pid = fork();
        if (pid == 0) {
            int bad = k == 1 && plot_save_svg(&p, svg, WRITE_REPLACE, err, sizeof err) != 0;
            _exit(bad || plot_save_png(&p, png[k], WRITE_REPLACE, err, sizeof err) != 0);
        }
        int status = -1;
        CHECK(pid > 0 && waitpid(pid, &status, 0) == pid && WIFEXITED(status) && WEXITSTATUS(status) == 0,
              "drawing %s failed", png[k]);
    }
    size_t n = 0;
    unsigned char *first = get_file(png[0], &n);
    CHECK(first && same_file(png[1], first, n), "the PNG drawn after an SVG differs from the one drawn alone");
    free(first);
}

int main(void) {
    if (scratch_open("test_plot")) return 1;
    test_order();
    test_curves();
    test_bad_values();
    test_linear();
    test_many();
    test_write_modes();
    return scratch_close(check_exit("test_plot"));
}
