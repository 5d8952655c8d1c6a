/* glint — the glTF/GLB importer under a fuzzer: any input must load or fail with one non-empty
 * line, and a loaded scene must take rays (Embree refuses some coordinates by aborting). Built
 * with libFuzzer (clang) as fuzz_gltf, and with replay.c's main() as a plain program that runs
 * stored inputs (the regressions) in any build. External URIs resolve in GLINT_FUZZ_FILES. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void trace_some_rays(const scene *s) {
    vec3 o = s->num_cameras ? s->cameras[0].position : add3(s->bounds.hi, v3s(s->diag));
    vec3 target = scale3(add3(s->bounds.lo, s->bounds.hi), 0.5f);
    for (int i = 0; i < 8; i++) {
        vec3 d = normalize3(sub3(add3(target, v3(0.1f * (float)i * s->diag, 0.0f, 0.0f)), o));
        if (!is_finite3(d)) d = v3(0, 0, -1);
        surface_hit h;
        if (scene_intersect(s, o, d, INFINITY, &h) && !is_finite3(h.p)) abort();
        (void)scene_occluded(s, o, d, 1.0f);
    }
}

/* Warnings too are one line each. */
static void on_warning(void *user, const char *msg) {
    (void)user;
    if (!msg[0] || strchr(msg, '\n')) {
        fprintf(stderr, "bad warning: '%s'\n", msg);
        abort();
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    char err[1024];
    err[0] = 0;
    scene *s = scene_load_memory(data, size, GLINT_FUZZ_FILES, "fuzz.gltf", on_warning, NULL, err, sizeof err);
    if (!s) {
        /* The promise: one line, naming the input, saying something. */
        if (strncmp(err, "fuzz.gltf: ", 11) != 0 || !err[11] || strchr(err, '\n')) {
            fprintf(stderr, "bad error message: '%s'\n", err);
            abort();
        }
        return 0;
    }
    trace_some_rays(s);
    /* Each material variant (a few), rebuilt and traced again; then back to the defaults. */
    for (int v = 0; v < scene_num_variants(s) && v < 4; v++) {
        if (scene_set_variant(s, v, err, sizeof err) == 0) trace_some_rays(s);
    }
    if (scene_num_variants(s) > 0 && scene_set_variant(s, -1, err, sizeof err) == 0) trace_some_rays(s);
    scene_destroy(s);
    return 0;
}
