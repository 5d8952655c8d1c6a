/* The VSL paper's comparisons, measured: relative L2 error of indirect illumination against a
 * path-traced reference at equal wall time (PT, clamped VPL, VSL), and the Fig. 8 sweeps (error
 * against the radius multiplier and against the column count at a fixed time).
 *
 * usage: bench_vsl SCENE|default REF.exr WxH REF_SECONDS "T1,T2,..." SWEEP_SECONDS [SEEDS]
 *   REF.exr is rendered with PT for REF_SECONDS when it does not exist (and reused after).
 *   SEEDS (default 4): independent runs of pt and vsl for the aim's table, since at these budgets
 *   a few pixels carry much of the error and single runs scatter.
 * Prints markdown tables. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "camera.h"
#include "clock.h"
#include "image_io.h"
#include "metrics.h"
#include "session.h"

static double now(void) { return 1e-9 * (double)clock_ns(); }

static void die(const char *what) {
    fprintf(stderr, "bench_vsl: %s\n", what);
    exit(1);
}

typedef struct {
    const scene *s;
    camera cam;
    int w, h;
    float *ref; /* indirect, interleaved RGB */
} bench;

static render_session *start(const bench *b, render_params p) {
    char err[256];
    p.width = b->w;
    p.height = b->h;
    render_session *rs = session_create(b->s, &b->cam, &p, err, sizeof err);
    if (!rs) die(err);
    return rs;
}

static double error_of(const bench *b, const render_session *rs) {
    size_t n = (size_t)b->w * (size_t)b->h * 3;
    float *img = malloc(sizeof(float) * n);
    film_resolve(session_film(rs), 1u << COMP_INDIRECT, img);
    double e = metric_rel_l2(img, b->ref, n);
    free(img);
    return e;
}

/* Renders one run progressively, reading the error and the frame count at each checkpoint. */
static void run_checkpoints(const bench *b, render_params p, const double *times, int nt, double *err,
                            long long *frames) {
    render_session *rs = start(b, p);
    double t0 = now();
    for (int k = 0; k < nt; k++) {
        while (now() - t0 < times[k])
            if (session_render_frame(rs) != 0) die(session_error(rs));
        err[k] = error_of(b, rs);
        frames[k] = session_frames(rs);
    }
    session_destroy(rs);
}

static void run_times(const bench *b, const char *label, render_params p, const double *times, int nt) {
    double err[16];
    long long frames[16];
    run_checkpoints(b, p, times, nt, err, frames);
    printf("| %s |", label);
    for (int k = 0; k < nt; k++) printf(" %.4f (%lld) |", err[k], frames[k]);
    printf("\n");
    fflush(stdout);
}

/* The same over independent runs (seeds 1..seeds): root mean square of the error at each
 * checkpoint, its range, and the mean frame count. */
static void run_seeds(const bench *b, const char *label, render_params p, const double *times, int nt, int seeds) {
    double sum2[16] = {0}, lo[16], hi[16], mean_frames[16] = {0};
    for (int k = 0; k < nt; k++) lo[k] = INFINITY, hi[k] = 0.0;
    for (int r = 0; r < seeds; r++) {
        double err[16];
        long long frames[16];
        p.seed = (uint64_t)r + 1;
        run_checkpoints(b, p, times, nt, err, frames);
        for (int k = 0; k < nt; k++) {
            sum2[k] += err[k] * err[k];
            lo[k] = fmin(lo[k], err[k]);
            hi[k] = fmax(hi[k], err[k]);
            mean_frames[k] += (double)frames[k] / seeds;
        }
    }
    printf("| %s |", label);
    for (int k = 0; k < nt; k++)
        printf(" %.3f (%.3f-%.3f; %.0f) |", sqrt(sum2[k] / seeds), lo[k], hi[k], mean_frames[k]);
    printf("\n");
    fflush(stdout);
}

static double run_for(const bench *b, render_params p, double seconds) {
    render_session *rs = start(b, p);
    double t0 = now();
    while (now() - t0 < seconds || session_frames(rs) == 0)
        if (session_render_frame(rs) != 0) die(session_error(rs));
    double e = error_of(b, rs);
    session_destroy(rs);
    return e;
}

int main(int argc, char **argv) {
    if (argc != 7 && argc != 8)
        die("usage: bench_vsl SCENE|default REF.exr WxH REF_SECONDS T1,T2,... SWEEP_SECONDS [SEEDS]");
    int seeds = argc == 8 ? atoi(argv[7]) : 4;
    if (seeds < 1 || seeds > 1000) die("SEEDS: expected 1 to 1000");
    char err[1024];
    scene *s = strcmp(argv[1], "default") == 0 ? scene_load_default(NULL, NULL, err, sizeof err)
                                               : scene_load(argv[1], NULL, NULL, err, sizeof err);
    if (!s) die(err);
    bench b = {.s = s};
    if (sscanf(argv[3], "%dx%d", &b.w, &b.h) != 2) die("bad size");
    b.cam = scene_camera(s, 0, (float)b.w / (float)b.h);
    double ref_seconds = atof(argv[4]), sweep_seconds = atof(argv[6]);
    double times[16];
    int nt = 0;
    for (char *t = strtok(argv[5], ","); t && nt < 16; t = strtok(NULL, ",")) times[nt++] = atof(t);

    size_t n = (size_t)b.w * (size_t)b.h * 3;
    b.ref = malloc(sizeof(float) * n);
    exr_image ex;
    if (exr_image_load(argv[2], &ex, err, sizeof err) == 0) {
        if (ex.width != b.w || ex.height != b.h) die("reference size mismatch");
        const float *c[3] = {exr_image_channel(&ex, "indirect.R"), exr_image_channel(&ex, "indirect.G"),
                             exr_image_channel(&ex, "indirect.B")};
        if (!c[0] || !c[1] || !c[2]) die("reference lacks the indirect layer");
        for (size_t i = 0; i < n / 3; i++)
            for (int k = 0; k < 3; k++) b.ref[3 * i + (size_t)k] = c[k][i];
        exr_image_free(&ex);
        fprintf(stderr, "bench_vsl: reference %s\n", argv[2]);
    } else {
        fprintf(stderr, "bench_vsl: rendering the PT reference for %.0f s\n", ref_seconds);
        render_session *rs = start(&b, (render_params){.method = METHOD_PT, .seed = 12345});
        double t0 = now();
        while (now() - t0 < ref_seconds) session_render_frame(rs);
        fprintf(stderr, "bench_vsl: reference %lld spp\n", session_frames(rs));
        film_resolve(session_film(rs), 1u << COMP_INDIRECT, b.ref);
        if (film_save_exr(session_film(rs), (1u << COMP_DIRECT) | (1u << COMP_INDIRECT), argv[2], WRITE_REPLACE, err,
                          sizeof err) != 0)
            die(err);
        session_destroy(rs);
    }

    printf("### Equal time: relative L2 error of indirect light (frames in brackets), %dx%d\n\n", b.w, b.h);
    printf("| method |");
    for (int k = 0; k < nt; k++) printf(" %g s |", times[k]);
    printf("\n|---|");
    for (int k = 0; k < nt; k++) printf("---|");
    printf("\n");
    run_times(&b, "pt", (render_params){.method = METHOD_PT}, times, nt);
    /* The paper's estimators gather every lobe from the lights (--trace-glossy off). */
    render_params vpl = {.method = METHOD_VPL};
    vpl.vl.trace_glossy = -1.0f;
    run_times(&b, "vpl, clamped, every lobe gathered", vpl, times, nt);
    render_params vsl = {.method = METHOD_VSL};
    render_params paper = vsl;
    paper.vl.trace_glossy = -1.0f;
    run_times(&b, "vsl, every lobe gathered (the paper's)", paper, times, nt);
    run_times(&b, "vsl (sharp lobes traced through)", vsl, times, nt);
    render_params ris = vsl;
    ris.vl.candidates = 4;
    run_times(&b, "vsl, lights resampled from 4 candidates", ris, times, nt);
    vsl.vl.radius_shrink = 0.7f;
    run_times(&b, "vsl, radius shrink 0.7", vsl, times, nt);

    printf("\n### The aim, over %d independent runs: root mean square error (range; mean frames)\n\n| method |", seeds);
    for (int k = 0; k < nt; k++) printf(" %g s |", times[k]);
    printf("\n|---|");
    for (int k = 0; k < nt; k++) printf("---|");
    printf("\n");
    run_seeds(&b, "pt", (render_params){.method = METHOD_PT}, times, nt, seeds);
    run_seeds(&b, "vsl", (render_params){.method = METHOD_VSL}, times, nt, seeds);

    printf("\n### Fig. 8 (right): error against the radius multiplier (every lobe gathered), %g s each\n\n"
           "| radius mult | rel. L2 |\n|---|---|\n",
           sweep_seconds);
    const float mults[] = {1, 2, 4, 8, 12, 16, 24};
    for (size_t k = 0; k < sizeof mults / sizeof mults[0]; k++) {
        render_params p = {.method = METHOD_VSL};
        p.vl.trace_glossy = -1.0f;
        p.vl.radius_mult = mults[k];
        printf("| %g | %.4f |\n", (double)mults[k], run_for(&b, p, sweep_seconds));
        fflush(stdout);
    }
    printf("\n### Fig. 8 (left): error against the column count (matrix row-column sampling, 4096 lights,\n"
           "300 rows, every lobe gathered), %g s each\n\n| columns | rel. L2 |\n|---|---|\n",
           sweep_seconds);
    const int cols[] = {64, 128, 256, 512, 1024};
    for (size_t k = 0; k < sizeof cols / sizeof cols[0]; k++) {
        render_params p = {.method = METHOD_VSL};
        p.vl.trace_glossy = -1.0f;
        p.vl.count = 4096;
        p.vl.columns = cols[k];
        printf("| %d | %.4f |\n", cols[k], run_for(&b, p, sweep_seconds));
        fflush(stdout);
    }
    free(b.ref);
    scene_destroy(s);
    return 0;
}
