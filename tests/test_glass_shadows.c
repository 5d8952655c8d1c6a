/* Shadow rays through smooth thin-walled glass, and next-event estimation through rough glass
 * (docs/design.md, "Transmission and volume"): a diffuse floor under a glass pane, lit through it.
 * The transmittance a shadow ray takes against the pane's (1 - F) x transmission x tint written
 * here from the glTF spec's Schlick Fresnel; the floor under a point light (light only next-event
 * estimation finds) against the closed form through a smooth pane and against a quadrature of the
 * BTDF through rough ones; a constant sky through a rough pane (light samples through the lobe and
 * the lobe's samples weighted against each other) against the quadrature of its transmittance; a
 * refracting slab still dark under a point light; an absorbing ior-1 slab's Beer-Lambert; under an
 * area light, the path tracer's mean against quadrature with a smooth and a slightly rough pane,
 * and the noise the smooth pane's shadow rays take away; vsl and vsl+hl against the path tracer in
 * a box divided by a pane; the path tracer's highlights layer and the highlight estimator's behind
 * a pane. */
#include <math.h>

#include "check.h"
#include "test_scenes.h"

static const vec3 TINT = {0.9f, 0.75f, 0.6f};
#define TRANSMISSION 0.8f
#define IOR 1.5f
#define ALBEDO 0.5f
#define PI_D 3.14159265358979323846

/* A glTF glass: transmission with a tint, a volume when thickness > 0. */
static material glass(float rough, float ior, float thickness, vec3 att_color, float att_dist) {
    material m = material_default();
    m.base_color = TINT;
    m.metallic = 0.0f;
    m.roughness = rough;
    m.ext.ior = ior;
    m.ext.transmission = TRANSMISSION;
    m.ext.thickness = thickness;
    m.ext.attenuation_color = att_color;
    m.ext.attenuation_distance = att_dist;
    return m;
}

/* What the spec's thin-walled transmission passes at cosine c to the normal: (1 - F(c)) t tint,
 * Schlick's F with F0 ((ior - 1) / (ior + 1))^2 and F90 1. */
static double pane_t(double c, double ior, int channel) {
    double f0 = pow((ior - 1.0) / (ior + 1.0), 2.0);
    double f = f0 + (1.0 - f0) * pow(1.0 - c, 5.0);
    const float tint[3] = {TINT.x, TINT.y, TINT.z};
    return (1.0 - f) * TRANSMISSION * tint[channel];
}

/* The floor y = 0 (Lambert ALBEDO), 40 m wide. */
static scene *floor_scene(const char *name) {
    scene *s = ts_new(name);
    ts_quad(s, v3(-20, 0, 20), v3(20, 0, 20), v3(20, 0, -20), v3(-20, 0, -20), ts_lambert(s, v3s(ALBEDO), v3s(0), 0));
    return s;
}
/* A horizontal pane as wide at height y, of material mat. */
static void pane(scene *s, float y, int mat) {
    ts_quad(s, v3(-20, y, 20), v3(20, y, 20), v3(20, y, -20), v3(-20, y, -20), mat);
}

enum { W = 8, H = 8, NPIX = W * H };

/* The camera between floor and pane, looking straight down at the origin through a narrow view. */
static camera floor_camera(void) { return camera_look_at(v3(0, 0.5f, 0), v3(0, 0, 0), v3(0, 0, 1), 0.02f); }

static void image_stats(const float *img, int c, double *mean, double *sd) {
    double s = 0, s2 = 0;
    for (int i = 0; i < NPIX; i++) s += img[3 * i + c], s2 += (double)img[3 * i + c] * img[3 * i + c];
    *mean = s / NPIX;
    *sd = sqrt(fmax(s2 / NPIX - *mean * *mean, 0.0));
}

/* Only the direct light (max depth 1): the floor lit through the pane, nothing else. */
static float *render_direct(const scene *s, int method, int spp, uint64_t seed) {
    camera cam = floor_camera();
    render_params p = {.width = W, .height = H, .method = (render_method)method, .max_depth = 1, .seed = seed};
    p.vl.count = 64;
    return ts_render_with(s, &cam, &p, spp, ~0u);
}

/* A shadow ray's transmittance through one and two panes at several angles, against pane_t. */
static void test_transmittance(void) {
    scene *s = floor_scene("panes");
    int mat = ts_material(s, glass(0.0f, IOR, 0.0f, v3s(1), INFINITY));
    pane(s, 1.0f, mat);
    pane(s, 1.5f, mat);
    ts_finalize(s);
    const float angles[4] = {0.0f, 30.0f, 60.0f, 80.0f};
    for (int a = 0; a < 4; a++) {
        float th = angles[a] * PI_F / 180.0f;
        vec3 d = v3(sinf(th), cosf(th), 0.0f), o = v3(0, 0.01f, 0);
        vec3 one = scene_transmittance(s, o, d, 1.2f / d.y, v3s(0.0f));
        vec3 two = scene_transmittance(s, o, d, 3.0f / d.y, v3s(0.0f));
        const float g1[3] = {one.x, one.y, one.z}, g2[3] = {two.x, two.y, two.z};
        for (int c = 0; c < 3; c++) {
            double want = pane_t(cos(th), IOR, c);
            CHECK_NEAR(g1[c], want, 1e-3 * want, "one pane at %.0f degrees, channel %d", (double)angles[a], c);
            CHECK_NEAR(g2[c], want * want, 1e-3 * want * want, "two panes at %.0f degrees, channel %d",
                       (double)angles[a], c);
        }
        CHECK(scene_occluded(s, o, d, 1.2f / d.y), "the plain occlusion query still stops at glass");
    }
    scene_destroy(s);
}

/* A point light 3 m above the floor (straight above, and 60 degrees off): the floor's radiance
 * ALBEDO / pi I cos / r^2 T(cos), which only a shadow ray through the pane can find. */
static void test_point_light(void) {
    const float offsets[2] = {0.0f, 3.0f * sqrtf(3.0f)};
    for (int k = 0; k < 2; k++) {
        scene *s = floor_scene("point light");
        pane(s, 1.0f, ts_material(s, glass(0.0f, IOR, 0.0f, v3s(1), INFINITY)));
        light pl = {.type = LIGHT_POINT, .color = v3s(20.0f), .position = v3(offsets[k], 3.0f, 0.0f)};
        scene_add_light(s, &pl);
        ts_finalize(s);
        double r2 = 9.0 + (double)offsets[k] * offsets[k], c = 3.0 / sqrt(r2);
        for (int method = METHOD_PT; method <= METHOD_VSL; method += METHOD_VSL - METHOD_PT) {
            float *img = render_direct(s, method, 4, 5);
            for (int ch = 0; ch < 3; ch++) {
                double mean, sd, want = ALBEDO / PI_D * 20.0 * c / r2 * pane_t(c, IOR, ch);
                image_stats(img, ch, &mean, &sd);
                CHECK_NEAR(mean, want, 3e-3 * want, "point light %.0f degrees off, %s, channel %d",
                           acos(c) * 180.0 / PI_D, method_name((render_method)method), ch);
            }
            free(img);
        }
        scene_destroy(s);
    }
}

/* What still stops shadow rays: a smooth refracting slab (the point light is dark below it: next-
 * event estimation cannot look through a delta lobe, and no sampled path can find the light); and
 * an ior-1 slab that absorbs, passed with its faces' (1 - F) t tint each and exp(-sigma d) between. */
static void test_slabs(void) {
    const char *names[2] = {"refracting slab", "ior-1 absorbing slab"};
    const vec3 att = v3(0.5f, 0.7f, 0.9f);
    for (int k = 0; k < 2; k++) {
        scene *s = floor_scene(names[k]);
        ts_box(s, v3(-20, 1.0f, -20), v3(20, 1.5f, 20), 0,
               ts_material(s, glass(0.0f, k == 0 ? IOR : 1.0f, 0.5f, att, 1.0f)));
        light pl = {.type = LIGHT_POINT, .color = v3s(20.0f), .position = v3(0, 3.0f, 0)};
        scene_add_light(s, &pl);
        ts_finalize(s);
        float *img = render_direct(s, METHOD_PT, 4, 6);
        const float a[3] = {att.x, att.y, att.z};
        for (int ch = 0; ch < 3; ch++) {
            double mean, sd, t = pane_t(1.0, 1.0, ch);
            double want = k == 0 ? 0.0 : ALBEDO / PI_D * 20.0 / 9.0 * t * t * pow(a[ch], 0.5);
            image_stats(img, ch, &mean, &sd);
            CHECK_NEAR(mean, want, 3e-3 * want, "%s, channel %d", names[k], ch);
        }
        free(img);
        scene_destroy(s);
    }
}

/* The BSDF of glass(rough, IOR, thin) as a hit from either side sees it. */
static bsdf pane_bsdf(float rough) {
    material m = glass(rough, IOR, 0.0f, v3s(1), INFINITY);
    surface_hit h = {0};
    gltf_layers x = material_layers(NULL, &m, &h);
    return make_bsdf_gltf_layered(m.base_color, 0.0f, rough, 0.0f, &x);
}

/* The floor's radiance at the origin under a point light of intensity 20 at (0, 3, 0), seen
 * through a rough thin pane at y = 1 (light only next-event estimation through the pane's lobe
 * finds), by quadrature of the pane's BTDF: a pane point g at distance rho from the axis, theta
 * its angle seen from the origin (rho = tan theta), radiance f(wo, wi) |cos_i| I / r^2 toward the
 * origin, integrated over the pane (the setting is symmetric about the axis). */
static double rough_pane_point_light(float rough, int channel) {
    bsdf b = pane_bsdf(rough);
    const int n = 40000;
    double sum = 0.0, step = 0.5 * PI_D / n;
    for (int i = 0; i < n; i++) {
        double th = (i + 0.5) * step, rho = tan(th), d = sqrt(1.0 + rho * rho), rl = sqrt(rho * rho + 4.0);
        /* local frame at g: n = -y (toward the floor), t = x */
        vec3 wo = v3((float)(-rho / d), 0.0f, (float)(1.0 / d)), wi = v3((float)(-rho / rl), 0.0f, (float)(-2.0 / rl));
        vec3 f = bsdf_eval(&b, wo, wi, BSDF_TRANSMIT);
        double fc = channel == 0 ? f.x : channel == 1 ? f.y : f.z;
        sum += fc * 2.0 / (rl * rl * rl) * 20.0 * sin(th) * cos(th) * step;
    }
    return ALBEDO / PI_D * 2.0 * PI_D * sum;
}

/* Rough panes under a point light: next-event estimation at the pane looks through its
 * transmission (before, the floor under them was black, the light found by no strategy), for pt
 * and for vsl, whose direct light is the same estimator; against the quadrature. */
static void test_rough_pane_point_light(void) {
    const float rough[2] = {0.3f, 0.6f};
    for (int k = 0; k < 2; k++) {
        scene *s = floor_scene("rough pane");
        pane(s, 1.0f, ts_material(s, glass(rough[k], IOR, 0.0f, v3s(1), INFINITY)));
        light pl = {.type = LIGHT_POINT, .color = v3s(20.0f), .position = v3(0, 3.0f, 0)};
        scene_add_light(s, &pl);
        ts_finalize(s);
        for (int method = METHOD_PT; method <= METHOD_VSL; method += METHOD_VSL - METHOD_PT) {
            float *img = render_direct(s, method, 256, 9);
            for (int ch = 0; ch < 3; ch++) {
                double mean, sd, want = rough_pane_point_light(rough[k], ch);
                image_stats(img, ch, &mean, &sd);
                double se = sd / sqrt((double)NPIX);
                if (ch == 0)
                    printf("point light through a pane of roughness %.1f, %s: mean %.5f (quadrature %.5f), pixel "
                           "sd %.5f\n",
                           (double)rough[k], method_name((render_method)method), mean, want, sd);
                CHECK_NEAR(mean, want, 4.0 * se + 2e-3 * want, "rough pane %.1f, %s, channel %d", (double)rough[k],
                           method_name((render_method)method), ch);
            }
            free(img);
        }
        scene_destroy(s);
    }
}

/* The transmission's directional albedo for wo at cosine c: the integral of f |cos_i| over the
 * lower hemisphere, midpoints in (cos, phi). */
static double pane_transmittance(const bsdf *b, double c, int channel) {
    const int nc = 256, np = 256;
    double sum = 0.0;
    vec3 wo = v3((float)sqrt(1.0 - c * c), 0.0f, (float)c);
    for (int i = 0; i < nc; i++) {
        double ci = (i + 0.5) / nc, si = sqrt(1.0 - ci * ci);
        for (int j = 0; j < np; j++) {
            double phi = 2.0 * PI_D * (j + 0.5) / np;
            vec3 f = bsdf_eval(b, wo, v3((float)(si * cos(phi)), (float)(si * sin(phi)), (float)-ci), BSDF_TRANSMIT);
            sum += (channel == 0 ? f.x : channel == 1 ? f.y : f.z) * ci;
        }
    }
    return sum * 2.0 * PI_D / ((double)nc * np);
}

/* A constant sky of radiance 1 over a rough pane (1 km wide) above the floor: the floor's radiance
 * is ALBEDO / pi times the integral of the pane's transmittance times cos over the hemisphere, 2
 * ALBEDO times the integral of T(c) c dc. The light through the pane is found both ways, next-event
 * estimation at the pane and its sampled transmissions reaching the sky, weighted against each
 * other: counted twice or not at all if the weights disagree. */
static void test_rough_pane_sky(void) {
    const float rough = 0.5f;
    scene *s = floor_scene("rough pane under the sky");
    const float r = 1000.0f;
    ts_quad(s, v3(-r, 1, r), v3(r, 1, r), v3(r, 1, -r), v3(-r, 1, -r),
            ts_material(s, glass(rough, IOR, 0.0f, v3s(1), INFINITY)));
    ts_finalize(s);
    ts_constant_env(s, 1.0f);
    float *img = render_direct(s, METHOD_PT, 256, 10);
    bsdf b = pane_bsdf(rough);
    for (int ch = 0; ch < 3; ch++) {
        const int nc = 64;
        double want = 0.0;
        for (int i = 0; i < nc; i++) {
            double c = (i + 0.5) / nc;
            want += 2.0 * ALBEDO * pane_transmittance(&b, c, ch) * c / nc;
        }
        double mean, sd;
        image_stats(img, ch, &mean, &sd);
        double se = sd / sqrt((double)NPIX);
        printf("sky through a pane of roughness %.1f, channel %d: mean %.5f (quadrature %.5f), pixel sd %.5f\n",
               (double)rough, ch, mean, want, sd);
        CHECK_NEAR(mean, want, 4.0 * se + 3e-3 * want, "sky through a rough pane, channel %d", ch);
    }
    free(img);
    scene_destroy(s);
}

/* A pane whose factors say rough metal (glTF's defaults, 1 and 1) but whose metallic-roughness
 * texture says smooth glass (G and B 0; as TransmissionRoughnessTest's): it passes shadow rays
 * where the texture says so; where it says rough (G 1) they stop, and next-event estimation looks
 * through the texel's lobe (the quadrature of roughness 1). */
static void test_textured_pane(void) {
    for (int rough = 0; rough <= 1; rough++) {
        scene *s = floor_scene("textured pane");
        const unsigned char texel[4] = {0, rough ? 255 : 0, 0, 255};
        material m = glass(1.0f, IOR, 0.0f, v3s(1), INFINITY);
        m.metallic = 1.0f;
        m.metal_rough_tex = (texture_slot){.texture = ts_texture(s, 1, 1, texel)};
        pane(s, 1.0f, ts_material(s, m));
        light pl = {.type = LIGHT_POINT, .color = v3s(20.0f), .position = v3(0, 3.0f, 0)};
        scene_add_light(s, &pl);
        ts_finalize(s);
        float *img = render_direct(s, METHOD_PT, rough ? 256 : 4, 8);
        for (int ch = 0; ch < 3; ch++) {
            double mean, sd;
            double want = rough ? rough_pane_point_light(1.0f, ch) : ALBEDO / PI_D * 20.0 / 9.0 * pane_t(1.0, IOR, ch);
            image_stats(img, ch, &mean, &sd);
            double tol = rough ? 4.0 * sd / sqrt((double)NPIX) + 2e-3 * want : 3e-3 * want;
            CHECK_NEAR(mean, want, tol, "pane textured %s, channel %d", rough ? "rough" : "smooth", ch);
        }
        free(img);
        scene_destroy(s);
    }
}

/* A 1 m square emitter of radiance LE facing down at 1.6 m over the pane at 1 m: the floor's
 * irradiance at the origin by quadrature, E = LE t tint integral of (1 - F(cos)) cos^2 / r^2 dA. */
#define LE 4.0
static double area_light_irradiance(int channel) {
    const int n = 600;
    double sum = 0, h = 1.6, step = 1.0 / n;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            double x = -0.5 + (i + 0.5) * step, z = -0.5 + (j + 0.5) * step, r2 = x * x + z * z + h * h;
            double c = h / sqrt(r2);
            sum += pane_t(c, IOR, channel) * c * c / r2 * step * step;
        }
    return LE * sum;
}

static scene *area_light_scene(float pane_roughness) {
    scene *s = floor_scene("area light");
    pane(s, 1.0f, ts_material(s, glass(pane_roughness, IOR, 0.0f, v3s(1), INFINITY)));
    ts_quad(s, v3(-0.5f, 1.6f, -0.5f), v3(0.5f, 1.6f, -0.5f), v3(0.5f, 1.6f, 0.5f), v3(-0.5f, 1.6f, 0.5f),
            ts_lambert(s, v3s(0), v3s((float)LE), 0));
    ts_finalize(s);
    return s;
}

/* The smooth pane: shadow rays pass it, and the BSDF's paths through it to the emitter are weighted
 * against them; the slightly rough pane (roughness 0.1) stops them, its light found by the BSDF's
 * paths and by light samples through its narrow lobe (few land in it). Both means against the quadrature, within four standard
 * errors (the pixels see nearly the same point, so their spread is one pixel's noise); the smooth
 * pane's noise a small part of the rough one's. */
static void test_area_light(void) {
    double sd_of[2] = {0, 0};
    const float rough[2] = {0.0f, 0.1f};
    for (int k = 0; k < 2; k++) {
        scene *s = area_light_scene(rough[k]);
        float *img = render_direct(s, METHOD_PT, 64, 7);
        for (int ch = 0; ch < 3; ch++) {
            double mean, sd, want = ALBEDO / PI_D * area_light_irradiance(ch);
            image_stats(img, ch, &mean, &sd);
            double se = sd / sqrt((double)NPIX);
            printf("area light, pane roughness %.1f, channel %d: mean %.5f (quadrature %.5f), pixel sd %.5f\n",
                   (double)rough[k], ch, mean, want, sd);
            CHECK_NEAR(mean, want, 4.0 * se + 2e-3 * want, "area light, pane roughness %.1f, channel %d",
                       (double)rough[k], ch);
            sd_of[k] += sd / want;
        }
        free(img);
        scene_destroy(s);
    }
    printf("area light: relative pixel noise %.4f with shadow rays through the pane, %.4f without\n", sd_of[0] / 3,
           sd_of[1] / 3);
    CHECK(sd_of[0] < 0.25 * sd_of[1], "shadow rays through the pane: noise %.4f, not well below %.4f", sd_of[0] / 3,
          sd_of[1] / 3);
}

/* A closed 2 m box of grey walls divided by a smooth pane at y = 0.2, a panel light under the
 * ceiling: everything the camera below the pane sees is lit through it, directly and after
 * bounces on either side. vsl and vsl+hl against the path tracer's mean. */
static void test_box_against_pt(void) {
    enum { BW = 24, BH = 18 };
    scene *s = ts_new("divided box");
    ts_box(s, v3(-1, -1, -1), v3(1, 1, 1), 1, ts_lambert(s, v3s(0.6f), v3s(0.0f), 0));
    ts_quad(s, v3(-0.3f, 0.98f, -0.3f), v3(0.3f, 0.98f, -0.3f), v3(0.3f, 0.98f, 0.3f), v3(-0.3f, 0.98f, 0.3f),
            ts_lambert(s, v3s(0.0f), v3s(6.0f), 0));
    pane(s, 0.2f, ts_material(s, glass(0.0f, IOR, 0.0f, v3s(1), INFINITY)));
    ts_finalize(s);
    camera cam = camera_look_at(v3(0.0f, -0.2f, 0.95f), v3(0, -0.6f, -1), v3(0, 1, 0), 1.2f);
    double ratios[2];
    ts_vsl_mean_ratios(s, &cam, BW, BH, 6, ratios);
    /* as test_glass: the virtual lights' radius costs a few percent near corners */
    for (int k = 0; k < 2; k++)
        CHECK(fabs(ratios[k] - 1.0) < 0.04, "divided box, %s: mean off by %+.4f", k ? "vsl+hl" : "vsl",
              ratios[k] - 1.0);
    scene_destroy(s);
}

/* A box of glossy walls (Phong 40) whose lid is a glass pane of roughness lid_rough, a panel light
 * and a point light just above it: no glossy surface beyond the pane (a camera - glossy - pane -
 * glossy path is not the highlights'). */
static scene *glossy_box_under_lid(float lid_rough) {
    material glossy = material_default();
    glossy.model = MATERIAL_PHONG;
    glossy.kd = v3s(0.0f);
    glossy.ks = v3s(0.9f);
    glossy.exponent = 40.0f;
    scene *s = ts_new("glossy box under a lid");
    int wall = ts_material(s, glossy);
    const float lo = -1.0f, hi = 0.9f;
    ts_quad(s, v3(-1, lo, -1), v3(1, lo, -1), v3(1, lo, 1), v3(-1, lo, 1), wall);
    ts_quad(s, v3(-1, lo, -1), v3(-1, hi, -1), v3(1, hi, -1), v3(1, lo, -1), wall);
    ts_quad(s, v3(-1, lo, 1), v3(1, lo, 1), v3(1, hi, 1), v3(-1, hi, 1), wall);
    ts_quad(s, v3(-1, lo, -1), v3(-1, lo, 1), v3(-1, hi, 1), v3(-1, hi, -1), wall);
    ts_quad(s, v3(1, lo, -1), v3(1, hi, -1), v3(1, hi, 1), v3(1, lo, 1), wall);
    pane(s, hi, ts_material(s, glass(lid_rough, IOR, 0.0f, v3s(1), INFINITY)));
    ts_quad(s, v3(-0.3f, 0.95f, -0.3f), v3(0.3f, 0.95f, -0.3f), v3(0.3f, 0.95f, 0.3f), v3(-0.3f, 0.95f, 0.3f),
            ts_lambert(s, v3s(0.0f), v3s(3.0f), 0));
    light pl = {.type = LIGHT_POINT, .color = v3s(0.5f), .position = v3(-0.4f, 0.93f, 0.2f)};
    scene_add_light(s, &pl);
    ts_finalize(s);
    return s;
}

/* Under a rough lid, which stops shadow rays: vsl+hl tracing the camera's sharp lobes, whose next
 * hit's highlight lobe is the highlight estimator's only where that estimator sees the light (it
 * lost the light through the lid: 0.16 of the path tracer's mean), against the path tracer. Both
 * are heavy-tailed here (the point light just above the rough lid): one 512-frame path-traced
 * image's mean moves by 7% between seeds, so each side is the mean of 4 seeds and the tolerance
 * carries their standard error. */
static double image_total(const scene *s, const camera *cam, render_params p, int frames) {
    float *img = ts_render_with(s, cam, &p, frames, ~0u);
    double t = 0.0;
    for (int i = 0; i < 3 * p.width * p.height; i++) t += img[i];
    free(img);
    return t;
}

static void test_rough_lid(void) {
    enum { HW = 16, HH = 12, SEEDS = 4 };
    scene *s = glossy_box_under_lid(0.3f);
    camera cam = camera_look_at(v3(0.3f, 0.2f, 0.9f), v3(-1, -0.8f, -1), v3(0, 1, 0), 1.2f);
    render_params p = {.width = HW, .height = HH, .max_depth = 2};
    render_params q = {.width = HW, .height = HH, .method = METHOD_VSL_HL, .max_depth = 2};
    q.vl.count = 1024;
    q.vl.per_pixel = 32;
    q.vl.radius_mult = 1.0f;
    double a[SEEDS], b[SEEDS], ma = 0.0, mb = 0.0, va = 0.0, vb = 0.0;
    for (int k = 0; k < SEEDS; k++) {
        p.seed = 24 + 2 * (uint64_t)k;
        q.seed = 25 + 2 * (uint64_t)k;
        b[k] = image_total(s, &cam, p, 512);
        a[k] = image_total(s, &cam, q, 128);
        ma += a[k] / SEEDS, mb += b[k] / SEEDS;
    }
    for (int k = 0; k < SEEDS; k++)
        va += (a[k] - ma) * (a[k] - ma) / (SEEDS - 1), vb += (b[k] - mb) * (b[k] - mb) / (SEEDS - 1);
    double ratio = ma / mb, se = ratio * sqrt(va / SEEDS / (ma * ma) + vb / SEEDS / (mb * mb));
    printf("glossy box under a rough lid, vsl+hl: mean ratio to PT %.4f +- %.4f\n", ratio, se);
    CHECK(mb > 0.0 && fabs(ratio - 1.0) < 0.03 + 3.0 * se,
          "glossy box under a rough lid, vsl+hl: %.4f +- %.4f of pt's mean", ratio, se);
    scene_destroy(s);
}

/* The path tracer's highlights layer (camera - glossy - glossy - light) with the panel light and a
 * point light behind a smooth pane: next-event estimation at the second glossy vertex sees the
 * lights through the pane, so the paths its BSDF samples carry through the pane to the panel are
 * highlights too. In a box of glossy walls at depth 2 all the indirect light is highlights, as
 * test_pt's box without the pane; the split moves light between the layers, never changes the sum. */
static void test_highlight_split(void) {
    enum { HW = 16, HH = 12, HN = HW * HH };
    scene *s = glossy_box_under_lid(0.0f);
    camera cam = camera_look_at(v3(0.3f, 0.2f, 0.9f), v3(-1, -0.8f, -1), v3(0, 1, 0), 1.2f);
    render_params p = {.width = HW, .height = HH, .max_depth = 2, .seed = 21};
    float *ind = ts_render_with(s, &cam, &p, 64, 1u << COMP_INDIRECT);
    p.pt_highlights = 1;
    float *ind_split = ts_render_with(s, &cam, &p, 64, 1u << COMP_INDIRECT);
    float *hl = ts_render_with(s, &cam, &p, 64, 1u << COMP_HIGHLIGHTS);
    int bad_sum = 0;
    double hl_total = 0.0, ind_total = 0.0, rest_total = 0.0;
    for (int i = 0; i < 3 * HN; i++) {
        bad_sum += !(fabsf(ind[i] - (ind_split[i] + hl[i])) <= 1e-4f * ind[i] + 1e-7f);
        hl_total += hl[i], ind_total += ind[i], rest_total += ind_split[i];
    }
    printf("highlights layer behind a pane: highlights %.4f of indirect %.4f\n", hl_total / ind_total, ind_total);
    CHECK(bad_sum == 0, "pane: indirect != split indirect + highlights at %d channels", bad_sum);
    CHECK(ind_total > 0.0 && rest_total <= 1e-6 * ind_total, "pane, depth 2: %.3g of the indirect is not highlights",
          rest_total / ind_total);
    /* The highlight estimator, tracing each secondary hit's lobe (shadow rays and lobe samples
     * through the pane), against the path tracer's layer. */
    p.seed = 22;
    float *ref = ts_render_with(s, &cam, &p, 512, 1u << COMP_HIGHLIGHTS);
    render_params q = {.width = HW, .height = HH, .method = METHOD_VSL_HL, .max_depth = 2, .seed = 23};
    q.vl.count = 64;
    q.vl.merge = HL_MERGE_TRACE;
    q.vl.secondary_rays = 16;
    float *est = ts_render_with(s, &cam, &q, 64, 1u << COMP_HIGHLIGHTS);
    for (int c = 0; c < 3; c++) {
        double a = 0, b = 0;
        for (int i = 0; i < HN; i++) a += est[3 * i + c], b += ref[3 * i + c];
        printf("highlights behind a pane, channel %d: vsl+hl %.4f, pt %.4f\n", c, a / HN, b / HN);
        CHECK(b > 0.0 && fabs(a / b - 1.0) < 0.03, "highlights behind a pane, channel %d: %.5f against pt's %.5f", c,
              a / HN, b / HN);
    }
    /* The whole of vsl+hl with the camera's lobes gathered, not traced: the virtual lights beyond
     * the pane are the light's first bounce, whose highlights the highlight estimator has (they
     * were counted twice: 1.80 times the path tracer's mean), against the path tracer's image. */
    float *all = ts_render_with(s, &cam, &p, 512, ~0u);
    q.vl.trace_glossy = 0.01f;
    q.vl.count = 1024;
    q.vl.per_pixel = 32;
    q.vl.radius_mult = 1.0f;
    float *gathered = ts_render_with(s, &cam, &q, 128, ~0u);
    double a = 0, b = 0;
    for (int i = 0; i < 3 * HN; i++) a += gathered[i], b += all[i];
    printf("glossy box behind a pane, vsl+hl gathering at the camera: mean ratio to PT %.4f\n", a / b);
    CHECK(b > 0.0 && fabs(a / b - 1.0) < 0.06, "glossy box behind a pane, vsl+hl gathering: %.4f of pt's mean", a / b);
    free(all);
    free(gathered);
    free(ref);
    free(est);
    free(ind);
    free(ind_split);
    free(hl);
    scene_destroy(s);
}

int main(void) {
    test_transmittance();
    test_point_light();
    test_slabs();
    test_rough_pane_point_light();
    test_rough_pane_sky();
    test_textured_pane();
    test_area_light();
    test_box_against_pt();
    test_highlight_split();
    test_rough_lid();
    return check_exit("test_glass_shadows");
}
