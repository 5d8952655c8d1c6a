/* glint render --shard and glint merge, run as a user would: four shards of one seed merged equal
 * the whole render to float rounding (they are its frames), means and variances both; a merge of
 * another seed, and one shard alone, agree with a render of the same spp within the standard
 * errors the two record, and the merge's noise estimate with the distance between them; a missing
 * shard, a repeated one (the same file twice, a copy, a merge holding it), parts of another seed,
 * method, parameters, size or total spp, and files that are no shard refused with one error line;
 * --allow-partial and a later merge of the rest; --shard's usage errors; the merged reference
 * usable by bench.
 * Usage: test_merge PATH_TO_GLINT */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "cli_harness.h"
#include "film.h"
#include "image_io.h"
#include "merge_stats.h"

#define SCENE "builtin:atelier --size 32x24 --max-depth 2 --threads 2 --quiet"
/* Direct light only: noise light-tailed enough for 64 samples to judge each pixel's variance */
#define DIRECT "builtin:doorway --size 32x24 --max-depth 1 --threads 2 --quiet"
#define BOUNCE "builtin:doorway --size 32x24 --max-depth 2 --threads 2 --quiet"

static int load(const char *name, exr_image *ex) {
    char p[1024], err[1024];
    snprintf(p, sizeof p, "%s/%s", tmp, name);
    if (exr_image_load(p, ex, err, sizeof err) != 0) {
        fprintf(stderr, "%s\n", err);
        memset(ex, 0, sizeof *ex);
        return -1;
    }
    return 0;
}

/* A number after "KEY": in a reference's description; NAN when absent. */
static double described(const char *name, const char *key) {
    char text[16384], pat[80];
    if (!read_reference(name, text, sizeof text)) return NAN;
    snprintf(pat, sizeof pat, "\"%s\":", key);
    const char *p = strstr(text, pat);
    return p ? strtod(p + strlen(pat), NULL) : NAN;
}

/* The error line of the last run holds want, and nothing was written to out. */
static void check_refused(const char *args, const char *want, const char *out) {
    char p[1024];
    snprintf(p, sizeof p, "%s/%s", tmp, out);
    remove(p);
    int rc = run(args);
    CHECK(rc == 1 || rc == 2, "merge %s: exit %d", args, rc);
    CHECK(strstr(err_text, want) != NULL && strncmp(err_text, "glint: error: ", 14) == 0 &&
              strchr(err_text, '\n') == err_text + strlen(err_text) - 1,
          "merge %s: stderr '%s', expected one error line with '%s'", args, err_text, want);
    FILE *f = fopen(p, "rb");
    CHECK(f == NULL, "merge %s: wrote %s", args, out);
    if (f) fclose(f);
}

/* Every channel of a equals b's to float rounding: relative rel (the means: the parts' floats
 * weighted again), absolute abs_tol for what cancels (variances near zero). */
static void check_same_pixels(const char *a_name, const char *b_name, double rel, double abs_tol, int channels) {
    exr_image a, b;
    if (load(a_name, &a) || load(b_name, &b)) {
        CHECK(0, "cannot load %s or %s", a_name, b_name);
        return;
    }
    size_t n = (size_t)a.width * (size_t)a.height;
    int compared = 0;
    for (int c = 0; c < b.num_channels; c++) {
        const float *pa = exr_image_channel(&a, b.names[c]), *pb = b.planes[c];
        CHECK(pa != NULL, "%s has no channel %s", a_name, b.names[c]);
        if (!pa) continue;
        double worst = 0.0;
        size_t at = 0;
        for (size_t i = 0; i < n; i++) {
            double d = fabs((double)pa[i] - (double)pb[i]) - rel * fmax(fabs(pa[i]), fabs(pb[i]));
            if (d > worst) worst = d, at = i;
        }
        CHECK(worst <= abs_tol, "%s %s pixel %zu: %.9g, %s %.9g", a_name, b.names[c], at, (double)pa[at], b_name,
              (double)pb[at]);
        compared++;
    }
    CHECK(compared == channels, "%d channels compared, expected %d", compared, channels);
    exr_image_free(&a);
    exr_image_free(&b);
}

static void test_exact(void) {
    /* 18 spp in 4 shards: 5, 5, 4, 4 frames (0,4,8,12,16 / 1,5,...). */
    char args[512];
    for (int i = 0; i < 4; i++) {
        snprintf(args, sizeof args, "render " SCENE " --spp 18 --shard %d/4 --out s%d.exr", i, i);
        CHECK(run(args) == 0, "%s: %s", args, err_text);
    }
    CHECK(described("s0.exr", "spp") == 5 && described("s3.exr", "spp") == 4, "shards' spp %g, %g",
          described("s0.exr", "spp"), described("s3.exr", "spp"));
    CHECK(run("render " SCENE " --spp 18 --shard 0/1 --out whole.exr") == 0, "%s", err_text);
    CHECK(run("render " SCENE " --spp 18 --out plain.exr") == 0, "%s", err_text);
    CHECK(run("merge s2.exr s0.exr s3.exr s1.exr --out merged.exr") == 0, "%s", err_text);
    CHECK(strstr(out_text, "merged 4 parts (18 spp) into merged.exr") != NULL, "%s", out_text);
    /* Means: each part's float mean weighted again; variances: the same sums, cancelling. */
    check_same_pixels("merged.exr", "whole.exr", 4e-7, 1e-6, 21); /* 3 layers, their variances, dropped */
    check_same_pixels("merged.exr", "plain.exr", 4e-7, 0.0, 9);   /* the frames of a plain render */
    CHECK_NEAR(described("merged.exr", "rel_l2_noise"), described("whole.exr", "rel_l2_noise"),
               1e-5 * described("whole.exr", "rel_l2_noise"), "the merged noise estimate is the whole render's");
    CHECK(described("merged.exr", "spp") == 18, "merged spp %g", described("merged.exr", "spp"));

    /* Partial, then the rest: the same image again. */
    CHECK(run("merge s0.exr s3.exr --out half.exr --allow-partial") == 0, "%s", err_text);
    CHECK(strstr(err_text, "glint: warning: half.exr: shards 1, 2 of 4 missing") != NULL, "%s", err_text);
    CHECK(described("half.exr", "spp") == 9, "partial spp %g", described("half.exr", "spp"));
    CHECK(run("merge half.exr s1.exr s2.exr --out again.exr") == 0, "%s", err_text);
    check_same_pixels("again.exr", "whole.exr", 4e-7, 1e-6, 21);
    /* An existing --out is replaced, as glint render's. */
    CHECK(run("merge s0.exr s1.exr s2.exr s3.exr --out again.exr --quiet") == 0 && out_text[0] == 0, "%s", err_text);
}

/* Another seed: the merge and a render of as many samples differ only by their noise. */
static void test_statistics(void) {
    char args[512];
    for (int i = 0; i < 4; i++) {
        snprintf(args, sizeof args, "render " DIRECT " --spp 64 --seed 11 --shard %d/4 --out t%d.exr", i, i);
        CHECK(run(args) == 0, "%s: %s", args, err_text);
    }
    CHECK(run("merge t0.exr t1.exr t2.exr t3.exr --out tm.exr") == 0, "%s", err_text);
    CHECK(run("render " DIRECT " --spp 64 --seed 12 --shard 0/1 --out ts.exr") == 0, "%s", err_text);
    merge_stats st;
    char pa[1024], pb[1024];
    snprintf(pa, sizeof pa, "%s/tm.exr", tmp);
    snprintf(pb, sizeof pb, "%s/ts.exr", tmp);
    CHECK(merge_stats_compare(pa, pb, &st) == 0, "cannot compare tm.exr and ts.exr");
    CHECK(merge_stats_agree(&st), "the merge and a render of another seed disagree (above)");
    /* A shard alone is a render too, here with a bounce: shards once took every N-th frame, whose
     * Sobol points (every other one for N = 2) cover half of a dimension, and such a shard
     * converged to another image (0.30 of |z| below 0.674). */
    CHECK(run("render " BOUNCE " --spp 512 --seed 13 --shard 1/2 --out th.exr") == 0, "%s", err_text);
    CHECK(run("render " BOUNCE " --spp 256 --seed 12 --shard 0/1 --out tw.exr") == 0, "%s", err_text);
    snprintf(pa, sizeof pa, "%s/th.exr", tmp);
    snprintf(pb, sizeof pb, "%s/tw.exr", tmp);
    CHECK(merge_stats_compare(pa, pb, &st) == 0, "cannot compare th.exr and tw.exr");
    CHECK(merge_stats_agree(&st), "one shard and a render of another seed disagree (above)");
    /* A merged reference is a reference: glint bench takes it (seed 11 + 1, as it would). */
    CHECK(run("bench " DIRECT " --reference tm.exr --methods pt --times 0.05 --out b") == 0, "bench: %s", err_text);
}

static void test_refusals(void) {
    check_refused("merge s0.exr s1.exr s3.exr --out r.exr", "r.exr: shard 2 of 4 missing", "r.exr");
    check_refused("merge s0.exr --out r.exr", "r.exr: shards 1, 2, 3 of 4 missing", "r.exr");
    check_refused("merge s0.exr s1.exr s2.exr s3.exr s1.exr --out r.exr", "s1.exr: shard 1 of 4 is in s1.exr too",
                  "r.exr");
    char cp[1200];
    snprintf(cp, sizeof cp, "cp '%s/s2.exr' '%s/copy.exr'", tmp, tmp);
    CHECK(system(cp) == 0, "cp");
    check_refused("merge s0.exr s1.exr s2.exr s3.exr copy.exr --out r.exr", "copy.exr: shard 2 of 4 is in s2.exr too",
                  "r.exr");
    check_refused("merge half.exr s0.exr s1.exr s2.exr --out r.exr", "s0.exr: shard 0 of 4 is in half.exr too",
                  "r.exr");
    /* Parts of another render. */
    const struct {
        const char *options, *error;
    } other[] = {
        {"--spp 18 --seed 5", "rendered with --seed 5, s0.exr with 0"},
        {"--spp 18 --method vsl", "rendered with --method vsl, s0.exr with pt"},
        {"--spp 18 --plan full", "rendered with parameters 'plan=full', s0.exr with 'plan=auto'"},
        {"--spp 18 --max-depth 3", "rendered with --max-depth 3, s0.exr with 2"},
        {"--spp 20", "a shard of 4 of 20 spp, s0.exr of 4 of 18 spp"},
        {"--spp 18 --size 16x16", "rendered at 16x16, not 32x24"},
    };
    for (size_t t = 0; t < sizeof other / sizeof other[0]; t++) {
        char args[512];
        snprintf(args, sizeof args, "render " SCENE " %s --shard 1/4 --out o.exr", other[t].options);
        CHECK(run(args) == 0, "%s: %s", args, err_text);
        check_refused("merge s0.exr o.exr s2.exr s3.exr --out r.exr", other[t].error, "r.exr");
    }
    /* Many-light parameters are part of the render. */
    CHECK(run("render " SCENE " --spp 4 --method vsl --shard 0/2 --out v0.exr") == 0, "%s", err_text);
    CHECK(run("render " SCENE " --spp 4 --method vsl --vsl-count 512 --shard 1/2 --out v1.exr") == 0, "%s", err_text);
    check_refused("merge v0.exr v1.exr --out r.exr", "count=1024", "r.exr");
    check_refused("merge plain.exr s1.exr --out r.exr", "plain.exr: not a shard (render one with glint render --shard",
                  "r.exr");
    check_refused("merge s0.exr s1.exr --out s1.exr", "--out 's1.exr' is a part: it would be replaced", "nothing.exr");
    check_refused("merge nosuch.exr --out r.exr", "nosuch.exr", "r.exr");
    check_refused("merge --out r.exr", "merge: no parts given", "r.exr");
    check_refused("merge s0.exr", "merge: --out REF.exr is required", "r.exr");
    /* --shard's own errors */
    check_refused("render " SCENE " --shard 4/4 --out x.exr", "--shard", "x.exr");
    check_refused("render " SCENE " --shard 1of4 --out x.exr", "--shard: '1of4' is not I/N", "x.exr");
    check_refused("render " SCENE " --shard 1/4", "--shard: a shard is its EXR", "x.exr");
    check_refused("render " SCENE " --spp 3 --shard 3/4 --out x.exr", "--spp 3 leaves shard 3 no frame", "x.exr");
}

/* Shard `from` again as `to` (its description kept), every mean set to value and every variance to
 * 0: what a hostile or broken writer could hand to merge. */
static int rewrite_shard(const char *from, const char *to, float value) {
    char desc[16384];
    exr_image ex;
    if (!read_reference(from, desc, sizeof desc) || load(from, &ex) != 0) return -1;
    for (int c = 0; c < ex.num_channels; c++) {
        int var = strncmp(ex.names[c], MOMENTS_VAR_PREFIX, strlen(MOMENTS_VAR_PREFIX)) == 0;
        if (strncmp(ex.names[c], MOMENTS_REJECTED, strlen(MOMENTS_REJECTED)) == 0) continue; /* as they were */
        for (size_t i = 0; i < (size_t)ex.width * (size_t)ex.height; i++) ex.planes[c][i] = var ? 0.0f : value;
    }
    int status = write_reference_image(&ex, to, desc, 0);
    exr_image_free(&ex);
    return status;
}

/* Shards whose means lie so far apart that the merged variance is past a float's range: refused
 * (a merged reference must never hold a non-finite value, and its description must stay JSON). */
static void test_far_apart(void) {
    CHECK(run("render " SCENE " --spp 4 --shard 0/2 --out f0.exr") == 0 &&
              run("render " SCENE " --spp 4 --shard 1/2 --out f1.exr") == 0,
          "far-apart shards: %s", err_text);
    const float far[] = {1e20f, 3.4028235e38f};
    for (size_t k = 0; k < sizeof far / sizeof far[0]; k++) {
        CHECK(rewrite_shard("f0.exr", "h0.exr", far[k]) == 0 && rewrite_shard("f1.exr", "h1.exr", -far[k]) == 0,
              "rewriting the shards");
        check_refused("merge h0.exr h1.exr --out r.exr", "does not fit in a float", "r.exr");
    }
    /* the same value in both: a merge as any other */
    CHECK(rewrite_shard("f0.exr", "h0.exr", 1e20f) == 0 && rewrite_shard("f1.exr", "h1.exr", 1e20f) == 0,
          "rewriting the shards");
    CHECK(run("merge h0.exr h1.exr --out r.exr") == 0, "equal far means: %s", err_text);
    CHECK(isfinite(described("r.exr", "mean_pixel_variance")), "the merge's noise is a number");
}

int main(int argc, char **argv) {
    int start = harness_start(argc, argv, "merge");
    if (start != 0) return start;
    test_exact();
    test_statistics();
    test_refusals();
    test_far_apart();
    return check_exit("test_merge");
}
