/* The display pipeline's temporal part (display.h), against answers known exactly: samples taken
 * at one view average as the film averages them; a camera move carries each surface point's
 * history to where the point lands (a light linear in position comes back exactly, since bilinear
 * taps of a linear function are exact); what the move reveals starts empty and never takes another
 * surface's light; a glossy lobe's share keeps what its width and the view's turn leave, a diffuse
 * point all of it; a light change keeps little (a sharp glossy surface, whose highlights move with
 * the light, nothing unconfirmed), a restart nothing; samples written for an old
 * view are not taken for a new one; the image shown is finite whatever the samples; each packet's
 * need follows its pixels' samples. The G-buffer's projection is checked against its own centre
 * rays. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "display.h"
#include "test_scenes.h"

#define W 64
#define H 40

/* A grey Lambert plane z = 0 (facing +z) of albedo kd, and in front of it a small quad at z = 1 of
 * another material; or a glossy plane (Phong, exponent n, glossy albedo ks) when n > 0. */
static scene *plane_scene(int with_quad, float phong_n, float kd, float ks) {
    scene *s = ts_new("display");
    int plane =
        phong_n > 0.0f ? ts_material(s, ts_phong(v3s(kd), v3s(ks), phong_n)) : ts_lambert(s, v3s(kd), v3s(0.0f), 0);
    ts_quad(s, v3(-50, -50, 0), v3(50, -50, 0), v3(50, 50, 0), v3(-50, 50, 0), plane);
    if (with_quad) {
        int q = ts_lambert(s, v3(0.8f, 0.2f, 0.1f), v3s(0.0f), 0);
        ts_quad(s, v3(-0.3f, -0.3f, 1), v3(0.3f, -0.3f, 1), v3(0.3f, 0.3f, 1), v3(-0.3f, 0.3f, 1), q);
    }
    ts_point_light(s, v3(0, 0, 10));
    ts_finalize(s);
    return s;
}

static camera view_from(vec3 eye, vec3 target) { return camera_look_at(eye, target, v3(0, 1, 0), 0.7f); }

/* The light a test writes for a surface point: linear in its position, per component. */
static vec3 light_at(vec3 p, int c) { return v3(2.0f + p.x + 0.1f * c, 3.0f + p.y, 1.0f + 0.5f * p.x - 0.25f * p.y); }

/* Writes one sample into every pixel of the sink: the light at the pixel's G-buffer point times
 * its albedo (so the demodulated history holds light_at), scaled by gain, or `value` when the
 * pixel shows material `mat` (>= 0). */
static void write_samples(display *d, float gain, int mat, float value) {
    const sample_sink *sk = display_sink(d);
    const gbuffer *g = display_gbuffer(d);
    for (int i = 0; i < W * H; i++) {
        vec3 p = v3(g->pos[3 * i], g->pos[3 * i + 1], g->pos[3 * i + 2]);
        vec3 a = v3(g->albedo[3 * i], g->albedo[3 * i + 1], g->albedo[3 * i + 2]);
        for (int c = 0; c < COMP_COUNT; c++) {
            vec3 l = mat >= 0 && g->material[i] == mat ? v3s(value) : scale3(light_at(p, c), gain);
            vec3 x = mul3(l, a);
            sk->rgb[c][3 * i] = x.x, sk->rgb[c][3 * i + 1] = x.y, sk->rgb[c][3 * i + 2] = x.z;
        }
        sk->stamp[i] = sk->serial;
    }
}

/* Pixel i's sample: light v in the components of mask (each times the albedo, as the film's samples
 * are), none in the others. */
static void put_grey(display *d, int i, float v, unsigned mask) {
    const sample_sink *sk = display_sink(d);
    const gbuffer *g = display_gbuffer(d);
    for (int c = 0; c < COMP_COUNT; c++)
        for (int e = 0; e < 3; e++) sk->rgb[c][3 * i + e] = mask >> c & 1u ? v * g->albedo[3 * i + e] : 0.0f;
    sk->stamp[i] = sk->serial;
}

/* `frames` frames of noisy samples taken: every pixel's light `level` times 0.5 to 1.5, in the
 * components of mask. */
static void noisy_frames(display *d, rng_state *rng, int frames, float level, unsigned mask) {
    for (int k = 0; k < frames; k++) {
        for (int i = 0; i < W * H; i++) put_grey(d, i, level * (0.5f + rng_float(rng)), mask);
        display_take_samples(d);
    }
}

/* A display of scene s at camera a, its first view taken; NULL out of memory. */
static display *display_at(const scene *s, const camera *a) {
    char err[256];
    display *d = display_create(W, H, 2, err, sizeof err);
    if (d) display_change_view(d, s, a, DISPLAY_CAMERA);
    return d;
}

static void check_projection(void) {
    scene *s = plane_scene(0, 0.0f, 0.5f, 0.0f);
    gbuffer g;
    CHECK(gbuffer_init(&g, W, H) == 0, "gbuffer_init");
    camera cam = view_from(v3(0.4f, -0.3f, 5), v3(0.1f, 0.2f, 0));
    gbuffer_trace(&g, s, &cam, NULL);
    double worst = 0.0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            int i = y * W + x;
            float px, py;
            vec3 p = v3(g.pos[3 * i], g.pos[3 * i + 1], g.pos[3 * i + 2]);
            CHECK(g.material[i] >= 0 && g.depth[i] > 0.0f, "pixel %d sees the plane", i);
            if (!gbuffer_project(&g, p, &px, &py)) continue;
            worst = fmax(worst, fmax(fabs(px - (x + 0.5)), fabs(py - (y + 0.5))));
            CHECK_NEAR(g.normal[3 * i + 2], 1.0, 1e-5, "the plane's normal faces the camera");
        }
    CHECK(worst < 2e-3, "a centre ray's hit projects back to the pixel's centre (worst %g pixels)", worst);
    gbuffer_deinit(&g);
    scene_destroy(s);
}

/* Samples at one view: the history is their mean, as the film's is. */
static void check_static_mean(void) {
    scene *s = plane_scene(0, 0.0f, 0.5f, 0.0f);
    char err[256];
    display *d = display_create(W, H, 2, err, sizeof err);
    CHECK(d != NULL, "display_create: %s", err);
    if (!d) return;
    camera cam = view_from(v3(0, 0, 5), v3(0, 0, 0));
    display_change_view(d, s, &cam, DISPLAY_CAMERA);
    const float gains[4] = {1.0f, 3.0f, 0.5f, 2.5f};
    for (int k = 0; k < 4; k++) {
        write_samples(d, gains[k], -1, 0.0f);
        CHECK(display_take_samples(d) == W * H, "every pixel's sample taken");
    }
    CHECK(display_take_samples(d) == 0, "a sample is taken once");
    float *img = malloc(sizeof(float) * 3 * W * H);
    display_resolve(d, 1u << COMP_INDIRECT, 0, img);
    const gbuffer *g = display_gbuffer(d);
    double worst = 0.0;
    for (int i = 0; i < W * H; i++) {
        vec3 p = v3(g->pos[3 * i], g->pos[3 * i + 1], g->pos[3 * i + 2]);
        vec3 want = mul3(scale3(light_at(p, COMP_INDIRECT), 7.0f / 4.0f), v3(g->albedo[3 * i], 0, 0));
        worst = fmax(worst, fabs(img[3 * i] - want.x) / want.x);
    }
    CHECK(worst < 1e-5, "the mean of four samples (worst relative difference %g)", worst);
    free(img);
    display_destroy(d);
    scene_destroy(s);
}

/* Moves the camera from a to b after n samples at a; returns the display (caller destroys). */
static display *moved(const scene *s, camera a, camera b, int n, unsigned change, int mat, float value) {
    char err[256];
    display *d = display_create(W, H, 2, err, sizeof err);
    if (!d) return NULL;
    display_change_view(d, s, &a, DISPLAY_CAMERA);
    for (int k = 0; k < n; k++) {
        write_samples(d, 1.0f, mat, value);
        display_take_samples(d);
    }
    display_change_view(d, s, &b, change);
    return d;
}

/* The history that comes with a pixel: its mean light (component c) and count, read back through
 * a resolve without the filter (the mean times the albedo) and the stats. */
static void check_reprojection(void) {
    scene *s = plane_scene(0, 0.0f, 0.5f, 0.0f);
    camera a = view_from(v3(0, 0, 5), v3(0, 0, 0));
    camera b = view_from(v3(0.37f, 0.11f, 5), v3(0.37f, 0.11f, 0)); /* a slide of a fraction of pixels */
    display *d = moved(s, a, b, 3, DISPLAY_CAMERA, -1, 0.0f);
    CHECK(d != NULL, "display");
    if (!d) return;
    display_stats st = display_get_stats(d);
    const gbuffer *g = display_gbuffer(d);
    float *img = malloc(sizeof(float) * 3 * W * H);
    display_resolve(d, 1u << COMP_DIRECT, 0, img);
    gbuffer ga;
    gbuffer_init(&ga, W, H);
    gbuffer_trace(&ga, s, &a, NULL);
    double worst = 0.0;
    long long inside = 0, empty_outside = 0, outside = 0;
    for (int i = 0; i < W * H; i++) {
        vec3 p = v3(g->pos[3 * i], g->pos[3 * i + 1], g->pos[3 * i + 2]);
        float ox, oy;
        gbuffer_project(&ga, p, &ox, &oy);
        /* inside: all four bilinear taps were in the old image */
        if (ox >= 0.5f && oy >= 0.5f && ox <= W - 0.5f && oy <= H - 0.5f) {
            inside++;
            vec3 want = mul3(light_at(p, COMP_DIRECT), v3(g->albedo[3 * i], g->albedo[3 * i + 1], 0));
            worst = fmax(worst, fmax(fabs(img[3 * i] - want.x) / want.x, fabs(img[3 * i + 1] - want.y) / want.y));
        } else if (ox < -0.5f || oy < -0.5f || ox > W + 0.5f || oy > H + 0.5f) {
            outside++;
            empty_outside += img[3 * i] == 0.0f;
        }
    }
    CHECK(inside > W * H / 2, "most pixels were seen before (%lld)", inside);
    CHECK(worst < 1e-4, "a linear light comes back exactly where its point lands (worst relative %g)", worst);
    CHECK(outside > 0 && empty_outside == outside, "what the move reveals starts empty: %lld of %lld", empty_outside,
          outside);
    CHECK(st.carried >= inside && st.lost >= outside, "stats: carried %lld, lost %lld", st.carried, st.lost);
    gbuffer_deinit(&ga);
    free(img);
    display_destroy(d);
    scene_destroy(s);
}

/* A quad in front of the plane, the camera slides: plane pixels that saw the quad before start
 * empty; no plane pixel takes the quad's light. */
static void check_disocclusion(void) {
    scene *s = plane_scene(1, 0.0f, 0.5f, 0.0f);
    camera a = view_from(v3(0, 0, 5), v3(0, 0, 0));
    camera b = view_from(v3(0.8f, 0, 5), v3(0.8f, 0, 0));
    int quad_material = 1;
    display *d = moved(s, a, b, 2, DISPLAY_CAMERA, quad_material, 100.0f);
    CHECK(d != NULL, "display");
    if (!d) return;
    float *img = malloc(sizeof(float) * 3 * W * H);
    display_resolve(d, 1u << COMP_DIRECT, 0, img);
    const gbuffer *g = display_gbuffer(d);
    gbuffer ga;
    gbuffer_init(&ga, W, H);
    gbuffer_trace(&ga, s, &a, NULL);
    long long revealed = 0, revealed_empty = 0, leaks = 0, quad_kept = 0, quad = 0;
    for (int i = 0; i < W * H; i++) {
        float ox, oy;
        vec3 p = v3(g->pos[3 * i], g->pos[3 * i + 1], g->pos[3 * i + 2]);
        if (!gbuffer_project(&ga, p, &ox, &oy)) continue;
        int tx = (int)ox, ty = (int)oy;
        if (tx < 1 || ty < 1 || tx >= W - 1 || ty >= H - 1) continue;
        float v = img[3 * i] / g->albedo[3 * i];
        if (g->material[i] == quad_material) {
            quad++;
            quad_kept += fabsf(v - 100.0f) < 1e-3f;
            continue;
        }
        leaks += v > 50.0f;
        /* the old pixel there showed the quad: the point was hidden */
        if (ga.material[ty * W + tx] == quad_material) {
            revealed++;
            revealed_empty += v == 0.0f;
        }
    }
    CHECK(revealed > 10 && revealed_empty == revealed, "revealed plane pixels start empty: %lld of %lld",
          revealed_empty, revealed);
    CHECK(leaks == 0, "%lld plane pixels took the quad's light", leaks);
    CHECK(quad > 10 && quad_kept * 10 >= quad * 9, "the quad keeps its own light: %lld of %lld", quad_kept, quad);
    gbuffer_deinit(&ga);
    free(img);
    display_destroy(d);
    scene_destroy(s);
}

/* The history's sample count after the view turns about the plane's centre by `degrees` in `steps`
 * equal steps with no samples between (every pixel sees the plane): diffuse keeps all (up to the
 * cap), glossy what its lobe allows. The plane is Lambert, or Phong (exponent n, diffuse kd and
 * glossy ks grey). Its 8 samples are 0 and twice the light in turn: as spread as they are bright,
 * as a Monte Carlo estimate's are (a history of exact samples may keep no more than one where
 * any of its light has moved on). */
static display *spread_history(const scene *s, camera a, int n) {
    char err[256];
    display *d = display_create(W, H, 2, err, sizeof err);
    if (!d) return NULL;
    display_change_view(d, s, &a, DISPLAY_CAMERA);
    for (int k = 0; k < n; k++) {
        write_samples(d, k % 2 ? 2.0f : 0.0f, -1, 0.0f);
        display_take_samples(d);
    }
    return d;
}

/* The samples d's history counts for in pixels [x0, x1) x [y0, y1) of component mask, on average:
 * one more sample of zero light everywhere, mean' = mean * count / (count + 1), tells the count
 * (pixels that show nothing are left out). *shown, if asked, is the light shown before it,
 * unfiltered, summed over the region. */
static double carried_count(display *d, unsigned mask, int x0, int y0, int x1, int y1, double *shown) {
    const gbuffer *g = display_gbuffer(d);
    write_samples(d, 0.0f, -1, 0.0f);
    float *before = malloc(sizeof(float) * 3 * W * H), *after = malloc(sizeof(float) * 3 * W * H);
    display_resolve(d, mask, 0, before);
    display_take_samples(d);
    display_resolve(d, mask, 0, after);
    double sum = 0.0, lit = 0.0;
    int m = 0;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            size_t i = (size_t)(y * W + x);
            lit += before[3 * i];
            if (g->material[i] < 0 || !(before[3 * i] > 0.0f)) continue;
            double q = after[3 * i] / before[3 * i];
            sum += q / (1.0 - q);
            m++;
        }
    free(before);
    free(after);
    if (shown) *shown = lit;
    return m ? sum / m : 0.0;
}

static double count_after_orbit(float phong_n, float kd, float ks, float degrees, int steps, unsigned mask_component) {
    scene *s = plane_scene(0, phong_n, kd, ks);
    float r = 5.0f, n = 8;
    camera a = view_from(v3(0, 0, r), v3(0, 0, 0));
    display *d = spread_history(s, a, (int)n);
    for (int k = 1; d && k <= steps; k++) {
        float t = degrees * PI_F / 180.0f * (float)k / (float)steps;
        camera b = view_from(v3(r * sinf(t), 0, r * cosf(t)), v3(0, 0, 0));
        display_change_view(d, s, &b, DISPLAY_CAMERA);
    }
    double count = 0.0;
    if (d) {
        count = carried_count(d, mask_component, 0, H / 4, W, 3 * H / 4, NULL);
        display_destroy(d);
    }
    scene_destroy(s);
    return count;
}

static void check_glossy_history(void) {
    const unsigned direct = 1u << COMP_DIRECT, highlights = 1u << COMP_HIGHLIGHTS;
    double diffuse = count_after_orbit(0.0f, 0.5f, 0.0f, 10.0f, 1, direct);
    CHECK_NEAR(diffuse, 8.0, 0.01, "a diffuse plane keeps its whole history through a 10 degree orbit");
    /* Phong 400: alpha = 1 / sqrt(801) = 0.035, the highlight moves twice the view's turn: a turn
     * of 2 degrees keeps exp(-(0.035 / 0.035)^2 / 2) = 0.61 of the glossy history at the centre (at
     * 3 degrees a third would hold, and the history is a last resort: check_last_resort_history) */
    double sharp_hl = count_after_orbit(400.0f, 0.3f, 0.3f, 2.0f, 1, highlights);
    CHECK(sharp_hl > 0.5 * 8.0 && sharp_hl < 0.72 * 8.0, "a sharp lobe's highlights keep 0.61 in 2 degrees: %g",
          sharp_hl);
    double far_turn = count_after_orbit(400.0f, 0.3f, 0.3f, 10.0f, 1, highlights);
    CHECK(far_turn < 0.05 * 8.0, "a sharp lobe's highlights keep nothing after 10 degrees: %g", far_turn);
    double small_turn = count_after_orbit(400.0f, 0.3f, 0.3f, 0.5f, 1, highlights);
    CHECK(small_turn > 0.9 * 8.0, "half a degree leaves a sharp lobe's history nearly whole: %g", small_turn);
    /* many small turns cost what one turn as large does */
    double steps_hl = count_after_orbit(400.0f, 0.3f, 0.3f, 2.0f, 10, highlights);
    CHECK(fabs(steps_hl - sharp_hl) < 0.1 * sharp_hl, "ten turns of 0.2 degrees leave what one of 2 does: %g, %g",
          steps_hl, sharp_hl);
    /* a sharp lobe's highlight of a light outshines the diffuse light though its albedo is half */
    double sharp_direct = count_after_orbit(400.0f, 0.3f, 0.3f, 2.0f, 1, direct);
    CHECK(sharp_direct < sharp_hl + 0.1, "a sharp glossy plane's direct light goes with its lobe: %g (highlights %g)",
          sharp_direct, sharp_hl);
    /* Phong 8 (alpha 0.24), glossy albedo 4% of the whole: its highlights outshine the diffuse light
     * less, so the direct light keeps what the lobe's worst share (0.4) leaves; 30 degrees turn the
     * lobe well past its width */
    double rough_hl = count_after_orbit(8.0f, 0.5f, 0.02f, 30.0f, 1, highlights);
    double rough_direct = count_after_orbit(8.0f, 0.5f, 0.02f, 30.0f, 1, direct);
    CHECK(rough_hl < 0.25 * 8.0, "a rough lobe's highlights lose most of their history in 30 degrees: %g", rough_hl);
    CHECK(rough_direct > rough_hl + 2.0 && rough_direct < 8.0 - 1.0,
          "a rough, weakly glossy plane's direct light keeps its diffuse share: %g (highlights %g)", rough_direct,
          rough_hl);
}

/* The samples a glossy plane's history counts for at its middle (8x8 pixels; Phong 400, diffuse kd,
 * glossy ks grey; normals tilted up to `bumps` radians by a normal map of texels about a pixel wide,
 * none at 0) after 8 samples and a turn of `degrees` (carried_count); *shown is the direct light
 * shown before, unfiltered. */
static double count_after_turn(float kd, float ks, float bumps, float degrees, double *shown) {
    scene *s = ts_new("display");
    material m = ts_phong(v3s(kd), v3s(ks), 400.0f);
    if (bumps > 0.0f) {
        static unsigned char px[32 * 32 * 4];
        ts_random_normal_map(px, 32 * 32, 3, bumps);
        m.normal_tex = (texture_slot){.texture = ts_texture(s, 32, 32, px)};
    }
    const vec3 corners[4] = {v3(-50, -50, 0), v3(50, -50, 0), v3(50, 50, 0), v3(-50, 50, 0)};
    const float uv[8] = {0, 0, 60, 0, 60, 60, 0, 60}; /* a texel 0.05 wide, a pixel 0.055 at 5 */
    ts_quad_uv(s, corners, uv, ts_material(s, m));
    ts_point_light(s, v3(0, 0, 10));
    ts_finalize(s);
    float r = 5.0f, t = degrees * PI_F / 180.0f;
    display *d = spread_history(s, view_from(v3(0, 0, r), v3(0, 0, 0)), 8);
    double count = 0.0;
    *shown = 0.0;
    if (d) {
        camera b = view_from(v3(r * sinf(t), 0, r * cosf(t)), v3(0, 0, 0));
        display_change_view(d, s, &b, DISPLAY_CAMERA);
        count = carried_count(d, 1u << COMP_DIRECT, W / 2 - 4, H / 2 - 4, W / 2 + 4, H / 2 + 4, shown);
        display_destroy(d);
    }
    scene_destroy(s);
    return count;
}

/* A history that holds less than half of its light after a move counts for next to nothing (any
 * new sample near it outweighs a neighbourhood of it in the filter) but is still shown while no new
 * sample comes: on a sharp lobe that is nearly all of the albedo after a turn of 3 degrees (a third
 * holds), not after 2 (0.61); not a lobe of a third of the albedo (its diffuse light holds), nor
 * where the normals turn across a pixel by more than the lobe's width (a curved or bumpy surface:
 * the pixel's highlight stays in it). */
static void check_last_resort_history(void) {
    double shown3, shown2, shown_mixed, shown_bumpy;
    double flat3 = count_after_turn(0.0f, 0.6f, 0.0f, 3.0f, &shown3),
           flat2 = count_after_turn(0.0f, 0.6f, 0.0f, 2.0f, &shown2);
    CHECK(flat3 < 1e-4 && flat2 > 0.5 * 8.0,
          "a sharp glossy plane's history counts for nothing after 3 degrees (%g), not after 2 (%g)", flat3, flat2);
    CHECK(shown3 > 0.0 && fabs(shown3 - shown2) < 1e-3 * shown2,
          "...and is shown as it was while no new sample comes: %g, %g", shown3, shown2);
    /* not a last resort, though the lobe's worst-case share (keep_factors) leaves them a low count */
    double mixed = count_after_turn(0.4f, 0.2f, 0.0f, 10.0f, &shown_mixed);
    CHECK(mixed > 1e-3, "a plane whose lobe is a third of its albedo counts after 10 degrees: %g", mixed);
    double bumpy = count_after_turn(0.0f, 0.6f, 0.3f, 3.0f, &shown_bumpy);
    CHECK(bumpy > 1e-3, "a sharp lobe whose normals turn across a pixel counts after 3 degrees: %g", bumpy);
}

/* Light edits keep little, a restart nothing; samples stamped before a change are not taken. */
static void check_changes(void) {
    scene *s = plane_scene(0, 0.0f, 0.5f, 0.0f);
    camera a = view_from(v3(0, 0, 5), v3(0, 0, 0));
    char err[256];
    display *d = display_create(W, H, 1, err, sizeof err);
    CHECK(d != NULL, "display");
    if (!d) return;
    display_change_view(d, s, &a, DISPLAY_CAMERA);
    for (int k = 0; k < 5; k++) {
        write_samples(d, 1.0f, -1, 0.0f);
        display_take_samples(d);
    }
    write_samples(d, 50.0f, -1, 0.0f); /* written for this view, but the view changes first */
    display_change_view(d, s, &a, DISPLAY_LIGHTS);
    CHECK(display_take_samples(d) == 0, "samples of the view before a change are not taken");
    float *img = malloc(sizeof(float) * 3 * W * H);
    display_resolve(d, 1u << COMP_DIRECT, 0, img);
    float kept = img[3 * (H / 2 * W + W / 2)];
    write_samples(d, 0.0f, -1, 0.0f);
    display_take_samples(d);
    float *after = malloc(sizeof(float) * 3 * W * H);
    display_resolve(d, 1u << COMP_DIRECT, 0, after);
    CHECK(kept > 0.0f && after[3 * (H / 2 * W + W / 2)] <= 0.51f * kept,
          "a light change keeps at most one sample's weight: %g -> %g", kept, after[3 * (H / 2 * W + W / 2)]);
    display_change_view(d, s, &a, DISPLAY_RESTART);
    display_resolve(d, COMP_MASK_ALL, 0, img);
    double sum = 0.0;
    for (int i = 0; i < 3 * W * H; i++) sum += fabs(img[i]);
    CHECK(sum == 0.0, "a restart keeps nothing");
    /* hostile samples: the image shown stays finite */
    const sample_sink *sk = display_sink(d);
    for (int i = 0; i < W * H; i++) {
        for (int c = 0; c < COMP_COUNT; c++)
            sk->rgb[c][3 * i] = sk->rgb[c][3 * i + 1] = sk->rgb[c][3 * i + 2] = FLT_MAX;
        sk->stamp[i] = sk->serial;
    }
    display_take_samples(d);
    for (int denoise = 0; denoise < 2; denoise++) {
        display_resolve(d, COMP_MASK_ALL, denoise, img);
        int finite = 1;
        for (int i = 0; i < 3 * W * H; i++) finite &= isfinite(img[i]);
        CHECK(finite, "huge samples give a finite image (denoise %d)", denoise);
    }
    free(img);
    free(after);
    display_destroy(d);
    scene_destroy(s);
}

/* A light change, judged tile by tile from new samples: where they agree with the history (the
 * left half, noisy samples about the same mean) it comes back in full; where the light tripled
 * (the right half) it goes; tiles without new samples show it meanwhile, but on a sharp glossy
 * plane (phong_n > 0), whose light is mostly its lobe's and moves with the light, they do not. */
static void check_light_judgement(float phong_n) {
    scene *s = phong_n > 0.0f ? plane_scene(0, phong_n, 0.3f, 0.3f) : plane_scene(0, 0.0f, 0.5f, 0.0f);
    camera a = view_from(v3(0, 0, 5), v3(0, 0, 0));
    display *d = display_at(s, &a);
    CHECK(d != NULL, "display");
    if (!d) return;
    const gbuffer *g = display_gbuffer(d);
    rng_state rng = rng_for(7, 0, 0);
    /* noisy samples: 1 +- 0.5 times the light, 8 of them before the change */
    noisy_frames(d, &rng, 8, 1.0f, COMP_MASK_ALL);
    display_change_view(d, s, &a, DISPLAY_LIGHTS);
    for (int i = 0; i < W * H; i++) {
        int x = i % W, y = i / W;
        /* after the change: the right half's light triples; the bottom rows get no sample */
        if (y >= 32) continue;
        put_grey(d, i, (x >= W / 2 ? 3.0f : 1.0f) * (0.5f + rng_float(&rng)), COMP_MASK_ALL);
    }
    display_take_samples(d);
    float *img = malloc(sizeof(float) * 3 * W * H);
    display_resolve(d, 1u << COMP_DIRECT, 0, img);
    double left = 0.0, left2 = 0.0, right = 0.0, unjudged = 0.0;
    int nl = 0, nr = 0, nu = 0;
    for (int i = 0; i < W * H; i++) {
        int x = i % W, y = i / W;
        double v = img[3 * i] / g->albedo[3 * i];
        if (y >= 32)
            unjudged += v, nu++;
        else if (x < W / 2)
            left += v, left2 += (v - 1.0) * (v - 1.0), nl++;
        else
            right += v, nr++;
    }
    left /= nl, right /= nr, unjudged /= nu;
    /* the left keeps 9 samples' mean (about 1 +- 0.1), the right shows its one new sample (about 3) */
    /* one sample's spread is 0.29; nine samples' a third of it */
    CHECK(fabs(left - 1.0) < 0.05 && sqrt(left2 / nl) < 0.15, "unchanged light keeps its history: mean %g, RMS %g",
          left, sqrt(left2 / nl));
    CHECK(fabs(right - 3.0) < 0.15, "changed light shows the new samples alone: mean %g", right);
    if (phong_n > 0.0f)
        CHECK(unjudged == 0.0, "a glossy plane's tiles without new samples show nothing of the old light: %g",
              unjudged);
    else
        CHECK(fabs(unjudged - 1.0) < 0.05, "tiles without new samples show the old light meanwhile: %g", unjudged);
    free(img);
    display_destroy(d);
    scene_destroy(s);
}

/* A tile whose new samples differ from its stale history by less than a tenth, but within a noise
 * that allows far more, is not judged the same until they show the change to be small: the stale
 * history (16 samples a pixel, one of them 16 times the light, the rest nothing) and one new sample
 * at 16 pixels of each tile, the light down by 8%. Judged the same, the sampled pixels would show
 * the old light again (0.995). */
static void check_noisy_judgement(void) {
    scene *s = plane_scene(0, 0.0f, 0.5f, 0.0f);
    camera a = view_from(v3(0, 0, 5), v3(0, 0, 0));
    display *d = display_at(s, &a);
    CHECK(d != NULL, "display");
    if (!d) return;
    const gbuffer *g = display_gbuffer(d);
    for (int k = 0; k <= 16; k++) {
        if (k == 16) display_change_view(d, s, &a, DISPLAY_LIGHTS);
        for (int i = 0; i < W * H; i++) {
            int x = i % W, y = i / W;
            if (k == 16 && (x % 4 || y % 4)) continue;
            float v = k == 16 ? 0.92f : k == 15 ? 16.0f : 0.0f;
            put_grey(d, i, v, COMP_MASK_ALL);
        }
        display_take_samples(d);
    }
    float *img = malloc(sizeof(float) * 3 * W * H);
    display_resolve(d, 1u << COMP_INDIRECT, 0, img);
    double worst = 0.0;
    for (int i = 0; i < W * H; i++)
        if (i % W % 4 == 0 && i / W % 4 == 0) worst = fmax(worst, fabs(img[3 * i] / g->albedo[3 * i] - 0.92));
    CHECK(worst < 1e-4, "a noisy tile's sampled pixels show their new light until it is judged: off by %g", worst);
    free(img);
    display_destroy(d);
    scene_destroy(s);
}

/* While a light change is judged, a pixel without a new sample shows its stale light only where
 * no new sample's light reaches: the filter fills it from its new neighbours (the light tripled;
 * new samples at one pixel in 32, too few for a verdict). */
static void check_stale_last_resort(void) {
    scene *s = plane_scene(0, 0.0f, 0.5f, 0.0f);
    camera a = view_from(v3(0, 0, 5), v3(0, 0, 0));
    display *d = display_at(s, &a);
    CHECK(d != NULL, "display");
    if (!d) return;
    const gbuffer *g = display_gbuffer(d);
    rng_state rng = rng_for(5, 0, 0);
    noisy_frames(d, &rng, 8, 1.0f, COMP_MASK_ALL); /* the light 1, then 3, each sample 0.5 to 1.5 times it */
    display_change_view(d, s, &a, DISPLAY_LIGHTS);
    for (int i = 0; i < W * H; i++)
        if (!(i % W % 4 || i / W % 8)) put_grey(d, i, 3.0f * (0.5f + rng_float(&rng)), COMP_MASK_ALL);
    display_take_samples(d);
    float *img = malloc(sizeof(float) * 3 * W * H);
    display_resolve(d, 1u << COMP_INDIRECT, 1, img);
    double sum = 0.0;
    int m = 0;
    for (int y = 4; y < H - 4; y++)
        for (int x = 4; x < W - 4; x++)
            if (x % 4 || y % 8) sum += img[3 * (y * W + x)] / g->albedo[3 * (y * W + x)], m++;
    CHECK(sum / m > 2.7, "pixels without a new sample show their new neighbours' light (3, the old 1): %g", sum / m);
    free(img);
    display_destroy(d);
    scene_destroy(s);
}

/* While a light change is judged, the display's own samples are evidence for their tile, as the
 * film's are: 32 of them at one pixel, where the light tripled, and the tile is judged changed (its
 * other pixels, without new samples, no longer show the old light); the next tile, without any,
 * still waits and shows it. */
static void check_extra_evidence(void) {
    scene *s = plane_scene(0, 0.0f, 0.5f, 0.0f);
    camera a = view_from(v3(0, 0, 5), v3(0, 0, 0));
    display *d = display_at(s, &a);
    CHECK(d != NULL, "display");
    if (!d) return;
    const gbuffer *g = display_gbuffer(d);
    rng_state rng = rng_for(3, 0, 0);
    noisy_frames(d, &rng, 8, 1.0f, COMP_MASK_ALL); /* the light 1, each sample 0.5 to 1.5 times it */
    display_change_view(d, s, &a, DISPLAY_LIGHTS);
    extra_request r = {.pixel = 5 * W + 5, .samples = 32, .taken = 32};
    for (int c = 0; c < COMP_COUNT; c++) {
        for (int e = 0; e < 3; e++) r.sum[c][e] = 32.0f * 3.0f * g->albedo[3 * r.pixel + e];
        r.sumsq[c] = 32.0f * 9.0f;
    }
    display_take_extra(d, &r, 1);
    display_take_samples(d); /* none: the tiles are judged */
    float *img = malloc(sizeof(float) * 3 * W * H);
    display_resolve(d, 1u << COMP_INDIRECT, 0, img);
    int other = 2 * W + 9, next = 2 * W + 20; /* in the extra samples' tile, and in the next one */
    CHECK(img[3 * r.pixel] / g->albedo[3 * r.pixel] > 2.99f, "the extra samples' pixel: %g",
          img[3 * r.pixel] / g->albedo[3 * r.pixel]);
    CHECK(img[3 * other] == 0.0f, "their tile judged changed: its old light gone (%g)", img[3 * other]);
    CHECK(img[3 * next] > 0.0f, "a tile without new samples still shows its old light");
    free(img);
    display_destroy(d);
    scene_destroy(s);
}

/* The filter as shown: an image whose pixels have no noise (three samples each, all the same, a
 * step of light across the plane) comes back as its own means, though the filter, seeing so few
 * samples, takes the step for noise; a noisy flat one comes back nearer its truth than its own
 * means are. */
static void check_filter_fades(void) {
    scene *s = plane_scene(0, 0.0f, 0.5f, 0.0f);
    camera a = view_from(v3(0, 0, 5), v3(0, 0, 0));
    display *d = display_at(s, &a);
    CHECK(d != NULL, "display");
    if (!d) return;
    const gbuffer *g = display_gbuffer(d);
    for (int k = 0; k < 3; k++) {
        for (int i = 0; i < W * H; i++) {
            float v = g->pos[3 * i] > 0.0f ? 4.0f : 1.0f; /* a step at x = 0 */
            put_grey(d, i, v, 1u << COMP_DIRECT);
        }
        display_take_samples(d);
    }
    float *raw = malloc(sizeof(float) * 3 * W * H), *shown = malloc(sizeof(float) * 3 * W * H);
    display_resolve(d, COMP_MASK_ALL, 0, raw);
    display_resolve(d, COMP_MASK_ALL, 1, shown);
    double worst = 0.0;
    for (int i = 0; i < 3 * W * H; i++) worst = fmax(worst, fabs(shown[i] - raw[i]) / fmax(raw[i], 1e-6));
    CHECK(worst < 1e-5, "a noiseless step comes back as it is (worst relative change %g)", worst);
    /* noisy and flat: 3 samples of 1 +- 0.5 */
    display_change_view(d, s, &a, DISPLAY_RESTART);
    rng_state rng = rng_for(3, 0, 0);
    noisy_frames(d, &rng, 3, 1.0f, 1u << COMP_DIRECT);
    display_resolve(d, COMP_MASK_ALL, 0, raw);
    display_resolve(d, COMP_MASK_ALL, 1, shown);
    double e_raw = 0.0, e_shown = 0.0;
    for (int i = 0; i < W * H; i++) {
        double truth = g->albedo[3 * i];
        e_raw += (raw[3 * i] - truth) * (raw[3 * i] - truth);
        e_shown += (shown[3 * i] - truth) * (shown[3 * i] - truth);
    }
    CHECK(e_shown < 0.25 * e_raw, "the filter takes most of a flat image's noise: squared error %g of the raw %g",
          e_shown, e_raw);
    free(raw);
    free(shown);
    display_destroy(d);
    scene_destroy(s);
}

/* The display is a view of the estimate, never the estimate: a session whose frames go in parts to
 * a display that takes, carries and filters them (a camera move in between, as the viewer makes)
 * keeps a film equal bit for bit to one rendered in whole frames with no display at all. */
static void check_film_untouched(void) {
    char err[1200];
    scene *s = scene_load("builtin:doorway", NULL, NULL, err, sizeof err);
    CHECK(s != NULL, "builtin:doorway: %s", err);
    if (!s) return;
    enum { FW = 70, FH = 42, FRAMES = 2 };
    render_params p = {.width = FW, .height = FH, .method = METHOD_VSL_HL, .max_depth = 4, .seed = 11, .threads = 2};
    camera cam = scene_camera(s, 0, (float)FW / (float)FH), moved = cam;
    moved.position = add3(moved.position, v3(0.05f, 0.0f, 0.0f));
    render_session *plain = session_create(s, &cam, &p, err, sizeof err);
    render_session *shown = session_create(s, &moved, &p, err, sizeof err);
    display *d = display_create(FW, FH, 2, err, sizeof err);
    CHECK(plain && shown && d, "sessions, display: %s", err);
    if (plain && shown && d) {
        for (int f = 0; f < FRAMES; f++) session_render_frame(plain);
        /* the viewer's way: a view, a part, the camera back, parts until the frames are done */
        session_set_sink(shown, display_sink(d));
        display_change_view(d, s, &moved, DISPLAY_RESTART);
        int done = 0;
        session_render_part(shown, 16, &done);
        display_take_samples(d);
        session_set_camera(shown, &cam);
        display_change_view(d, s, &cam, DISPLAY_CAMERA);
        float *img = malloc(sizeof(float) * 3 * FW * FH);
        while (session_frames(shown) < FRAMES) {
            session_render_part(shown, 16, &done);
            display_take_samples(d);
            display_resolve(d, COMP_MASK_ALL, 1, img);
        }
        free(img);
        const film *a = session_film(plain), *b = session_film(shown);
        int same = a->passes == b->passes && memcmp(a->rejected, b->rejected, sizeof(uint32_t) * FW * FH) == 0;
        for (int c = 0; c < COMP_COUNT; c++) same &= memcmp(a->sum[c], b->sum[c], sizeof(double) * 3 * FW * FH) == 0;
        CHECK(same, "the film with a display on it differs from the film without one");
    }
    display_destroy(d);
    session_destroy(shown);
    session_destroy(plain);
    scene_destroy(s);
}

/* What each packet needs (display_packet_need). Before any sample every packet needs the most
 * (15); after one sample everywhere, the upper band by the lack, 8 + 7 / 2 rounded (12). After three
 * samples whose light varies in the left half (gains 0.5, 1.5, 1) and not in the right, every left
 * packet is in the lower band above every right one (nothing to gain: level 0), the brightest left
 * ones above the mean packet (level 5 or more: the mean counts the right's zeros). After a slide of
 * the view by a quarter of its width, the new strip at the right needs the most again, and the
 * carried packets stay in the lower band. */
static void scale_left(display *d, float gain) {
    const sample_sink *sk = display_sink(d);
    for (int i = 0; i < W * H; i++)
        if (i % W < W / 2)
            for (int c = 0; c < COMP_COUNT; c++)
                for (int e = 0; e < 3; e++) sk->rgb[c][3 * i + e] *= gain;
}

static void check_packet_need(void) {
    enum { PX = (W + SESSION_PACKET - 1) / SESSION_PACKET, PY = (H + SESSION_PACKET - 1) / SESSION_PACKET };
    scene *s = plane_scene(0, 0.0f, 0.5f, 0.0f);
    camera a = view_from(v3(0, 0, 5), v3(0, 0, 0));
    /* half the view's width at the plane: 5 tan(0.35) x 1.6 = 2.92; the slide is 0.26 of the width */
    camera b = view_from(v3(1.5f, 0, 5), v3(1.5f, 0, 0));
    display *d = moved(s, a, a, 0, DISPLAY_CAMERA, -1, 0.0f);
    CHECK(d != NULL, "display");
    if (!d) return;
    int off = 0;
    const uint8_t *need = display_packet_need(d);
    for (int k = 0; k < PX * PY; k++) off += need[k] != SESSION_NEED_LEVELS - 1;
    CHECK(off == 0, "before any sample every packet needs everything: %d do not", off);
    const float gains[3] = {0.5f, 1.5f, 1.0f};
    for (int k = 0; k < 3; k++) {
        write_samples(d, 1.0f, -1, 0.0f);
        scale_left(d, gains[k]);
        display_take_samples(d);
        if (k > 0) continue;
        need = display_packet_need(d);
        off = 0;
        for (int q = 0; q < PX * PY; q++) off += need[q] != 12;
        CHECK(off == 0, "after one sample every packet is in the upper band at 12: %d are not", off);
    }
    need = display_packet_need(d);
    int lowest_left = SESSION_NEED_LEVELS, highest_left = -1, highest_right = -1;
    for (int j = 0; j < PY; j++)
        for (int i = 0; i < PX; i++) {
            int x0 = SESSION_PACKET * i, x1 = x0 + SESSION_PACKET, v = need[j * PX + i];
            if (x1 <= W / 2) {
                lowest_left = v < lowest_left ? v : lowest_left;
                highest_left = v > highest_left ? v : highest_left;
            } else if (x0 >= W / 2) {
                highest_right = v > highest_right ? v : highest_right;
            }
        }
    CHECK(highest_right == 0 && lowest_left > highest_right && highest_left >= 5 &&
              highest_left < SESSION_NEED_LEVELS / 2,
          "after three samples: the varying packets at levels %d to %d, the steady ones up to %d", lowest_left,
          highest_left, highest_right);
    display_change_view(d, s, &b, DISPLAY_CAMERA);
    need = display_packet_need(d);
    int old_off = 0, new_off = 0;
    for (int j = 0; j < PY; j++)
        for (int i = 0; i < PX; i++) {
            int x0 = SESSION_PACKET * i, x1 = x0 + SESSION_PACKET;
            if (x1 <= W * 7 / 10) old_off += need[j * PX + i] >= SESSION_NEED_LEVELS / 2;
            if (x0 >= W * 8 / 10) new_off += need[j * PX + i] != SESSION_NEED_LEVELS - 1;
        }
    CHECK(old_off == 0 && new_off == 0, "after the slide: %d carried packets and %d new ones with another need",
          old_off, new_off);
    display_destroy(d);
    scene_destroy(s);
}

int main(void) {
    check_projection();
    check_static_mean();
    check_reprojection();
    check_disocclusion();
    check_glossy_history();
    check_last_resort_history();
    check_changes();
    check_light_judgement(0.0f);
    check_light_judgement(400.0f);
    check_noisy_judgement();
    check_stale_last_resort();
    check_extra_evidence();
    check_filter_fades();
    check_film_untouched();
    check_packet_need();
    return check_exit("test_display");
}
