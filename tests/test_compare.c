/* glint compare, and the poses of glint render it compares: the error of an image against a
 * reference, checked against the same sum done here and against images made to a known error;
 * the reference's noise taken out in quadrature; the refusals (size, scene, camera, light edits;
 * glint bench's of a reference with a light moved);
 * glint render's --camera-from (the camera of another file's description, refused without one or
 * of another scene) and --move-light / --light-gain (the edits applied, recorded, compared);
 * --denoise: the filtered image a layer of its own, the estimate's layers the same pixels as
 * without it, and nearer a long render than the estimate it filters (a young vsl image).
 * Usage: test_compare PATH_TO_GLINT */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "cli_harness.h"
#include "image_io.h"

/* Exit code `code`, and stderr exactly one "glint: error: ..." line containing `needle`. */
static void expect_failure(const char *args, int code, const char *needle) {
    int rc = run(args);
    CHECK(rc == code, "'%s': exit %d, expected %d (stderr: %s)", args, rc, code, err_text);
    const char *nl = strchr(err_text, '\n');
    CHECK(strncmp(err_text, "glint: error: ", 14) == 0 && nl && !nl[1], "'%s': stderr is not one error line: '%s'",
          args, err_text);
    CHECK(strstr(err_text, needle), "'%s': error '%s' lacks '%s'", args, err_text, needle);
}

/* Runs glint compare ARGS, which must succeed; its four numbers into v. */
static void compare(const char *args, double v[4]) {
    char cmd[600];
    snprintf(cmd, sizeof cmd, "compare %s", args);
    int rc = run(cmd);
    v[0] = v[1] = v[2] = v[3] = NAN;
    CHECK(rc == 0, "'%s': exit %d (%s)", cmd, rc, err_text);
    CHECK(sscanf(out_text, "rel_l2=%lf ref_noise=%lf net=%lf peak_share=%lf", &v[0], &v[1], &v[2], &v[3]) == 4 &&
              !strchr(out_text, '\n')[1],
          "'%s': output '%s'", cmd, out_text);
}

static int render(const char *args) {
    char cmd[600];
    snprintf(cmd, sizeof cmd, "render builtin:atelier --size 32x18 --quiet %s", args);
    int rc = run(cmd);
    CHECK(rc == 0, "'%s': exit %d (%s)", cmd, rc, err_text);
    return rc;
}

/* The layer `prefix` of EXR `name` (in tmp), interleaved; NULL when unreadable. */
static float *layer(const char *name, const char *prefix, int *w, int *h) {
    char p[1024], err[1024];
    snprintf(p, sizeof p, "%s/%s", tmp, name);
    exr_image ex;
    if (exr_image_load(p, &ex, err, sizeof err) != 0) return NULL;
    float *rgb = exr_image_layer_rgb(&ex, prefix);
    *w = ex.width;
    *h = ex.height;
    exr_image_free(&ex);
    return rgb;
}

/* ||a - b|| / ||b|| summed here, in double. */
/* ... of layer pa of a against layer pb of b. */
static double rel_l2_here_layers(const char *a, const char *pa, const char *b, const char *pb) {
    int w, h, w2, h2;
    float *x = layer(a, pa, &w, &h), *y = layer(b, pb, &w2, &h2);
    int ok = x && y && w == w2 && h == h2;
    double d = 0.0, n = 0.0;
    for (size_t i = 0; ok && i < 3 * (size_t)w * (size_t)h; i++) {
        d += ((double)x[i] - y[i]) * ((double)x[i] - y[i]);
        n += (double)y[i] * y[i];
    }
    free(x);
    free(y);
    return ok ? sqrt(d / n) : NAN;
}

static double rel_l2_here(const char *a, const char *b, const char *prefix) {
    return rel_l2_here_layers(a, prefix, b, prefix);
}

/* A w x h image of value v * (1 + pixel index / 100) in every channel, no description; pixel
 * `speck` (if in it) `extra` brighter. */
static void write_ramp_speck(const char *name, int w, int h, float v, int speck, float extra) {
    char p[1024], err[1024];
    float *rgb = malloc(sizeof(float) * 3 * (size_t)w * (size_t)h);
    for (int i = 0; i < w * h; i++)
        for (int k = 0; k < 3; k++) rgb[3 * i + k] = v * (1.0f + (float)i / 100.0f) + (i == speck ? extra : 0.0f);
    snprintf(p, sizeof p, "%s/%s", tmp, name);
    exr_layer l = {"", rgb};
    CHECK(exr_save_layers(p, w, h, &l, 1, WRITE_REPLACE, err, sizeof err) == 0, "%s", err);
    free(rgb);
}

static void write_ramp(const char *name, int w, int h, float v) { write_ramp_speck(name, w, h, v, -1, 0.0f); }

/* The largest pixel's share of ||a - b||^2 (the pixels' squared errors summed over channels). */
static double top_share_here(const char *a, const char *b) {
    int w, h, w2, h2;
    float *x = layer(a, "", &w, &h), *y = layer(b, "", &w2, &h2);
    int ok = x && y && w == w2 && h == h2;
    double all = 0.0, top = 0.0;
    for (size_t i = 0; ok && i < (size_t)w * (size_t)h; i++) {
        double e = 0.0;
        for (size_t k = 3 * i; k < 3 * i + 3; k++) e += ((double)x[k] - y[k]) * ((double)x[k] - y[k]);
        all += e;
        top = fmax(top, e);
    }
    free(x);
    free(y);
    return ok && all > 0.0 ? top / all : NAN;
}

static void test_numbers(void) {
    double v[4];
    /* Made to a known error: 1.1 times the reference everywhere is 0.1 off. */
    write_ramp("ramp.exr", 8, 4, 2.0f);
    write_ramp("ramp-more.exr", 8, 4, 2.2f);
    compare("ramp-more.exr ramp.exr", v);
    CHECK_NEAR(v[0], 0.1, 1e-5, "1.1 times the reference");
    CHECK(v[1] == 0.0 && v[2] == v[0], "no description: no noise to take out (%g, %g)", v[1], v[2]);
    /* 32 pixels: the peak is one pixel (a thousandth, rounded up), the brightest: its error is
     * 0.2 (1 + 31/100) in each channel, the others' 0.2 (1 + i/100). */
    double ramp_all = 0.0;
    for (int i = 0; i < 32; i++) ramp_all += (1.0 + i / 100.0) * (1.0 + i / 100.0);
    CHECK_NEAR(v[3], 1.31 * 1.31 / ramp_all, 1e-4, "the ramp's peak share");
    /* The error all in one pixel: all of it in the peak. */
    write_ramp_speck("ramp-speck.exr", 8, 4, 2.0f, 13, 500.0f);
    compare("ramp-speck.exr ramp.exr", v);
    CHECK_NEAR(v[3], 1.0, 1e-6, "a speck's share");
    compare("ramp.exr ramp.exr", v);
    CHECK(v[0] == 0.0 && v[2] == 0.0 && v[3] == 0.0, "an image against itself: %g %g %g", v[0], v[2], v[3]);
    /* Two renders: the sum done here, and the reference's noise (its description's) taken out. */
    if (render("--method pt --spp 2 --seed 1 --out a.exr") || render("--method pt --spp 16 --seed 2 --out b.exr"))
        return;
    char desc[65536];
    read_reference("b.exr", desc, sizeof desc);
    const char *noise_at = strstr(desc, "\"rel_l2_noise\": ");
    double noise = noise_at ? atof(noise_at + 16) : NAN;
    CHECK(noise > 0.0, "b.exr has its noise in its description");
    compare("a.exr b.exr", v);
    CHECK_NEAR(v[0], rel_l2_here("a.exr", "b.exr", ""), 1e-5 * v[0], "against the sum done here");
    CHECK_NEAR(v[1], noise, 1e-5 * noise, "the reference's noise");
    CHECK_NEAR(v[2], sqrt(fmax(v[0] * v[0] - noise * noise, 0.0)), 1e-5, "net: the noise out in quadrature");
    CHECK(v[2] < v[0], "net %g below rel_l2 %g", v[2], v[0]);
    CHECK_NEAR(v[3], top_share_here("a.exr", "b.exr"), 1e-4, "the peak share (576 pixels: the largest one's)");
    /* A layer: its own error, and no noise known for it. */
    compare("a.exr b.exr --layer direct", v);
    CHECK_NEAR(v[0], rel_l2_here("a.exr", "b.exr", "direct"), 1e-5 * v[0], "the direct layer");
    CHECK(v[1] == 0.0 && v[2] == v[0], "a layer's noise is unknown: %g %g", v[1], v[2]);
    expect_failure("compare a.exr b.exr --layer nosuch", 1, "nosuch.R,G,B");
    expect_failure("compare a.exr", 2, "IMAGE.exr REFERENCE.exr");
    expect_failure("compare a.exr b.exr ramp.exr", 2, "ramp.exr");
    expect_failure("compare a.exr missing.exr", 1, "missing.exr");
}

static void test_refusals(void) {
    if (render("--method pt --spp 2 --seed 1 --out a.exr")) return;
    run("render builtin:atelier --size 16x9 --spp 1 --quiet --out small.exr");
    expect_failure("compare a.exr small.exr", 1, "32x18, but small.exr is 16x9");
    expect_failure("compare ramp.exr a.exr", 1, "8x4, but a.exr is 32x18");
    run("render builtin:doorway --size 32x18 --spp 1 --quiet --out doorway.exr");
    expect_failure("compare a.exr doorway.exr", 1, "builtin:doorway");
    if (render("--spp 1 --camera 1 --out cam1.exr")) return;
    expect_failure("compare a.exr cam1.exr", 1, "seen from");
    if (render("--spp 1 --move-light 0,0.5,0,0 --out moved.exr")) return;
    expect_failure("compare a.exr moved.exr", 1, "edited '0:0.5,0,0*1'");
    expect_failure("compare moved.exr a.exr", 1, "as loaded");
    /* glint bench renders the scene as loaded: a reference with a light moved is not of it. */
    expect_failure("bench builtin:atelier --reference moved.exr --methods pt --times 0.05 --quiet", 1,
                   "rendered with lights edited '0:0.5,0,0*1', not the lights as loaded");
    /* An older description, without the lights field: as loaded. */
    char desc[65536];
    read_reference("a.exr", desc, sizeof desc);
    char *at = strstr(desc, "  \"lights\": \"\",\n");
    CHECK(at != NULL, "a.exr's description has an empty lights field: %s", desc);
    if (at) memmove(at, at + strlen("  \"lights\": \"\",\n"), strlen(at + strlen("  \"lights\": \"\",\n")) + 1);
    CHECK(write_reference("a.exr", "old.exr", desc, 0) == 0, "old.exr written");
    double v[4];
    compare("old.exr a.exr", v);
    CHECK(v[0] == 0.0, "an older description, the same image: %g", v[0]);
    expect_failure("compare old.exr moved.exr", 1, "as loaded");
    /* A malformed edit list is a malformed description, whoever reads it. */
    static const char *const bad[] = {"0:1,0,0", "0:1,0,0*1;", "x:1,0,0*1", "0:1,0,0*1;0:2,0,0*1", "0:1,0,0*0"};
    for (int i = 0; i < (int)(sizeof bad / sizeof bad[0]); i++) {
        char edited[65600], *field = NULL;
        read_reference("a.exr", desc, sizeof desc);
        field = strstr(desc, "\"lights\": \"\"");
        if (!field) break;
        snprintf(edited, sizeof edited, "%.*s\"lights\": \"%s\"%s", (int)(field - desc), desc, bad[i],
                 field + strlen("\"lights\": \"\""));
        CHECK(write_reference("a.exr", "bad-lights.exr", edited, 0) == 0, "bad-lights.exr written");
        expect_failure("compare a.exr bad-lights.exr", 1, "bad \"lights\"");
    }
}

static void test_render_poses(void) {
    double v[4];
    /* Two moves of one light add up to one move; the recorded edit is the same, the image too. */
    if (render("--spp 2 --seed 3 --move-light 0,0.25,0,0 --move-light 0,0.25,0,0 --out twice.exr") ||
        render("--spp 2 --seed 3 --move-light 0,0.5,0,0 --out once.exr") || render("--spp 2 --seed 3 --out still.exr"))
        return;
    compare("twice.exr once.exr", v);
    CHECK(v[0] < 1e-6, "two moves and their sum: %g", v[0]);
    expect_failure("compare twice.exr still.exr", 1, "lights");
    /* The move changes the image (the only light moved); the gain scales it (the only light). */
    double moved = rel_l2_here("once.exr", "still.exr", "");
    CHECK(moved > 0.01, "a light moved half a metre changes the image by %g", moved);
    if (render("--spp 2 --seed 3 --light-gain 0,2 --out bright.exr")) return;
    int w, h;
    float *a = layer("bright.exr", "", &w, &h), *b = layer("still.exr", "", &w, &h);
    double sa = 0.0, sb = 0.0;
    for (size_t i = 0; a && b && i < 3 * (size_t)w * (size_t)h; i++) sa += a[i], sb += b[i];
    CHECK_NEAR(sa / sb, 2.0, 1e-3, "the one light at twice its intensity doubles the image");
    free(a);
    free(b);
    char desc[65536];
    read_reference("bright.exr", desc, sizeof desc);
    CHECK(strstr(desc, "\"lights\": \"0:0,0,0*2\""), "the gain recorded: %s", desc);
    /* --camera-from: the camera of the file's description, whatever the file's size. */
    if (render("--spp 1 --seed 4 --camera-from cam1.exr --move-light 0,0.5,0,0 --out from.exr")) return;
    read_reference("from.exr", desc, sizeof desc);
    CHECK(strstr(desc, "\"index\": 1,"), "camera 1's view is recorded as camera 1: %s", desc);
    expect_failure("compare from.exr once.exr", 1, "seen from");
    run("render builtin:atelier --size 32x18 --quiet --spp 1 --seed 5 --camera 1 --move-light 0,0.5,0,0 --out c1.exr");
    compare("from.exr c1.exr", v);
    CHECK(v[0] > 0.0 && isfinite(v[0]), "the same pose: compared (%g)", v[0]);
    expect_failure("render builtin:atelier --size 32x18 --spp 1 --camera-from ramp.exr --out x.exr", 1,
                   "no glint description");
    expect_failure("render builtin:atelier --size 32x18 --spp 1 --camera-from doorway.exr --out x.exr", 1,
                   "another scene");
    expect_failure("render builtin:atelier --spp 1 --camera 1 --camera-from a.exr --out x.exr", 2, "exclude");
    expect_failure("render builtin:atelier --spp 1 --camera-from nosuch.exr --out x.exr", 1, "nosuch.exr");
    expect_failure("render builtin:atelier --spp 1 --move-light 0,1,2 --out x.exr", 2, "G,DX,DY,DZ");
    expect_failure("render builtin:atelier --spp 1 --move-light 0,1,2,x --out x.exr", 2, "G,DX,DY,DZ");
    expect_failure("render builtin:atelier --spp 1 --move-light 5,1,0,0 --out x.exr", 2, "no light 5");
    expect_failure("render builtin:atelier --spp 1 --light-gain 0,2 --light-gain 0,3 --out x.exr", 2, "twice");
    expect_failure("render builtin:atelier --spp 1 --light-gain 0,0 --out x.exr", 2, "1e-6 to 1e6");
}

static void test_denoise_layer(void) {
    /* the doorway at 96x54: 2 frames of vsl, and a 256-frame pt reference */
    const char *scene = "render builtin:doorway --size 96x54 --quiet";
    char cmd[600];
    snprintf(cmd, sizeof cmd, "%s --method vsl --spp 2 --seed 3 --denoise --out dn.exr", scene);
    CHECK(run(cmd) == 0, "'%s': %s", cmd, err_text);
    snprintf(cmd, sizeof cmd, "%s --method vsl --spp 2 --seed 3 --out raw.exr", scene);
    CHECK(run(cmd) == 0, "'%s': %s", cmd, err_text);
    snprintf(cmd, sizeof cmd, "%s --method pt --spp 256 --seed 9 --out long.exr", scene);
    CHECK(run(cmd) == 0, "'%s': %s", cmd, err_text);
    const char *layers[] = {"", "direct", "indirect"};
    for (int k = 0; k < 3; k++)
        CHECK(rel_l2_here("dn.exr", "raw.exr", layers[k]) == 0.0, "--denoise changed the estimate's layer '%s'",
              layers[k]);
    /* the errors against the truth, the long render's own noise (its description's) taken out */
    double v[4];
    compare("raw.exr long.exr", v);
    double noise2 = v[1] * v[1], filtered = rel_l2_here_layers("dn.exr", "denoised", "long.exr", "");
    double raw = rel_l2_here("raw.exr", "long.exr", "");
    filtered = sqrt(fmax(filtered * filtered - noise2, 0.0));
    raw = sqrt(fmax(raw * raw - noise2, 0.0));
    CHECK(filtered < 0.85 * raw, "the denoised layer is no nearer the truth: %g against the estimate's %g", filtered,
          raw);
    expect_failure("render builtin:atelier --spp 1 --denoise --png x.png", 2, "--out");
    expect_failure("render builtin:atelier --spp 4 --shard 0/2 --denoise --out x.exr", 2, "shard");
}

int main(int argc, char **argv) {
    int start = harness_start(argc, argv, "compare");
    if (start != 0) return start;
    test_numbers();
    test_refusals();
    test_render_poses();
    test_denoise_layer();
    return check_exit("test_compare");
}
