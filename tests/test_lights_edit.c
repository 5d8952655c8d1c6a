/* Editing lights between frames (scene_move_light, scene_set_light_gain), checked against
 * closed-form irradiance at a point of a Lambert floor: a point light's I cos / d^2, and a square
 * emitter's through the form factor of a rectangle seen from below one corner. The path tracer
 * renders a few pixels of the floor straight below a camera with a tiny field of view, so every
 * sample lands within a hair of that point. Also: the light groups (punctual lights, emissive
 * materials), the BVH and bounds following a moved emitter, the selection distribution following
 * intensity, and bad edits rejected. */
#include <math.h>
#include <stdlib.h>

#include "check.h"
#include "test_scenes.h"

#define PI 3.14159265358979323846

static const float ALBEDO = 0.5f;

/* Form factor from a point to a parallel rectangle w x l at height h, with the rectangle's corner
 * straight above the point (the standard closed form, e.g. Howell's catalogue, C-11). */
static double corner_form_factor(double w, double l, double h) {
    double a = w / h, b = l / h;
    double sa = sqrt(1.0 + a * a), sb = sqrt(1.0 + b * b);
    return (a / sa * atan(b / sa) + b / sb * atan(a / sb)) / (2.0 * PI);
}

/* Mean radiance (channel average) of a small patch of floor around p, seen from above, direct
 * light only; *sem gets its standard error over pixels. */
static double floor_radiance(const scene *s, vec3 p, int frames, double *sem) {
    camera cam = camera_look_at(v3(p.x, p.y + 0.5f, p.z), p, v3(0, 0, -1), 0.002f);
    render_params rp = {.width = 8, .height = 8, .max_depth = 1, .seed = 11};
    float *img = ts_render_with(s, &cam, &rp, frames, COMP_MASK_ALL);
    double mean;
    ts_stats(img, 64, &mean, sem);
    free(img);
    return mean;
}

static scene *floor_scene(const char *name) {
    scene *s = ts_new(name);
    int m = ts_lambert(s, v3s(ALBEDO), v3s(0), 0);
    ts_quad(s, v3(-20, 0, 20), v3(20, 0, 20), v3(20, 0, -20), v3(-20, 0, -20), m);
    return s;
}

static void test_point_light(void) {
    scene *s = floor_scene("point");
    light l = {.type = LIGHT_POINT, .color = v3s(3.0f), .position = v3(0.3f, 1.5f, -0.2f)};
    snprintf(l.name, sizeof l.name, "bulb");
    scene_add_light(s, &l);
    ts_finalize(s);
    light_group g;
    CHECK(scene_light_groups(s, &g, 1) == 1, "one light group");
    CHECK(g.type == LIGHT_POINT && strcmp(g.name, "bulb") == 0, "the group is the bulb");
    const vec3 p = v3(0, 0, 0);
    char err[256];
    vec3 delta = v3(0.5f, -0.6f, 0.4f);
    double sem;
    for (int step = 0; step < 3; step++) {
        vec3 q = step == 0 ? l.position : add3(l.position, delta);
        float gain = step == 2 ? 2.0f : 1.0f;
        vec3 d = sub3(q, p);
        double expected = ALBEDO / PI * gain * 3.0 * (double)(d.y / length3(d)) / (double)length_sq3(d);
        double got = floor_radiance(s, p, 4, &sem);
        CHECK_NEAR(got, expected, 2e-3 * expected, "point light, step %d", step);
        if (step == 0) CHECK(scene_move_light(s, 0, delta, err, sizeof err) == 0, "move: %s", err);
        if (step == 1) CHECK(scene_set_light_gain(s, 0, 2.0f, err, sizeof err) == 0, "gain: %s", err);
    }
    scene_light_groups(s, &g, 1);
    CHECK_NEAR(length3(sub3(g.center, add3(l.position, delta))), 0.0, 1e-6, "the group's position moved");
    CHECK_NEAR(g.gain, 2.0, 0.0, "the group's gain");
    /* Gains are against the light as loaded, never compounded. */
    CHECK(scene_set_light_gain(s, 0, 2.0f, err, sizeof err) == 0, "gain again: %s", err);
    CHECK_NEAR(s->lights[0].color.x, 6.0, 1e-6, "gain 2 twice is still 2");
    scene_destroy(s);
}

/* A square emitter of side a at height h, facing down, starting centred over the origin. */
static void test_area_light(void) {
    const float a = 1.0f, h = 1.0f, le = 4.0f;
    scene *s = floor_scene("area");
    int em = ts_lambert(s, v3s(0), v3s(le), 0);
    ts_quad(s, v3(-0.5f, h, -0.5f), v3(0.5f, h, -0.5f), v3(0.5f, h, 0.5f), v3(-0.5f, h, 0.5f), em); /* faces down */
    light punctual = {.type = LIGHT_DIRECTIONAL, .color = v3s(0.0f), .direction = v3(0, -1, 0)};
    snprintf(punctual.name, sizeof punctual.name, "sun");
    scene_add_light(s, &punctual); /* dark: only here to take group 0 */
    ts_finalize(s);
    light_group g[3];
    CHECK(scene_light_groups(s, g, 3) == 2, "two light groups (a directional light and one emitter of two triangles)");
    CHECK(g[0].type == LIGHT_DIRECTIONAL && g[1].type == LIGHT_TRIANGLE && g[1].index == em, "groups: punctual first");
    CHECK_NEAR(length3(sub3(g[1].center, v3(0, h, 0))), 0.0, 1e-6, "the emitter's centre");
    const vec3 p = v3(0, 0, 0);
    char err[256];
    double sem;
    /* centred: four rectangles a/2 x a/2 with a corner above p */
    double e0 = PI * le * 4.0 * corner_form_factor(a / 2, a / 2, h);
    double got = floor_radiance(s, p, 256, &sem);
    CHECK_NEAR(got, ALBEDO / PI * e0, 4.0 * sem + 2e-3 * got, "centred emitter");
    /* moved so that p is under a corner, and up by a half */
    CHECK(scene_move_light(s, 1, v3(a / 2, 0.5f, a / 2), err, sizeof err) == 0, "move: %s", err);
    double e1 = PI * le * corner_form_factor(a, a, h + 0.5);
    got = floor_radiance(s, p, 256, &sem);
    CHECK_NEAR(got, ALBEDO / PI * e1, 4.0 * sem + 2e-3 * got, "moved emitter");
    CHECK(e1 < 0.5 * e0, "the test moves the light far enough to tell (%g vs %g)", e1, e0);
    /* twice the intensity: the same samples, twice the radiance */
    double before = got;
    CHECK(scene_set_light_gain(s, 1, 2.0f, err, sizeof err) == 0, "gain: %s", err);
    got = floor_radiance(s, p, 256, &sem);
    CHECK_NEAR(got / before, 2.0, 1e-5, "intensity x2 doubles the direct light");
    CHECK_NEAR(luminance3(s->materials[em].emission), 2.0f * le, 1e-5, "the material's emission");
    /* The BVH has the emitter where it now is: a ray up from below its corner hits it at 1.5. */
    surface_hit hit;
    CHECK(scene_intersect(s, v3(0.5f, 0.01f, 0.5f), v3(0, 1, 0), INFINITY, &hit) && fabsf(hit.t - 1.49f) < 1e-4f,
          "ray up hits the moved emitter (t %g)", hit.t);
    CHECK(!scene_intersect(s, v3(-0.4f, 0.01f, -0.4f), v3(0, 1, 0), INFINITY, &hit), "nothing where it was");
    /* Bounds follow: moved far up, the scene is taller. */
    CHECK(scene_move_light(s, 1, v3(0, 5, 0), err, sizeof err) == 0, "move up: %s", err);
    CHECK_NEAR(s->bounds.hi.y, h + 5.5f, 1e-4, "bounds follow the emitter");
    CHECK_NEAR(s->diag, bounds_diagonal(s->bounds), 1e-4, "and the scene's size");
    scene_light_groups(s, g, 3);
    CHECK_NEAR(length3(sub3(g[1].center, v3(a / 2, h + 5.5f, a / 2))), 0.0, 1e-5, "the emitter's centre moved");
    /* Bad edits are refused and change nothing. */
    CHECK(scene_move_light(s, 0, v3(1, 0, 0), err, sizeof err) != 0 && strstr(err, "directional"), "directional: %s",
          err);
    CHECK(scene_move_light(s, 2, v3(1, 0, 0), err, sizeof err) != 0 && strstr(err, "no light 2"), "no such group: %s",
          err);
    CHECK(scene_move_light(s, 1, v3(NAN, 0, 0), err, sizeof err) != 0, "a NaN move");
    CHECK(scene_move_light(s, 1, v3(1e9f, 0, 0), err, sizeof err) != 0, "a huge move");
    CHECK(scene_set_light_gain(s, 1, 0.0f, err, sizeof err) != 0, "gain 0");
    CHECK(scene_set_light_gain(s, 1, NAN, err, sizeof err) != 0, "gain NaN");
    CHECK(scene_set_light_gain(s, -1, 1.0f, err, sizeof err) != 0, "group -1");
    CHECK_NEAR(s->bounds.hi.y, h + 5.5f, 1e-4, "refused moves changed nothing");
    scene_destroy(s);
}

/* Light selection is by power: intensity moves it. */
static void test_selection(void) {
    scene *s = floor_scene("selection");
    int em = ts_lambert(s, v3s(0), v3s(1.0f), 0);
    ts_quad(s, v3(-0.5f, 1, -0.5f), v3(0.5f, 1, -0.5f), v3(0.5f, 1, 0.5f), v3(-0.5f, 1, 0.5f), em);
    light l = {.type = LIGHT_POINT, .color = v3s(1.0f), .position = v3(0, 1.5f, 0)};
    scene_add_light(s, &l);
    ts_finalize(s);
    /* lights: the point light, then the emitter's two triangles */
    float p0 = dist1d_pmf(&s->light_dist, 0);
    char err[256];
    CHECK(scene_set_light_gain(s, 0, 10.0f, err, sizeof err) == 0, "gain: %s", err);
    float p1 = dist1d_pmf(&s->light_dist, 0);
    /* point power 4 pi I against the emitter's pi Le A = pi: p = 4g / (4g + 1) */
    CHECK_NEAR(p0, 4.0 / 5.0, 1e-5, "the point light's share before");
    CHECK_NEAR(p1, 40.0 / 41.0, 1e-5, "the point light's share at ten times the intensity");
    CHECK(s->num_lights == 3, "no light added or lost (%d)", s->num_lights);
    scene_destroy(s);
}

int main(void) {
    test_point_light();
    test_area_light();
    test_selection();
    return check_exit("test_lights_edit");
}
