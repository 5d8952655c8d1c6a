/* The display's extra samples: session_render_extra, display_plan_extra, display_take_extra. They
 * estimate what the film estimates: over many frames their mean and the film's differ by no more
 * than their noise allows (z under 4 over the image, and over 4 when they are scaled by 1.25: the
 * test can fail), for pt and vsl. There are none before a frame has begun, after a reset or while
 * the abort flag is set. The plan gives samples where one takes most off the error shown: to the
 * pixel whose samples spread, none to those whose samples agree, some to a hole beside the spread
 * one, within the budget; in a young image also to the spread pixel's neighbours, whose few samples
 * may have missed what its found; and to a sharp glossy surface's pixels once the view has turned
 * at them past the lobe's width. Taken, a request's samples are blended into the history as their sums say.
 * (That they never touch the film is test_parts'.) */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "display.h"
#include "test_scenes.h"

static const float LUM[3] = {0.2126f, 0.7152f, 0.0722f};

/* z of the extra samples' mean luminance against the film's, summed over the pixels, by the extra
 * samples' own spread (the film's is no larger: its points are stratified), the extra samples
 * scaled by `scale`. Each request one sample, so that its sums are that sample. */
static double extra_z(render_method method, int frames, double scale) {
    enum { W = 24, H = 16, N = W * H, EACH = 2 };
    char err[256];
    scene *s = scene_load("builtin:showcase", NULL, NULL, err, sizeof err);
    CHECK(s != NULL, "showcase: %s", err);
    if (!s) return 0.0;
    camera cam = scene_camera(s, 0, (float)W / (float)H);
    render_params p = {.width = W, .height = H, .max_depth = 4, .seed = 3, .threads = 2, .method = method};
    p.vl.count = 64;
    render_session *rs = session_create(s, &cam, &p, err, sizeof err);
    CHECK(rs != NULL, "session: %s", err);
    if (!rs) return 0.0;
    static extra_request req[EACH * N];
    static double sum[N], sumsq[N], taken[N];
    memset(sum, 0, sizeof sum), memset(sumsq, 0, sizeof sumsq), memset(taken, 0, sizeof taken);
    for (int f = 0; f < frames; f++) {
        CHECK(session_render_frame(rs) == 0, "a frame: %s", session_error(rs));
        for (int r = 0; r < EACH * N; r++) {
            req[r].pixel = r % N, req[r].samples = 1;
            memcpy(req[r].weight, LUM, sizeof LUM);
        }
        CHECK(session_render_extra(rs, req, EACH * N) == 0, "extra samples after a frame");
        for (int r = 0; r < EACH * N; r++) {
            double l = 0.0;
            for (int c = 0; c < COMP_COUNT; c++)
                for (int e = 0; e < 3; e++) l += LUM[e] * req[r].sum[c][e];
            int i = req[r].pixel;
            sum[i] += l, sumsq[i] += l * l, taken[i] += req[r].taken;
        }
    }
    static float rgb[3 * N];
    film_resolve(session_film(rs), COMP_MASK_ALL, rgb);
    double diff = 0.0, var = 0.0;
    for (int i = 0; i < N; i++) {
        if (!(taken[i] > 1.0)) continue;
        double m = sum[i] / taken[i], v = fmax(sumsq[i] / taken[i] - m * m, 0.0) * taken[i] / (taken[i] - 1.0);
        diff += scale * m - (LUM[0] * rgb[3 * i] + LUM[1] * rgb[3 * i + 1] + LUM[2] * rgb[3 * i + 2]);
        var += v / taken[i] + v / (double)frames;
    }
    session_destroy(rs);
    scene_destroy(s);
    return var > 0.0 ? diff / sqrt(var) : 0.0;
}

static void check_unbiased(void) {
    double z = extra_z(METHOD_PT, 48, 1.0), wrong = extra_z(METHOD_PT, 48, 1.25);
    CHECK(fabs(z) < 4.0, "pt: the extra samples' mean must be the film's (z %.2f)", z);
    CHECK(fabs(wrong) > 4.0, "pt: the test must see extra samples 25%% too bright (z %.2f)", wrong);
    z = extra_z(METHOD_VSL, 24, 1.0);
    wrong = extra_z(METHOD_VSL, 24, 1.25);
    CHECK(fabs(z) < 4.0, "vsl: the extra samples' mean must be the film's, with the frame's lights (z %.2f)", z);
    CHECK(fabs(wrong) > 4.0, "vsl: the test must see extra samples 25%% too bright (z %.2f)", wrong);
}

/* None before a frame, after a reset, or while the abort flag is set; the requests then say so. */
static void check_refusals(void) {
    char err[256];
    scene *s = scene_load("builtin:showcase", NULL, NULL, err, sizeof err);
    if (!s) return;
    camera cam = scene_camera(s, 0, 1.5f);
    render_params p = {.width = 12, .height = 8, .max_depth = 2, .seed = 1, .threads = 2, .method = METHOD_VSL};
    p.vl.count = 16;
    render_session *rs = session_create(s, &cam, &p, err, sizeof err);
    if (!rs) return;
    extra_request q = {.pixel = 5, .samples = 3, .weight = {1.0f, 1.0f, 1.0f}, .taken = 7};
    CHECK(session_render_extra(rs, &q, 1) == 1 && q.taken == 0, "no extra samples before a frame");
    session_render_part(rs, 4, NULL);
    CHECK(session_render_extra(rs, &q, 1) == 0 && q.taken == 3, "extra samples in a frame begun (%d)", q.taken);
    q.pixel = -1;
    CHECK(session_render_extra(rs, &q, 1) == 0 && q.taken == 0, "a pixel outside the image takes none");
    q.pixel = 5;
    session_reset(rs);
    CHECK(session_render_extra(rs, &q, 1) == 1 && q.taken == 0, "no extra samples after a reset");
    session_render_frame(rs);
    atomic_int stop = 1;
    session_set_abort_flag(rs, &stop);
    CHECK(session_render_extra(rs, &q, 1) == 1 && q.taken == 0, "no extra samples while the abort flag is set");
    session_destroy(rs);
    scene_destroy(s);
}

/* A Lambert plane filling the view; samples written by hand. */
enum { PW = 32, PH = 20 };
static void write(display *d, const float *value, const unsigned char *skip) {
    const sample_sink *sk = display_sink(d);
    const gbuffer *g = display_gbuffer(d);
    for (int i = 0; i < PW * PH; i++) {
        if (skip[i]) continue;
        for (int c = 0; c < COMP_COUNT; c++)
            for (int e = 0; e < 3; e++)
                sk->rgb[c][3 * i + e] = c == COMP_DIRECT ? value[i] * g->albedo[3 * i + e] : 0.0f;
        sk->stamp[i] = sk->serial;
    }
    display_take_samples(d);
}

/* The plane z = 0 filling a PW x PH view from (0, 0, 5), Lambert (albedo 0.5) or, phong_n > 0,
 * Phong of that exponent; its display at that view, or NULL (the scene freed). */
static display *plane_display(float phong_n, scene **out) {
    scene *s = ts_new("extra plane");
    int m = phong_n > 0.0f ? ts_material(s, ts_phong(v3s(0.3f), v3s(0.3f), phong_n))
                           : ts_lambert(s, v3s(0.5f), v3s(0.0f), 0);
    ts_quad(s, v3(-50, -50, 0), v3(50, -50, 0), v3(50, 50, 0), v3(-50, 50, 0), m);
    ts_point_light(s, v3(0, 0, 10));
    ts_finalize(s);
    camera cam = camera_look_at(v3(0, 0, 5), v3(0, 0, 0), v3(0, 1, 0), 0.7f);
    char err[256];
    display *d = display_create(PW, PH, 2, err, sizeof err);
    CHECK(d != NULL, "display: %s", err);
    if (!d) {
        scene_destroy(s);
        return NULL;
    }
    display_change_view(d, s, &cam, DISPLAY_RESTART);
    *out = s;
    return d;
}

static void check_plan(void) {
    scene *s;
    display *d = plane_display(0.0f, &s);
    if (!d) return;
    const int spread = 10 * PW + 10, hole = 10 * PW + 11, calm = 5 * PW + 25;
    static float value[PW * PH];
    static unsigned char skip[PW * PH];
    skip[hole] = 1;
    for (int k = 0; k < 4; k++) { /* four samples each: the spread pixel's 0 and 20 in turn */
        for (int i = 0; i < PW * PH; i++) value[i] = i == calm ? 5.0f : 1.0f;
        value[spread] = k & 1 ? 20.0f : 0.0f;
        write(d, value, skip);
    }
    static extra_request req[PW * PH];
    int n = display_plan_extra(d, 200, req, PW * PH);
    int at[3] = {0, 0, 0}, other = 0, total = 0;
    for (int r = 0; r < n; r++) {
        total += req[r].samples;
        if (req[r].pixel == spread)
            at[0] += req[r].samples;
        else if (req[r].pixel == hole)
            at[1] += req[r].samples;
        else if (req[r].pixel == calm)
            at[2] += req[r].samples;
        else
            other += req[r].samples;
        CHECK(req[r].samples >= 1 && req[r].samples <= 16, "a request of %d samples", req[r].samples);
    }
    CHECK(total <= 200 + n && total >= 150, "the plan must spend the budget of 200: %d", total);
    CHECK(at[0] > 0 && at[1] > 0 && at[2] == 0 && other == 0,
          "samples where they spread (%d), beside it in the hole (%d), none where samples agree (%d, %d)", at[0], at[1],
          at[2], other);
    /* taken: the spread pixel's mean with 10 samples of 4 is (4 x 10 + 10 x 4) / 14, times the albedo */
    extra_request q = {.pixel = spread, .samples = 10, .taken = 10};
    const gbuffer *g = display_gbuffer(d);
    for (int e = 0; e < 3; e++) q.sum[COMP_DIRECT][e] = 40.0f * g->albedo[3 * spread + e];
    q.sumsq[COMP_DIRECT] = 160.0f;
    display_take_extra(d, &q, 1);
    static float rgb[3 * PW * PH];
    display_resolve(d, COMP_MASK_ALL, 0, rgb);
    float want = (4.0f * 10.0f + 40.0f) / 14.0f * g->albedo[3 * spread];
    CHECK(fabsf(rgb[3 * spread] - want) < 1e-4f * want, "the extra samples blended in: %g, want %g", rgb[3 * spread],
          want);
    CHECK(display_get_stats(d).extra == 10, "the display counts the extra samples taken");
    display_destroy(d);
    scene_destroy(s);
}

/* A young image (two samples a pixel): one pixel's samples spread (a speck one of them found), its
 * neighbours' agree. The neighbours on its surface may have missed the speck: the plan gives them
 * samples too, and none to the pixels beyond (with four samples each, check_plan, they get none). */
static void check_young(void) {
    scene *s;
    display *d = plane_display(0.0f, &s);
    if (!d) return;
    const int speck = 10 * PW + 10, beside = 11 * PW + 11, beyond = 10 * PW + 13;
    static float value[PW * PH];
    static unsigned char skip[PW * PH];
    for (int k = 0; k < 2; k++) {
        for (int i = 0; i < PW * PH; i++) value[i] = 1.0f;
        value[speck] = k ? 40.0f : 0.0f;
        write(d, value, skip);
    }
    static extra_request req[PW * PH];
    int n = display_plan_extra(d, 200, req, PW * PH);
    int at[3] = {0, 0, 0};
    for (int r = 0; r < n; r++) {
        int i = req[r].pixel, dx = i % PW - speck % PW, dy = i / PW - speck / PW;
        at[i == speck ? 0 : i == beside ? 1 : 2] += req[r].samples;
        CHECK(abs(dx) <= 1 && abs(dy) <= 1, "samples at (%d, %d) from the speck: only it and its neighbours", dx, dy);
        CHECK(i != beyond, "samples two pixels from the speck");
    }
    CHECK(at[0] > 0 && at[1] > 0, "samples at the speck (%d) and at its young neighbour (%d)", at[0], at[1]);
    display_destroy(d);
    scene_destroy(s);
}

/* Many samples, spread alike everywhere (one in ten is 10, the rest 0), but a speck's pixel (0 and
 * 200 in turn); then the view orbits 3 degrees. On a sharp glossy plane (Phong 400, alpha 0.035)
 * the turn is more than the lobe is wide: what the carried samples say of the light is mostly
 * stale (the speck has moved), and the plan takes each pixel as it takes a hole, as hard as its
 * hardest neighbour: the speck's neighbours get many times the samples of pixels far from it. On a
 * Lambert plane nothing is stale, and they get what their own samples ask for (some of the speck's,
 * which the carry's bilinear taps mix in). Returns the ratio of the samples per pixel beside the
 * speck to those of the pixels beyond (0.5 at least). */
static double turned_planned(float phong_n) {
    scene *s;
    display *d = plane_display(phong_n, &s);
    if (!d) return -1.0;
    const int speck = 10 * PW + 16;
    static float value[PW * PH];
    static unsigned char skip[PW * PH];
    for (int k = 0; k < 40; k++) {
        for (int i = 0; i < PW * PH; i++) value[i] = (i + k) % 10 == 0 ? 10.0f : 0.0f;
        value[speck] = k & 1 ? 200.0f : 0.0f;
        write(d, value, skip);
    }
    float t = 3.0f * PI_F / 180.0f;
    camera turned = camera_look_at(v3(5.0f * sinf(t), 0, 5.0f * cosf(t)), v3(0, 0, 0), v3(0, 1, 0), 0.7f);
    display_change_view(d, s, &turned, DISPLAY_CAMERA);
    static extra_request req[PW * PH];
    int n = display_plan_extra(d, 2000, req, PW * PH);
    double beside = 0.0, beyond = 0.0;
    int nb = 0, nf = 0;
    static int got[PW * PH];
    memset(got, 0, sizeof got);
    for (int r = 0; r < n; r++) got[req[r].pixel] += req[r].samples;
    for (int i = 0; i < PW * PH; i++) {
        int dx = abs(i % PW - speck % PW), dy = abs(i / PW - speck / PW);
        if (dx + dy == 0) continue;
        if (dx <= 1 && dy <= 1)
            beside += got[i], nb++;
        else if (dx > 3 || dy > 3)
            beyond += got[i], nf++;
    }
    display_destroy(d);
    scene_destroy(s);
    return (beside / nb) / fmax(beyond / nf, 0.5);
}

static void check_turned(void) {
    double glossy = turned_planned(400.0f), lambert = turned_planned(0.0f);
    CHECK(glossy > 4.0 * lambert,
          "the speck's neighbours get %.1f times a far pixel's samples on a turned sharp glossy plane, %.1f on a "
          "Lambert plane (its own smear in the carry): want four times as many",
          glossy, lambert);
}

int main(void) {
    check_refusals();
    check_turned();
    check_plan();
    check_young();
    check_unbiased();
    return check_exit("test_extra");
}
