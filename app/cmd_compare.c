/* glint compare: the relative L2 error of one image against a reference, with the reference's own
 * noise taken out in quadrature (as glint bench does), for images made elsewhere: a viewer's
 * capture, a render. When both files carry glint descriptions they must show the same thing:
 * scene, camera (the viewer's tolerance, camera_same_view), variant, environment and light edits. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "camera.h"
#include "cli.h"
#include "commands.h"
#include "image_io.h"
#include "metrics.h"
#include "reference.h"

/* The pixels whose share of the error compare reports: a thousandth, a light's speck and its rim. */
#define PEAK_FRACTION 1e-3

static void print_compare_help(void) {
    printf("usage: glint compare IMAGE.exr REFERENCE.exr [--layer NAME]\n"
           "\n"
           "Prints one line, rel_l2=X ref_noise=Y net=Z peak_share=P: the relative L2 error\n"
           "||I - R|| / ||R|| of the image against the reference, the reference's own noise from its\n"
           "description (0 when it has none, and for a layer), the error with that noise taken out in\n"
           "quadrature, sqrt(max(0, X^2 - Y^2)), and the share of the squared error in the 0.1%% of the\n"
           "pixels where it is largest (near 1: a few pixels, such as a light's speck in a mirror,\n"
           "carry the error). Refuses images of different sizes and, when both carry glint\n"
           "descriptions, of another scene, camera, material variant, environment or light edits.\n"
           "\n"
           "options:\n"
           "  --layer NAME   compare the layer NAME.R,G,B (direct, indirect, highlights) [R,G,B]\n"
           "  --help         this text\n");
}

/* The layer of the EXR at path (prefix "" for R,G,B) into *rgb, its size into *w, *h. 0, or -1
 * after printing the error. */
static int load_layer(const char *path, const char *prefix, float **rgb, int *w, int *h) {
    exr_image ex;
    char err[1200];
    if (exr_image_load(path, &ex, err, sizeof err) != 0) return cli_error("%s", err), -1;
    *rgb = exr_image_layer_rgb(&ex, prefix);
    *w = ex.width;
    *h = ex.height;
    exr_image_free(&ex);
    if (!*rgb) return cli_error("%s: no %s%sR,G,B channels (or out of memory)", path, prefix, prefix[0] ? "." : ""), -1;
    size_t bad = 0, n = 3 * (size_t)*w * (size_t)*h;
    for (size_t i = 0; i < n; i++) bad += !isfinite((*rgb)[i]);
    if (bad) {
        free(*rgb);
        *rgb = NULL;
        return cli_error("%s: %zu values are not finite (NaN or Inf)", path, bad), -1;
    }
    return 0;
}

/* Whether two descriptions show the same thing. 0, or -1 after printing the first difference. */
static int same_subject(const char *img, const reference_info *a, const char *ref, const reference_info *b) {
    if (a->model[0] && b->model[0] && strcmp(a->model, b->model) != 0)
        return cli_error("%s: rendered by material model '%s', %s by '%s': re-render the reference", img, a->model, ref,
                         b->model),
               -1;
    if (strcmp(a->scene_hash, b->scene_hash) != 0)
        return cli_error("%s: a view of '%s' (%s), %s of '%s' (%s)", img, a->scene, a->scene_hash, ref, b->scene,
                         b->scene_hash),
               -1;
    if (strcmp(a->env_hash, b->env_hash) != 0 || fabs(a->env_rotation - b->env_rotation) > 1e-6)
        return cli_error("%s: environment '%s' (rotated %g), %s '%s' (rotated %g)", img, a->env[0] ? a->env : "none",
                         a->env_rotation, ref, b->env[0] ? b->env : "none", b->env_rotation),
               -1;
    if (strcmp(a->variant, b->variant) != 0)
        return cli_error("%s: material variant '%s', %s '%s'", img, a->variant[0] ? a->variant : "default", ref,
                         b->variant[0] ? b->variant : "default"),
               -1;
    /* The viewer's tolerance, at the scene's size; descriptions older than that size: equal. */
    float scale = fmaxf(a->scene_diag, b->scene_diag);
    if (!camera_same_view(&a->cam, &b->cam, scale))
        return cli_error("%s: seen from %g %g %g looking %g %g %g, %s from %g %g %g looking %g %g %g", img,
                         (double)a->cam.position.x, (double)a->cam.position.y, (double)a->cam.position.z,
                         (double)a->cam.forward.x, (double)a->cam.forward.y, (double)a->cam.forward.z, ref,
                         (double)b->cam.position.x, (double)b->cam.position.y, (double)b->cam.position.z,
                         (double)b->cam.forward.x, (double)b->cam.forward.y, (double)b->cam.forward.z),
               -1;
    if (!reference_lights_same(a->lights, b->lights))
        return cli_error("%s: lights %s%s%s, %s %s%s%s", img, a->lights[0] ? "edited '" : "as loaded", a->lights,
                         a->lights[0] ? "'" : "", ref, b->lights[0] ? "edited '" : "as loaded", b->lights,
                         b->lights[0] ? "'" : ""),
               -1;
    return 0;
}

int cmd_compare(int argc, char **argv) {
    const char *files[2] = {NULL, NULL}, *layer = "";
    int num_files = 0;
    for (int i = 0; i < argc; i++) {
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            print_compare_help();
            return EXIT_OK;
        } else if (strcmp(argv[i], "--layer") == 0) {
            if (!(layer = cli_value(argc, argv, &i))) return EXIT_USAGE;
            if (strlen(layer) > 200) return cli_error("--layer: name too long"), EXIT_USAGE;
        } else if (argv[i][0] == '-') {
            return cli_error("compare: unknown option '%s' (see glint compare --help)", argv[i]), EXIT_USAGE;
        } else if (num_files == 2) {
            return cli_error("compare: one image and one reference, not '%s' too", argv[i]), EXIT_USAGE;
        } else {
            files[num_files++] = argv[i];
        }
    }
    if (num_files != 2)
        return cli_error("compare: needs IMAGE.exr REFERENCE.exr (see glint compare --help)"), EXIT_USAGE;
    reference_info info[2];
    int described[2];
    char err[4400];
    for (int k = 0; k < 2; k++) {
        int st = reference_load(files[k], &info[k], err, sizeof err);
        if (st < 0) return cli_error("%s", err), EXIT_FAILURE_;
        described[k] = st == 0;
    }
    if (described[0] && described[1] && same_subject(files[0], &info[0], files[1], &info[1]) != 0) return EXIT_FAILURE_;
    float *img = NULL, *ref = NULL;
    int w[2], h[2], status = EXIT_FAILURE_;
    if (load_layer(files[0], layer, &img, &w[0], &h[0]) == 0 && load_layer(files[1], layer, &ref, &w[1], &h[1]) == 0) {
        if (w[0] != w[1] || h[0] != h[1]) {
            cli_error("%s: %dx%d, but %s is %dx%d", files[0], w[0], h[0], files[1], w[1], h[1]);
        } else {
            size_t pixels = (size_t)w[0] * (size_t)h[0];
            double e = metric_rel_l2(img, ref, 3 * pixels);
            /* The noise a description gives is the whole image's: a layer's is unknown. */
            double noise = described[1] && info[1].has_noise && !layer[0] ? info[1].rel_l2_noise : 0.0;
            double peak = metric_peak_share(img, ref, pixels, 3, PEAK_FRACTION);
            if (peak < 0.0) {
                cli_error("%s: out of memory", files[0]);
            } else {
                printf("rel_l2=%.6g ref_noise=%.6g net=%.6g peak_share=%.4f\n", e, noise,
                       metric_without_noise(e, noise), peak);
                status = EXIT_OK;
            }
        }
    }
    free(img);
    free(ref);
    return status;
}
