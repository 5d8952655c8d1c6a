/* The path tracer against answers known in closed form or by brute-force quadrature: the white
 * furnace (a closed box, and a convex object under a constant sky), point, spot and directional
 * lights on a plane, a square area light on a Lambert plane (Lambert's polygon formula), and
 * glossy reflection of an area light (quadrature over the light). The path tracer is the
 * reference every other estimator is judged against, so these tests are its warrant. */
#include <math.h>
#include <stdlib.h>

#include "check.h"
#include "rng.h"
#include "test_scenes.h"

static const unsigned ALL = COMP_MASK_ALL;

/* Mean of (rendered - expected) over pixels and its standard error: an unbiased renderer gives a
 * mean within a few standard errors of zero. */
static void diff_stats(const float *img, const float *expected, int n, double *mean, double *sem) {
    float *d = malloc(sizeof(float) * 3 * (size_t)n);
    for (int i = 0; i < 3 * n; i++) d[i] = img[i] - expected[i];
    ts_stats(d, n, mean, sem);
    free(d);
}

/* A closed box, every wall Lambert with albedo a and emitting Le: radiance is Le / (1 - a)
 * everywhere; Le + a Le of it is direct (emitted, and one bounce), the rest indirect. */
static void test_furnace_box(float a, int max_depth) {
    const float le = 0.5f;
    scene *s = ts_new("furnace-box");
    int m = ts_lambert(s, v3s(a), v3s(le), 0);
    ts_box(s, v3(-1, -1, -1), v3(1, 1, 1), 1, m);
    ts_finalize(s);
    camera cam = camera_look_at(v3(0.1f, 0.2f, 0.3f), v3(0.5f, 0.1f, 1.0f), v3(0, 1, 0), 1.2f);
    const int w = 32, h = 24, n = w * h, spp = 64;
    float *all = ts_render(s, &cam, w, h, spp, max_depth, 7, ALL);
    float *direct = ts_render(s, &cam, w, h, spp, max_depth, 7, 1u << COMP_DIRECT);
    float *indirect = ts_render(s, &cam, w, h, spp, max_depth, 7, 1u << COMP_INDIRECT);
    double mean, sem;
    /* Paths longer than max_depth are cut: the expected value is the truncated series. */
    double expect = le * (1.0 - pow(a, max_depth + 1)) / (1.0 - a);
    ts_stats(all, n, &mean, &sem);
    CHECK_NEAR(mean, expect, 4.0 * sem + 1e-4 * expect, "furnace a=%g depth=%d (sem %g)", a, max_depth, sem);
    CHECK(sem < 0.01 * expect, "furnace noise too high: sem %g", sem);
    ts_stats(direct, n, &mean, &sem);
    CHECK_NEAR(mean, le * (1.0 + a), 4.0 * sem + 1e-4, "furnace direct a=%g", a);
    ts_stats(indirect, n, &mean, &sem);
    CHECK_NEAR(mean, expect - le * (1.0 + a), 4.0 * sem + 1e-4, "furnace indirect a=%g", a);
    free(all);
    free(direct);
    free(indirect);
    scene_destroy(s);
}

/* Directional albedo of b for wo, by quadrature over the hemisphere in (1 - cos theta, phi), with
 * the theta grid dense near the lobe's peak (log-spaced in 1 - cos around the mirror direction
 * wo reflected about z works only at normal incidence, which is all this test uses). */
static double albedo_quadrature(const bsdf *b, vec3 wo) {
    const int nt = 2000, np = 256;
    double sum = 0.0;
    /* u = 1 - cos(theta) from 1e-9 to 1, log-spaced; midpoint rule in log u. */
    double lo = log(1e-9), hi = 0.0;
    for (int i = 0; i < nt; i++) {
        double lu = lo + (hi - lo) * (i + 0.5) / nt;
        double u = exp(lu), du = u * (hi - lo) / nt;
        double ct = 1.0 - u, st = sqrt(fmax(0.0, 1.0 - ct * ct));
        for (int j = 0; j < np; j++) {
            double phi = 2.0 * 3.14159265358979323846 * (j + 0.5) / np;
            vec3 wi = v3((float)(st * cos(phi)), (float)(st * sin(phi)), (float)ct);
            vec3 f = bsdf_eval(b, wo, wi, BSDF_ALL);
            sum += avg3(f) * ct * du * (2.0 * 3.14159265358979323846 / np);
        }
    }
    return sum;
}

/* A convex object under a constant sky of radiance 1 reflects its directional albedo (no
 * inter-reflection is possible). The camera looks straight at one face with a narrow field, so
 * wo is the normal for every pixel. Exercises environment sampling and MIS with BSDF sampling. */
static void test_env_furnace(const char *name, material mat) {
    scene *s = ts_new(name);
    int m = ts_material(s, mat);
    ts_box(s, v3(-0.5f, -0.5f, -0.5f), v3(0.5f, 0.5f, 0.5f), 0, m);
    ts_finalize(s);
    ts_constant_env(s, 1.0f);
    camera cam = camera_look_at(v3(0, 0, 3), v3(0, 0, 0), v3(0, 1, 0), 0.02f);
    const int w = 16, h = 16, n = w * h;
    float *img = ts_render(s, &cam, w, h, 256, 8, 11, ALL);
    frame3 fr;
    surface_hit hit;
    scene_intersect(s, cam.position, cam.forward, INFINITY, &hit);
    bsdf b = material_bsdf(s, &hit, &fr);
    double expect = albedo_quadrature(&b, v3(0, 0, 1));
    double mean, sem;
    ts_stats(img, n, &mean, &sem);
    CHECK_NEAR(mean, expect, 4.0 * sem + 2e-3 * expect, "%s: sky furnace (sem %g)", name, sem);
    free(img);
    scene_destroy(s);
}

/* ---- punctual lights on a plane ---------------------------------------------------------------- */

typedef float (*radiance_fn)(vec3 p, const void *ctx);

/* Expected image of the plane y = 0 seen by cam: fn at the hit point, averaged over a 4x4 grid in
 * each pixel (the renderer jitters uniformly within pixels). */
static float *plane_expected(const camera *cam, int w, int h, radiance_fn fn, const void *ctx) {
    float *e = calloc(3 * (size_t)w * (size_t)h, sizeof(float));
    float aspect = (float)w / (float)h;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double sum = 0.0;
            for (int k = 0; k < 16; k++) {
                float sx = ((float)x + ((float)(k & 3) + 0.5f) / 4.0f) / (float)w;
                float sy = ((float)y + ((float)(k >> 2) + 0.5f) / 4.0f) / (float)h;
                vec3 d = camera_ray_dir(cam, aspect, sx, sy);
                float t = -cam->position.y / d.y;
                sum += t > 0.0f ? fn(madd3(cam->position, d, t), ctx) : 0.0f;
            }
            for (int c = 0; c < 3; c++) e[3 * (y * w + x) + c] = (float)(sum / 16.0);
        }
    return e;
}

typedef struct {
    light l;
    float albedo;
} plane_light;

/* Radiance of a Lambert plane lit by a punctual light, from the KHR_lights_punctual definitions
 * (candela at distance d: I/d^2; spot smooth falloff as the extension's reference code). */
static float punctual_radiance(vec3 p, const void *ctx) {
    const plane_light *pl = ctx;
    const light *l = &pl->l;
    const vec3 n = v3(0, 1, 0);
    float e;
    if (l->type == LIGHT_DIRECTIONAL) {
        e = l->color.x * fmaxf(0.0f, -l->direction.y);
    } else {
        vec3 d = sub3(l->position, p);
        float r2 = length_sq3(d), r = sqrtf(r2);
        float cos_s = dot3(d, n) / r;
        float atten = 1.0f;
        if (l->type == LIGHT_SPOT) {
            float cd = -dot3(d, l->direction) / r;
            float scale = 1.0f / fmaxf(0.001f, l->cos_inner - l->cos_outer);
            float t = clampf(cd * scale - l->cos_outer * scale, 0.0f, 1.0f);
            atten = t * t;
        }
        e = l->color.x * atten * fmaxf(cos_s, 0.0f) / r2;
    }
    return pl->albedo * INV_PI_F * e;
}

static void test_punctual(const char *name, light l) {
    const float albedo = 0.6f;
    scene *s = ts_new(name);
    int m = ts_lambert(s, v3s(albedo), v3s(0), 0);
    ts_quad(s, v3(-20, 0, 20), v3(20, 0, 20), v3(20, 0, -20), v3(-20, 0, -20), m);
    scene_add_light(s, &l);
    ts_finalize(s);
    camera cam = camera_look_at(v3(0.3f, 2.5f, 1.5f), v3(0, 0, 0), v3(0, 1, 0), 1.0f);
    const int w = 40, h = 30, n = w * h;
    float *img = ts_render(s, &cam, w, h, 256, 4, 3, ALL);
    plane_light pl = {l, albedo};
    float *e = plane_expected(&cam, w, h, punctual_radiance, &pl);
    /* Deterministic apart from pixel jitter (which 256 samples average out to well under the
     * tolerance where the image is smooth): every pixel must match closely. */
    float peak = 0.0f;
    for (int i = 0; i < n; i++) peak = fmaxf(peak, e[3 * i]);
    int bad = 0;
    double worst = 0.0, sum_e = 0.0;
    for (int i = 0; i < n; i++) {
        double tol = 0.02 * e[3 * i] + 0.01 * peak;
        double err = fabs(img[3 * i] - e[3 * i]);
        if (err > tol && bad++ < 5) fprintf(stderr, "%s: pixel %d: %g, expected %g\n", name, i, img[3 * i], e[3 * i]);
        if (err > worst) worst = err;
        sum_e += e[3 * i];
    }
    CHECK(bad <= n / 100, "%s: %d of %d pixels off (worst abs error %g)", name, bad, n, worst);
    CHECK(sum_e > 0.01 * n, "%s: the test scene is dark, it tests nothing", name);
    free(img);
    free(e);
    scene_destroy(s);
}

/* ---- a square area light over a Lambert plane ------------------------------------------------ */

typedef struct {
    vec3 corners[4]; /* the emitter, counter-clockwise seen from below */
    float le, albedo;
} area_setup;

/* Lambert's formula: irradiance at p (normal n) from a uniform polygon of radiance Le is
 * Le/2 * sum over edges of angle(v_i, v_i+1) * (n . normalize(v_i x v_i+1)). */
static float polygon_irradiance(vec3 p, vec3 n, const vec3 *poly, int count, float le) {
    double sum = 0.0;
    for (int i = 0; i < count; i++) {
        vec3 a = normalize3(sub3(poly[i], p)), b = normalize3(sub3(poly[(i + 1) % count], p));
        double angle = acos(fmax(-1.0, fmin(1.0, (double)dot3(a, b))));
        vec3 c = normalize3(cross3(a, b));
        sum += angle * dot3(c, n);
    }
    return (float)(0.5 * le * fabs(sum));
}

static float area_radiance(vec3 p, const void *ctx) {
    const area_setup *as = ctx;
    return as->albedo * INV_PI_F * polygon_irradiance(p, v3(0, 1, 0), as->corners, 4, as->le);
}

static void test_area_light(void) {
    area_setup as = {{v3(-0.5f, 1, -0.5f), v3(0.5f, 1, -0.5f), v3(0.5f, 1, 0.5f), v3(-0.5f, 1, 0.5f)}, 4.0f, 0.5f};
    scene *s = ts_new("area-light");
    int plane = ts_lambert(s, v3s(as.albedo), v3s(0), 0);
    int emitter = ts_lambert(s, v3s(0), v3s(as.le), 0);
    ts_quad(s, v3(-20, 0, 20), v3(20, 0, 20), v3(20, 0, -20), v3(-20, 0, -20), plane);
    /* facing down: counter-clockwise seen from below */
    ts_quad(s, as.corners[0], as.corners[1], as.corners[2], as.corners[3], emitter);
    ts_finalize(s);
    CHECK(s->tri_light[s->num_triangles - 1] >= 0, "the emissive quad is not a light");
    camera cam = camera_look_at(v3(0.2f, 3.0f, 2.0f), v3(0, 0, 0), v3(0, 1, 0), 1.0f);
    const int w = 32, h = 24, n = w * h;
    /* max_depth 1: direct light only (light hitting the plane, then the back of the emitter is
     * black, so deeper paths add nothing anyway). */
    float *img = ts_render(s, &cam, w, h, 64, 1, 5, ALL);
    float *e = plane_expected(&cam, w, h, area_radiance, &as);
    /* The camera also sees the emitter's unlit back (radiance 0); plane_expected does not know
     * about it, so zero those pixels in both images. */
    for (int i = 0; i < n; i++) {
        int y = i / w, x = i % w;
        vec3 d = camera_ray_dir(&cam, (float)w / (float)h, ((float)x + 0.5f) / (float)w, ((float)y + 0.5f) / (float)h);
        surface_hit hit;
        if (scene_intersect(s, cam.position, d, INFINITY, &hit) && hit.p.y > 0.5f) {
            for (int c = 0; c < 3; c++) img[3 * i + c] = e[3 * i + c] = 0.0f;
        }
    }
    double mean, sem, mean_e, sem_e;
    diff_stats(img, e, n, &mean, &sem);
    ts_stats(e, n, &mean_e, &sem_e);
    CHECK_NEAR(mean, 0.0, 4.0 * sem + 2e-3 * mean_e, "area light: mean error (expected mean %g)", mean_e);
    /* Near and far halves separately, so that errors of opposite sign cannot cancel. */
    diff_stats(img, e, n / 2, &mean, &sem);
    CHECK_NEAR(mean, 0.0, 4.0 * sem + 2e-3 * mean_e, "area light: far half");
    diff_stats(img + 3 * (n / 2), e + 3 * (n / 2), n - n / 2, &mean, &sem);
    CHECK_NEAR(mean, 0.0, 4.0 * sem + 2e-3 * mean_e, "area light: near half");
    CHECK(mean_e > 0.05, "area light: scene too dark to test");
    free(img);
    free(e);
    scene_destroy(s);
}

/* ---- several lights at once: next-event estimation's candidates ------------------------------ */

typedef struct {
    area_setup as;
    plane_light point, spot;
} mixed_setup;

static float mixed_radiance(vec3 p, const void *ctx) {
    const mixed_setup *ms = ctx;
    return area_radiance(p, &ms->as) + punctual_radiance(p, &ms->point) + punctual_radiance(p, &ms->spot);
}

static light mixed_spot(void) {
    return (light){.type = LIGHT_SPOT,
                   .color = v3s(2.0f),
                   .position = v3(-1.0f, 1.2f, 0.5f),
                   .direction = normalize3(v3(0.5f, -1, -0.2f)),
                   .cos_inner = cosf(0.3f),
                   .cos_outer = cosf(0.7f)};
}

/* A point light, a spot and the square area light over the Lambert plane, direct light only: the
 * image is the sum of the three closed forms. Next-event estimation takes the punctual lights and
 * a draw among the area lights as candidates and keeps one by what it brings; the mean must stay
 * the sum (and the MIS weights of the emitter found by BSDF sampling must match the draw's). */
static void test_mixed_lights(void) {
    mixed_setup ms = {{{v3(-0.5f, 1, -0.5f), v3(0.5f, 1, -0.5f), v3(0.5f, 1, 0.5f), v3(-0.5f, 1, 0.5f)}, 4.0f, 0.5f},
                      {{.type = LIGHT_POINT, .color = v3s(1.5f), .position = v3(1.2f, 0.8f, 0.6f)}, 0.5f},
                      {mixed_spot(), 0.5f}};
    scene *s = ts_new("mixed-lights");
    int plane = ts_lambert(s, v3s(0.5f), v3s(0), 0);
    int emitter = ts_lambert(s, v3s(0), v3s(ms.as.le), 0);
    ts_quad(s, v3(-20, 0, 20), v3(20, 0, 20), v3(20, 0, -20), v3(-20, 0, -20), plane);
    ts_quad(s, ms.as.corners[0], ms.as.corners[1], ms.as.corners[2], ms.as.corners[3], emitter);
    scene_add_light(s, &ms.point.l);
    scene_add_light(s, &ms.spot.l);
    ts_finalize(s);
    CHECK(s->nee_each == 2 && s->nee_draws, "mixed lights: %d punctual lights taken each", s->nee_each);
    camera cam = camera_look_at(v3(0.2f, 3.0f, 2.0f), v3(0, 0, 0), v3(0, 1, 0), 1.0f);
    const int w = 32, h = 24, n = w * h;
    float *img = ts_render(s, &cam, w, h, 64, 1, 9, ALL);
    float *e = plane_expected(&cam, w, h, mixed_radiance, &ms);
    for (int i = 0; i < n; i++) { /* the emitter's unlit back, which plane_expected does not know */
        vec3 d = camera_ray_dir(&cam, (float)w / (float)h, ((float)(i % w) + 0.5f) / (float)w,
                                ((float)(i / w) + 0.5f) / (float)h);
        surface_hit hit;
        if (scene_intersect(s, cam.position, d, INFINITY, &hit) && hit.p.y > 0.5f)
            for (int c = 0; c < 3; c++) img[3 * i + c] = e[3 * i + c] = 0.0f;
    }
    double mean, sem, mean_e, sem_e;
    ts_stats(e, n, &mean_e, &sem_e);
    diff_stats(img, e, n, &mean, &sem);
    CHECK_NEAR(mean, 0.0, 4.0 * sem + 2e-3 * mean_e, "mixed lights: mean error (expected mean %g)", mean_e);
    diff_stats(img, e, n / 2, &mean, &sem);
    CHECK_NEAR(mean, 0.0, 4.0 * sem + 2e-3 * mean_e, "mixed lights: far half");
    diff_stats(img + 3 * (n / 2), e + 3 * (n / 2), n - n / 2, &mean, &sem);
    CHECK_NEAR(mean, 0.0, 4.0 * sem + 2e-3 * mean_e, "mixed lights: near half");
    free(img);
    free(e);
    scene_destroy(s);
}

/* A spot of a twentieth of the scene's power, seen in a glossy metal plane, beside a bright panel
 * the plane's lobe does not face there: at the spot's highlight one sample picking its light by
 * power varies by at least E^2 (1 - p) / p (E the spot's share, p its power's); keeping a
 * candidate by what it brings leaves a small part of that. */
static void test_weak_light_in_lobe(void) {
    scene *s = ts_new("weak-light");
    material metal = material_default();
    metal.base_color = v3s(0.9f);
    metal.metallic = 1.0f;
    metal.roughness = 0.3f;
    int plane = ts_material(s, metal);
    int emitter = ts_lambert(s, v3s(0), v3s(6.0f), 0);
    ts_quad(s, v3(-20, 0, 20), v3(20, 0, 20), v3(20, 0, -20), v3(-20, 0, -20), plane);
    ts_quad(s, v3(3, 3, -1), v3(5, 3, -1), v3(5, 3, 1), v3(3, 3, 1), emitter); /* facing down */
    light spot = {.type = LIGHT_SPOT,
                  .color = v3s(3.0f),
                  .position = v3(0, 1.5f, -2.0f),
                  .direction = normalize3(v3(0, -1.5f, 2.0f)),
                  .cos_inner = cosf(0.4f),
                  .cos_outer = cosf(0.8f)};
    scene_add_light(s, &spot);
    ts_finalize(s);
    float p = dist1d_pmf(&s->light_dist, 0); /* punctual lights come first */
    CHECK(p > 0.02f && p < 0.2f, "weak light: the spot's share of the power is %g", p);
    camera cam = camera_look_at(v3(0, 1.5f, 2.0f), v3(0, 0, 0), v3(0, 1, 0), 0.5f);
    const int w = 16, h = 12, n = w * h, runs = 200;
    double *sum = calloc((size_t)n, sizeof *sum), *sum2 = calloc((size_t)n, sizeof *sum2);
    for (int r = 0; r < runs; r++) {
        float *img = ts_render(s, &cam, w, h, 1, 1, (uint64_t)(100 + r), ALL);
        for (int i = 0; i < n; i++) sum[i] += img[3 * i], sum2[i] += (double)img[3 * i] * img[3 * i];
        free(img);
    }
    int peak = 0;
    for (int i = 1; i < n; i++)
        if (sum[i] > sum[peak]) peak = i;
    double e = sum[peak] / runs, var = sum2[peak] / runs - e * e, by_power = e * e * (1.0 - p) / p;
    CHECK(e > 0.1, "weak light: its highlight is dark (%g)", e);
    CHECK(var < 0.05 * by_power, "weak light: variance %g at its highlight (%g), picking by power %g", var, e,
          by_power);
    free(sum);
    free(sum2);
    scene_destroy(s);
}

/* ---- glossy reflection of an area light: brute-force quadrature over the light ---------------- */

typedef struct {
    const scene *s;
    vec3 eye;
    vec3 corner, edge_u, edge_v; /* the emitter */
    float le;
} glossy_setup;

/* Radiance towards the eye from plane point p: integral over the emitter of
 * f(wo, wi) Le cos(theta_p) cos(theta_l) / d^2, midpoint rule on a 160x160 grid. */
static float glossy_radiance(vec3 p, const void *ctx) {
    const glossy_setup *g = ctx;
    surface_hit hit;
    vec3 to_p = sub3(p, g->eye);
    float dist = length3(to_p);
    if (!scene_intersect(g->s, g->eye, scale3(to_p, 1.0f / dist), INFINITY, &hit)) return 0.0f;
    frame3 fr;
    bsdf b = material_bsdf(g->s, &hit, &fr);
    vec3 wo = to_local(fr, normalize3(sub3(g->eye, p)));
    vec3 nl = normalize3(cross3(g->edge_u, g->edge_v)); /* the emitting side */
    float area = length3(cross3(g->edge_u, g->edge_v));
    const int k = 160;
    double sum = 0.0;
    for (int i = 0; i < k; i++)
        for (int j = 0; j < k; j++) {
            vec3 q = add3(g->corner, add3(scale3(g->edge_u, ((float)i + 0.5f) / (float)k),
                                          scale3(g->edge_v, ((float)j + 0.5f) / (float)k)));
            vec3 d = sub3(q, p);
            float r2 = length_sq3(d);
            vec3 wi_w = scale3(d, 1.0f / sqrtf(r2));
            float cos_l = -dot3(wi_w, nl);
            if (cos_l <= 0.0f) continue;
            vec3 wi = to_local(fr, wi_w);
            sum += avg3(bsdf_eval(&b, wo, wi, BSDF_ALL)) * fmaxf(wi.z, 0.0f) * cos_l / r2;
        }
    return (float)(sum * g->le * area / (k * k));
}

static void test_glossy_area(const char *name, material mat) {
    scene *s = ts_new(name);
    int plane = ts_material(s, mat);
    int emitter = ts_lambert(s, v3s(0), v3s(5.0f), 0);
    ts_quad(s, v3(-3, 0, 3), v3(3, 0, 3), v3(3, 0, -3), v3(-3, 0, -3), plane);
    /* A light panel behind the plane's centre, tilted towards the camera's mirror direction. */
    vec3 c0 = v3(-0.6f, 0.8f, -1.4f), eu = v3(1.2f, 0, 0), ev = v3(0, 0.6f, 0.3f);
    ts_quad(s, c0, add3(c0, eu), add3(add3(c0, eu), ev), add3(c0, ev), emitter);
    ts_finalize(s);
    camera cam = camera_look_at(v3(0, 1.0f, 2.5f), v3(0, 0, -0.3f), v3(0, 1, 0), 0.5f);
    const int w = 20, h = 16, n = w * h;
    float *img = ts_render(s, &cam, w, h, 256, 1, 9, ALL);
    glossy_setup g = {s, cam.position, c0, eu, ev, 5.0f};
    float *e = plane_expected(&cam, w, h, glossy_radiance, &g);
    for (int i = 0; i < n; i++) {
        int y = i / w, x = i % w;
        vec3 d = camera_ray_dir(&cam, (float)w / (float)h, ((float)x + 0.5f) / (float)w, ((float)y + 0.5f) / (float)h);
        surface_hit hit;
        if (!scene_intersect(s, cam.position, d, INFINITY, &hit) || hit.p.y > 1e-3f)
            for (int c = 0; c < 3; c++) img[3 * i + c] = e[3 * i + c] = 0.0f;
    }
    double mean, sem, mean_e, sem_e;
    diff_stats(img, e, n, &mean, &sem);
    ts_stats(e, n, &mean_e, &sem_e);
    CHECK(mean_e > 0.02, "%s: the highlight is not in view (mean %g)", name, mean_e);
    CHECK_NEAR(mean, 0.0, 4.0 * sem + 5e-3 * mean_e, "%s: mean error against quadrature (expected mean %g)", name,
               mean_e);
    /* Per-region agreement: the brightest quarter of pixels (the highlight itself). */
    double sum_i = 0.0, sum_e = 0.0, thresh;
    {
        float *sorted = malloc(sizeof(float) * (size_t)n);
        for (int i = 0; i < n; i++) sorted[i] = e[3 * i];
        for (int i = 1; i < n; i++)
            for (int j = i; j > 0 && sorted[j - 1] > sorted[j]; j--) {
                float t = sorted[j];
                sorted[j] = sorted[j - 1];
                sorted[j - 1] = t;
            }
        thresh = sorted[3 * n / 4];
        free(sorted);
    }
    for (int i = 0; i < n; i++)
        if (e[3 * i] >= thresh)
            sum_i += avg3(v3(img[3 * i], img[3 * i + 1], img[3 * i + 2])),
                sum_e += avg3(v3(e[3 * i], e[3 * i + 1], e[3 * i + 2]));
    CHECK_NEAR(sum_i / sum_e, 1.0, 0.03, "%s: highlight pixels' energy against quadrature", name);
    free(img);
    free(e);
    scene_destroy(s);
}

static material glossy_material(material_model model) {
    material m = material_default();
    m.model = model;
    m.kd = v3s(0.1f);
    m.ks = v3s(0.8f);
    m.exponent = 60.0f;
    m.alpha_x = 0.25f;
    m.alpha_y = 0.08f;
    return m;
}

/* The path tracer's highlights layer (camera - glossy - glossy - light, the highlight
 * estimator's paths). The same seed makes the same samples, so splitting must move light between
 * layers without changing the sum; in a box of purely glossy walls at depth 2 every indirect path
 * is a highlight, and in a diffuse box none is. Lit by a panel (its emission found by BSDF
 * sampling, under MIS) and a point light (next-event only). */
static void test_highlights_layer(void) {
    enum { HW = 16, HH = 12, HN = HW * HH };
    material mixed = material_default(), glossy, diffuse;
    mixed.model = MATERIAL_PHONG;
    mixed.kd = v3s(0.3f);
    mixed.ks = v3s(0.6f);
    mixed.exponent = 40.0f;
    glossy = mixed;
    glossy.kd = v3s(0.0f);
    glossy.ks = v3s(0.9f);
    diffuse = mixed;
    diffuse.ks = v3s(0.0f);
    diffuse.kd = v3s(0.8f);
    const material *mats[3] = {&mixed, &glossy, &diffuse};
    const char *names[3] = {"mixed", "glossy", "diffuse"};
    camera cam = camera_look_at(v3(0.3f, 0.2f, 0.9f), v3(-1, -0.8f, -1), v3(0, 1, 0), 1.2f);
    for (int k = 0; k < 3; k++) {
        scene *s = ts_new("highlights box");
        ts_box(s, v3(-1, -1, -1), v3(1, 1, 1), 1, ts_material(s, *mats[k]));
        ts_quad(s, v3(-0.3f, 0.95f, -0.3f), v3(0.3f, 0.95f, -0.3f), v3(0.3f, 0.95f, 0.3f), v3(-0.3f, 0.95f, 0.3f),
                ts_lambert(s, v3s(0.0f), v3s(3.0f), 0));
        light pl = {.type = LIGHT_POINT, .color = v3s(0.5f), .position = v3(-0.4f, 0.3f, 0.2f)};
        scene_add_light(s, &pl);
        ts_finalize(s);
        int depth = k == 1 ? 2 : 6;
        render_params p = {.width = HW, .height = HH, .max_depth = depth, .seed = 21};
        float *ind = ts_render_with(s, &cam, &p, 64, 1u << COMP_INDIRECT);
        p.pt_highlights = 1;
        float *ind_split = ts_render_with(s, &cam, &p, 64, 1u << COMP_INDIRECT);
        float *hl = ts_render_with(s, &cam, &p, 64, 1u << COMP_HIGHLIGHTS);
        float *dir0 = ts_render_with(s, &cam, &p, 64, 1u << COMP_DIRECT);
        p.pt_highlights = 0;
        float *dir1 = ts_render_with(s, &cam, &p, 64, 1u << COMP_DIRECT);
        int bad_sum = 0, negative = 0, direct_changed = 0;
        double hl_total = 0.0, ind_total = 0.0, rest_total = 0.0;
        for (int i = 0; i < 3 * HN; i++) {
            if (!(fabsf(ind[i] - (ind_split[i] + hl[i])) <= 1e-4f * ind[i] + 1e-7f)) bad_sum++;
            negative += hl[i] < 0.0f || ind_split[i] < 0.0f;
            direct_changed += dir0[i] != dir1[i];
            hl_total += hl[i];
            ind_total += ind[i];
            rest_total += ind_split[i];
        }
        printf("highlights layer, %s box: highlights %.4f of indirect %.4f\n", names[k], hl_total / ind_total,
               ind_total);
        CHECK(bad_sum == 0 && negative == 0, "%s: indirect != split indirect + highlights at %d channels, %d negative",
              names[k], bad_sum, negative);
        CHECK(direct_changed == 0, "%s: the split changed the direct light at %d channels", names[k], direct_changed);
        CHECK(ind_total > 0.0, "%s: no indirect light", names[k]);
        if (k == 0)
            CHECK(hl_total > 0.05 * ind_total && rest_total > 0.05 * ind_total, "mixed: highlights share %.3f",
                  hl_total / ind_total);
        if (k == 1)
            CHECK(rest_total <= 1e-6 * ind_total, "glossy, depth 2: %.3g of the indirect is not highlights",
                  rest_total / ind_total);
        if (k == 2) CHECK(hl_total == 0.0, "diffuse: highlights %g", hl_total);
        free(ind);
        free(ind_split);
        free(hl);
        free(dir0);
        free(dir1);
        scene_destroy(s);
    }
}

/* Camera rays traced as a packet find what one-by-one tracing finds: the same hits and misses,
 * the same surface records, for every packet size (partial packets at image edges), on the
 * showcase scene's curved and anisotropic surfaces: from inside the room, and from outside it
 * looking at a corner, where most rays miss. */
static int hits_agree(const surface_hit *a, const surface_hit *b) {
    const float tol = 1e-5f;
    return a->tri == b->tri && a->material == b->material && a->backface == b->backface &&
           fabsf(a->t - b->t) <= tol * (1.0f + a->t) && length3(sub3(a->p, b->p)) <= tol * (1.0f + length3(a->p)) &&
           length3(sub3(a->ng, b->ng)) <= tol && length3(sub3(a->shading.n, b->shading.n)) <= 1e-4f &&
           length3(sub3(a->shading.t, b->shading.t)) <= 1e-4f && fabsf(a->uv0.x - b->uv0.x) <= 1e-4f &&
           fabsf(a->uv0.y - b->uv0.y) <= 1e-4f;
}

static void test_camera_packets(void) {
    char err[256];
    scene *s = scene_load("builtin:showcase", NULL, NULL, err, sizeof err);
    CHECK(s != NULL, "builtin:showcase: %s", err);
    if (!s) return;
    vec3 c = bounds_center(s->bounds);
    camera views[2] = {camera_look_at(c, add3(c, v3(1, -0.3f, 0.7f)), v3(0, 1, 0), 1.0f),
                       camera_look_at(add3(s->bounds.hi, v3s(0.3f * s->diag)), s->bounds.hi, v3(0, 1, 0), 0.9f)};
    rng_state rng = rng_make(99, 1);
    int rays = 0, hits = 0, bad = 0;
    for (int v = 0; v < 2; v++) {
        for (int n = 1; n <= SCENE_PACKET; n++) {
            for (int rep = 0; rep < 40; rep++) {
                vec3 d[SCENE_PACKET];
                surface_hit packet[SCENE_PACKET];
                for (int i = 0; i < n; i++) d[i] = camera_ray_dir(&views[v], 1.5f, rng_float(&rng), rng_float(&rng));
                unsigned mask = scene_intersect_packet(s, views[v].position, d, n, packet);
                CHECK(mask >> n == 0, "packet of %d reports hits beyond its rays (mask %x)", n, mask);
                for (int i = 0; i < n; i++) {
                    surface_hit one;
                    int hit = scene_intersect(s, views[v].position, d[i], INFINITY, &one);
                    rays++;
                    hits += hit;
                    if (hit != (int)(mask >> i & 1u) || (hit && !hits_agree(&one, &packet[i]))) bad++;
                }
            }
        }
    }
    CHECK(bad == 0, "packet and single rays disagree on %d of %d rays", bad, rays);
    CHECK(hits > rays / 10 && hits < rays - rays / 10, "the views mix hits and misses (%d of %d hit)", hits, rays);
    scene_destroy(s);
}

int main(void) {
    test_camera_packets();
    test_highlights_layer();
    test_furnace_box(0.5f, 64);
    test_furnace_box(0.8f, 200);
    test_furnace_box(0.8f, 3); /* truncation at max_depth is exact too */

    material lam = material_default();
    lam.model = MATERIAL_PHONG;
    lam.kd = v3s(0.7f);
    lam.ks = v3s(0.0f);
    test_env_furnace("sky-lambert", lam);
    material ward = glossy_material(MATERIAL_WARD);
    test_env_furnace("sky-ward", ward);
    material metal = material_default();
    metal.base_color = v3(0.95f, 0.9f, 0.8f);
    metal.metallic = 1.0f;
    metal.roughness = 0.3f;
    test_env_furnace("sky-ggx-metal", metal);

    light point = {.type = LIGHT_POINT, .color = v3s(3.0f), .position = v3(0.2f, 1.0f, -0.1f)};
    test_punctual("point", point);
    light spot = {.type = LIGHT_SPOT,
                  .color = v3s(5.0f),
                  .position = v3(0, 1.5f, 0),
                  .direction = normalize3(v3(0.3f, -1, 0)),
                  .cos_inner = cosf(0.3f),
                  .cos_outer = cosf(0.6f)};
    test_punctual("spot", spot);
    light sun = {.type = LIGHT_DIRECTIONAL, .color = v3s(2.0f), .direction = normalize3(v3(0.4f, -1, -0.3f))};
    test_punctual("directional", sun);

    test_area_light();
    test_mixed_lights();
    test_weak_light_in_lobe();

    test_glossy_area("glossy-phong", glossy_material(MATERIAL_PHONG));
    test_glossy_area("glossy-ward", glossy_material(MATERIAL_WARD));
    material ggx = material_default();
    ggx.base_color = v3s(0.8f);
    ggx.metallic = 1.0f;
    ggx.roughness = 0.35f;
    ggx.anisotropy_strength = 0.5f;
    test_glossy_area("glossy-ggx-aniso", ggx);
    return check_exit("test_pt");
}
