/* glint — the reader of reference descriptions (reference_parse: cJSON, then every field checked)
 * under a fuzzer. Any input must parse or fail with one non-empty line starting with the label; a
 * parsed description must be in range, written again by reference_json must read back the same,
 * and must match itself (reference_check). Built with libFuzzer (clang) as fuzz_reference, and
 * with replay.c's main() in any build. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "reference.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define LABEL "fuzz.exr: bad glint.reference header attribute"

static void bad(const char *what) {
    fprintf(stderr, "fuzz_reference: %s\n", what);
    abort();
}

static int close_to(double a, double b) { return fabs(a - b) <= 1e-6 * (1.0 + fmax(fabs(a), fabs(b))); }

static void check_info(const reference_info *r) {
    if (!memchr(r->scene, 0, sizeof r->scene) || !memchr(r->scene_hash, 0, sizeof r->scene_hash) ||
        !memchr(r->env, 0, sizeof r->env) || !memchr(r->env_hash, 0, sizeof r->env_hash) ||
        !memchr(r->method, 0, sizeof r->method))
        bad("an unterminated string");
    if (r->width < 1 || r->width > 16384 || r->height < 1 || r->height > 16384) bad("a size out of range");
    if (r->camera_index < -1 || r->max_depth < 1 || r->spp < 0) bad("a count out of range");
    if (!isfinite(r->env_rotation) || !isfinite(r->seconds) || !isfinite(r->cam.yfov) || !is_finite3(r->cam.position) ||
        !is_finite3(r->cam.right) || !is_finite3(r->cam.up) || !is_finite3(r->cam.forward))
        bad("a number not finite");
    if (r->has_noise && (!isfinite(r->mean_variance) || !isfinite(r->rel_l2_noise))) bad("noise not finite");
}

/* What reference_json writes reads back as the same description. */
static void check_round_trip(const reference_info *r) {
    char *json = reference_json(r);
    if (!json) bad("reference_json failed");
    reference_info back;
    char err[1024];
    if (reference_parse(json, strlen(json), LABEL, &back, err, sizeof err) != 0) {
        fprintf(stderr, "fuzz_reference: its own JSON does not read back (%s):\n%s\n", err, json);
        abort();
    }
    free(json);
    if (strcmp(r->scene, back.scene) || strcmp(r->scene_hash, back.scene_hash) || strcmp(r->env, back.env) ||
        strcmp(r->env_hash, back.env_hash) || strcmp(r->method, back.method) || strcmp(r->model, back.model))
        bad("a string changed in the round trip");
    if (r->width != back.width || r->height != back.height || r->camera_index != back.camera_index ||
        r->max_depth != back.max_depth || r->spp != back.spp || r->seed != back.seed ||
        r->highlights_layer != back.highlights_layer || r->has_noise != back.has_noise)
        bad("a count changed in the round trip");
    if (!close_to(r->env_rotation, back.env_rotation) || !close_to(r->seconds, back.seconds) ||
        (r->has_noise &&
         (!close_to(r->mean_variance, back.mean_variance) || !close_to(r->rel_l2_noise, back.rel_l2_noise))))
        bad("a number changed in the round trip");
    if (reference_check("fuzz.exr", r, &back, err, sizeof err) != 0) {
        fprintf(stderr, "fuzz_reference: does not match its round trip: %s\n", err);
        abort();
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    char *text = malloc(size + 1);
    if (!text) return 0;
    if (size) memcpy(text, data, size);
    text[size] = '\0';
    reference_info info;
    char err[1024];
    err[0] = 0;
    if (reference_parse(text, size, LABEL, &info, err, sizeof err) != 0) {
        /* The promise: one line, starting with the label, saying something after it. */
        if (strncmp(err, LABEL, strlen(LABEL)) != 0 || !err[strlen(LABEL)] || strchr(err, '\n')) {
            fprintf(stderr, "fuzz_reference: bad error message: '%s'\n", err);
            abort();
        }
    } else {
        check_info(&info);
        check_round_trip(&info);
    }
    free(text);
    return 0;
}
