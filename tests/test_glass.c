/* Glass in whole renders (docs/design.md, "Transmission and volume"): a slab of known thickness
 * in front of an emitter passes Beer-Lambert's exp(-sigma d) (and Fresnel's (1 - F0)^2 with an
 * ior), for the path tracer and the many-light methods' shared direct estimator; and in a closed
 * box with an area light behind and in front of a rough glass slab, the virtual-light methods
 * (which trace through the transmission, deposit no light on it and stop shadow rays at it)
 * converge to the path tracer's image. */
#include <math.h>

#include "check.h"
#include "test_scenes.h"

/* A glTF glass: base colour white, transmission 1, a volume when thickness > 0. */
static material glass_material(float rough, float ior, float thickness, vec3 att_color, float att_dist) {
    material m = material_default();
    m.base_color = v3s(1.0f);
    m.metallic = 0.0f;
    m.roughness = rough;
    m.ext.ior = ior;
    m.ext.transmission = 1.0f;
    m.ext.thickness = thickness;
    m.ext.attenuation_color = att_color;
    m.ext.attenuation_distance = att_dist;
    return m;
}

static double channel_mean(const float *img, int n, int c) {
    double m = 0;
    for (int i = 0; i < n; i++) m += img[3 * i + c];
    return m / n;
}

enum { SW = 12, SH = 12 };

/* A 1 m slab (z in [-0.5, 0.5]) before an emitter of radiance 1 at z = -3, seen head-on through a
 * narrow camera: radiance (1 - F0)^2 attenuation_color^(d / attenuation_distance). */
static void test_slab_beer_lambert(void) {
    const vec3 color = v3(0.5f, 0.25f, 0.8f);
    const float iors[2] = {1.0f, 1.5f};
    for (int i = 0; i < 2; i++) {
        scene *s = ts_new("slab");
        ts_box(s, v3(-3, -3, -0.5f), v3(3, 3, 0.5f), 0,
               ts_material(s, glass_material(0.0f, iors[i], 1.0f, color, 0.5f)));
        ts_quad(s, v3(-20, -20, -3), v3(20, -20, -3), v3(20, 20, -3), v3(-20, 20, -3),
                ts_lambert(s, v3s(0.0f), v3s(1.0f), 0));
        ts_finalize(s);
        camera cam = camera_look_at(v3(0, 0, 4), v3(0, 0, -1), v3(0, 1, 0), 0.05f);
        double f0 = pow((iors[i] - 1.0) / (iors[i] + 1.0), 2.0), k = (1.0 - f0) * (1.0 - f0);
        for (int method = METHOD_PT; method <= METHOD_VSL; method += METHOD_VSL - METHOD_PT) {
            render_params p = {.width = SW, .height = SH, .method = (render_method)method, .max_depth = 4, .seed = 3};
            p.vl.count = 64;
            float *img = ts_render_with(s, &cam, &p, 64, ~0u);
            const float want[3] = {color.x * color.x, color.y * color.y, color.z * color.z};
            for (int c = 0; c < 3; c++) {
                double got = channel_mean(img, SW * SH, c);
                CHECK_NEAR(got, k * want[c], 0.015 * k * want[c] + 1e-4, "slab, ior %.1f, %s, channel %d",
                           (double)iors[i], method_name(p.method), c);
            }
            free(img);
        }
        scene_destroy(s);
    }
}

enum { W = 24, H = 18, NPIX = W * H };

/* A closed 2 m box of grey walls, a panel light under the ceiling, and a rough glass slab (a
 * volume, ior 1.5, slightly absorbing) standing before the back wall: half the light the camera
 * sees through the slab reaches the wall through it. */
static void test_glass_box_against_pt(void) {
    scene *s = ts_new("glass box");
    ts_box(s, v3(-1, -1, -1), v3(1, 1, 1), 1, ts_lambert(s, v3s(0.6f), v3s(0.0f), 0));
    ts_quad(s, v3(-0.3f, 0.98f, -0.7f), v3(0.3f, 0.98f, -0.7f), v3(0.3f, 0.98f, -0.1f), v3(-0.3f, 0.98f, -0.1f),
            ts_lambert(s, v3s(0.0f), v3s(6.0f), 0));
    ts_box(s, v3(-0.6f, -1.0f, -0.5f), v3(0.6f, 0.6f, -0.35f), 0,
           ts_material(s, glass_material(0.3f, 1.5f, 0.15f, v3(0.9f, 0.8f, 0.7f), 1.0f)));
    ts_finalize(s);
    camera cam = camera_look_at(v3(0.0f, 0.0f, 0.95f), v3(0, -0.1f, -1), v3(0, 1, 0), 1.2f);
    double ratios[2];
    ts_vsl_mean_ratios(s, &cam, W, H, 8, ratios);
    /* the virtual lights' radius costs a few percent near corners (test_vsl's boxes: 6%) */
    for (int k = 0; k < 2; k++)
        CHECK(fabs(ratios[k] - 1.0) < 0.04, "glass box, %s: mean off by %+.4f", k ? "vsl+hl" : "vsl", ratios[k] - 1.0);
    scene_destroy(s);
}

int main(void) {
    test_slab_beer_lambert();
    test_glass_box_against_pt();
    return check_exit("test_glass");
}
