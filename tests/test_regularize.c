/* --regularize-image: at the hit a many-light method's traced direction reaches, a light's image
 * in the hit's glossy lobe is kept no narrower than a share of the lobe that sent the direction
 * (docs/design.md, "Regularised images"). Checked: the widening at one hit against the BSDF built
 * at the roughness the rule names (C x the sending roughness x (1 + t / d) for a point light,
 * distances measured here), and in a render, that the rule blurs without absorbing and that it
 * takes the noise of a sharp mirror's point-light image, seen in a rough floor, down. */
#include "check.h"
#include "pt.h"
#include "session.h"
#include "test_scenes.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#define MIRROR_EXPONENT 2000.0f /* alpha 0.032 */

/* One Phong floor (y = 0, facing up) and a point light at light_pos. */
static scene *mirror_floor(vec3 light_pos) {
    scene *s = ts_new("mirror floor");
    int mat = ts_material(s, ts_phong(v3s(0.0f), v3s(0.8f), MIRROR_EXPONENT));
    ts_quad(s, v3(-4, 0, 4), v3(4, 0, 4), v3(4, 0, -4), v3(-4, 0, -4), mat);
    ts_point_light(s, light_pos);
    ts_finalize(s);
    return s;
}

/* The direct light a ray from o to the floor point q takes there under reg. */
static double reflected(const scene *s, vec3 o, vec3 q, pt_regularize reg) {
    rng_state rng = rng_make(1, 2);
    uint64_t rays[RAY_KIND_COUNT] = {0};
    vec3 direct;
    surface_hit h;
    if (!pt_reflected_direct(s, o, normalize3(sub3(q, o)), v3s(0.0f), BSDF_ALL, reg, &rng, &direct, NULL, &h, rays))
        return -1.0;
    return direct.y;
}

/* The Phong floor's f at q for light at lp seen from o, its lobe widened to alpha. */
static double floor_f(vec3 o, vec3 q, vec3 lp, float alpha) {
    bsdf b = make_bsdf_phong(v3s(0.0f), v3s(0.8f), MIRROR_EXPONENT);
    bsdf_regularize(&b, alpha);
    frame3 fr = frame_from_normal(v3(0, 1, 0));
    vec3 wo = to_local(fr, normalize3(sub3(o, q))), wi = to_local(fr, normalize3(sub3(lp, q)));
    return bsdf_eval(&b, wo, wi, BSDF_ALL).y;
}

static void test_widening_at_a_hit(void) {
    vec3 o = v3(-1.0f, 1.0f, 0.0f), q = v3(0.0f, 0.0f, 0.0f);
    double t = length3(sub3(q, o));
    /* 0.05 rad off the mirror direction, where the lobe's width shows, a light near q (t / d = 4.7)
     * and one far (0.47). */
    vec3 off = normalize3(v3(1.0f, 1.0f, 0.0707f));
    double dist[2] = {0.3, 3.0};
    for (int k = 0; k < 2; k++) {
        vec3 lp = scale3(off, (float)dist[k]);
        scene *s = mirror_floor(lp);
        double d = length3(sub3(lp, q));
        const float c_alpha = 0.02f; /* C x the sending lobe's roughness */
        double sharp = reflected(s, o, q, (pt_regularize){0});
        double wide = reflected(s, o, q, (pt_regularize){0.0f, c_alpha});
        double floor_only = reflected(s, o, q, (pt_regularize){c_alpha, 0.0f});
        float alpha = fminf((float)(c_alpha * (1.0 + t / d)), BSDF_HIGHLIGHT_ALPHA);
        double f0 = floor_f(o, q, lp, 0.0f);
        double want = floor_f(o, q, lp, alpha) / f0, want_floor = floor_f(o, q, lp, c_alpha) / f0;
        printf("light %d (t/d %.2f): widened / sharp %.4f (the lobe at alpha %.3f: %.4f), floor alone %.4f (%.4f)\n", k,
               t / d, wide / sharp, alpha, want, floor_only / sharp, want_floor);
        CHECK(sharp > 0.0, "light %d: no direct light at the hit (%g)", k, sharp);
        CHECK(fabs(wide / sharp / want - 1.0) < 1e-3, "light %d: widened by %.4f, the lobe at alpha %.3f gives %.4f", k,
              wide / sharp, alpha, want);
        CHECK(fabs(floor_only / sharp / want_floor - 1.0) < 1e-3, "light %d: the floor alone gave %.4f, want %.4f", k,
              floor_only / sharp, want_floor);
        CHECK(fabs(log(want)) > 0.4, "light %d: the test's direction hardly tells widths apart (%.4f)", k, want);
        scene_destroy(s);
    }
}

/* A rough metal floor (GGX alpha 0.25) before a glossy wall (Phong, exponent as given) with a point
 * light a metre from the wall: the floor's glossy directions find the light's image in the wall,
 * rarely when the wall is near-specular, each then worth many times the pixel. */
static scene *floor_and_wall(float exponent) {
    scene *s = ts_new("rough floor, glossy wall");
    material metal = material_default();
    metal.base_color = v3(0.9f, 0.6f, 0.4f);
    metal.metallic = 1.0f;
    metal.roughness = 0.5f; /* alpha 0.25 */
    int floor = ts_material(s, metal);
    int wall = ts_material(s, ts_phong(v3s(0.0f), v3s(0.8f), exponent));
    ts_quad(s, v3(-2, 0, 2), v3(2, 0, 2), v3(2, 0, -2), v3(-2, 0, -2), floor);
    ts_quad(s, v3(-2, 0, -2), v3(2, 0, -2), v3(2, 2, -2), v3(-2, 2, -2), wall);
    ts_point_light(s, v3(0.0f, 0.6f, -1.0f));
    ts_finalize(s);
    return s;
}

enum { RW = 32, RH = 24, RPIX = RW * RH, SEEDS = 6 };

/* vsl's indirect light on the floor over SEEDS seeds of `frames` frames, with the images
 * regularised at C (< 0: not): the mean of the seeds' means and the per-pixel variance over the
 * seeds, summed. */
static void render_seeds(const scene *s, float c, int frames, double *mean, double *noise2) {
    camera cam = camera_look_at(v3(0.0f, 0.8f, 1.8f), v3(0.0f, 0.1f, -1.0f), v3(0, 1, 0), 0.9f);
    float *img[SEEDS];
    for (int seed = 0; seed < SEEDS; seed++) {
        render_params p = {.width = RW, .height = RH, .method = METHOD_VSL, .max_depth = 2, .seed = 40 + seed};
        p.vl.count = 64;
        p.vl.radius_shrink = -1.0f; /* C stays as given */
        p.vl.reg_image = c;
        img[seed] = ts_render_with(s, &cam, &p, frames, 1u << COMP_INDIRECT);
    }
    *mean = *noise2 = 0.0;
    for (int i = 0; i < 3 * RPIX; i++) {
        double m = 0, m2 = 0;
        for (int seed = 0; seed < SEEDS; seed++) m += img[seed][i], m2 += (double)img[seed][i] * img[seed][i];
        m /= SEEDS;
        *mean += m / (3 * RPIX);
        *noise2 += (m2 / SEEDS - m * m) * SEEDS / (SEEDS - 1);
    }
    for (int seed = 0; seed < SEEDS; seed++) free(img[seed]);
}

/* Blurs without absorbing: on a Phong-100 wall (alpha 0.14, widened to about 0.25 from the floor)
 * the sharp render converges in a few hundred frames, and the regularised mean stays within a few
 * per cent of it (measured: -2.2%). On a near-mirror wall (Phong 2000) the sharp render's noise is
 * a few rare directions', which the widening spreads (measured: noise 0.055 of the sharp's). */
static void test_render_blurs_without_absorbing(void) {
    double mean[2], noise2[2];
    scene *s = floor_and_wall(100.0f);
    render_seeds(s, -1.0f, 128, &mean[0], &noise2[0]);
    render_seeds(s, 0.25f, 128, &mean[1], &noise2[1]);
    double ratio = mean[1] / mean[0];
    printf("rough floor, Phong-100 wall: regularised mean / sharp %.4f (sharp %.5f)\n", ratio, mean[0]);
    CHECK(mean[0] > 0.0, "the floor reflects nothing of the wall");
    CHECK(fabs(ratio - 1.0) < 0.05, "regularised images: the mean moved by %+.4f", ratio - 1.0);
    scene_destroy(s);

    s = floor_and_wall(MIRROR_EXPONENT);
    render_seeds(s, -1.0f, 16, &mean[0], &noise2[0]);
    render_seeds(s, 0.25f, 16, &mean[1], &noise2[1]);
    double noise = sqrt(noise2[1] / noise2[0]);
    printf("rough floor, Phong-2000 wall: regularised noise %.3f of the sharp lobe's (means %.5f, %.5f)\n", noise,
           mean[1], mean[0]);
    CHECK(noise < 0.5, "regularised images: the noise only fell to %.3f of the sharp lobe's", noise);
    scene_destroy(s);
}

int main(void) {
    test_widening_at_a_hit();
    test_render_blurs_without_absorbing();
    return check_exit("test_regularize");
}
