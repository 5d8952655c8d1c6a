/* A punctual light's change to the direct light shown, computed rather than judged (display.h,
 * docs/design.md "Light moves"): what a punctual light brings to a hit (pt_punctual_direct) is
 * Lambert's law where the light is seen and nothing where a quad shadows it, and the mean of the
 * path tracer's direct estimate where two lights compete; after a point light moves over a plane,
 * the direct light shown before any new sample is the new light's, to float precision, while the
 * light through other paths is still judged; a sharp glossy plane (whose light at a pixel's centre
 * is not its footprint's) and a moved area light (which this does not compute) are judged as
 * before. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "display.h"
#include "lights.h"
#include "pt.h"
#include "test_scenes.h"

#define W 48
#define H 32

/* A plane z = 0 (Lambert kd 0.5, or Phong with a sharp lobe), a point light of intensity 1 at
 * (0, 0, 10); with_quad: a small quad at z = 1 shadowing the plane's middle; with_lamp: an
 * emissive quad (an area light) at z = 6, off to the side. */
static scene *plane_scene(float phong_n, int with_quad, int with_lamp) {
    scene *s = ts_new("relight");
    int plane = phong_n > 0.0f ? ts_material(s, ts_phong(v3s(0.2f), v3s(0.6f), phong_n))
                               : ts_lambert(s, v3s(0.5f), v3s(0.0f), 0);
    ts_quad(s, v3(-50, -50, 0), v3(50, -50, 0), v3(50, 50, 0), v3(-50, 50, 0), plane);
    if (with_quad) {
        int q = ts_lambert(s, v3s(0.5f), v3s(0.0f), 1);
        ts_quad(s, v3(-0.3f, -0.3f, 1), v3(0.3f, -0.3f, 1), v3(0.3f, 0.3f, 1), v3(-0.3f, 0.3f, 1), q);
    }
    if (with_lamp) {
        int e = ts_lambert(s, v3s(0.0f), v3s(5.0f), 1);
        ts_quad(s, v3(4, -1, 6), v3(6, -1, 6), v3(6, 1, 6), v3(4, 1, 6), e);
    }
    ts_point_light(s, v3(0, 0, 10));
    ts_finalize(s);
    return s;
}

/* Lambert's law: radiance kd / pi I cos / d^2 from a point light of intensity I. */
static double lambert(vec3 p, vec3 lamp, double kd) {
    vec3 d = sub3(lamp, p);
    double d2 = (double)length_sq3(d);
    return kd / (double)PI_F * (double)d.z / sqrt(d2) / d2;
}

static void check_punctual_direct(void) {
    scene *s = plane_scene(0.0f, 1, 0);
    surface_hit h;
    uint64_t rays = 0;
    vec3 out, d = v3(0, 0, -1);
    /* seen from above, beside the quad */
    CHECK(scene_intersect(s, v3(3, 0.5f, 5), d, INFINITY, &h) && h.material == 0, "the plane at (3, 0.5)");
    CHECK(pt_punctual_direct(s, &s->lights[0], 1, d, &h, &out, &rays) == 1, "a Lambert plane is reckoned");
    CHECK_NEAR(out.y, lambert(h.p, s->lights[0].position, 0.5), 1e-5 * out.y, "Lambert's law beside the quad");
    /* under the quad, seen from the side: shadowed; a light moved aside (as given, not the scene's) is seen */
    vec3 from = v3(2, 0.1f, 0.5f), to = v3(0.1f, 0.1f, 0.0f), dir = normalize3(sub3(to, from));
    CHECK(scene_intersect(s, from, dir, INFINITY, &h) && h.material == 0, "the plane under the quad");
    pt_punctual_direct(s, &s->lights[0], 1, dir, &h, &out, &rays);
    CHECK(is_black3(out), "the quad shadows the light: %g", (double)out.y);
    light aside = s->lights[0];
    aside.position = v3(5, 0, 10);
    pt_punctual_direct(s, &aside, 1, dir, &h, &out, &rays);
    CHECK_NEAR(out.y, lambert(h.p, aside.position, 0.5), 1e-5 * out.y, "the light as given, moved aside");
    CHECK(rays == 3, "one shadow ray each: %llu", (unsigned long long)rays);
    scene_destroy(s);

    /* two lights on a glossy plane: the path tracer's direct estimate (one light kept of the two
     * in proportion to what each brings) averages to the sum of what each brings */
    s = ts_new("relight-two");
    ts_quad(s, v3(-50, -50, 0), v3(50, -50, 0), v3(50, 50, 0), v3(-50, 50, 0),
            ts_material(s, ts_phong(v3s(0.3f), v3s(0.4f), 30.0f)));
    ts_point_light(s, v3(0, 0, 4));
    ts_point_light(s, v3(-3, 1, 2));
    ts_finalize(s);
    vec3 o = v3(2, 0.5f, 3);
    dir = normalize3(sub3(v3(0.5f, 0.2f, 0), o));
    CHECK(scene_intersect(s, o, dir, INFINITY, &h), "the glossy plane");
    vec3 ab[2];
    pt_punctual_direct(s, s->lights, 2, dir, &h, ab, &rays);
    vec3 a = ab[0], b = ab[1];
    double want = (double)(a.y + b.y), sum = 0.0, sum2 = 0.0;
    rng_state rng = rng_for(11, 0, 0);
    const int n = 20000;
    for (int k = 0; k < n; k++) {
        uint64_t r[RAY_KIND_COUNT] = {0};
        double v = (double)pt_direct(s, o, dir, &h, -1.0f, &rng, NULL, r).y;
        sum += v, sum2 += v * v;
    }
    double mean = sum / n, sem = sqrt(fmax(sum2 / n - mean * mean, 0.0) / n);
    CHECK(fabs(mean - want) <= 4.0 * sem + 1e-6 * want, "pt_direct's mean %g against the lights' sum %g (sem %g)", mean,
          want, sem);
    CHECK(a.y > 0.0f && b.y > 0.0f, "both lights bring light: %g, %g", (double)a.y, (double)b.y);
    scene_destroy(s);
}

/* Writes one sample into every pixel: the direct light of the scene's point light (Lambert's law
 * at the pixel's point, 0 where with_quad shadows it: not used there), and `indirect` in the
 * other components, each times the albedo as the film's samples are. */
static void write_samples(display *d, const scene *s, float indirect) {
    const sample_sink *sk = display_sink(d);
    const gbuffer *g = display_gbuffer(d);
    for (int i = 0; i < W * H; i++) {
        vec3 p = v3(g->pos[3 * i], g->pos[3 * i + 1], g->pos[3 * i + 2]);
        float direct = (float)lambert(p, s->lights[0].position, 1.0);
        for (int c = 0; c < COMP_COUNT; c++)
            for (int e = 0; e < 3; e++)
                sk->rgb[c][3 * i + e] = (c == COMP_DIRECT ? direct : indirect) * g->albedo[3 * i + e];
        sk->stamp[i] = sk->serial;
    }
}

/* The largest relative difference of component c shown (no filter) from Lambert's law for light
 * (over the albedo), and its mean over the pixels with light. */
static double worst_against(display *d, int c, vec3 lamp, double *mean) {
    float *img = malloc(sizeof(float) * 3 * W * H);
    display_resolve(d, 1u << c, 0, img);
    const gbuffer *g = display_gbuffer(d);
    double worst = 0.0, sum = 0.0;
    for (int i = 0; i < W * H; i++) {
        vec3 p = v3(g->pos[3 * i], g->pos[3 * i + 1], g->pos[3 * i + 2]);
        double want = lambert(p, lamp, 1.0), got = img[3 * i + 1] / g->albedo[3 * i + 1];
        worst = fmax(worst, fabs(got - want) / want);
        sum += got;
    }
    *mean = sum / (W * H);
    free(img);
    return worst;
}

/* The plane seen from above, 4 samples, then light 0 moved by `by` (group `group`: 0 the point
 * light, 1 the area light); returns the display before any new sample (caller destroys). */
static display *after_move(scene *s, int group, vec3 by) {
    char err[256];
    display *d = display_create(W, H, 2, err, sizeof err);
    if (!d) return NULL;
    camera cam = camera_look_at(v3(0, 0, 5), v3(0, 0, 0), v3(0, 1, 0), 0.9f);
    display_change_view(d, s, &cam, DISPLAY_CAMERA);
    for (int k = 0; k < 4; k++) {
        write_samples(d, s, 0.2f);
        display_take_samples(d);
    }
    CHECK(scene_move_light(s, group, by, err, sizeof err) == 0, "scene_move_light: %s", err);
    display_change_view(d, s, &cam, DISPLAY_LIGHTS);
    return d;
}

static void check_relit_display(void) {
    vec3 was = v3(0, 0, 10), by = v3(3, 0, -4), now = add3(was, by);
    scene *s = plane_scene(0.0f, 0, 0);
    display *d = after_move(s, 0, by);
    CHECK(d != NULL, "display");
    if (!d) return;
    double mean, other;
    double worst = worst_against(d, COMP_DIRECT, now, &mean);
    CHECK(worst < 1e-4, "the direct light shown is the moved light's before any new sample (worst %g)", worst);
    CHECK(worst_against(d, COMP_DIRECT, was, &mean) > 0.5, "...not the old light's");
    /* the other light is judged: shown meanwhile (the stale 0.2), and where new samples say it
     * doubled, after enough of them, those alone; the direct light stays the moved light's */
    worst_against(d, COMP_INDIRECT, now, &other);
    CHECK_NEAR(other, 0.2, 1e-4, "the light through other paths, stale, shown meanwhile");
    for (int k = 0; k < 20; k++) {
        write_samples(d, s, 0.4f);
        display_take_samples(d);
    }
    worst_against(d, COMP_INDIRECT, now, &other);
    CHECK_NEAR(other, 0.4, 1e-3, "the other light judged changed: the new samples alone");
    worst = worst_against(d, COMP_DIRECT, now, &mean);
    CHECK(worst < 1e-4, "the relit direct light kept through the verdict (worst %g)", worst);
    display_destroy(d);
    scene_destroy(s);

    /* a sharp glossy plane is not relit: its direct light, not confirmed, is not shown */
    s = plane_scene(2000.0f, 0, 0);
    d = after_move(s, 0, by);
    worst_against(d, COMP_DIRECT, now, &mean);
    CHECK(mean == 0.0, "a sharp glossy plane's direct light is judged, not relit: %g", mean);
    display_destroy(d);
    scene_destroy(s);

    /* an area light moved: not computed; the old direct light shown meanwhile, judged as before */
    s = plane_scene(0.0f, 0, 1);
    d = after_move(s, 1, v3(-2, 0, 0));
    CHECK(worst_against(d, COMP_DIRECT, was, &mean) < 1e-4, "an area light's move is judged: the old light shown");
    display_destroy(d);
    scene_destroy(s);
}

int main(void) {
    check_punctual_direct();
    check_relit_display();
    return check_exit("test_relight");
}
