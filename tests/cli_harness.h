/* glint tests — the glint program run as a user would: in a scratch directory of its own, stdin
 * empty, stdout and stderr captured. For tests that take the program's path as their argument. */
#ifndef GLINT_CLI_HARNESS_H
#define GLINT_CLI_HARNESS_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

#include "image_io.h"

static const char *glint;                     /* the program under test */
static char tmp[512];                         /* its working directory */
static char out_text[65536], err_text[65536]; /* the last run's stdout and stderr */

/* Reads file `name` (relative to tmp) into buf, NUL-terminated; returns its length (0: none). */
static size_t read_file(const char *name, char *buf, size_t cap) {
    char p[1024];
    snprintf(p, sizeof p, "%s/%s", tmp, name);
    buf[0] = 0;
    FILE *f = fopen(p, "rb");
    if (!f) return 0;
    size_t n = fread(buf, 1, cap - 1, f);
    buf[n] = 0;
    fclose(f);
    return n;
}

/* Runs glint with the given arguments (a shell command tail) in tmp; returns the exit status, or
 * -1 when it did not exit normally (a crash). */
static int run(const char *args) {
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "cd '%s' && '%s' %s >stdout.txt 2>stderr.txt </dev/null", tmp, glint, args);
    int status = system(cmd);
    read_file("stdout.txt", out_text, sizeof out_text);
    read_file("stderr.txt", err_text, sizeof err_text);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/* The description glint render stores in a reference's header (the glint.reference attribute)
 * of file `name` (relative to tmp) into buf, NUL-terminated; returns its length (0: none). */
static inline size_t read_reference(const char *name, char *buf, size_t cap) {
    char p[1024], err[1024];
    snprintf(p, sizeof p, "%s/%s", tmp, name);
    buf[0] = 0;
    char *value = NULL;
    size_t len = 0;
    if (exr_header_string(p, "glint.reference", &value, &len, err, sizeof err) != 0) return 0;
    snprintf(buf, cap, "%s", value);
    free(value);
    return strlen(buf);
}

/* Writes the pixels of EXR `from` (relative to tmp; every R,G,B and PREFIX.R,G,B layer) again as
 * `to`: with description (NULL: none) in its glint.reference header attribute or, when sidecar
 * is set, with none in the header and description in the file TO.json beside it, as glint wrote
 * references before they carried it. Returns 0, or -1 after printing why. */
static inline int write_reference_image(const exr_image *image, const char *to, const char *description, int sidecar);
static inline int write_reference(const char *from, const char *to, const char *description, int sidecar) {
    char p[1024], err[1024];
    snprintf(p, sizeof p, "%s/%s", tmp, from);
    exr_image ex;
    if (exr_image_load(p, &ex, err, sizeof err) != 0) {
        fprintf(stderr, "%s\n", err);
        return -1;
    }
    int status = write_reference_image(&ex, to, description, sidecar);
    exr_image_free(&ex);
    return status;
}

/* The same from pixels in memory (an EXR as read, maybe changed). */
static inline int write_reference_image(const exr_image *image, const char *to, const char *description, int sidecar) {
    char p[1024], err[1024];
    const exr_image ex = *image;
    size_t n = (size_t)ex.width * (size_t)ex.height;
    exr_layer layers[16];
    char prefixes[16][64];
    int nl = 0, status = 0;
    for (int c = 0; c < ex.num_channels && nl < 16; c++) {
        const char *name = ex.names[c], *dot = strrchr(name, '.');
        if (strcmp(dot ? dot + 1 : name, "R") != 0) continue;
        snprintf(prefixes[nl], sizeof prefixes[nl], "%.*s", dot ? (int)(dot - name) : 0, name);
        float *rgb = malloc(sizeof(float) * 3 * n);
        for (int k = 0; k < 3 && rgb; k++) {
            char chan[80];
            snprintf(chan, sizeof chan, "%s%s%c", prefixes[nl], dot ? "." : "", "RGB"[k]);
            const float *plane = exr_image_channel(&ex, chan);
            for (size_t i = 0; i < n; i++) rgb[3 * i + (size_t)k] = plane ? plane[i] : 0.0f;
        }
        layers[nl] = (exr_layer){prefixes[nl], rgb};
        if (rgb) nl++;
    }
    exr_text_attr attr = {"glint.reference", description};
    snprintf(p, sizeof p, "%s/%s", tmp, to);
    if (exr_save_layers_attrs(p, ex.width, ex.height, layers, nl, &attr, description && !sidecar ? 1 : 0, WRITE_REPLACE,
                              err, sizeof err) != 0) {
        fprintf(stderr, "%s\n", err);
        status = -1;
    }
    if (status == 0 && sidecar && description) {
        snprintf(p, sizeof p, "%s/%s.json", tmp, to);
        FILE *f = fopen(p, "wb");
        status = f && fputs(description, f) >= 0 ? 0 : -1;
        if (f && fclose(f) != 0) status = -1;
    }
    for (int l = 0; l < nl; l++) free((void *)layers[l].rgb);
    return status;
}

/* Takes the program from argv[1] and makes tmp an empty directory $GLINT_TEST_TMP/name (or under
 * /tmp). Returns 0, or the status main should exit with. */
static int harness_start(int argc, char **argv, const char *name) {
    if (argc < 2) {
        fprintf(stderr, "usage: test_%s GLINT\n", name);
        return 2;
    }
    glint = argv[1];
    const char *t = getenv("GLINT_TEST_TMP");
    snprintf(tmp, sizeof tmp, "%s/%s", t ? t : "/tmp", name);
    char cmd[1100];
    snprintf(cmd, sizeof cmd, "rm -rf '%s' && mkdir -p '%s'", tmp, tmp);
    return system(cmd) == 0 ? 0 : 1;
}

#endif
