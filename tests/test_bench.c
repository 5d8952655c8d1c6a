/* glint bench and references, run as a user would: the description in a reference EXR's header
 * (no sidecar), which a copy keeps, and an older reference's sidecar still read; a bench whose
 * CSV parses (header, monotone time, pt's error falling), whose SVG and PNG plots and report
 * appear, sweeps, the highlights component; several seeds per run, their summary and its split
 * into noise and bias; mismatched references (size, camera, scene, no or broken description,
 * one of unexpected shape, in the header or a sidecar, one rendered by another material model)
 * and impossible seed counts refused with one error line; nothing ever overwritten; the plots' words, and the SVG drawn as the PNG is (the
 * curves and legend in the PNG legend's colours, the legend's names as glyphs).
 * Usage: test_bench PATH_TO_GLINT */
#define _POSIX_C_SOURCE 200809L
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include <stb_image.h>

#include "bench_harness.h"
#include "check.h"
#include "cli_harness.h"
#include "image_io.h"
#include "svg_read.h"

static void write_text(const char *name, const char *text) {
    char p[1024];
    snprintf(p, sizeof p, "%s/%s", tmp, name);
    FILE *f = fopen(p, "w");
    if (f) {
        fputs(text, f);
        fclose(f);
    }
}

static const char *const other_scene =
    "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":60,\"uri\":\"data:application/octet-stream;base64,"
    "AACAvwAAAAAAAIC/AACAPwAAAAAAAIC/AACAPwAAAAAAAIA/AACAvwAAAAAAAIA/AAACAAEAAAADAAIA\"}],\"bufferViews\":[{\"buffer\":"
    "0,\"byteOffset\":0,\"byteLength\":48},{\"buffer\":0,\"byteOffset\":48,\"byteLength\":12}],\"accessors\":[{"
    "\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\",\"min\":[-1,0,-1],\"max\":[1,0,1]},{"
    "\"bufferView\":1,\"componentType\":5123,\"count\":6,\"type\":\"SCALAR\"}],\"meshes\":[{\"primitives\":[{"
    "\"attributes\":{\"POSITION\":0},\"indices\":1}]}],\"extensionsUsed\":[\"KHR_lights_punctual\"],\"extensions\":{"
    "\"KHR_lights_punctual\":{\"lights\":[{\"type\":\"point\",\"intensity\":5}]}},\"cameras\":[{\"type\":"
    "\"perspective\",\"perspective\":{\"yfov\":0.8,\"znear\":0.01}}],\"nodes\":[{\"mesh\":0},{\"extensions\":{\"KHR_"
    "lights_punctual\":{\"light\":0}},"
    "\"translation\":[0,1,0]},{\"camera\":0,\"translation\":[0,1,3]}],\"scenes\":[{\"nodes\":[0,1,2]}],\"scene\":0}\n";

/* The extent of dark pixels (text, not the light grid) in [x0, x1) x [y0, y1) of an RGB image:
 * width and height in pixels, 0 when there are none. */
static void ink(const unsigned char *rgb, int w, int h, int x0, int y0, int x1, int y1, int *iw, int *ih) {
    int lx = x1, hx = x0 - 1, ly = y1, hy = y0 - 1;
    for (int y = y0 < 0 ? 0 : y0; y < y1 && y < h; y++)
        for (int x = x0 < 0 ? 0 : x0; x < x1 && x < w; x++) {
            const unsigned char *q = rgb + 3 * ((size_t)y * (size_t)w + (size_t)x);
            if (q[0] < 150 && q[1] < 150 && q[2] < 150) {
                lx = x < lx ? x : lx, hx = x > hx ? x : hx;
                ly = y < ly ? y : ly, hy = y > hy ? y : hy;
            }
        }
    *iw = hx >= lx ? hx - lx + 1 : 0;
    *ih = hy >= ly ? hy - ly + 1 : 0;
}

/* The PNG plot has words where the SVG has them: title, axis labels, the curves' names and the
 * readings' in the legend. The regions hold nothing else (app/bench/plot.c's layout: the plot area
 * 80..580 x 40..430, the legend from x 600, a row every 20 px from y 50). A digit alone, as the
 * PNG once had beside its legend swatches, is narrower than the names asked for (unhinted 12 px
 * text: "vsl" 14 px of ink). */
static void check_png_words(const unsigned char *png, int w, int h) {
    enum { AREA_X0 = 80, AREA_X1 = 580, AREA_Y0 = 40, AREA_Y1 = 430, LEGEND_X = 600 };
    int iw, ih;
    ink(png, w, h, AREA_X0, 0, AREA_X1, AREA_Y0 - 6, &iw, &ih);
    CHECK(iw >= 150 && ih >= 8, "the PNG has no title (ink %dx%d)", iw, ih);
    ink(png, w, h, AREA_X0, AREA_Y1 + 24, AREA_X1, h, &iw, &ih);
    CHECK(iw >= 60 && ih >= 8, "the PNG has no x axis label (ink %dx%d)", iw, ih);
    ink(png, w, h, 0, AREA_Y0, 30, AREA_Y1, &iw, &ih);
    CHECK(ih >= 80 && iw >= 8, "the PNG has no y axis label (ink %dx%d)", iw, ih);
    ink(png, w, h, 30, AREA_Y0 - 8, AREA_X0 - 6, AREA_Y1 + 8, &iw, &ih);
    CHECK(iw >= 15 && ih >= 200, "the PNG has no y tick labels (ink %dx%d)", iw, ih);
    ink(png, w, h, AREA_X0 - 20, AREA_Y1 + 8, AREA_X1 + 20, AREA_Y1 + 24, &iw, &ih);
    CHECK(iw >= 400 && ih >= 6, "the PNG has no x tick labels (ink %dx%d)", iw, ih);
    static const char *const names[] = {"pt", "vsl", "equal time", "equal error"};
    static const int rows[] = {50, 70, 100, 120}, widths[] = {10, 12, 45, 45};
    for (int k = 0; k < 4; k++) {
        ink(png, w, h, LEGEND_X + 28, rows[k] - 9, w, rows[k] + 7, &iw, &ih);
        CHECK(iw >= widths[k] && ih >= 6, "the PNG's legend lacks '%s' (ink %dx%d)", names[k], iw, ih);
    }
}

/* The SVG plot NAME beside its PNG (decoded, 860x500): well-formed, of the PNG's size, with a
 * curve in the plot area and a line at its legend row in the colour of each of the first
 * num_series legend swatches of the PNG (one description drawn twice), each legend name as glyphs
 * at its row, and with bands, a band of the first curve's colour. */
static void check_svg_plot(const char *name, const unsigned char *png, const char *const *names, const int *rows,
                           int num_names, int num_series, int band) {
    enum { AREA_X0 = 80, AREA_X1 = 580, AREA_Y0 = 40, AREA_Y1 = 430, LEGEND_X = 600 };
    static char svg[1 << 20];
    read_file(name, svg, sizeof svg);
    const char *problem = xml_problem(svg);
    CHECK(problem == NULL, "%s is not well-formed XML: %s", name, problem);
    drawing *dr = calloc(1, sizeof *dr);
    if (!dr) return;
    read_drawing(svg, dr);
    CHECK(strcmp(dr->width, "860") == 0 && strcmp(dr->height, "500") == 0 && strcmp(dr->view_box, "0 0 860 500") == 0,
          "%s: %s x %s, viewBox '%s', not the PNG's 860x500", name, dr->width, dr->height, dr->view_box);
    for (int s = 0; s < num_series; s++) {
        const unsigned char *q = png + 3 * (rows[s] * 860 + LEGEND_X + 12);
        const double c[3] = {q[0], q[1], q[2]};
        CHECK(paths_within(dr, c, 2.0, -1.0, AREA_X0 - 0.5, AREA_Y0 - 0.5, AREA_X1 + 0.5, AREA_Y1 + 0.5) >= 1,
              "%s: no curve in the colour of '%s' in the PNG (%g %g %g)", name, names[s], c[0], c[1], c[2]);
        CHECK(paths_within(dr, c, 2.0, -1.0, LEGEND_X, rows[s] - 0.5, LEGEND_X + 24, rows[s] + 0.5) == 1,
              "%s: no legend line for '%s'", name, names[s]);
        if (band && s == 0)
            CHECK(paths_within(dr, c, 0.0, 0.15, AREA_X0 - 0.5, AREA_Y0 - 0.5, AREA_X1 + 0.5, AREA_Y1 + 0.5) >= 1,
                  "%s: no band in the colour of '%s'", name, names[s]);
    }
    for (int k = 0; k < num_names; k++)
        CHECK(glyphs_in(dr, LEGEND_X + 28, rows[k] - 2, 860, rows[k] + 8) >= visible_chars(names[k]),
              "%s: the legend lacks '%s'", name, names[k]);
    free(dr);
}

static void test_reference_header(void) {
    /* 1024 spp: the reference's own noise must stay below pt's error at the bench's budgets. */
    int rc = run("render --spp 1024 --size 24x16 --max-depth 3 --seed 7 --out ref.exr --quiet");
    CHECK(rc == 0, "reference render: exit %d: %s", rc, err_text);
    CHECK(!exists("ref.exr.json"), "a sidecar beside the reference");
    char json[8192];
    read_reference("ref.exr", json, sizeof json);
    CHECK(strstr(json, "\"scene_hash\": \"builtin:atelier:fnv1a64:") && strstr(json, "\"spp\": 1024") &&
              strstr(json, "\"width\": 24") && strstr(json, "\"height\": 16") && strstr(json, "\"max_depth\": 3") &&
              strstr(json, "\"seed\": 7") && strstr(json, "\"index\": 0") && strstr(json, "\"method\": \"pt\"") &&
              strstr(json, "\"mean_pixel_variance\": "),
          "the reference's description: %s", json);
    const char *noise = strstr(json, "\"rel_l2_noise\": ");
    double rel = noise ? atof(noise + 16) : -1.0;
    CHECK(rel > 0.0 && rel < 1.0, "the reference's relative noise %g", rel);
    /* A reference with the highlights split off, for the highlights component. */
    rc = run("render --spp 64 --size 24x16 --max-depth 3 --seed 7 --highlights-layer --out refhl.exr --quiet");
    CHECK(rc == 0, "highlights reference render: exit %d: %s", rc, err_text);
    read_reference("refhl.exr", json, sizeof json);
    CHECK(strstr(json, "\"highlights_layer\": true") != NULL, "highlights reference: %s", json);
    /* A reference of another scene. */
    write_text("other.gltf", other_scene);
    rc = run("render other.gltf --spp 16 --size 24x16 --max-depth 3 --out other.exr --quiet");
    CHECK(rc == 0, "other scene render: exit %d: %s", rc, err_text);
    read_reference("other.exr", json, sizeof json);
    CHECK(strstr(json, "\"scene_hash\": \"fnv1a64:") && strstr(json, "\"scene\": \"other.gltf\""), "other: %s", json);
}

static void test_bench_run(void) {
    int rc = run("bench --reference ref.exr --methods pt,vsl --vsl-count 64 --times 0.01,0.3,1 --threads 2 --out b1");
    CHECK(rc == 0, "bench: exit %d: %s", rc, err_text);
    row rows[64];
    int n = parse_csv("b1/results.csv", rows, 64);
    CHECK(n == 6, "results.csv: %d rows (-1: bad header), expected 6", n);
    for (int i = 0; i < n; i++) {
        CHECK(rows[i].fields == 22, "row %d has %d fields", i, rows[i].fields);
        CHECK(rows[i].seed == 8, "row %d: seed %lld, expected the reference's + 1", i, rows[i].seed);
        CHECK(isfinite(rows[i].rel_l2) && rows[i].rel_l2 > 0.0 && !rows[i].has_highlights,
              "row %d: rel_l2 %g, highlights column filled without a highlights layer", i, rows[i].rel_l2);
        /* Non-decreasing: a frame longer than two budgets (a loaded machine, a sanitised build)
         * meets both at once, and both rows read the same moment. */
        if (i % 3 > 0)
            CHECK(rows[i].seconds >= rows[i - 1].seconds && rows[i].frames >= rows[i - 1].frames &&
                      strcmp(rows[i].method, rows[i - 1].method) == 0,
                  "row %d: seconds %g after %g, not monotone within one run", i, rows[i].seconds, rows[i - 1].seconds);
    }
    if (n == 6) {
        CHECK(strcmp(rows[0].method, "pt") == 0 && strcmp(rows[3].method, "vsl") == 0, "methods in order");
        CHECK(rows[0].seconds >= 0.01 && rows[2].seconds >= 1.0, "budgets met: %g, %g", rows[0].seconds,
              rows[2].seconds);
        /* By frames (seed 8): 1.39 at 2, 0.65 at 10, 0.29 at 44, 0.25 at 200, 0.19 at 700; one
         * firefly can raise the curve a little, so only a clear fall counts. */
        CHECK(rows[2].rel_l2 < 0.6 * rows[0].rel_l2, "pt's error does not fall: %g at %g s, %g at %g s", rows[0].rel_l2,
              rows[0].seconds, rows[2].rel_l2, rows[2].seconds);
    }
    /* One seed: the summary's RMS is the run's own error; noise and bias are unknown (empty). */
    summary_row sum[16];
    int ns = parse_summary("b1/summary.csv", sum, 16);
    CHECK(ns == 6, "summary.csv: %d rows (-1: bad header), expected 6", ns);
    for (int i = 0; i < ns && i < n; i++)
        CHECK(sum[i].fields == 14 && sum[i].seeds == 1 && strcmp(sum[i].method, rows[i].method) == 0 &&
                  strcmp(sum[i].component, "all") == 0 &&
                  fabs(sum[i].rel_l2 - rows[i].rel_l2) <= 1e-5 * rows[i].rel_l2 && sum[i].lo == sum[i].hi &&
                  fabs(sum[i].lo - sum[i].rel_l2) <= 1e-5 * sum[i].lo && isnan(sum[i].noise) && isnan(sum[i].bias),
              "summary row %d: %d fields, %d seeds, %s, rel_l2 %g (run %g), noise %g, bias %g", i, sum[i].fields,
              sum[i].seeds, sum[i].method, sum[i].rel_l2, rows[i].rel_l2, sum[i].noise, sum[i].bias);
    char p[1024];
    snprintf(p, sizeof p, "%s/b1/error-vs-time.png", tmp);
    int w = 0, h = 0, c = 0;
    unsigned char *png = stbi_load(p, &w, &h, &c, 3);
    CHECK(png && w > 100 && h > 100, "error-vs-time.png does not decode (%dx%d)", w, h);
    if (png) {
        long dark = 0;
        for (long i = 0; i < (long)w * h * 3; i++) dark += png[i] < 128;
        CHECK(dark > 1000, "the png is blank (%ld dark values)", dark);
        if (w == 860 && h == 500) {
            static const char *const names[] = {"pt", "vsl", "equal time", "equal error"};
            static const int legend_rows[] = {50, 70, 100, 120};
            check_png_words(png, w, h);
            check_svg_plot("b1/error-vs-time.svg", png, names, legend_rows, 4, 2, 0);
        } else
            CHECK(0, "error-vs-time.png is %dx%d, not the 860x500 of the layout the words are looked for in", w, h);
    }
    stbi_image_free(png);
    char md[1 << 16];
    read_file("b1/report.md", md, sizeof md);
    CHECK(strstr(md, "| pt |") && strstr(md, "| vsl |") && strstr(md, "## Convergence") &&
              strstr(md, "## Equal error") && strstr(md, "| 1 s |") && strstr(md, "| 0.3–1 s |"),
          "report.md: %s", md);

    /* Nothing is overwritten: the same --out is refused, the files stay as they were. */
    char before[1 << 16], after[1 << 16];
    read_file("b1/results.csv", before, sizeof before);
    expect_refusal("bench --reference ref.exr --methods pt --times 0.05 --out b1", "results.csv");
    read_file("b1/results.csv", after, sizeof after);
    CHECK(strcmp(before, after) == 0, "results.csv changed");
    /* Without --out: bench, then bench-1. */
    CHECK(run("bench --reference ref.exr --methods pt --times 0.05 --quiet") == 0 && exists("bench/results.csv"),
          "default output directory: %s", err_text);
    CHECK(run("bench --reference ref.exr --methods pt --times 0.05 --quiet") == 0 && exists("bench-1/results.csv"),
          "second default output directory: %s", err_text);
}

static void test_sweeps_and_highlights(void) {
    int rc = run("bench --reference ref.exr --methods pt,vsl --vsl-count 64 --sweep radius-mult=1,4 --sweep "
                 "columns=0,16 --times 0.05,0.1 --quiet --out b2");
    CHECK(rc == 0, "sweep bench: exit %d: %s", rc, err_text);
    row rows[64];
    int n = parse_csv("b2/results.csv", rows, 64);
    CHECK(n == 10, "sweep results: %d rows, expected 2 (pt) + 4 settings x 2 (vsl)", n);
    int found = 0;
    for (int i = 0; i < n; i++)
        found += strcmp(rows[i].method, "vsl") == 0 && strcmp(rows[i].params, "radius-mult=4") == 0;
    CHECK(found == 2, "no vsl radius-mult=4 rows");
    CHECK(exists("b2/sweep-radius-mult.svg") && exists("b2/sweep-columns.png"), "sweep plots missing");
    char md[1 << 16];
    read_file("b2/report.md", md, sizeof md);
    CHECK(strstr(md, "## Sweep: radius-mult") && strstr(md, "## Sweep: columns"), "report lacks the sweeps");

    rc = run("bench --reference refhl.exr --methods pt,vsl+hl --vsl-count 64 --secondary-rays 4 --component highlights "
             "--times 0.05,0.1 --quiet --out b3");
    CHECK(rc == 0, "highlights bench: exit %d: %s", rc, err_text);
    n = parse_csv("b3/results.csv", rows, 64);
    CHECK(n == 4, "highlights results: %d rows", n);
    for (int i = 0; i < n; i++)
        CHECK(rows[i].has_highlights && isfinite(rows[i].highlights_rel_l2), "row %d lacks its highlights error", i);
}

static void test_seeds(void) {
    /* pt against a reference of the same scene rendered far longer (1024 spp against some 10 to
     * 60 frames here): unbiased, so the bias estimate is left with the estimate's own scatter.
     * Measured on 12 benches of 4 seeds: bias/noise at most 0.64 per budget, the sum of bias^2
     * at most 0.4 of the sum of noise^2 over the budgets; 6 seeds narrow that. Swapping noise and
     * bias puts the ratio far above 1. */
    int rc = run("bench --reference ref.exr --methods pt --seeds 6 --times 0.02,0.06 --threads 1 --quiet --out s1");
    CHECK(rc == 0, "--seeds 6: exit %d: %s", rc, err_text);
    row rows[64];
    int n = parse_csv("s1/results.csv", rows, 64);
    CHECK(n == 12, "--seeds 6: %d rows in results.csv (-1: bad header), expected 6 seeds x 2 budgets", n);
    for (int i = 0; i < n; i++)
        CHECK(rows[i].fields == 22 && rows[i].seed == 8 + i / 2 && isfinite(rows[i].rel_l2),
              "row %d: seed %lld, expected %d (the reference's + 1, + 2, ...)", i, rows[i].seed, 8 + i / 2);
    summary_row sum[16];
    int ns = parse_summary("s1/summary.csv", sum, 16);
    CHECK(ns == 2, "--seeds 6: %d summary rows (-1: bad header), expected 2", ns);
    double noise2 = 0.0, bias2 = 0.0;
    for (int i = 0; i < ns; i++) {
        CHECK(sum[i].fields == 14 && sum[i].seeds == 6 && strcmp(sum[i].method, "pt") == 0 &&
                  sum[i].budget == (i == 0 ? 0.02 : 0.06) && sum[i].ref_noise > 0.0,
              "summary row %d: %d fields, %d seeds, %s at %g, ref_noise %g", i, sum[i].fields, sum[i].seeds,
              sum[i].method, sum[i].budget, sum[i].ref_noise);
        /* The summary against results.csv: RMS, least and largest over the seeds at this budget. */
        double sq = 0.0, lo = INFINITY, hi = 0.0, frames = 0.0;
        for (int j = i; j < n; j += 2) {
            sq += rows[j].rel_l2 * rows[j].rel_l2;
            lo = fmin(lo, rows[j].rel_l2);
            hi = fmax(hi, rows[j].rel_l2);
            frames += (double)rows[j].frames;
        }
        CHECK(fabs(sum[i].rel_l2 - sqrt(sq / 6)) <= 1e-4 * sum[i].rel_l2 && fabs(sum[i].lo - lo) <= 1e-5 * lo &&
                  fabs(sum[i].hi - hi) <= 1e-5 * hi && fabs(sum[i].frames - frames / 6) <= 1e-4 * frames,
              "summary row %d: RMS %g, min %g, max %g, frames %g; from results.csv %g, %g, %g, %g", i, sum[i].rel_l2,
              sum[i].lo, sum[i].hi, sum[i].frames, sqrt(sq / 6), lo, hi, frames / 6);
        check_identity(&sum[i], "pt");
        CHECK(sum[i].bias < sum[i].noise, "pt at %g s: bias %g not below noise %g", sum[i].budget, sum[i].bias,
              sum[i].noise);
        noise2 += sum[i].noise * sum[i].noise;
        bias2 += sum[i].bias * sum[i].bias;
    }
    CHECK(bias2 < 0.5 * noise2, "pt: bias^2 %g against noise^2 %g over the budgets", bias2, noise2);
    char md[1 << 16];
    read_file("s1/report.md", md, sizeof md);
    CHECK(strstr(md, "RMS over 6 seeds") && strstr(md, "## Noise and bias") && strstr(md, "### pt") &&
              strstr(md, "| noise | bias |"),
          "report.md with seeds: %s", md);
    /* The band over the seeds, named in the legend below the curve. */
    char p[1024];
    snprintf(p, sizeof p, "%s/s1/error-vs-time.png", tmp);
    int w = 0, h = 0, c = 0;
    unsigned char *png = stbi_load(p, &w, &h, &c, 3);
    CHECK(png && w == 860 && h == 500, "s1/error-vs-time.png: %dx%d", w, h);
    if (png && w == 860 && h == 500) {
        static const char *const names[] = {"pt", "min–max of 6 seeds", "equal time", "equal error"};
        static const int legend_rows[] = {50, 80, 100, 120};
        check_svg_plot("s1/error-vs-time.svg", png, names, legend_rows, 4, 1, 1);
    }
    stbi_image_free(png);

    /* All bias, no noise: at depth 1 the path tracer has no indirect light at all, so every seed's
     * indirect image is zero: noise 0 and bias 1 exactly (the reference's noise is not known for a
     * component, so it counts as 0). */
    rc = run("bench --reference ref.exr --methods pt --seeds 2 --max-depth 1 --component indirect --times 0.01 "
             "--threads 1 --quiet --out s2");
    CHECK(rc == 0, "depth 1: exit %d: %s", rc, err_text);
    ns = parse_summary("s2/summary.csv", sum, 16);
    CHECK(ns == 1 && strcmp(sum[0].component, "indirect") == 0 && sum[0].noise == 0.0 && sum[0].bias == 1.0 &&
              sum[0].rel_l2 == 1.0 && sum[0].ref_noise == 0.0,
          "depth 1, indirect: %d rows, noise %g, bias %g, RMS %g, ref_noise %g", ns, sum[0].noise, sum[0].bias,
          sum[0].rel_l2, sum[0].ref_noise);
    if (ns == 1) check_identity(&sum[0], "depth 1");
    /* Bias and noise together: the whole image at depth 1 lacks the indirect light, a bias of
     * 0.19 to 0.35 of the reference measured (8 benches of 3 seeds, 16 to 60 frames), never
     * clamped at 0; its noise is the direct light's. So the identity holds in its strict form here,
     * which a split that forgets the mean's noise or the reference's would break. */
    rc =
        run("bench --reference ref.exr --methods pt --seeds 3 --max-depth 1 --times 0.06 --threads 1 --quiet --out s3");
    CHECK(rc == 0, "depth 1, all: exit %d: %s", rc, err_text);
    ns = parse_summary("s3/summary.csv", sum, 16);
    CHECK(ns == 1 && sum[0].bias > 0.1 && sum[0].noise > 0.0, "depth 1, all: %d rows, noise %g, bias %g", ns,
          sum[0].noise, sum[0].bias);
    if (ns == 1) check_identity(&sum[0], "depth 1, all");

    /* Impossible seed counts: usage errors, nothing created. The reference's seed is 7: the
     * seeds 5, 6, 7 hold it. */
    expect_usage("bench --reference ref.exr --seeds 0 --times 0.05 --out q1", "--seeds");
    expect_usage("bench --reference ref.exr --seeds 1001 --times 0.05 --out q2", "--seeds");
    expect_usage("bench --reference ref.exr --seeds two --times 0.05 --out q3", "--seeds");
    expect_usage("bench --reference ref.exr --seed 5 --seeds 3 --times 0.05 --out q4", "reference's seed 7");
    expect_usage("bench --reference ref.exr --methods vsl --sweep columns=1,2,3,4,5 --seeds 1000 --times 0.05 --out q5",
                 "5000 renders");
    /* The split's sum images, 640x560 doubles x 3 x 64 budgets, are 525 MiB: refused. */
    rc = run("render --spp 1 --size 640x560 --max-depth 1 --out big.exr --quiet");
    CHECK(rc == 0, "big reference: exit %d: %s", rc, err_text);
    char times[512] = "1";
    for (int k = 2; k <= 64; k++) snprintf(times + strlen(times), sizeof times - strlen(times), ",%d", k);
    char cmd[1024];
    snprintf(cmd, sizeof cmd, "bench --reference big.exr --seeds 2 --times %s --out q6", times);
    expect_usage(cmd, "MiB");
    CHECK(!exists("q1") && !exists("q4") && !exists("q5") && !exists("q6"), "a refused bench created its directory");
}

static void test_refusals(void) {
    CHECK(run("bench --help") == 0 && strstr(out_text, "--reference") && strstr(out_text, "--sweep") &&
              strstr(out_text, "--component"),
          "bench --help: %s", out_text);
    CHECK(run("--help") == 0 && strstr(out_text, "glint bench"), "glint --help lacks bench");
    expect_refusal("bench --reference ref.exr --size 32x16 --times 0.05 --out r1", "24x16");
    expect_refusal("bench --reference ref.exr --camera 1 --times 0.05 --out r2", "camera");
    expect_refusal("bench --reference other.exr --times 0.05 --out r3", "another scene");
    expect_refusal("bench other.gltf --reference ref.exr --times 0.05 --out r4", "another scene");
    expect_refusal("bench --reference ref.exr --seed 7 --times 0.05 --out r5", "seed");
    expect_refusal("bench --reference ref.exr --component highlights --times 0.05 --out r6", "highlights");
    expect_refusal("bench --reference missing.exr --times 0.05 --out r7", "missing.exr");
    expect_refusal("bench --times 0.05 --out r8", "--reference");
    expect_refusal("bench --reference ref.exr --times 2,1 --out r9", "--times");
    expect_refusal("bench --reference ref.exr --sweep bogus=1,2 --out r10", "bogus");
    expect_refusal("bench --reference ref.exr --sweep radius-mult=1,x --out r11", "--radius-mult");
    expect_refusal("bench --reference ref.exr --methods pt,nope --out r12", "nope");
    CHECK(!exists("r1") && !exists("r2") && !exists("r3"), "a refused bench created its directory");
    /* Without a description: refused unless --force; a broken one, in the header or in an older
     * reference's sidecar, is refused always. */
    CHECK(write_reference("ref.exr", "bare.exr", NULL, 0) == 0, "writing a bare EXR");
    expect_refusal("bench --reference bare.exr --times 0.05 --out r13",
                   "bare.exr: no glint.reference header attribute nor sidecar bare.exr.json");
    CHECK(run("bench --reference bare.exr --force --methods pt --times 0.05 --quiet --out r14") == 0 &&
              exists("r14/results.csv"),
          "--force: %s", err_text);
    /* A reference holding a NaN (or Inf) answers nothing: refused even with --force. */
    static float nan_rgb[3 * 24 * 16];
    nan_rgb[3 * 100 + 1] = NAN;
    nan_rgb[3 * 200] = INFINITY;
    char nan_path[1024], nan_err[512];
    snprintf(nan_path, sizeof nan_path, "%s/nan.exr", tmp);
    exr_layer nan_layer = {"", nan_rgb};
    CHECK(exr_save_layers(nan_path, 24, 16, &nan_layer, 1, WRITE_REPLACE, nan_err, sizeof nan_err) == 0, "nan.exr: %s",
          nan_err);
    expect_refusal("bench --reference nan.exr --force --methods pt --times 0.05 --out r16",
                   "nan.exr: 2 values of R,G,B are not finite");
    static const char broken[] = "{\"glint_reference\": 1, \"scene\": \"x\"";
    CHECK(write_reference("ref.exr", "broken.exr", broken, 1) == 0 &&
              write_reference("ref.exr", "broken2.exr", broken, 0) == 0,
          "writing broken references");
    expect_refusal("bench --reference broken.exr --times 0.05 --out r15",
                   "broken.exr.json: not a glint reference sidecar (not JSON");
    expect_refusal("bench --reference broken2.exr --times 0.05 --out r16",
                   "broken2.exr: bad glint.reference header attribute (not JSON");
    CHECK(!exists("r13") && !exists("r15") && !exists("r16"), "a refused bench created its directory");
}

/* A reference is one file: a copy under another name is the same reference, no sidecar needed;
 * an older reference, its description in a sidecar FILE.exr.json, is still one and still checked;
 * where both are there the header wins. */
static void test_reference_files(void) {
    static char report[1 << 16];
    char cmd[4096], json[8192];
    snprintf(cmd, sizeof cmd, "cp '%s/ref.exr' '%s/copy.exr'", tmp, tmp);
    CHECK(system(cmd) == 0, "copying the reference");
    CHECK(run("bench --reference copy.exr --methods pt --times 0.05 --quiet --out f1") == 0, "a copied reference: %s",
          err_text);
    read_file("f1/report.md", report, sizeof report);
    CHECK(strstr(report, "- reference: `copy.exr`, pt, 1024 spp") != NULL, "f1/report.md: %s", report);

    read_reference("ref.exr", json, sizeof json);
    CHECK(write_reference("ref.exr", "old.exr", json, 1) == 0, "writing an old-style reference");
    char none[16];
    CHECK(read_reference("old.exr", none, sizeof none) == 0 && exists("old.exr.json"), "old.exr is not old-style");
    CHECK(run("bench --reference old.exr --methods pt --times 0.05 --quiet --out f2") == 0, "an old reference: %s",
          err_text);
    read_file("f2/report.md", report, sizeof report);
    CHECK(strstr(report, "- reference: `old.exr`, pt, 1024 spp") != NULL, "f2/report.md: %s", report);
    expect_refusal("bench --reference old.exr --size 32x16 --times 0.05 --out f3", "24x16");
    expect_refusal("bench other.gltf --reference old.exr --times 0.05 --out f4", "another scene");

    /* A reference rendered by another material model is stale, in the header or a sidecar:
     * refused, saying so and what to do; without a model recorded it predates the stamp. */
    CHECK(strstr(json, "\"model\": \"glint-bsdf-") != NULL, "the description has no material model: %s", json);
    static char edited[8192];
    const char *at = strstr(json, "\"model\": ");
    const char *eol = at ? strchr(at, '\n') : NULL;
    if (at && eol) {
        for (int sidecar = 0; sidecar < 2; sidecar++) {
            char name[32], args[128];
            snprintf(edited, sizeof edited, "%.*s%s", (int)(at - json), json, eol + 1);
            snprintf(name, sizeof name, "stale%d.exr", sidecar);
            CHECK(write_reference("ref.exr", name, edited, sidecar) == 0, "writing %s", name);
            snprintf(args, sizeof args, "bench --reference %s --times 0.05 --out stale-out%d", name, sidecar);
            expect_refusal(args, "rendered by an older glint (no material model recorded), not this glint's material "
                                 "model 'glint-bsdf-");
            expect_refusal(args, "re-render the reference");
            snprintf(edited, sizeof edited, "%.*s\"model\": \"glint-bsdf-1\",%s", (int)(at - json), json, eol);
            snprintf(name, sizeof name, "older%d.exr", sidecar);
            CHECK(write_reference("ref.exr", name, edited, sidecar) == 0, "writing %s", name);
            snprintf(args, sizeof args, "bench --reference %s --times 0.05 --out older-out%d", name, sidecar);
            expect_refusal(args, "rendered by material model 'glint-bsdf-1', not this glint's material model");
        }
    }
    CHECK(!exists("stale-out0") && !exists("stale-out1") && !exists("older-out0") && !exists("older-out1"),
          "a refused bench created its directory");

    write_text("copy.exr.json", "{\"glint_reference\": 1, \"scene\": \"x\"");
    CHECK(run("bench --reference copy.exr --methods pt --times 0.05 --quiet --out f5") == 0,
          "a stale sidecar beside a reference: %s", err_text);
    CHECK(!exists("f3") && !exists("f4"), "a refused bench created its directory");
}

/* The reference ref.exr with the description text as shape<k>.exr (in its header) or, when
 * sidecar is set, as shape<k>s.exr with text in shape<k>s.exr.json beside it: a bench of it must
 * be refused with one error line naming the file and problem, and create nothing. */
static void expect_bad_description(int k, int sidecar, const char *text, const char *problem) {
    char exr[64], args[256], needle[256];
    snprintf(exr, sizeof exr, "shape%d%s.exr", k, sidecar ? "s" : "");
    CHECK(write_reference("ref.exr", exr, text, sidecar) == 0, "writing %s", exr);
    snprintf(args, sizeof args, "bench --reference %s --times 0.05 --out out-%s", exr, exr);
    if (sidecar)
        snprintf(needle, sizeof needle, "%s.json: not a glint reference sidecar (%s", exr, problem);
    else
        snprintf(needle, sizeof needle, "%s: bad glint.reference header attribute (%s", exr, problem);
    expect_refusal(args, needle);
    snprintf(args, sizeof args, "out-%s", exr);
    CHECK(!exists(args), "a refused bench created %s", args);
}

/* Descriptions of unexpected shape, in the header or a sidecar, as a hand edit, another program
 * or a broken disk might leave them: wrong types, missing keys, nesting deeper than any parser's
 * stack, numbers past every range, not JSON at all. Each is one error line naming the file and
 * what is wrong, never a crash. A seed above 2^53, beyond a double's integers, reads back
 * exactly. */
static void test_description_shapes(void) {
    static char good[8192];
    read_reference("ref.exr", good, sizeof good);
    CHECK(strstr(good, "\"seed\": 7,") && strstr(good, "\"width\": 24,"), "ref.exr: %s", good);
    static char huge[420] = "\"spp\": 1"; /* 400 digits: past a double's range */
    memset(huge + strlen(huge), '0', 400);
    struct {
        const char *from, *to, *problem; /* to replaces the first from in the good description */
    } edits[] = {
        {"\"width\": 24", "\"width\": \"24\"", "missing or bad \"width\""},
        {"\"width\": 24", "\"width\": 1e999", "missing or bad \"width\""},
        {"\"width\": 24", "\"width\": 24.5", "missing or bad \"width\""},
        {"\"height\": 16", "\"height\": -16", "missing or bad \"height\""},
        {"\"spp\": 1024", "\"spp\": 123456789012345678901234567890", "missing or bad \"spp\""},
        {"\"spp\": 1024", huge, "missing or bad \"spp\""},
        {"\"seed\": 7", "\"seed\": -7", "missing or bad \"seed\""},
        {"\"seed\": 7", "\"seed\": 18446744073709551616", "missing or bad \"seed\""},
        {"\"seed\": 7", "\"seed\": \"7\"", "missing or bad \"seed\""},
        {"\"scene_hash\"", "\"scene_hush\"", "missing or bad \"scene_hash\""},
        {"\"scene\": ", "\"scene\": [[[[[[[[1]]]]]]]], \"x\": ", "missing or bad \"scene\""},
        {"\"index\": 0", "\"index\": null", "missing or bad \"camera index\""},
        {"\"position\": [", "\"position\": [1, ", "missing or bad \"camera position\""},
        {"\"yfov\": ", "\"yfov\": 1e300, \"x\": ", "missing or bad \"camera yfov\""},
        {"\"camera\": {", "\"camera\": 5, \"cam\": {", "missing or bad \"camera index\""},
        {"\"highlights_layer\": false", "\"highlights_layer\": 0", "missing or bad \"highlights_layer\""},
        {"\"method\": \"pt\"", "\"method\": \"a method name longer than any\"", "missing or bad \"method\""},
        {"\"glint_reference\": 1,", "", "missing or bad \"glint_reference\""},
        {"\"model\": \"", "\"model\": 2, \"m\": \"", "missing or bad \"model\""},
        {"{", "[", "not JSON, line 2)"},
    };
    enum { N = sizeof edits / sizeof edits[0], EXTRA = 5 };
    static char text[1 << 21];
    for (int sidecar = 0; sidecar < 2; sidecar++)
        for (int k = 0; k < N; k++) {
            const char *at = strstr(good, edits[k].from);
            CHECK(at != NULL, "the good description lacks '%s'", edits[k].from);
            if (!at) continue;
            snprintf(text, sizeof text, "%.*s%s%s", (int)(at - good), good, edits[k].to, at + strlen(edits[k].from));
            expect_bad_description(k, sidecar, text, edits[k].problem);
        }
    /* Nesting a million deep, a top-level value that is no object, trailing text, an empty
     * description, more than the 1 MiB a description may take. */
    const char *problems[EXTRA] = {"not JSON, line 1", "not a JSON object", "not JSON, line", "not JSON, line 1",
                                   "too large"};
    for (int sidecar = 0; sidecar < 2; sidecar++)
        for (int k = 0; k < EXTRA; k++) {
            size_t n = 0;
            if (k == 0) {
                n = (size_t)snprintf(text, sizeof text, "{\"glint_reference\": 1, \"x\": ");
                memset(text + n, '[', 1000000);
                n += 1000000;
            } else if (k == 1) {
                n = (size_t)snprintf(text, sizeof text, "[%s]", good);
            } else if (k == 2) {
                n = (size_t)snprintf(text, sizeof text, "%s}", good);
            } else if (k == 4) {
                n = (size_t)snprintf(text, sizeof text, "%s", good);
                memset(text + n, ' ', (1 << 20) + 1);
                n += (1 << 20) + 1;
            }
            text[n] = 0;
            expect_bad_description(N + k, sidecar, text, problems[k]);
        }
    /* 2^53 + 1 and 2^64 - 1: a double would read 2^53 and 2^64, and the bench's seeds just below
     * would not seem to hold the reference's. */
    const char *at = strstr(good, "\"seed\": 7");
    static const char *const seeds[2][2] = {{"9007199254740992", "9007199254740993"},
                                            {"18446744073709551614", "18446744073709551615"}};
    char args[256], needle[256];
    for (int sidecar = 0; sidecar < 2; sidecar++)
        for (int k = 0; at && k < 2; k++) {
            snprintf(text, sizeof text, "%.*s\"seed\": %s%s", (int)(at - good), good, seeds[k][1], at + 9);
            CHECK(write_reference("ref.exr", "seedbig.exr", text, sidecar) == 0, "writing seedbig.exr");
            snprintf(args, sizeof args, "bench --reference seedbig.exr --seed %s --seeds 2 --times 0.05 --out seedbig",
                     seeds[k][0]);
            snprintf(needle, sizeof needle, "the reference's seed %s;", seeds[k][1]);
            expect_usage(args, needle);
        }
    CHECK(!exists("seedbig"), "a refused bench created seedbig");
}

/* References must read back exactly. OpenEXR 3.1's C core, which glint once wrote with, kept ZIP
 * output exactly as long as the raw chunk, which readers take for raw pixels (OpenEXR issue
 * #2306); partly compressible chunks of every length between all-zero and all-random meet that
 * length now and then, so any writer is held to it. */
static void test_exr_round_trip(void) {
    enum { W = 16, H = 2, N = 3 * W * H };
    float rgb[N];
    uint32_t x = 12345u;
    int bad = 0, cases = 0;
    char path[1024], err[1024];
    snprintf(path, sizeof path, "%s/roundtrip.exr", tmp);
    for (int seed = 0; seed < 4; seed++)
        for (int k = 0; k <= N; k++, cases++) {
            for (int i = 0; i < N; i++) {
                x = x * 1664525u + 1013904223u;
                /* the first k values random in [0, 2), the rest repeat a constant */
                rgb[i] = i < k ? (float)(x >> 8) * (1.0f / 8388608.0f) : 0.25f;
            }
            exr_layer layer = {"", rgb};
            exr_image ex;
            if (exr_save_layers(path, W, H, &layer, 1, WRITE_REPLACE, err, sizeof err) != 0 ||
                exr_image_load(path, &ex, err, sizeof err) != 0) {
                bad++;
                continue;
            }
            const float *c[3] = {exr_image_channel(&ex, "R"), exr_image_channel(&ex, "G"), exr_image_channel(&ex, "B")};
            int same = c[0] && c[1] && c[2];
            for (int i = 0; same && i < W * H; i++)
                for (int j = 0; j < 3; j++) same &= memcmp(&c[j][i], &rgb[3 * i + j], sizeof(float)) == 0;
            bad += !same;
            exr_image_free(&ex);
        }
    CHECK(bad == 0, "%d of %d EXR round trips differ", bad, cases);
}

/* The reference as OpenEXR's own tools rewrite it (the openexr package): tiled PIZ and DWAA by
 * exrmaketiled, both in one multi-part file by exrmultipart. Each keeps the header's description
 * and is accepted by glint bench; its pixels are the original's (exactly for PIZ and the
 * multi-part file's first part, within DWAA's loss). */
static void test_reference_by_openexr_tools(void) {
    int rc = system("command -v exrmaketiled >/dev/null && command -v exrmultipart >/dev/null");
    CHECK(rc == 0, "exrmaketiled and exrmultipart (package openexr) are not installed");
    if (rc != 0) return;
    char cmd[4096];
    snprintf(cmd, sizeof cmd,
             "cd '%s' && exrmaketiled -z piz ref.exr ref-piz.exr >/dev/null && exrmaketiled -z dwaa ref.exr "
             "ref-dwaa.exr >/dev/null && exrmultipart -combine -i ref-piz.exr ref-dwaa.exr -o ref-multi.exr >/dev/null",
             tmp);
    CHECK(system(cmd) == 0, "the OpenEXR tools failed: %s", cmd);
    const char *refs[] = {"ref-piz.exr", "ref-dwaa.exr", "ref-multi.exr"};
    const double tolerance[] = {0.0, 0.02, 0.0}; /* largest difference relative to the image's largest value */
    char path[1024], err[1024];
    snprintf(path, sizeof path, "%s/ref.exr", tmp);
    exr_image orig;
    if (exr_image_load(path, &orig, err, sizeof err) != 0) {
        CHECK(0, "ref.exr: %s", err);
        return;
    }
    const float *o = exr_image_channel(&orig, "R");
    size_t n = (size_t)orig.width * (size_t)orig.height;
    double peak = 0.0;
    for (size_t i = 0; o && i < n; i++) peak = fmax(peak, o[i]);
    for (int k = 0; k < 3; k++) {
        char args[512], csv[64];
        snprintf(args, sizeof args, "bench --reference %s --methods pt --times 0.02 --seed 40 --quiet --out t%d",
                 refs[k], k);
        rc = run(args);
        CHECK(rc == 0, "%s: exit %d: %s", refs[k], rc, err_text);
        snprintf(csv, sizeof csv, "t%d/results.csv", k);
        row rows[4];
        int nr = parse_csv(csv, rows, 4);
        CHECK(nr == 1 && isfinite(rows[0].rel_l2), "%s: %d rows", refs[k], nr);
        snprintf(path, sizeof path, "%s/%s", tmp, refs[k]);
        exr_image img;
        if (exr_image_load(path, &img, err, sizeof err) != 0) {
            CHECK(0, "%s: %s", refs[k], err);
            continue;
        }
        const float *r = exr_image_channel(&img, "R");
        double worst = 0.0;
        for (size_t i = 0; r && o && i < n && img.width == orig.width && img.height == orig.height; i++)
            worst = fmax(worst, fabs((double)r[i] - o[i]));
        CHECK(r && img.width == orig.width && img.height == orig.height && worst <= tolerance[k] * peak,
              "%s: pixels differ from the original's by up to %g (peak %g)", refs[k], worst, peak);
        exr_image_free(&img);
    }
    exr_image_free(&orig);
}

int main(int argc, char **argv) {
    int start = harness_start(argc, argv, "bench");
    if (start != 0) return start;
    test_exr_round_trip();
    test_reference_header();
    test_reference_by_openexr_tools();
    test_bench_run();
    test_sweeps_and_highlights();
    test_seeds();
    test_refusals();
    test_reference_files();
    test_description_shapes();
    return check_exit("test_bench");
}
