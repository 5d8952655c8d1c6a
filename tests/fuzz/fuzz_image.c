/* glint — the image loaders under a fuzzer: the bytes as an environment map (image_rgb_load: EXR
 * or Radiance HDR by magic), as a reference image (exr_image_load, every channel) and as a
 * reference's header (exr_header_string). Each must load or fail with one non-empty line starting
 * with the path; what loads must be sane. The bytes reach the loaders through a memory file
 * (memfd_create) opened by its /proc/self/fd path, a regular file, so nothing touches the disk.
 * Built with libFuzzer (clang) as fuzz_image, and with replay.c's main() in any build. */
#define _GNU_SOURCE /* memfd_create */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image_io.h"
#include "memfile.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static memfile input = {-1, ""};

/* The promise of a failure: one line, "PATH: something". */
static void check_error(const char *what, const char *err) {
    size_t n = strlen(input.path);
    if (strncmp(err, input.path, n) != 0 || strncmp(err + n, ": ", 2) != 0 || !err[n + 2] || strchr(err, '\n')) {
        fprintf(stderr, "%s: bad error message: '%s'\n", what, err);
        abort();
    }
}

static void check_size(const char *what, int w, int h) {
    if (w <= 0 || h <= 0 || w > 131072 || h > 131072 || (int64_t)w * h > ((int64_t)1 << 28)) {
        fprintf(stderr, "%s: loaded an image of %dx%d\n", what, w, h);
        abort();
    }
}

/* Every texel of a small image, a sample of a large one: a file of a few hundred bytes may declare
 * a display window of 2^28 pixels, all zero, which the loaders may take (within their bounds). */
static size_t step(size_t n) { return n <= ((size_t)1 << 20) ? 1 : 4099; }

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    char err[1024];
    memfile_put(&input, data, size);

    image_rgb env;
    err[0] = 0;
    if (image_rgb_load(input.path, &env, err, sizeof err) != 0) {
        check_error("image_rgb_load", err);
    } else {
        check_size("image_rgb_load", env.width, env.height);
        size_t n = (size_t)env.width * (size_t)env.height * 3;
        for (size_t i = 0; i < n; i += step(n))
            if (!isfinite(env.rgb[i]) || env.rgb[i] < 0.0f) {
                fprintf(stderr, "image_rgb_load: texel %zu is %g\n", i, (double)env.rgb[i]);
                abort();
            }
        if (!isfinite(env.rgb[n - 1])) abort(); /* the sanitizer checks the buffer's end */
        image_rgb_free(&env);
    }

    exr_image ref;
    err[0] = 0;
    if (exr_image_load(input.path, &ref, err, sizeof err) != 0) {
        check_error("exr_image_load", err);
    } else {
        check_size("exr_image_load", ref.width, ref.height);
        if (ref.num_channels <= 0) fprintf(stderr, "exr_image_load: no channels\n"), abort();
        volatile float sum = 0.0f; /* texels read: the sanitizer checks each plane, its end too */
        size_t n = (size_t)ref.width * (size_t)ref.height;
        for (int c = 0; c < ref.num_channels; c++) {
            if (!ref.names[c] || !ref.names[c][0]) fprintf(stderr, "exr_image_load: unnamed channel\n"), abort();
            if (exr_image_channel(&ref, ref.names[c]) == NULL) abort();
            for (size_t i = 0; i < n; i += step(n)) sum += ref.planes[c][i];
            sum += ref.planes[c][n - 1];
        }
        exr_image_free(&ref);
    }

    char *value = NULL;
    size_t len = 0;
    err[0] = 0;
    int st = exr_header_string(input.path, "glint.reference", &value, &len, err, sizeof err);
    if (st < 0) check_error("exr_header_string", err);
    if (st == 0 && (!value || value[len] != '\0')) fprintf(stderr, "exr_header_string: bad value\n"), abort();
    if (st != 0 && value) fprintf(stderr, "exr_header_string: a value without success\n"), abort();
    free(value);
    return 0;
}
