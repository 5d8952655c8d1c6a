/* The glint command line, run as a user would: exit codes (0, 1, 2), one-line errors naming the
 * file, the outputs (EXR layers that sum to the image, a PNG of the right size, stats JSON),
 * atomic and non-overwriting exports, progress lines when stderr is not a terminal; glint info's
 * OBJ export against its own summary, its method and depth read (and refused) as render's, the
 * camera in the stats.
 * Usage: test_cli PATH_TO_GLINT */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "check.h"
#include "cli_harness.h"
#include "image_io.h"
#include "scene.h"

static int count_lines(const char *s) {
    int n = 0;
    for (; *s; s++) n += *s == '\n';
    return n;
}

/* Exit code `code`, and stderr exactly one "glint: error: ..." line containing `needle`. */
static void expect_failure(const char *args, int code, const char *needle) {
    int rc = run(args);
    CHECK(rc == code, "'%s': exit %d, expected %d (stderr: %s)", args, rc, code, err_text);
    CHECK(strncmp(err_text, "glint: error: ", 14) == 0 && count_lines(err_text) == 1,
          "'%s': stderr is not one error line: '%s'", args, err_text);
    CHECK(needle == NULL || strstr(err_text, needle), "'%s': error '%s' lacks '%s'", args, err_text, needle);
}

static int file_exists(const char *name) {
    char p[1024];
    snprintf(p, sizeof p, "%s/%s", tmp, name);
    struct stat st;
    return stat(p, &st) == 0;
}

/* No temporary files may survive an export, failed or not. */
static int stray_temp_files(void) {
    DIR *d = opendir(tmp);
    int n = 0;
    struct dirent *e;
    while (d && (e = readdir(d)))
        if (strstr(e->d_name, ".tmp")) n++;
    if (d) closedir(d);
    return n;
}

static void test_usage(void) {
    CHECK(run("--help") == 0, "--help exit code");
    const char *options[] = {"render",   "info",   "--spp", "--time", "--size",  "--max-depth", "--env",
                             "--camera", "--seed", "--out", "--png",  "--stats", "--method",    "--quiet"};
    char all[sizeof out_text * 2];
    snprintf(all, sizeof all, "%s", out_text);
    CHECK(run("render --help") == 0, "render --help exit code");
    strncat(all, out_text, sizeof all - strlen(all) - 1);
    for (size_t i = 0; i < sizeof options / sizeof options[0]; i++)
        CHECK(strstr(all, options[i]) != NULL, "help does not mention %s", options[i]);
    CHECK(run("--version") == 0 && strstr(out_text, "glint"), "--version");

    expect_failure("frobnicate", 2, "frobnicate");
    expect_failure("render --bogus", 2, "--bogus");
    expect_failure("render --spp", 2, "--spp");
    expect_failure("render --spp -3", 2, "--spp");
    expect_failure("render --spp 10x", 2, "--spp");
    expect_failure("render --size 0x5", 2, "--size");
    /* an image whose film would not fit: at once, with what it would take */
    expect_failure("render --size 16384x16384 --spp 1 --out big.exr", 2,
                   "--size: 16384x16384 would take 32.0 GiB (128 bytes a pixel), over the limit of 16 GiB");
    expect_failure("render --size 100", 2, "--size");
    expect_failure("render --spp 4 --time 2", 2, NULL);
    expect_failure("render --method nope", 2, "nope");
    expect_failure("render --max-depth -1", 2, "--max-depth");
}

static void test_errors(void) {
    expect_failure("render missing-scene.gltf --spp 1", 1, "missing-scene.gltf");
    expect_failure("info missing-scene.gltf", 1, "missing-scene.gltf");
    char p[1024];
    snprintf(p, sizeof p, "%s/broken.gltf", tmp);
    FILE *f = fopen(p, "w");
    fputs("{\"asset\": {\"version\": \"2.0\"}, \"nodes\": [", f);
    fclose(f);
    expect_failure("render broken.gltf --spp 1", 1, "broken.gltf");
    snprintf(p, sizeof p, "%s/fake.exr", tmp);
    f = fopen(p, "w");
    fputs("not an image", f);
    fclose(f);
    expect_failure("render --env fake.exr --spp 1 --size 8x8 --png x.png", 1, "fake.exr");
    expect_failure("render --env none.hdr --spp 1 --size 8x8 --png x.png", 1, "none.hdr");
    CHECK(!file_exists("x.png"), "a failed render wrote its output");
    expect_failure("render --spp 1 --size 8x8 --png no-such-dir/x.png", 1, "no-such-dir");
    CHECK(stray_temp_files() == 0, "temporary files left behind");
}

static void test_outputs(void) {
    int rc =
        run("render --spp 4 --size 48x27 --max-depth 4 --seed 3 --out img.exr --png img.png --stats img.json --quiet");
    CHECK(rc == 0, "render: exit %d: %s", rc, err_text);
    CHECK(err_text[0] == 0, "--quiet render printed to stderr: %s", err_text);
    char p[1024], err[512];
    snprintf(p, sizeof p, "%s/img.exr", tmp);
    exr_image exr;
    if (exr_image_load(p, &exr, err, sizeof err) == 0) {
        CHECK(exr.width == 48 && exr.height == 27, "exr size %dx%d", exr.width, exr.height);
        const char *ch[3] = {"R", "G", "B"};
        double total = 0.0;
        for (int c = 0; c < 3; c++) {
            char dn[32], in[32];
            snprintf(dn, sizeof dn, "direct.%s", ch[c]);
            snprintf(in, sizeof in, "indirect.%s", ch[c]);
            const float *all = exr_image_channel(&exr, ch[c]), *d = exr_image_channel(&exr, dn),
                        *ind = exr_image_channel(&exr, in);
            CHECK(all && d && ind, "exr lacks channel %s, %s or %s", ch[c], dn, in);
            if (!(all && d && ind)) continue;
            int bad = 0;
            for (int i = 0; i < 48 * 27; i++) {
                if (!(fabsf(all[i] - (d[i] + ind[i])) <= 1e-5f * fabsf(all[i]) + 1e-7f)) bad++;
                if (!isfinite(all[i]) || all[i] < 0.0f) bad++;
                total += all[i];
            }
            CHECK(bad == 0, "exr %s != direct + indirect (or not finite) at %d pixels", ch[c], bad);
        }
        CHECK(total > 0.0, "the render is black");
        exr_image_free(&exr);
    } else {
        CHECK(0, "exr unreadable: %s", err);
    }
    /* PNG: signature, then IHDR with the big-endian width and height. */
    snprintf(p, sizeof p, "%s/img.png", tmp);
    unsigned char hdr[24] = {0};
    FILE *pf = fopen(p, "rb");
    CHECK(pf && fread(hdr, 1, 24, pf) == 24, "png missing or short");
    if (pf) fclose(pf);
    CHECK(memcmp(hdr, "\x89PNG", 4) == 0 && hdr[19] == 48 && hdr[23] == 27, "png header or size wrong");
    char json[8192];
    read_file("img.json", json, sizeof json);
    CHECK(strstr(json, "\"spp\": 4") && strstr(json, "\"method\": \"pt\"") && strstr(json, "\"width\": 48"),
          "stats json: %s", json);

    /* Same seed, same image: runs reproduce. */
    rc = run("render --spp 4 --size 48x27 --max-depth 4 --seed 3 --out img2.exr --quiet");
    char p2[1024];
    snprintf(p, sizeof p, "%s/img.exr", tmp);
    snprintf(p2, sizeof p2, "%s/img2.exr", tmp);
    exr_image a, b;
    if (rc == 0 && exr_image_load(p, &a, err, sizeof err) == 0) {
        if (exr_image_load(p2, &b, err, sizeof err) == 0) {
            const float *ra = exr_image_channel(&a, "R"), *rb = exr_image_channel(&b, "R");
            CHECK(ra && rb && memcmp(ra, rb, sizeof(float) * 48 * 27) == 0, "same seed, different image");
            exr_image_free(&b);
        }
        exr_image_free(&a);
    }

    /* A named output is replaced; the default output never is. */
    CHECK(run("render --spp 1 --size 16x9 --png img.png --quiet") == 0, "re-render to a named png");
    CHECK(run("render --spp 1 --size 16x9 --quiet") == 0 && file_exists("render.png"), "default output render.png");
    CHECK(run("render --spp 1 --size 16x9 --quiet") == 0 && file_exists("render-1.png"), "second default output is "
                                                                                         "render-1.png");
    CHECK(stray_temp_files() == 0, "temporary files left behind");

    /* Without a terminal, progress comes as plain lines. */
    rc = run("render --time 1.5 --size 32x18 --png timed.png");
    CHECK(rc == 0, "timed render: %s", err_text);
    CHECK(strstr(err_text, "spp") && !strchr(err_text, '\r') && !strstr(err_text, "\033"),
          "progress on a non-terminal: '%s'", err_text);

    rc = run("info");
    CHECK(rc == 0 && strstr(out_text, "triangles"), "glint info: %s%s", out_text, err_text);
    /* info reads the method and depth as render does (one table of options): the same words */
    rc = run("info --method vsl --max-depth 4");
    CHECK(rc == 0 && strstr(out_text, "method:     vsl\n") && strstr(out_text, "max depth: 4"),
          "info --method vsl: %s%s", out_text, err_text);
    /* with auto, its choice as a map of tiles: 12 rows of 20, counted as the summary says; doorway
     * is the virtual lights' regime (test_choice), most of its tiles theirs */
    rc = run("info builtin:doorway --method auto --max-depth 4");
    const char *map = strstr(out_text, "auto:       after 8 frames at 320x192");
    int rows = 0, hashes = 0, said = -1;
    for (const char *line = map ? strchr(map, '\n') : NULL; line && rows < 13; line = strchr(line + 1, '\n')) {
        const char *t = line + 1 + strspn(line + 1, " ");
        size_t n = strspn(t, "#.+");
        if (n == 20 && t[n] == '\n') {
            rows++;
            for (size_t k = 0; k < n; k++) hashes += t[k] == '#';
        }
    }
    const char *summary = map ? strstr(map, " of 240 tiles mostly the virtual lights'") : NULL;
    if (summary) {
        while (summary > map && summary[-1] != ' ') summary--;
        said = atoi(summary);
    }
    CHECK(rc == 0 && rows == 12 && said == hashes && hashes >= 120,
          "info --method auto: %d rows, %d '#', said %d: %s%s", rows, hashes, said, out_text, err_text);
    const char *commands[] = {"info", "render --spp 1 --size 8x8"};
    for (int i = 0; i < 2; i++) {
        char cmd[128];
        snprintf(cmd, sizeof cmd, "%s --method bogus", commands[i]);
        expect_failure(cmd, 2, "--method: expected one of pt, vpl, vsl, vsl+hl, auto, got 'bogus'");
        snprintf(cmd, sizeof cmd, "%s --max-depth 0", commands[i]);
        expect_failure(cmd, 2, "--max-depth: expected an integer in [1, 10000], got '0'");
    }
}

/* builtin:NAME: listed in the help, loaded by every command, an unknown name one error; a
 * reference of a built-in names it and hashes the very bytes of its glTF under assets/scenes/. */
static void test_builtin_scenes(void) {
    int n;
    const builtin_scene *all = scene_builtins(&n);
    char names[256] = "", help[sizeof out_text * 2];
    CHECK(run("--help") == 0, "--help");
    snprintf(help, sizeof help, "%s", out_text);
    CHECK(run("info --help") == 0, "info --help");
    for (int i = 0; i < n; i++) {
        snprintf(names + strlen(names), sizeof names - strlen(names), "%s%s", i ? ", " : "", all[i].name);
        CHECK(strstr(help, all[i].name) && strstr(help, all[i].description), "--help does not list %s", all[i].name);
        CHECK(strstr(out_text, all[i].name) != NULL, "info --help does not list %s", all[i].name);
    }
    CHECK(strstr(help, "builtin:NAME") != NULL, "--help does not explain builtin:NAME");

    char want[512], cmd[512];
    snprintf(want, sizeof want, "builtin:nosuch: no such built-in scene (have: %s)", names);
    const char *commands[] = {"render builtin:nosuch --spp 1 --size 8x8 --png x.png", "info builtin:nosuch",
                              "view builtin:nosuch", "builtin:nosuch"};
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++) expect_failure(commands[i], 1, want);

    CHECK(run("info builtin:showcase") == 0 && strstr(out_text, "scene:      builtin:showcase\n"),
          "info builtin:showcase: %s%s", out_text, err_text);
    char json[8192], hash_builtin[64] = "", hash_file[64] = "";
    CHECK(run("render --spp 1 --size 16x9 --out default.exr --quiet") == 0, "default render: %s", err_text);
    read_reference("default.exr", json, sizeof json);
    snprintf(want, sizeof want, "\"scene\": \"builtin:%s\"", all[0].name);
    CHECK(strstr(json, want) != NULL, "the default scene's reference: %s", json);
    CHECK(!file_exists("default.exr.json"), "a sidecar beside the reference");
    CHECK(run("render builtin:showcase --spp 1 --size 16x9 --out showcase.exr --quiet") == 0, "showcase: %s", err_text);
    read_reference("showcase.exr", json, sizeof json);
    const char *h = strstr(json, "\"scene_hash\": \"builtin:showcase:fnv1a64:");
    CHECK(strstr(json, "\"scene\": \"builtin:showcase\"") && h, "showcase reference: %s", json);
    if (h) sscanf(h + strlen("\"scene_hash\": \"builtin:showcase:"), "%63[^\"]", hash_builtin);
    snprintf(cmd, sizeof cmd, "render '%s/scenes/showcase.gltf' --spp 1 --size 16x9 --out file.exr --quiet",
             GLINT_ASSETS_DIR);
    CHECK(run(cmd) == 0, "showcase.gltf: %s", err_text);
    read_reference("file.exr", json, sizeof json);
    h = strstr(json, "\"scene_hash\": \"");
    if (h) sscanf(h + strlen("\"scene_hash\": \""), "%63[^\"]", hash_file);
    CHECK(hash_builtin[0] && strcmp(hash_builtin, hash_file) == 0,
          "the built-in showcase (%s) is not assets/scenes/showcase.gltf (%s)", hash_builtin, hash_file);
    snprintf(want, sizeof want, "builtin:nosuch: no such built-in scene (have: %s)", names);
    expect_failure("bench builtin:nosuch --reference showcase.exr --times 0.01 --out nosuch", 1, want);
    /* A sidecar from before there were several built-ins calls the showcase builtin:default. */
    read_reference("showcase.exr", json, sizeof json);
    char *at = strstr(json, "builtin:showcase:fnv1a64:"), old[8192];
    CHECK(at != NULL, "showcase reference: %s", json);
    if (at)
        snprintf(old, sizeof old, "%.*sbuiltin:default:%s", (int)(at - json), json, at + strlen("builtin:showcase:"));
    CHECK(at && write_reference("showcase.exr", "legacy.exr", old, 1) == 0, "writing an old reference");
    CHECK(run("bench builtin:showcase --reference legacy.exr --methods pt --times 0.01 --quiet --out legacy") == 0,
          "an old builtin:default sidecar refused: %s", err_text);
    expect_failure("bench builtin:doorway --reference legacy.exr --methods pt --times 0.01 --quiet --out other", 1,
                   "another scene");
}

/* The many-light options: listed in the help, bad values refused with a usage error, and the
 * methods run with them, report their lights and clamping in the stats, and write finite images. */
static void test_many_light_options(void) {
    CHECK(run("render --help") == 0, "render --help exit code");
    const char *options[] = {"--vsl-count",  "--clamp ",      "--clamp-value",   "--clamp-growth",
                             "--vpl-glossy", "--radius-mult", "--radius-shrink", "--rows",
                             "--columns",    "--per-pixel",   "--candidates",    "--trace-glossy"};
    for (size_t i = 0; i < sizeof options / sizeof options[0]; i++)
        CHECK(strstr(out_text, options[i]) != NULL, "render help does not mention %s", options[i]);

    expect_failure("render --method vsl --radius-mult -1", 2, "--radius-mult");
    expect_failure("render --method vsl --radius-mult banana", 2, "--radius-mult");
    expect_failure("render --method vsl --radius-shrink 1.5", 2, "--radius-shrink");
    expect_failure("render --method vpl --clamp maybe", 2, "--clamp");
    expect_failure("render --method vpl --clamp-value 0", 2, "--clamp-value");
    expect_failure("render --method vsl --candidates 0", 2, "--candidates");
    expect_failure("render --method vsl --per-pixel none", 2, "--per-pixel");
    expect_failure("render --method vsl --vsl-count", 2, "--vsl-count");
    expect_failure("render --method vsl --trace-glossy sharp", 2, "--trace-glossy");
    expect_failure("render --method vsl --highlights-layer", 2, "--highlights-layer");

    char p[1024], json[8192], err[512];
    /* A tiny clamp bound clamps; switching clamping off clamps nothing. */
    int rc = run("render --method vpl --spp 2 --size 32x18 --vsl-count 64 --clamp-value 1e-4 --stats vpl.json --quiet");
    CHECK(rc == 0, "vpl render: exit %d: %s", rc, err_text);
    read_file("vpl.json", json, sizeof json);
    const char *total = strstr(json, "\"virtual_lights_total\": ");
    CHECK(strstr(json, "\"method\": \"vpl\"") && strstr(json, "\"virtual_lights_per_frame\": 64") && total &&
              atol(total + 24) >= 128 && !strstr(json, "\"clamped\": 0,"),
          "vpl stats json: %s", json);
    rc = run(
        "render --method vpl --spp 2 --size 32x18 --vsl-count 64 --clamp off --vpl-glossy --stats vpl2.json --quiet");
    CHECK(rc == 0, "unclamped glossy vpl render: exit %d: %s", rc, err_text);
    read_file("vpl2.json", json, sizeof json);
    CHECK(strstr(json, "\"clamped\": 0,") != NULL, "clamping off still clamped: %s", json);

    rc = run("render --method vsl --spp 2 --size 32x18 --vsl-count 256 --radius-mult 4 --candidates 2 --columns 32 "
             "--rows 40 --out vsl.exr --stats vsl.json --quiet");
    CHECK(rc == 0, "vsl render: exit %d: %s", rc, err_text);
    read_file("vsl.json", json, sizeof json);
    /* The default scene's metals are sharper than the default --trace-glossy: paths go through. */
    CHECK(strstr(json, "\"method\": \"vsl\"") && strstr(json, "\"columns\": 32") &&
              !strstr(json, "\"vsl_samples\": 0,") && !strstr(json, "\"glossy_bounces\": 0,"),
          "vsl stats json: %s", json);
    rc = run("render --method vsl --spp 1 --size 32x18 --vsl-count 64 --trace-glossy off --stats off.json --quiet");
    read_file("off.json", json, sizeof json);
    CHECK(rc == 0 && strstr(json, "\"glossy_bounces\": 0,"), "--trace-glossy off still traced: %s", json);
    snprintf(p, sizeof p, "%s/vsl.exr", tmp);
    exr_image exr;
    if (exr_image_load(p, &exr, err, sizeof err) == 0) {
        const float *ind = exr_image_channel(&exr, "indirect.G");
        double sum = 0.0;
        int bad = 0;
        for (int i = 0; ind && i < 32 * 18; i++) {
            bad += !isfinite(ind[i]) || ind[i] < 0.0f;
            sum += ind[i];
        }
        CHECK(ind && bad == 0 && sum > 0.0, "vsl indirect layer: %d bad pixels, sum %g", bad, sum);
        exr_image_free(&exr);
    } else {
        CHECK(0, "vsl exr unreadable: %s", err);
    }
}

/* --highlights-layer: the EXR gains highlights.* and the layers still add up to the image. */
static void test_highlights_layer(void) {
    int rc = run("render --spp 4 --size 32x18 --max-depth 4 --highlights-layer --out hl.exr --quiet");
    CHECK(rc == 0, "render --highlights-layer: exit %d: %s", rc, err_text);
    char p[1024], err[512];
    snprintf(p, sizeof p, "%s/hl.exr", tmp);
    exr_image exr;
    if (exr_image_load(p, &exr, err, sizeof err) != 0) {
        CHECK(0, "highlights exr unreadable: %s", err);
        return;
    }
    const float *all = exr_image_channel(&exr, "G"), *d = exr_image_channel(&exr, "direct.G"),
                *ind = exr_image_channel(&exr, "indirect.G"), *hl = exr_image_channel(&exr, "highlights.G");
    CHECK(all && d && ind && hl, "the exr lacks a layer (highlights.G?)");
    if (all && d && ind && hl) {
        int bad = 0;
        double hl_sum = 0.0;
        for (int i = 0; i < 32 * 18; i++) {
            bad += !(fabsf(all[i] - (d[i] + ind[i] + hl[i])) <= 1e-5f * fabsf(all[i]) + 1e-7f) || hl[i] < 0.0f;
            hl_sum += hl[i];
        }
        CHECK(bad == 0 && hl_sum > 0.0,
              "highlights layer: %d pixels off the sum, total %g (the default scene has "
              "glossy-glossy light)",
              bad, hl_sum);
    }
    exr_image_free(&exr);
}

/* glint info --obj: as many vertices and triangles as the summary says, bounds of its size,
 * every face's indices in range, every material it uses defined in the MTL it names. glint
 * render --stats: the camera as an orthonormal frame with a field of view. */
static void test_obj_and_camera(void) {
    int rc = run("info builtin:showcase --obj scene.obj");
    CHECK(rc == 0, "info --obj: exit %d: %s", rc, err_text);
    long triangles = -1, vertices = -1;
    double ext[3] = {0, 0, 0};
    const char *g = strstr(out_text, "geometry:   "), *z = strstr(out_text, "size:       ");
    CHECK(g && sscanf(g, "geometry: %ld triangles, %ld vertices", &triangles, &vertices) == 2 && z &&
              sscanf(z, "size: %lf x %lf x %lf", &ext[0], &ext[1], &ext[2]) == 3,
          "info: %s", out_text);
    static char obj[1 << 20], mtl[1 << 16];
    read_file("scene.obj", obj, sizeof obj);
    read_file("scene.mtl", mtl, sizeof mtl);
    long v = 0, vn = 0, f = 0, bad = 0;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    CHECK(strncmp(obj, "mtllib scene.mtl\n", 17) == 0, "scene.obj does not name scene.mtl: %.40s", obj);
    for (char *line = obj; *line; line = strchr(line, '\n') ? strchr(line, '\n') + 1 : line + strlen(line)) {
        double p[3];
        long a[6];
        char name[64], want[80];
        if (sscanf(line, "v %lf %lf %lf", &p[0], &p[1], &p[2]) == 3) {
            v++;
            for (int k = 0; k < 3; k++) lo[k] = fmin(lo[k], p[k]), hi[k] = fmax(hi[k], p[k]);
        } else if (strncmp(line, "vn ", 3) == 0) {
            vn++;
        } else if (sscanf(line, "f %ld//%ld %ld//%ld %ld//%ld", &a[0], &a[1], &a[2], &a[3], &a[4], &a[5]) == 6) {
            f++;
            for (int k = 0; k < 6; k++) bad += a[k] < 1 || a[k] > vertices || a[k] != a[k & ~1];
        } else if (sscanf(line, "usemtl %63s", name) == 1) {
            snprintf(want, sizeof want, "newmtl %s\nKd ", name);
            bad += strstr(mtl, want) == NULL;
        }
    }
    CHECK(v == vertices && vn == vertices && f == triangles && bad == 0,
          "scene.obj: %ld v, %ld vn, %ld f, %ld bad (the summary: %ld vertices, %ld triangles)", v, vn, f, bad,
          vertices, triangles);
    for (int k = 0; k < 3; k++)
        CHECK(fabs((hi[k] - lo[k]) - ext[k]) <= 1e-3 * ext[k], "scene.obj spans %g on axis %d, the summary %g",
              hi[k] - lo[k], k, ext[k]);
    expect_failure("info --obj nowhere/scene.obj", 1, "nowhere");

    rc = run("render --spp 1 --size 16x9 --stats cam.json --quiet");
    CHECK(rc == 0, "render --stats: exit %d: %s", rc, err_text);
    char json[8192];
    read_file("cam.json", json, sizeof json);
    double c[3][3], fov = 0.0;
    const char *cam = strstr(json, "\"camera\": {\"position\": [");
    CHECK(cam && sscanf(cam,
                        "\"camera\": {\"position\": [%lf, %lf, %lf], \"forward\": [%lf, %lf, %lf], \"up\": [%lf, %lf, "
                        "%lf], \"yfov_degrees\": %lf}",
                        &c[0][0], &c[0][1], &c[0][2], &c[1][0], &c[1][1], &c[1][2], &c[2][0], &c[2][1], &c[2][2],
                        &fov) == 10,
          "stats lack the camera: %s", json);
    double ff = c[1][0] * c[1][0] + c[1][1] * c[1][1] + c[1][2] * c[1][2];
    double uu = c[2][0] * c[2][0] + c[2][1] * c[2][1] + c[2][2] * c[2][2];
    double fu = c[1][0] * c[2][0] + c[1][1] * c[2][1] + c[1][2] * c[2][2];
    CHECK(fabs(ff - 1.0) < 1e-5 && fabs(uu - 1.0) < 1e-5 && fabs(fu) < 1e-5 && fov > 1.0 && fov < 179.0,
          "camera: |forward|^2 %g, |up|^2 %g, forward.up %g, yfov %g", ff, uu, fu, fov);
}

/* Two roles never share a file: two outputs, or an output and an input (the scene, the
 * environment map), the same file by another spelling or through a link, is a usage error before
 * anything renders, and every file stays as it was. */
static void test_output_roles(void) {
    char scene_path[1024], env[1024], err[256];
    snprintf(scene_path, sizeof scene_path, "%s/roles.gltf", tmp);
    FILE *f = fopen(scene_path, "w");
    fputs("{\"asset\": {\"version\": \"2.0\"}}", f);
    fclose(f);
    snprintf(env, sizeof env, "%s/roles-sky.exr", tmp);
    float px[3 * 8] = {1, 1, 1};
    exr_layer layer = {"", px};
    CHECK(exr_save_layers(env, 4, 2, &layer, 1, WRITE_REPLACE, err, sizeof err) == 0, "sky: %s", err);
    char link_path[1100];
    snprintf(link_path, sizeof link_path, "%s/roles-link.gltf", tmp);
    CHECK(symlink("roles.gltf", link_path) == 0, "symlink: %s", strerror(errno));
    /* The format follows the option: an EXR named .png (or a PNG named .exr) is refused. */
    expect_failure("render --spp 1 --size 8x8 --out same.exr --png same.exr", 2, "--png writes a PNG");
    expect_failure("render --spp 1 --size 8x8 --out picture.png", 2, "--out writes OpenEXR");
    CHECK(!file_exists("picture.png"), "--out picture.png wrote a file");
    expect_failure("render --spp 1 --size 8x8 --out same.exr --stats ./same.exr", 2, "--out and --stats");
    expect_failure("render --spp 1 --size 8x8 --png same.png --stats ../cli/same.png", 2, "--png and --stats");
    /* A scene is no .png or .exr: the names' check refuses it first. */
    expect_failure("render roles.gltf --spp 1 --size 8x8 --png roles.gltf", 2, "--png writes a PNG");
    expect_failure("render roles-link.gltf --spp 1 --size 8x8 --out roles.gltf", 2, "--out writes OpenEXR");
    expect_failure("render roles.gltf --env roles-sky.exr --spp 1 --size 8x8 --out roles-sky.exr", 2,
                   "is the environment map");
    expect_failure("info roles.gltf --obj roles.gltf", 2, "is the scene");
    CHECK(!file_exists("same.exr") && !file_exists("same.png"), "a refused render wrote an output");
    char text[256];
    CHECK(read_file("roles.gltf", text, sizeof text) > 0 && strstr(text, "\"2.0\""), "the scene was changed");
    exr_image img;
    int loaded = exr_image_load(env, &img, err, sizeof err) == 0;
    CHECK(loaded && img.width == 4, "the map was changed: %s", err);
    if (loaded) exr_image_free(&img);
}

int main(int argc, char **argv) {
    /* An empty directory, so the default-output numbering is known. */
    int start = harness_start(argc, argv, "cli");
    if (start != 0) return start;
    test_usage();
    test_errors();
    test_builtin_scenes();
    test_outputs();
    test_many_light_options();
    test_highlights_layer();
    test_obj_and_camera();
    test_output_roles();
    return check_exit("test_cli");
}
