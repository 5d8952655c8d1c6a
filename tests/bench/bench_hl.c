/* The highlight paper's comparison, measured: the highlight component alone (camera rays and
 * the highlight estimator, nothing else) at equal wall time, relative L2 error against a
 * converged estimate of the same paths, for path tracing those paths (--merge trace: each
 * secondary hit lit through its true glossy lobe, light and lobe sampling under MIS), the
 * paper's no-merging comparison (--merge off) and merging into K lobes, for N secondary rays;
 * and the share of the render threads' time spent clustering and merging (Table 1, column C);
 * then, for N = 8, each estimator's error split into noise and bias by two independent runs;
 * last, the whole renderer at equal time, as the viewer shows it (the paper's Fig. 1): the
 * path tracer's highlights layer against vsl+hl's, each frame rendering everything.
 *
 * usage: bench_hl SCENE|default REF.exr WxH REF_SECONDS SECONDS
 *   REF.exr (layer highlights.*) is rendered with --merge trace, 64 secondary rays, for
 *   REF_SECONDS when it does not exist, and reused after.
 * Prints a markdown table. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "camera.h"
#include "clock.h"
#include "envfilter.h"
#include "highlights.h"
#include "image_io.h"
#include "lights.h"
#include "manylight.h"
#include "metrics.h"
#include "session.h"
#include "threadpool.h"

static double now(void) { return 1e-9 * (double)clock_ns(); }

static void die(const char *what) {
    fprintf(stderr, "bench_hl: %s\n", what);
    exit(1);
}

typedef struct {
    const scene *s;
    camera cam;
    int w, h;
    hl_setup hl;
    long long frame;
    double *sum;         /* running sum per pixel channel */
    render_stats *stats; /* per worker */
    uint64_t seed;
} run;

/* One image row of one frame: a jittered camera ray per pixel, the highlights at its hit. */
static void render_row(void *ctx, int y, int worker) {
    run *r = ctx;
    float aspect = (float)r->w / (float)r->h;
    render_stats *st = &r->stats[worker];
    for (int x = 0; x < r->w; x++) {
        int pixel = y * r->w + x;
        rng_state rng = rng_for((uint64_t)pixel, (uint64_t)r->frame, 99 + 1000 * r->seed);
        vec2 j = rng_vec2(&rng);
        vec3 d = camera_ray_dir(&r->cam, aspect, ((float)x + j.x) / (float)r->w, ((float)y + j.y) / (float)r->h);
        surface_hit h;
        st->rays[RAY_CAMERA]++;
        if (!scene_intersect(r->s, r->cam.position, d, INFINITY, &h)) continue;
        shading_point sp = shading_point_at(r->s, &h, d);
        vec3 c = hl_estimate(&r->hl, r->s, &sp, &rng, st);
        if (!is_finite3(c)) continue;
        r->sum[3 * pixel] += (double)c.x;
        r->sum[3 * pixel + 1] += (double)c.y;
        r->sum[3 * pixel + 2] += (double)c.z;
    }
}

/* Renders frames until `seconds` have passed; the mean into img. Returns the frames rendered
 * and the share of thread time spent merging in *merge_share. */
static long long render_for(const run *proto, threadpool *pool, double seconds, float *img, double *merge_share) {
    run r = *proto;
    size_t n = (size_t)r.w * (size_t)r.h * 3;
    int threads = threadpool_size(pool);
    r.sum = calloc(n, sizeof(double));
    r.stats = calloc((size_t)threads, sizeof(render_stats));
    if (!r.sum || !r.stats) die("out of memory");
    double t0 = now(), elapsed = 0.0;
    for (r.frame = 0; r.frame == 0 || (elapsed = now() - t0) < seconds; r.frame++)
        threadpool_run(pool, render_row, &r, r.h);
    uint64_t merge_ns = 0;
    for (int t = 0; t < threads; t++) merge_ns += r.stats[t].hl_merge_ns;
    *merge_share = 1e-9 * (double)merge_ns / (elapsed * threads);
    for (size_t i = 0; i < n; i++) img[i] = (float)(r.sum[i] / (double)r.frame);
    free(r.sum);
    free(r.stats);
    return r.frame;
}

/* The whole renderer (session) with params for `seconds`: its highlights layer into img. Returns
 * the frames rendered. */
static long long session_render_for(const scene *s, const camera *cam, const render_params *params, double seconds,
                                    float *img) {
    char err[256];
    render_session *rs = session_create(s, cam, params, err, sizeof err);
    if (!rs) die(err);
    double t0 = now();
    do {
        if (session_render_frame(rs) != 0) die(session_error(rs));
    } while (now() - t0 < seconds);
    film_resolve(session_film(rs), 1u << COMP_HIGHLIGHTS, img);
    long long frames = session_frames(rs);
    session_destroy(rs);
    return frames;
}

/* sum (a - b)^2 / sum ref^2 */
static double rel_sq(const float *a, const float *b, const float *ref, size_t n) {
    double d = 0.0, r = 0.0;
    for (size_t i = 0; i < n; i++) {
        d += ((double)a[i] - (double)b[i]) * ((double)a[i] - (double)b[i]);
        r += (double)ref[i] * (double)ref[i];
    }
    return r > 0.0 ? d / r : 0.0;
}

int main(int argc, char **argv) {
    if (argc != 6) die("usage: bench_hl SCENE|default REF.exr WxH REF_SECONDS SECONDS");
    char err[1024];
    scene *s = strcmp(argv[1], "default") == 0 ? scene_load_default(NULL, NULL, err, sizeof err)
                                               : scene_load(argv[1], NULL, NULL, err, sizeof err);
    if (!s) die(err);
    run proto = {.s = s};
    if (sscanf(argv[3], "%dx%d", &proto.w, &proto.h) != 2) die("bad size");
    proto.cam = scene_camera(s, 0, (float)proto.w / (float)proto.h);
    double ref_seconds = atof(argv[4]), seconds = atof(argv[5]);
    threadpool *pool = threadpool_create(0);
    if (!pool) die("no threads");
    size_t n = (size_t)proto.w * (size_t)proto.h * 3;
    float *ref = malloc(sizeof(float) * n), *img = malloc(sizeof(float) * n);
    if (!ref || !img) die("out of memory");
    env_vmf_filter *envf = s->env ? env_vmf_filter_create(s->env, err, sizeof err) : NULL;
    if (s->env && !envf) die(err);

    exr_image ex;
    double share;
    if (exr_image_load(argv[2], &ex, err, sizeof err) == 0) {
        if (ex.width != proto.w || ex.height != proto.h) die("reference size mismatch");
        const float *c[3] = {exr_image_channel(&ex, "highlights.R"), exr_image_channel(&ex, "highlights.G"),
                             exr_image_channel(&ex, "highlights.B")};
        if (!c[0] || !c[1] || !c[2]) die("reference lacks the highlights layer");
        for (size_t i = 0; i < n / 3; i++)
            for (int k = 0; k < 3; k++) ref[3 * i + (size_t)k] = c[k][i];
        exr_image_free(&ex);
        fprintf(stderr, "bench_hl: reference %s\n", argv[2]);
    } else {
        fprintf(stderr, "bench_hl: rendering the reference for %.0f s\n", ref_seconds);
        vl_params vp = {.merge = HL_MERGE_TRACE, .secondary_rays = 64};
        proto.hl = hl_setup_from(s, &vp, envf);
        long long frames = render_for(&proto, pool, ref_seconds, ref, &share);
        fprintf(stderr, "bench_hl: reference %lld frames\n", frames);
        exr_layer layer = {"highlights", ref};
        if (exr_save_layers(argv[2], proto.w, proto.h, &layer, 1, WRITE_REPLACE, err, sizeof err) != 0) die(err);
    }

    printf("### Highlights alone at equal time (%g s each, %dx%d): relative L2 error (frames)\n\n", seconds, proto.w,
           proto.h);
    printf("| estimator | N = 8 | N = 16 | N = 32 |\n|---|---|---|---|\n");
    const int rays[3] = {8, 16, 32};
    const struct {
        const char *label;
        int merge, clusters;
    } rows[] = {{"path tracing (`--merge trace`)", HL_MERGE_TRACE, 0},
                {"no merging (`--merge off`)", HL_MERGE_OFF, 0},
                {"merged, K = 1", HL_MERGE_ON, 1},
                {"merged, K = 2", HL_MERGE_ON, 2},
                {"merged, K = 4", HL_MERGE_ON, 4}};
    double shares[5][3] = {{0}};
    for (size_t r = 0; r < sizeof rows / sizeof rows[0]; r++) {
        printf("| %s |", rows[r].label);
        for (int k = 0; k < 3; k++) {
            vl_params vp = {.merge = rows[r].merge, .clusters = rows[r].clusters, .secondary_rays = rays[k]};
            proto.hl = hl_setup_from(s, &vp, envf);
            long long frames = render_for(&proto, pool, seconds, img, &shares[r][k]);
            printf(" %.4f (%lld) |", metric_rel_l2(img, ref, n), frames);
            fflush(stdout);
        }
        printf("\n");
    }
    printf("\nShare of the render threads' time spent clustering and merging (column C of the paper's Table 1):\n\n"
           "| K | N = 8 | N = 16 | N = 32 |\n|---|---|---|---|\n");
    for (int r = 2; r < 5; r++)
        printf("| %d | %.1f%% | %.1f%% | %.1f%% |\n", rows[r].clusters, 100 * shares[r][0], 100 * shares[r][1],
               100 * shares[r][2]);

    /* Two independent runs A, B: E|A - B|^2 = 2 var, E|A - ref|^2 = var + bias^2 (bias here
     * includes the reference's own noise). */
    printf("\nNoise and bias, N = 8, two independent runs of %g s each:\n\n"
           "| estimator | frames | noise | bias |\n|---|---|---|---|\n",
           0.5 * seconds);
    float *img2 = malloc(sizeof(float) * n);
    if (!img2) die("out of memory");
    const int split_rows[] = {0, 1, 4};
    for (int i = 0; i < 3; i++) {
        int r = split_rows[i];
        vl_params vp = {.merge = rows[r].merge, .clusters = rows[r].clusters, .secondary_rays = 8};
        proto.hl = hl_setup_from(s, &vp, envf);
        proto.seed = 1;
        long long fa = render_for(&proto, pool, 0.5 * seconds, img, &share);
        proto.seed = 2;
        long long fb = render_for(&proto, pool, 0.5 * seconds, img2, &share);
        proto.seed = 0;
        double ea = metric_rel_l2(img, ref, n), eb = metric_rel_l2(img2, ref, n);
        double noise2 = 0.5 * rel_sq(img, img2, ref, n);
        double bias2 = 0.5 * (ea * ea + eb * eb) - noise2;
        printf("| %s | %lld, %lld | %.4f | %.4f |\n", rows[r].label, fa, fb, sqrt(noise2),
               bias2 > 0.0 ? sqrt(bias2) : 0.0);
        fflush(stdout);
    }
    free(img2);

    /* Each method renders all of the image every frame; only the highlights are compared. The
     * path tracer reaches those paths through its one sample per pixel, vsl+hl through its
     * dedicated pass of N secondary rays. */
    printf("\nThe whole renderer at equal time (%g s each, every component rendered, the highlights layer "
           "compared): relative L2 error (frames)\n\n| method | N = 8 | N = 32 |\n|---|---|---|\n",
           seconds);
    render_params pp = {.width = proto.w, .height = proto.h, .method = METHOD_PT, .pt_highlights = 1, .seed = 5};
    long long pf = session_render_for(s, &proto.cam, &pp, seconds, img);
    printf("| path tracer (`--method pt --highlights-layer`) | %.4f (%lld) | |\n", metric_rel_l2(img, ref, n), pf);
    fflush(stdout);
    for (size_t r = 0; r < sizeof rows / sizeof rows[0]; r++) {
        printf("| `vsl+hl`, %s |", rows[r].label);
        for (int k = 0; k < 2; k++) {
            render_params vp = {.width = proto.w, .height = proto.h, .method = METHOD_VSL_HL, .seed = 5};
            vp.vl.merge = rows[r].merge;
            vp.vl.clusters = rows[r].clusters;
            vp.vl.secondary_rays = k == 0 ? 8 : 32;
            long long f = session_render_for(s, &proto.cam, &vp, seconds, img);
            printf(" %.4f (%lld) |", metric_rel_l2(img, ref, n), f);
            fflush(stdout);
        }
        printf("\n");
    }
    free(ref);
    free(img);
    threadpool_destroy(pool);
    env_vmf_filter_destroy(envf);
    scene_destroy(s);
    return 0;
}
