/* glint bench's presets and the options they are made of, each on a tiny image and budget: the
 * runs a preset promises, in order, with their settings in the params column; the component it
 * reports; the passes each run times (a pass a run skips reads exactly 0 s, the passes' thread
 * time fits in the threads' render time, merging only where lobes merge); the noise and bias
 * split over its seeds; its report's sections. --run, --only and --plan on their own, an option
 * of the user's replacing the preset's, and every misuse refused with one error line. Never a
 * timing: the budgets only bound how long each render runs.
 * Usage: test_bench_presets PATH_TO_GLINT */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_harness.h"
#include "check.h"
#include "cli_harness.h"

enum { PATHS = 0, DIRECT, VIRTUAL_LIGHTS, GATHER, HIGHLIGHTS }; /* pass_s */
enum { ALL = 0, E_DIRECT, E_INDIRECT, E_HIGHLIGHTS };           /* err */

static row rows[256];
static summary_row sums[128];

static int bench(const char *args, const char *out) {
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "bench %s --threads 2 --quiet --out %s", args, out);
    int rc = run(cmd);
    CHECK(rc == 0, "'%s': exit %d: %s", cmd, rc, err_text);
    return rc;
}

static int results(const char *dir) {
    char p[256];
    snprintf(p, sizeof p, "%s/results.csv", dir);
    return parse_csv(p, rows, 256);
}

static int summary(const char *dir) {
    char p[256];
    snprintf(p, sizeof p, "%s/summary.csv", dir);
    return parse_summary(p, sums, 128);
}

static int report_has(const char *dir, const char *text) {
    static char md[1 << 17];
    char p[256];
    snprintf(p, sizeof p, "%s/report.md", dir);
    read_file(p, md, sizeof md);
    return strstr(md, text) != NULL;
}

/* The passes' thread time fits in the threads' render time (the CSV's rounding aside), and the
 * virtual lights' wall time in the render time. */
static void check_times(const row *r, int i) {
    double threads = r->pass_s[PATHS] + r->pass_s[DIRECT] + r->pass_s[GATHER] + r->pass_s[HIGHLIGHTS];
    CHECK(r->threads == 2 && threads <= 2.0 * r->seconds * (1.0 + 1e-3) + 1e-5 &&
              r->pass_s[VIRTUAL_LIGHTS] <= r->seconds * (1.0 + 1e-3) + 1e-5 && r->merge_s >= 0.0 &&
              r->merge_s <= r->pass_s[HIGHLIGHTS] + 1e-6,
          "row %d (%s %s): %d threads, passes %g s and virtual lights %g s in %g s, merging %g s of %g s", i, r->method,
          r->params, r->threads, threads, r->pass_s[VIRTUAL_LIGHTS], r->seconds, r->merge_s, r->pass_s[HIGHLIGHTS]);
}

/* Rows n0.. of one run: this method and params, and seeds x budgets rows. */
static void check_run(int at, int per_run, const char *method, const char *params) {
    for (int i = at; i < at + per_run; i++)
        CHECK(strcmp(rows[i].method, method) == 0 && strcmp(rows[i].params, params) == 0,
              "row %d: '%s' '%s', expected '%s' '%s'", i, rows[i].method, rows[i].params, method, params);
}

static void test_headline(void) {
    if (bench("--reference ref.exr --preset headline --times 0.02", "head")) return;
    int n = results("head"), ns = summary("head");
    CHECK(n == 6 && ns == 3, "headline: %d rows, %d summary rows; expected 3 methods x 2 seeds, 3", n, ns);
    const char *methods[3] = {"pt", "vsl", "vsl+hl"};
    for (int k = 0; k < 3 && n == 6; k++) {
        check_run(2 * k, 2, methods[k], "");
        CHECK(rows[2 * k].seed == 8 && rows[2 * k + 1].seed == 9, "%s: seeds %lld, %lld", methods[k], rows[2 * k].seed,
              rows[2 * k + 1].seed);
    }
    for (int i = 0; i < ns; i++) {
        CHECK(sums[i].seeds == 2 && strcmp(sums[i].component, "all") == 0, "headline summary %d: %d seeds, %s", i,
              sums[i].seeds, sums[i].component);
        check_identity(&sums[i], sums[i].method);
    }
    CHECK(report_has("head", "- preset: `headline`"), "the report does not name the preset");
    /* The user's options that take one value replace the preset's. */
    if (bench("--reference ref.exr --preset headline --methods pt --seeds 1 --times 0.02", "head2")) return;
    n = results("head2");
    CHECK(n == 1 && strcmp(rows[0].method, "pt") == 0 && rows[0].seed == 8, "headline, --methods pt --seeds 1: %d rows",
          n);
}

static void test_vsl_paper(void) {
    if (bench("--reference ref.exr --preset vsl-paper --times 0.02 --seeds 1", "vsl")) return;
    int n = results("vsl"), ns = summary("vsl");
    CHECK(n == 6 && ns == 6, "vsl-paper: %d rows, %d summary rows, expected 6 runs", n, ns);
    const char *runs[6][2] = {{"pt", ""},  {"vpl", "trace-glossy=off"}, {"vsl", "trace-glossy=off"},
                              {"vsl", ""}, {"vsl", "candidates=4"},     {"vsl", "radius-shrink=0.7"}};
    for (int k = 0; k < n && n == 6; k++) {
        check_run(k, 1, runs[k][0], runs[k][1]);
        check_times(&rows[k], k);
        /* The reported component is the indirect light: the summary's error is that column's. */
        CHECK(ns == 6 && strcmp(sums[k].component, "indirect") == 0 && isfinite(rows[k].err[E_INDIRECT]) &&
                  fabs(sums[k].rel_l2 - rows[k].err[E_INDIRECT]) <= 1e-5 * rows[k].err[E_INDIRECT],
              "vsl-paper run %d: summary %s %g, results' indirect %g", k, sums[k].component, sums[k].rel_l2,
              rows[k].err[E_INDIRECT]);
    }
}

static void test_fig8(void) {
    if (bench("--reference ref.exr --preset fig8 --times 0.02", "fig8")) return;
    int n = results("fig8");
    CHECK(n == 12, "fig8: %d rows, expected 7 radius multipliers + 5 cluster counts", n);
    const char *values[12] = {"radius-mult=1",  "radius-mult=2",  "radius-mult=4",  "radius-mult=8",
                              "radius-mult=12", "radius-mult=16", "radius-mult=24", "columns=64",
                              "columns=128",    "columns=256",    "columns=512",    "columns=1024"};
    for (int k = 0; k < n && n == 12; k++) {
        char params[96];
        snprintf(params, sizeof params, "trace-glossy=off vsl-count=4096 %s", values[k]);
        check_run(k, 1, "vsl", params);
    }
    CHECK(report_has("fig8", "## Sweep: radius-mult") && report_has("fig8", "## Sweep: columns") &&
              report_has("fig8", "| columns | vsl trace-glossy=off vsl-count=4096 |"),
          "fig8: the report lacks a sweep's table");
    CHECK(exists("fig8/sweep-radius-mult.svg") && exists("fig8/sweep-columns.png"), "fig8: sweep plots missing");
}

static void test_highlights(void) {
    if (bench("--reference ref.exr --preset highlights --times 0.02,0.04", "hl")) return;
    int n = results("hl"), ns = summary("hl");
    CHECK(n == 60 && ns == 30, "highlights: %d rows, %d summary rows; expected 5 settings x 3 N x 2 seeds x 2 budgets",
          n, ns);
    const char *settings[5] = {"merge=trace", "merge=off", "clusters=1", "clusters=2", "clusters=4"};
    const int rays[3] = {8, 16, 32};
    for (int k = 0; k < 15 && n == 60; k++) {
        char params[96];
        snprintf(params, sizeof params, "%s secondary-rays=%d", settings[k / 3], rays[k % 3]);
        check_run(4 * k, 4, "vsl+hl", params);
    }
    for (int i = 0; i < n; i++) {
        const row *r = &rows[i];
        /* Only the highlights are rendered: the other errors are not measured, the passes of the
         * virtual lights never run, the estimator does; lobes merge only where they are merged. */
        CHECK(isnan(r->err[ALL]) && isnan(r->err[E_DIRECT]) && isnan(r->err[E_INDIRECT]) &&
                  isfinite(r->err[E_HIGHLIGHTS]) && r->err[E_HIGHLIGHTS] > 0.0,
              "highlights row %d: errors %g %g %g %g", i, r->err[0], r->err[1], r->err[2], r->err[3]);
        CHECK(r->pass_s[PATHS] == 0.0 && r->pass_s[VIRTUAL_LIGHTS] == 0.0 && r->pass_s[GATHER] == 0.0 &&
                  r->pass_s[HIGHLIGHTS] > 0.0 && (strncmp(r->params, "merge=", 6) != 0 || r->merge_s == 0.0),
              "highlights row %d (%s): passes %g %g %g %g %g, merging %g", i, r->params, r->pass_s[0], r->pass_s[1],
              r->pass_s[2], r->pass_s[3], r->pass_s[4], r->merge_s);
        check_times(r, i);
    }
    for (int i = 0; i < ns; i++) {
        CHECK(sums[i].seeds == 2 && strcmp(sums[i].component, "highlights") == 0, "highlights summary %d: %d seeds, %s",
              i, sums[i].seeds, sums[i].component);
        check_identity(&sums[i], "highlights");
    }
    CHECK(report_has("hl", "## Where the time goes") && report_has("hl", "| vsl+hl clusters=4 secondary-rays=32 | ") &&
              report_has("hl", "| secondary-rays | vsl+hl merge=trace | vsl+hl merge=off | vsl+hl clusters=1 |"),
          "highlights: the report lacks the time per pass or the sweep's table");
}

static void test_highlights_whole(void) {
    if (bench("--reference ref.exr --preset highlights-whole --times 0.02 --seeds 1", "hlw")) return;
    int n = results("hlw");
    CHECK(n == 11, "highlights-whole: %d rows, expected pt + 5 settings x 2 N", n);
    if (n != 11) return;
    check_run(0, 1, "pt", "");
    for (int i = 0; i < n; i++) {
        const row *r = &rows[i];
        int pt = i == 0;
        CHECK(isfinite(r->err[ALL]) && isfinite(r->err[E_DIRECT]) && isfinite(r->err[E_INDIRECT]) &&
                  isfinite(r->err[E_HIGHLIGHTS]),
              "highlights-whole row %d: errors %g %g %g %g", i, r->err[0], r->err[1], r->err[2], r->err[3]);
        /* The path tracer times its paths as one pass; vsl+hl runs every pass. */
        CHECK(pt ? r->pass_s[PATHS] > 0.0 && r->pass_s[DIRECT] == 0.0 && r->pass_s[GATHER] == 0.0 &&
                       r->pass_s[HIGHLIGHTS] == 0.0
                 : r->pass_s[PATHS] == 0.0 && r->pass_s[DIRECT] > 0.0 && r->pass_s[GATHER] > 0.0 &&
                       r->pass_s[HIGHLIGHTS] > 0.0,
              "highlights-whole row %d (%s): passes %g %g %g %g %g", i, r->method, r->pass_s[0], r->pass_s[1],
              r->pass_s[2], r->pass_s[3], r->pass_s[4]);
        check_times(r, i);
    }
}

/* Against a direct-light reference (max depth 1) the plan drops the virtual lights, which the
 * forced plan still traces. */
static void test_plan(void) {
    if (bench("--reference ref1.exr --preset plan --component direct --times 0.02,0.04", "plan")) return;
    int n = results("plan"), ns = summary("plan");
    CHECK(n == 8 && ns == 4, "plan: %d rows, %d summary rows; expected 2 plans x 2 seeds x 2 budgets", n, ns);
    if (n != 8) return;
    check_run(0, 4, "vsl+hl", "plan=auto");
    check_run(4, 4, "vsl+hl", "plan=full");
    for (int i = 0; i < n; i++) {
        const row *r = &rows[i];
        int full = i >= 4;
        CHECK(full ? r->pass_s[VIRTUAL_LIGHTS] > 0.0
                   : r->pass_s[VIRTUAL_LIGHTS] == 0.0 && r->pass_s[GATHER] == 0.0 && r->pass_s[HIGHLIGHTS] == 0.0,
              "plan row %d (%s): virtual lights %g s, gather %g s, highlights %g s", i, r->params,
              r->pass_s[VIRTUAL_LIGHTS], r->pass_s[GATHER], r->pass_s[HIGHLIGHTS]);
        CHECK(isfinite(r->err[E_DIRECT]), "plan row %d: direct error %g", i, r->err[E_DIRECT]);
        check_times(r, i);
    }
    for (int i = 0; i < ns; i++) check_identity(&sums[i], "plan");
    CHECK(report_has("plan", "## Equal error") && report_has("plan", "| plan | vsl+hl |") &&
              report_has("plan", "| auto |") && report_has("plan", "| full |"),
          "plan: the report lacks the equal-error reading or the plans' table");
}

/* --run on its own: after --methods, in order, a sweep applied on top of a run's own settings;
 * --plan for every run, in the report. */
static void test_runs(void) {
    if (bench("--reference ref.exr --methods pt --run vsl:trace-glossy=off --run vsl+hl:clusters=2,plan=full "
              "--sweep radius-mult=1,4 --plan full --times 0.02",
              "runs"))
        return;
    int n = results("runs");
    CHECK(n == 5, "runs: %d rows, expected pt + 2 x 2 radius multipliers", n);
    if (n != 5) return;
    check_run(0, 1, "pt", "");
    check_run(1, 1, "vsl", "trace-glossy=off radius-mult=1");
    check_run(2, 1, "vsl", "trace-glossy=off radius-mult=4");
    check_run(3, 1, "vsl+hl", "clusters=2 plan=full radius-mult=1");
    check_run(4, 1, "vsl+hl", "clusters=2 plan=full radius-mult=4");
    CHECK(report_has("runs", "`--plan full`") && report_has("runs", "| radius-mult | vsl trace-glossy=off | vsl+hl "
                                                                    "clusters=2 plan=full |"),
          "runs: the report lacks --plan full or the sweep's columns");
}

static void test_refusals(void) {
    CHECK(run("bench --help") == 0 && strstr(out_text, "--preset NAME") && strstr(out_text, "--run METHOD") &&
              strstr(out_text, "--only LIST") && strstr(out_text, "  vsl-paper ") &&
              strstr(out_text, "--run vpl:trace-glossy=off"),
          "bench --help lacks the presets or their options: %s", out_text);
    const char *usage[][2] = {
        {"--preset nope", "nope"},
        {"--preset plan --preset fig8", "given twice"},
        {"--preset highlights --run pt", "pt renders whole paths"},
        {"--only highlights --methods vsl+hl", "--component all"},
        {"--only glow --methods vsl", "--only"},
        {"--run vsl:secondary-rays=8", "does not apply"},
        {"--run vsl:bogus=1", "bogus"},
        {"--run vsl:plan=sometimes", "--plan"},
        {"--run vsl:radius-mult", "NAME=VALUE"},
        {"--run vsl:radius-mult=2 --sweep radius-mult=1,4", "sets it already"},
        {"--run vsl --run vsl", "listed twice"},
        {"--run nope", "nope"},
        {"--sweep plan=auto,sometimes", "--plan"},
    };
    char cmd[512], dir[32];
    for (size_t k = 0; k < sizeof usage / sizeof usage[0]; k++) {
        snprintf(dir, sizeof dir, "u%zu", k);
        snprintf(cmd, sizeof cmd, "bench --reference ref.exr %s --times 0.02 --out %s", usage[k][0], dir);
        expect_usage(cmd, usage[k][1]);
        CHECK(!exists(dir), "'%s' created %s", cmd, dir);
    }
    /* At max depth 1 no highlight pass runs: timing it alone is refused. */
    expect_refusal("bench --reference ref1.exr --only highlights --component highlights --methods vsl+hl --times 0.02 "
                   "--quiet --out u-depth1",
                   "no highlight pass");
}

int main(int argc, char **argv) {
    int start = harness_start(argc, argv, "bench_presets");
    if (start != 0) return start;
    int rc = run("render --spp 256 --size 24x16 --max-depth 3 --seed 7 --highlights-layer --out ref.exr --quiet");
    CHECK(rc == 0, "reference: exit %d: %s", rc, err_text);
    rc = run("render --spp 64 --size 24x16 --max-depth 1 --seed 7 --highlights-layer --out ref1.exr --quiet");
    CHECK(rc == 0, "depth-1 reference: exit %d: %s", rc, err_text);
    if (check_failures_) return check_exit("test_bench_presets");
    test_refusals();
    test_headline();
    test_vsl_paper();
    test_fig8();
    test_highlights();
    test_highlights_whole();
    test_plan();
    test_runs();
    return check_exit("test_bench_presets");
}
