/* What the effect plan saves: the same method with only the passes the scene calls for
 * (--plan auto) and with every pass forced on (--plan full), for the same wall time: frames, the
 * time each pass took, and the relative L2 error of the indirect light (highlights included)
 * against a path-traced reference. Error falls as 1/sqrt(time), so the time the forced plan
 * needs to reach the plan's error is T (e_full / e_auto)^2: the saving at equal error.
 *
 * usage: bench_plan SCENE|default REF.exr WxH REF_SECONDS SECONDS [METHOD [ENV_MAP]]
 *   REF.exr (layer indirect.*) is path-traced for REF_SECONDS when it does not exist, and reused.
 * Prints one markdown table row per plan. */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "camera.h"
#include "clock.h"
#include "image_io.h"
#include "metrics.h"
#include "session.h"

static void die(const char *what) {
    fprintf(stderr, "bench_plan: %s\n", what);
    exit(1);
}

static render_session *render_for(const scene *s, const camera *cam, render_params p, double seconds) {
    char err[256];
    render_session *rs = session_create(s, cam, &p, err, sizeof err);
    if (!rs) die(err);
    uint64_t t0 = clock_ns();
    do {
        if (session_render_frame(rs) != 0) die(session_error(rs));
    } while (1e-9 * (double)(clock_ns() - t0) < seconds);
    return rs;
}

int main(int argc, char **argv) {
    if (argc < 6 || argc > 8) die("usage: bench_plan SCENE|default REF.exr WxH REF_SECONDS SECONDS [METHOD [ENV_MAP]]");
    char err[1024];
    scene *s = strcmp(argv[1], "default") == 0 ? scene_load_default(NULL, NULL, err, sizeof err)
                                               : scene_load(argv[1], NULL, NULL, err, sizeof err);
    if (!s) die(err);
    if (argc == 8 && scene_set_env(s, argv[7], 0.0f, err, sizeof err) != 0) die(err);
    int w, h;
    if (sscanf(argv[3], "%dx%d", &w, &h) != 2) die("bad size");
    camera cam = scene_camera(s, 0, (float)w / (float)h);
    double ref_seconds = atof(argv[4]), seconds = atof(argv[5]);
    int method = argc >= 7 ? method_from_name(argv[6]) : METHOD_VSL_HL;
    if (method < 0) die("unknown method");
    size_t n = (size_t)w * (size_t)h * 3;
    float *ref = malloc(sizeof(float) * n), *img = malloc(sizeof(float) * n);
    if (!ref || !img) die("out of memory");

    exr_image ex;
    if (exr_image_load(argv[2], &ex, err, sizeof err) != 0) {
        fprintf(stderr, "bench_plan: path tracing the reference for %.0f s\n", ref_seconds);
        render_params p = {.width = w, .height = h, .method = METHOD_PT, .seed = 77};
        render_session *rs = render_for(s, &cam, p, ref_seconds);
        if (film_save_exr(session_film(rs), (1u << COMP_DIRECT) | (1u << COMP_INDIRECT), argv[2], WRITE_REPLACE, err,
                          sizeof err) != 0)
            die(err);
        session_destroy(rs);
        if (exr_image_load(argv[2], &ex, err, sizeof err) != 0) die(err);
    }
    if (ex.width != w || ex.height != h) die("reference size mismatch");
    const float *c[3] = {exr_image_channel(&ex, "indirect.R"), exr_image_channel(&ex, "indirect.G"),
                         exr_image_channel(&ex, "indirect.B")};
    if (!c[0] || !c[1] || !c[2]) die("reference lacks the indirect layer");
    for (size_t i = 0; i < n / 3; i++)
        for (int k = 0; k < 3; k++) ref[3 * i + (size_t)k] = c[k][i];
    exr_image_free(&ex);

    printf("| scene | plan | frames | direct s | virtual lights s | gather s | highlights s | error | time to the "
           "plan's error |\n|---|---|---|---|---|---|---|---|---|\n");
    double err_of[2];
    for (int mode = PLAN_AUTO; mode <= PLAN_FULL; mode++) {
        render_params p = {.width = w, .height = h, .method = method, .seed = 5, .plan = mode};
        render_session *rs = render_for(s, &cam, p, seconds);
        film_resolve(session_film(rs), (1u << COMP_INDIRECT) | (1u << COMP_HIGHLIGHTS), img);
        err_of[mode] = metric_rel_l2(img, ref, n);
        render_stats st = session_stats(rs);
        printf("| %s | %s | %lld | %.1f | %.1f | %.1f | %.1f | %.4f |", argv[1], mode == PLAN_AUTO ? "auto" : "full",
               session_frames(rs), 1e-9 * (double)st.pass_ns[PASS_DIRECT],
               1e-9 * (double)st.pass_ns[PASS_VIRTUAL_LIGHTS], 1e-9 * (double)st.pass_ns[PASS_GATHER],
               1e-9 * (double)st.pass_ns[PASS_HIGHLIGHTS], err_of[mode]);
        if (mode == PLAN_AUTO)
            printf(" %.0f s |\n", seconds);
        else
            printf(" %.0f s (the plan saves %.0f%%) |\n", seconds * (err_of[1] / err_of[0]) * (err_of[1] / err_of[0]),
                   100.0 * (1.0 - (err_of[0] / err_of[1]) * (err_of[0] / err_of[1])));
        fflush(stdout);
        session_destroy(rs);
    }
    free(ref);
    free(img);
    scene_destroy(s);
    return 0;
}
