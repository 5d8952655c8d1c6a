/* The render session's contract for interactive use: a frame stopped by the abort flag returns 1
 * and is not counted; with the flag clear frames finish and count; a reset after a stopped frame
 * leaves a film equal to one never stopped (same seed: the same image, bit for bit); statistics
 * count the frames since the last reset (the viewer's rays per second and virtual lights); a scene
 * edit re-analyses the scene and restarts. And the frames' positions inside a pixel cover it evenly:
 * an emitter's straight edge seen directly converges faster than independent positions would.
 * render_params.only: the components left out stay exactly zero and their passes never run. The
 * many-light methods' direct samples of a frame: spread over the pixel (the same edge after 16
 * frames of 4 nearer than 64 independent positions) and their lights' choice stratified (two
 * lights: a frame's value hardly varies, where choosing at random would). */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "test_scenes.h"

#define W 16
#define H 12

/* A pixel's mean over N frames against the exact share of it an emitter's edge covers (on the
 * plane z = -1 the emitter is x < 0.1 + 0.3 y; the share counted on a 32 x 32 grid of rays).
 * Independent positions leave an RMS error of sqrt(c (1 - c) / n), about 0.05 at n = 64 for
 * c near 1/2; positions that cover the pixel evenly leave far less. pt takes one position a frame,
 * vsl (--adapt off, only the direct light) 4 a frame: 64 positions each. */
static void check_edge_coverage(render_method method, int frames, int positions) {
    enum { EW = 64, EH = 40, G = 32 };
    scene *s = ts_new("edge");
    ts_quad(s, v3(-5, -5, -1), v3(-1.4f, -5, -1), v3(1.6f, 5, -1), v3(-5, 5, -1),
            ts_lambert(s, v3s(0.0f), v3s(1.0f), 0));
    ts_finalize(s);
    camera cam = camera_look_at(v3(0, 0, 0), v3(0, 0, -1), v3(0, 1, 0), 0.6f);
    render_params p = {.width = EW, .height = EH, .method = method, .max_depth = 1, .seed = 11};
    p.vl.adapt = VL_ADAPT_OFF;
    float *img = ts_render_with(s, &cam, &p, frames, ~0u);
    camera_raster r = camera_raster_make(&cam, EW, EH);
    double err2 = 0.0, indep2 = 0.0;
    int edge = 0;
    for (int y = 0; y < EH; y++) {
        for (int x = 0; x < EW; x++) {
            int in = 0;
            for (int j = 0; j < G; j++) {
                for (int i = 0; i < G; i++) {
                    vec3 d = camera_raster_dir(&r, (float)x + (i + 0.5f) / G, (float)y + (j + 0.5f) / G);
                    vec3 q = scale3(d, -1.0f / d.z);
                    in += q.x < 0.1f + 0.3f * q.y;
                }
            }
            double c = (double)in / (G * G), v = img[3 * (y * EW + x) + 1];
            if (c < 0.05 || c > 0.95) continue;
            edge++;
            err2 += (v - c) * (v - c);
            indep2 += c * (1.0 - c) / positions;
        }
    }
    CHECK(edge >= 20, "the edge must cross pixels (%d)", edge);
    double rms = sqrt(err2 / edge), indep = sqrt(indep2 / edge);
    CHECK(rms < 0.5 * indep,
          "%s, pixels along an edge after %d frames: RMS error %.4f, %d independent positions would "
          "leave %.4f",
          method_name(method), frames, rms, positions, indep);
    free(img);
    scene_destroy(s);
}

/* A session of p over n frames: their mean to mean and, when frames is not NULL, each frame's own
 * image (from the running means) to frames[f]. */
static void session_frames_of(const scene *s, const camera *cam, const render_params *p, int n, float *mean,
                              float **frames) {
    char err[256];
    int len = 3 * p->width * p->height;
    render_session *rs = session_create(s, cam, p, err, sizeof err);
    CHECK(rs != NULL, "session: %s", err);
    float *prev = calloc((size_t)len, sizeof *prev);
    for (int f = 0; rs && f < n; f++) {
        CHECK(session_render_frame(rs) == 0, "frame %d: %s", f, session_error(rs));
        film_resolve(session_film(rs), ~0u, mean);
        for (int i = 0; frames && i < len; i++) frames[f][i] = (float)((f + 1.0) * mean[i] - f * (double)prev[i]);
        memcpy(prev, mean, sizeof(float) * (size_t)len);
    }
    free(prev);
    session_destroy(rs);
}

/* A Lambert floor under two point lights of equal power, far apart, seen by vsl's 4 direct samples a
 * frame (--adapt off): their mean over the frames is the sum of the lights' images rendered apart,
 * and a frame's value varies far less than choosing each sample's light at random would make it
 * ((f1 - f2)^2 / 4 at a pixel where the lights alone give f1 and f2). */
static void check_direct_light_choice(void) {
    enum { N = 24, LEN = 3 * W * H };
    const vec3 lights[2] = {v3(-1.0f, 2.0f, -1.0f), v3(1.0f, 1.5f, -1.0f)};
    camera cam = camera_look_at(v3(0, 2.5f, 0.0f), v3(0, 0, -1), v3(0, 1, 0), 0.8f);
    render_params p = {.width = W, .height = H, .method = METHOD_VSL, .max_depth = 1, .seed = 7};
    p.vl.adapt = VL_ADAPT_OFF;
    float alone[2][LEN], both[LEN];
    float *frames[N];
    for (int f = 0; f < N; f++) frames[f] = malloc(sizeof(float) * LEN);
    for (int k = 0; k <= 2; k++) {
        scene *s = ts_new("two lights");
        ts_quad(s, v3(-4, 0, 2), v3(4, 0, 2), v3(4, 0, -6), v3(-4, 0, -6), ts_lambert(s, v3s(0.8f), v3s(0), 0));
        for (int l = 0; l < 2; l++)
            if (k == 2 || k == l) ts_point_light(s, lights[l]);
        ts_finalize(s);
        session_frames_of(s, &cam, &p, N, k < 2 ? alone[k] : both, k < 2 ? NULL : frames);
        scene_destroy(s);
    }
    double sum = 0.0, expect = 0.0, var = 0.0, random_choice = 0.0;
    for (int i = 0; i < LEN; i++) {
        double f1 = alone[0][i], f2 = alone[1][i], m = 0.0, m2 = 0.0;
        sum += both[i];
        expect += f1 + f2;
        for (int f = 0; f < N; f++) m += frames[f][i], m2 += (double)frames[f][i] * frames[f][i];
        m /= N;
        var += (m2 - N * m * m) / (N - 1);
        random_choice += (f1 - f2) * (f1 - f2) / 4.0;
    }
    CHECK(expect > 0.0 && fabs(sum / expect - 1.0) < 0.01, "two lights: mean %.5f of the lights' images apart",
          sum / expect);
    CHECK(var < 0.05 * random_choice,
          "two lights: a frame's variance %.4g, against %.4g were each sample's light chosen at random", var,
          random_choice);
    for (int f = 0; f < N; f++) free(frames[f]);
}

/* Sums of each component's film after two frames of p, and the statistics. */
static render_stats render_only(const scene *s, const camera *cam, render_params p, double sum[COMP_COUNT]) {
    char err[256];
    render_session *rs = session_create(s, cam, &p, err, sizeof err);
    CHECK(rs != NULL, "session: %s", err);
    if (!rs) return (render_stats){0};
    for (int f = 0; f < 2; f++) CHECK(session_render_frame(rs) == 0, "frame %d: %s", f, session_error(rs));
    float img[3 * W * H];
    for (int c = 0; c < COMP_COUNT; c++) {
        film_resolve(session_film(rs), 1u << c, img);
        sum[c] = 0.0;
        for (int i = 0; i < 3 * W * H; i++) sum[c] += img[i];
    }
    render_stats st = session_stats(rs);
    session_destroy(rs);
    return st;
}

/* A glossy room (every wall a sharp Phong lobe), every pass forced on, some components left out. */
static void check_only(void) {
    scene *s = ts_new("glossy room");
    ts_box(s, v3(-1, 0, -1), v3(1, 2, 1), 1, ts_material(s, ts_phong(v3s(0.3f), v3s(0.6f), 2000.0f)));
    ts_quad(s, v3(-0.3f, 1.98f, -0.3f), v3(0.3f, 1.98f, -0.3f), v3(0.3f, 1.98f, 0.3f), v3(-0.3f, 1.98f, 0.3f),
            ts_lambert(s, v3s(0.0f), v3s(5.0f), 0));
    ts_finalize(s);
    camera cam = camera_look_at(v3(0, 1, 0.9f), v3(0, 1, -1), v3(0, 1, 0), 1.2f);
    const unsigned D = 1u << COMP_DIRECT, I = 1u << COMP_INDIRECT, HL = 1u << COMP_HIGHLIGHTS;
    const unsigned masks[] = {0, HL, D, D | I};
    for (int k = 0; k < 4; k++) {
        render_params p = {.width = W,
                           .height = H,
                           .method = METHOD_VSL_HL,
                           .max_depth = 4,
                           .seed = 5,
                           .plan = PLAN_FULL,
                           .only = masks[k],
                           .vl = {.count = 64}};
        double sum[COMP_COUNT];
        render_stats st = render_only(s, &cam, p, sum);
        unsigned rendered = masks[k] ? masks[k] : COMP_MASK_ALL;
        for (int c = 0; c < COMP_COUNT; c++)
            CHECK((rendered >> c & 1u) ? sum[c] > 0.0 && isfinite(sum[c]) : sum[c] == 0.0,
                  "only %#x: component %d sums to %g", masks[k], c, sum[c]);
        /* One camera ray a pixel a frame, and those of the pixels' extra direct and highlight points */
        CHECK(st.rays[RAY_CAMERA] == (uint64_t)(2 * W * H) + st.pixel_points,
              "only %#x: %llu camera rays for %d + %llu", masks[k], (unsigned long long)st.rays[RAY_CAMERA], 2 * W * H,
              (unsigned long long)st.pixel_points);
        /* a pixel's probe, and a frame's 3 more direct samples (4 a pixel before the records decide)
         * and 7 more highlight points at most */
        CHECK(st.pixel_points <= (uint64_t)(W * H * (1 + 2 * (3 + 7))), "only %#x: %llu extra points", masks[k],
              (unsigned long long)st.pixel_points);
        CHECK((rendered & I) ? st.virtual_lights > 0 : st.virtual_lights == 0 && st.pass_ns[PASS_GATHER] == 0,
              "only %#x: %llu virtual lights", masks[k], (unsigned long long)st.virtual_lights);
        CHECK((rendered & HL) ? st.hl_points > 0 : st.hl_points == 0 && st.pass_ns[PASS_HIGHLIGHTS] == 0,
              "only %#x: the highlight estimator ran at %llu points", masks[k], (unsigned long long)st.hl_points);
    }
    /* The path tracer renders whole paths whatever is asked. */
    render_params p = {.width = W, .height = H, .max_depth = 4, .seed = 5, .only = HL};
    double sum[COMP_COUNT];
    render_only(s, &cam, p, sum);
    CHECK(sum[COMP_DIRECT] > 0.0 && sum[COMP_INDIRECT] > 0.0, "pt with only set: direct %g, indirect %g",
          sum[COMP_DIRECT], sum[COMP_INDIRECT]);
    scene_destroy(s);
}

/* A sky of finite texels near FLT_MAX over a white floor (a hostile environment map): samples
 * that overflow are dropped and counted, and every value of the image and of each layer stays
 * finite and non-negative, for the path tracer and for vsl+hl. */
static void check_huge_sky(void) {
    enum { EW = 8, EH = 6, EN = 3 };
    const render_method methods[] = {METHOD_PT, METHOD_VSL_HL};
    for (int k = 0; k < 2; k++) {
        render_method method = methods[k];
        scene *s = ts_new("huge sky");
        ts_quad(s, v3(-50, -1, 50), v3(50, -1, 50), v3(50, -1, -50), v3(-50, -1, -50),
                ts_lambert(s, v3s(0.9f), v3s(0), 0));
        image_rgb sky = {EW, EH, malloc(sizeof(float) * 3 * EW * EH)};
        for (int i = 0; i < 3 * EW * EH; i++) sky.rgb[i] = 0.9f * FLT_MAX;
        char err[256];
        CHECK(scene_set_env_image(s, &sky, 0.0f, err, sizeof err) == 0, "env: %s", err);
        ts_finalize(s);
        camera cam = camera_look_at(v3(0, 0, 0), v3(0, -0.3f, -1), v3(0, 1, 0), 1.0f);
        render_params p = {.width = EW, .height = EH, .method = method, .max_depth = 3, .seed = 5};
        p.vl.count = 16;
        render_session *rs = session_create(s, &cam, &p, err, sizeof err);
        CHECK(rs != NULL, "session: %s", err);
        for (int f = 0; rs && f < EN; f++) session_render_frame(rs);
        int bad = 0;
        for (unsigned mask = 1; rs && mask <= COMP_MASK_ALL; mask++) {
            float img[3 * EW * EH];
            film_resolve(session_film(rs), mask, img);
            for (int i = 0; i < 3 * EW * EH; i++) bad += !isfinite(img[i]) || img[i] < 0.0f;
        }
        CHECK(bad == 0, "%s: %d values of the image or its layers are not finite and non-negative", method_name(method),
              bad);
        CHECK(rs && session_stats(rs).rejected_samples > 0, "%s: no overflowing sample was counted",
              method_name(method));
        session_destroy(rs);
        scene_destroy(s);
    }
}

int main(void) {
    check_edge_coverage(METHOD_PT, 64, 64);
    check_edge_coverage(METHOD_VSL, 16, 64);
    check_direct_light_choice();
    check_huge_sky();
    check_only();
    scene *s = ts_new("box");
    ts_box(s, v3(-1, 0, -1), v3(1, 2, 1), 1, ts_lambert(s, v3s(0.6f), v3s(0.0f), 0));
    ts_quad(s, v3(-0.3f, 1.98f, -0.3f), v3(0.3f, 1.98f, -0.3f), v3(0.3f, 1.98f, 0.3f), v3(-0.3f, 1.98f, 0.3f),
            ts_lambert(s, v3s(0.0f), v3s(5.0f), 0));
    ts_finalize(s);
    camera cam = camera_look_at(v3(0, 1, 0.9f), v3(0, 1, -1), v3(0, 1, 0), 1.2f);
    render_params p = {.width = W, .height = H, .max_depth = 4, .seed = 3};
    char err[256];
    render_session *a = session_create(s, &cam, &p, err, sizeof err), *b = session_create(s, &cam, &p, err, sizeof err);
    CHECK(a && b, "session: %s", err);
    atomic_int stop = 1;
    session_set_abort_flag(a, &stop);
    CHECK(session_render_frame(a) == 1, "a frame with the flag set must report that it stopped");
    CHECK(session_frames(a) == 0, "a stopped frame must not count (%lld frames)", session_frames(a));
    atomic_store(&stop, 0);
    session_reset(a);
    for (int f = 0; f < 3; f++) {
        CHECK(session_render_frame(a) == 0, "frame %d with the flag clear must finish", f);
        CHECK(session_render_frame(b) == 0, "frame %d without a flag must finish", f);
    }
    CHECK(session_frames(a) == 3, "3 frames expected, got %lld", session_frames(a));
    render_stats sa = session_stats(a), sb = session_stats(b);
    CHECK(sa.rays[RAY_CAMERA] == (uint64_t)(3 * W * H) && sb.rays[RAY_CAMERA] == sa.rays[RAY_CAMERA],
          "statistics must count the frames since the reset: %llu and %llu camera rays for %d",
          (unsigned long long)sa.rays[RAY_CAMERA], (unsigned long long)sb.rays[RAY_CAMERA], 3 * W * H);
    float ia[3 * W * H], ib[3 * W * H];
    film_resolve(session_film(a), ~0u, ia);
    film_resolve(session_film(b), ~0u, ib);
    int differ = 0;
    for (int i = 0; i < 3 * W * H; i++) differ += ia[i] != ib[i];
    CHECK(differ == 0, "after a stopped frame and a reset, %d channels differ from an uninterrupted render", differ);
    double mean = 0;
    for (int i = 0; i < 3 * W * H; i++) mean += ia[i];
    CHECK(mean > 0.0 && isfinite(mean), "the box must be lit");
    session_reset(b);
    CHECK(session_stats(b).rays[RAY_SHADOW] == 0, "a reset must clear the statistics");
    /* A scene edit: the analysis runs again and the accumulation restarts. */
    CHECK(scene_move_light(s, 0, v3(0.1f, 0, 0), err, sizeof err) == 0, "move: %s", err);
    CHECK(session_scene_changed(a) == 0 && session_frames(a) == 0, "after a scene change the session must restart");
    CHECK(session_analysis(a)->area == 2 && session_analysis(a)->indirect, "the new analysis must see the moved light");
    session_destroy(a);
    session_destroy(b);
    scene_destroy(s);
    return check_exit("test_session");
}
