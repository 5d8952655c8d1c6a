/* glTF alpha. MASK: a ray meets a masked square exactly where its texture's alpha reaches the
 * cutoff, for single rays, packets and shadow rays alike (brute force over a grid), the shadow on
 * the floor below follows the cut-outs, light paths deposit no virtual light in them, and a
 * half-cut emitter gives the light of its uncut half. BLEND: a ray passes with probability
 * 1 - alpha (statistical), independently at each of two layers, the same ray always the same way,
 * and renders agree whatever the thread count. Materials that never cut anything stay on
 * Embree's filterless path. From a file: alphaMode, alphaCutoff, baseColorFactor's alpha. */
#define _POSIX_C_SOURCE 200809L
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "gltf_textured.h"
#include "rng.h"
#include "sampling.h"
#include "scene_parts.h"
#include "test_scenes.h"
#include "vlights.h"

static const unsigned ALL = COMP_MASK_ALL;

/* An 8 x 8 texture of random alphas (white): texel (i, j) at row j from the top. */
static unsigned char alphas[8 * 8 * 4];
static int alpha_texture(scene *s) {
    rng_state rng = rng_for(21, 0, 0);
    for (int i = 0; i < 64; i++) {
        alphas[4 * i] = alphas[4 * i + 1] = alphas[4 * i + 2] = 255;
        alphas[4 * i + 3] = (unsigned char)(rng_float(&rng) * 256.0f);
    }
    return ts_texture(s, 8, 8, alphas);
}

/* A grey Lambert floor at y = 0 under the squares and around them; returns its material. */
static int add_floor(scene *s) {
    int floor_m = ts_lambert(s, v3s(0.8f), v3s(0), 0);
    ts_quad(s, v3(-1, 0, -1), v3(-1, 0, 2), v3(2, 0, 2), v3(2, 0, -1), floor_m);
    return floor_m;
}

/* The square [0,1]^2 at height y facing up, uvs: u = x, v = z. */
static void square_at(scene *s, float y, int mat) {
    const vec3 p[4] = {v3(0, y, 0), v3(0, y, 1), v3(1, y, 1), v3(1, y, 0)};
    const float uv[8] = {0, 0, 0, 1, 1, 1, 1, 0};
    ts_quad_uv(s, p, uv, mat);
}

static material masked(int tex, float cutoff) {
    material m = ts_phong(v3s(0.5f), v3s(0), 1.0f);
    m.base_color_tex = (texture_slot){.texture = tex};
    m.alpha = ALPHA_MASK;
    m.alpha_cutoff = cutoff;
    m.double_sided = 1;
    return m;
}

/* Straight down through the masked square on a 64 x 64 grid (and at every texel's centre): a hit,
 * a packet hit and an occluded shadow ray exactly where alpha >= cutoff. */
static void test_mask_grid(void) {
    scene *s = ts_new("mask");
    material m = masked(alpha_texture(s), 0.5f);
    m.base_alpha = 0.9f;
    square_at(s, 1.0f, ts_material(s, m));
    ts_finalize(s);
    CHECK(s->bvh_count[1] == 2, "the masked square is filtered: %d triangles in the filtered geometry",
          s->bvh_count[1]);
    int bad = 0, hits = 0, n = 0;
    for (int k = 0; k < 64 * 64 + 64; k++) {
        float x, z;
        int centre = k >= 64 * 64;
        if (centre) {
            x = ((float)((k - 64 * 64) % 8) + 0.5f) / 8.0f, z = ((float)((k - 64 * 64) / 8) + 0.5f) / 8.0f;
        } else {
            x = ((float)(k % 64) + 0.37f) / 64.0f, z = ((float)(k / 64) + 0.61f) / 64.0f;
        }
        float a = 0.9f * texture_lookup(s, m.base_color_tex, v2(x, z), v2(x, z), 0).w;
        if (centre) { /* the texel itself, not the lookup: the oracle is the file's byte */
            int i = (k - 64 * 64) % 8, j = (k - 64 * 64) / 8;
            CHECK(fabsf(a - 0.9f * alphas[4 * (8 * j + i) + 3] / 255.0f) < 1e-6f, "texel (%d, %d) alpha", i, j);
        }
        int expect = a >= 0.5f;
        surface_hit h;
        vec3 o = v3(x, 3.0f, z), d = v3(0, -1, 0);
        int hit = scene_intersect(s, o, d, INFINITY, &h);
        int occluded = scene_occluded(s, o, d, 10.0f);
        surface_hit hp[SCENE_PACKET];
        vec3 dirs[1] = {d};
        int packet = (int)(scene_intersect_packet(s, o, dirs, 1, hp) & 1u);
        if ((hit != expect || occluded != expect || packet != expect) && bad++ < 5)
            fprintf(stderr, "(%g, %g): alpha %g: hit %d, occluded %d, packet %d\n", x, z, a, hit, occluded, packet);
        hits += expect;
        n++;
    }
    CHECK(bad == 0, "%d of %d rays disagree with the texture", bad, n);
    CHECK(hits > n / 5 && hits < 4 * n / 5, "the texture cuts %d of %d: it tests little", n - hits, n);
    scene_destroy(s);
}

/* The floor under a masked square, lit straight from above: dark exactly under what the mask
 * keeps. Pixel by pixel against the mask's own answer, averaged over each pixel's footprint. */
static void test_mask_shadow(void) {
    scene *s = ts_new("mask shadow");
    material m = masked(alpha_texture(s), 0.4f);
    square_at(s, 1.0f, ts_material(s, m));
    add_floor(s);
    light l = {.type = LIGHT_DIRECTIONAL, .color = v3s(2.0f), .direction = v3(0, -1, 0)};
    scene_add_light(s, &l);
    ts_finalize(s);
    /* Looking straight down from between the floor and the square, at the square's shadow. */
    camera cam = camera_look_at(v3(0.5f, 0.5f, 0.5f), v3(0.5f, 0, 0.5f), v3(0, 0, -1), 2.0f * atanf(1.0f));
    const int w = 32, h = 32;
    float *img = ts_render(s, &cam, w, h, 64, 1, 4, ALL);
    double lit = 0.8 * INV_PI_F * 2.0, sum_err = 0.0, sum = 0.0;
    int bad = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double e = 0.0;
            for (int k = 0; k < 64; k++) { /* the pixel's footprint, 8 x 8 points */
                vec3 d =
                    camera_ray_dir(&cam, 1.0f, (x + ((k & 7) + 0.5f) / 8.0f) / w, (y + ((k >> 3) + 0.5f) / 8.0f) / h);
                vec3 p = madd3(cam.position, d, -cam.position.y / d.y);
                float a = texture_lookup(s, m.base_color_tex, v2(p.x, p.z), v2(p.x, p.z), 0).w;
                e += (p.x < 0 || p.x > 1 || p.z < 0 || p.z > 1 || a < 0.4f) ? lit / 64.0 : 0.0;
            }
            double got = img[3 * (y * w + x)];
            sum_err += fabs(got - e);
            sum += e;
            if (fabs(got - e) > 0.2 * lit) bad++;
        }
    CHECK(bad <= w * h / 50, "%d of %d floor pixels off the mask's shadow", bad, w * h);
    CHECK(sum_err < 0.03 * sum, "floor: mean abs error %g of mean %g", sum_err / (w * h), sum / (w * h));
    free(img);
    scene_destroy(s);
}

/* Light paths pass the cut-outs: no virtual light lands where the mask cuts. */
static void test_mask_vlights(void) {
    scene *s = ts_new("mask vlights");
    material m = masked(alpha_texture(s), 0.5f);
    square_at(s, 1.0f, ts_material(s, m));
    add_floor(s);
    light l = {.type = LIGHT_POINT, .color = v3s(10.0f), .position = v3(0.5f, 2.0f, 0.5f)};
    scene_add_light(s, &l);
    ts_finalize(s);
    vlight_set set = {0};
    uint64_t rays = 0;
    CHECK(vlights_trace(s, 4000, 4, 1, 0, &set, &rays) == 0, "vlights_trace");
    int on_square = 0, on_floor = 0, in_cut = 0;
    for (int i = 0; i < set.count; i++) {
        vec3 p = set.v[i].p;
        if (fabsf(p.y - 1.0f) < 1e-4f) {
            on_square++;
            in_cut += texture_lookup(s, m.base_color_tex, v2(p.x, p.z), v2(p.x, p.z), 0).w < 0.5f;
        } else if (fabsf(p.y) < 1e-4f) {
            on_floor++;
        }
    }
    CHECK(on_square > 100 && on_floor > 100, "virtual lights: %d on the square, %d on the floor", on_square, on_floor);
    CHECK(in_cut == 0, "%d of %d virtual lights landed in the cut-outs", in_cut, on_square);
    vlight_set_free(&set);
    scene_destroy(s);
}

/* An emissive square, its left half cut out by the mask, above a floor: the floor receives what
 * the right half alone would give (next-event estimation and emission found by the BSDF both
 * honour the mask), by path tracing and by virtual lights. */
static void test_mask_emitter(void) {
    unsigned char half[2 * 1 * 4] = {255, 255, 255, 0, 255, 255, 255, 255};
    float means[2][2];
    for (int cut = 0; cut < 2; cut++) {
        scene *s = ts_new("mask emitter");
        material m = ts_phong(v3s(0), v3s(0), 1.0f);
        m.emission = v3s(5.0f);
        if (cut) {
            /* Clamped 2 x 1 texture: alpha 0 for u < 0.5 - a texel's blur, 1 beyond. */
            int img = scene_add_image(s, 2, 1, 4, 8, half);
            m.base_color_tex =
                (texture_slot){.texture = scene_add_texture(s, (scene_texture){img, WRAP_CLAMP, WRAP_CLAMP})};
            m.alpha = ALPHA_MASK;
            m.alpha_cutoff = 0.5f;
            const vec3 p[4] = {v3(0, 1, 0), v3(1, 1, 0), v3(1, 1, 1), v3(0, 1, 1)};
            const float uv[8] = {0, 0, 1, 0, 1, 1, 0, 1};
            ts_quad_uv(s, p, uv, ts_material(s, m));
        } else {
            const vec3 p[4] = {v3(0.5f, 1, 0), v3(1, 1, 0), v3(1, 1, 1), v3(0.5f, 1, 1)};
            const float uv[8] = {0.5f, 0, 1, 0, 1, 1, 0.5f, 1};
            ts_quad_uv(s, p, uv, ts_material(s, m));
        }
        int floor_m = add_floor(s);
        ts_quad(s, v3(-1, 2, -1), v3(2, 2, -1), v3(2, 2, 2), v3(-1, 2, 2), floor_m); /* a ceiling: indirect light */
        ts_finalize(s);
        camera cam = camera_look_at(v3(0.5f, 0.5f, 3.0f), v3(0.5f, 0.2f, 0.5f), v3(0, 1, 0), 1.0f);
        for (int k = 0; k < 2; k++) {
            render_params p = {
                .width = 24, .height = 16, .max_depth = 3, .method = k ? METHOD_VSL : METHOD_PT, .seed = 5};
            float *img = ts_render_with(s, &cam, &p, 256, ALL);
            double mean, sem;
            ts_stats(img, 24 * 16, &mean, &sem);
            means[cut][k] = (float)mean;
            free(img);
        }
        scene_destroy(s);
    }
    /* The texel blur puts the cut at u = 0.5 exactly (bilinear between texel centres 0.25, 0.75). */
    CHECK_NEAR(means[1][0] / means[0][0], 1.0, 0.02, "path tracing: half-cut emitter against the half emitter");
    CHECK_NEAR(means[1][1] / means[0][1], 1.0, 0.03, "vsl: half-cut emitter against the half emitter");
}

static material blend(float a) {
    material m = ts_phong(v3s(0.5f), v3s(0), 1.0f);
    m.alpha = ALPHA_BLEND;
    m.base_alpha = a;
    m.double_sided = 1;
    return m;
}

/* Random rays through one BLEND square (alpha 0.3) and through two (0.3 over 0.6): the share
 * stopped is alpha, and 1 - (1 - 0.3)(1 - 0.6) for the pair, within 5 standard deviations; the
 * same ray always meets the same fate. */
static void test_blend_statistics(void) {
    for (int layers = 1; layers <= 2; layers++) {
        scene *s = ts_new("blend");
        square_at(s, 1.0f, ts_material(s, blend(0.3f)));
        if (layers == 2) square_at(s, 0.5f, ts_material(s, blend(0.6f)));
        ts_finalize(s);
        double expect = layers == 1 ? 0.3 : 1.0 - 0.7 * 0.4;
        rng_state rng = rng_for(13, (uint64_t)layers, 0);
        const int n = 40000;
        int stopped = 0, occluded = 0, fickle = 0;
        for (int i = 0; i < n; i++) {
            vec3 o = v3(0.2f + 0.6f * rng_float(&rng), 2.0f, 0.2f + 0.6f * rng_float(&rng));
            vec3 d = normalize3(v3(0.1f * (rng_float(&rng) - 0.5f), -1.0f, 0.1f * (rng_float(&rng) - 0.5f)));
            surface_hit h, h2;
            int hit = scene_intersect(s, o, d, INFINITY, &h);
            stopped += hit;
            occluded += scene_occluded(s, o, d, 10.0f);
            int again = scene_intersect(s, o, d, INFINITY, &h2);
            fickle += again != hit || (hit && h2.tri != h.tri);
        }
        double sigma = sqrt(expect * (1.0 - expect) / n);
        CHECK_NEAR((double)stopped / n, expect, 5.0 * sigma, "%d layer(s): share of rays stopped", layers);
        CHECK_NEAR((double)occluded / n, expect, 5.0 * sigma, "%d layer(s): share of shadow rays blocked", layers);
        CHECK(fickle == 0, "%d rays changed their mind when traced again", fickle);
        scene_destroy(s);
    }
}

/* A floor in the shadow of a BLEND square (alpha 0.35) receives 1 - alpha of the light on average;
 * the same scene renders identically on one thread and on three. */
static void test_blend_shadow(void) {
    scene *s = ts_new("blend shadow");
    square_at(s, 1.0f, ts_material(s, blend(0.35f)));
    add_floor(s);
    light l = {.type = LIGHT_DIRECTIONAL, .color = v3s(2.0f), .direction = v3(0, -1, 0)};
    scene_add_light(s, &l);
    ts_finalize(s);
    camera cam = camera_look_at(v3(0.5f, 0.5f, 0.5f), v3(0.5f, 0, 0.5f), v3(0, 0, -1), 1.0f);
    const int w = 16, h = 16, spp = 64;
    float *img = ts_render(s, &cam, w, h, spp, 1, 4, ALL);
    double mean, sem;
    ts_stats(img, w * h, &mean, &sem);
    double lit = 0.8 * INV_PI_F * 2.0, expect = 0.65 * lit;
    double sigma = lit * sqrt(0.35 * 0.65 / (w * h * spp));
    CHECK_NEAR(mean, expect, 5.0 * sigma, "floor under a BLEND square: mean %g", mean);
    render_params p1 = {.width = w, .height = h, .max_depth = 3, .method = METHOD_VSL, .seed = 4, .threads = 1};
    render_params p3 = p1;
    p3.threads = 3;
    float *a = ts_render_with(s, &cam, &p1, 4, ALL), *b = ts_render_with(s, &cam, &p3, 4, ALL);
    CHECK(memcmp(a, b, sizeof(float) * 3 * w * h) == 0, "one thread and three render differently");
    free(a);
    free(b);
    free(img);
    scene_destroy(s);
}

/* Materials that cannot cut anything stay off the filters; one that cuts everything is left out. */
static void test_fast_path(void) {
    unsigned char opaque_px[4 * 4] = {10, 20, 30, 255, 10, 20, 30, 255, 10, 20, 30, 255, 10, 20, 30, 255};
    scene *s = ts_new("fast path");
    int tex = ts_texture(s, 2, 2, opaque_px);
    material mask = ts_phong(v3s(0.5f), v3s(0), 1.0f), blend_m = mask, gone = mask;
    mask.alpha = ALPHA_MASK, mask.base_alpha = 0.6f; /* above the default cutoff everywhere */
    blend_m.alpha = ALPHA_BLEND, blend_m.base_color_tex = (texture_slot){.texture = tex};
    gone.alpha = ALPHA_MASK, gone.base_alpha = 0.2f;
    square_at(s, 0.0f, ts_lambert(s, v3s(0.5f), v3s(0), 0));
    square_at(s, 1.0f, ts_material(s, mask));
    square_at(s, 2.0f, ts_material(s, blend_m));
    square_at(s, 3.0f, ts_material(s, gone));
    ts_finalize(s);
    CHECK(s->bvh_count[1] == 0, "%d triangles filtered, expected none", s->bvh_count[1]);
    CHECK(s->bvh_count[0] == 6, "%d triangles on the fast path, expected 6", s->bvh_count[0]);
    surface_hit h;
    CHECK(scene_intersect(s, v3(0.5f, 5, 0.5f), v3(0, -1, 0), INFINITY, &h) && fabsf(h.p.y - 2.0f) < 1e-5f,
          "the first surface from above is the opaque BLEND square, not the cut-away one");
    scene_destroy(s);
    s = ts_new("opaque only");
    square_at(s, 0.0f, ts_lambert(s, v3s(0.5f), v3s(0), 0));
    ts_finalize(s);
    CHECK(s->bvh_tri[0] == NULL && s->bvh_count[1] == 0, "an opaque scene uses the scene's own index buffer");
    scene_destroy(s);
}

/* Moving an area light refits both geometries: the emitter is found where it went, the mask
 * still cuts. */
static void test_move_light(void) {
    scene *s = ts_new("move");
    material m = masked(alpha_texture(s), 0.5f);
    square_at(s, 1.0f, ts_material(s, m));
    square_at(s, 3.0f, ts_lambert(s, v3s(0), v3s(1.0f), 1));
    ts_finalize(s);
    int groups = scene_light_groups(s, NULL, 0);
    char err[256];
    CHECK(groups == 1 && scene_move_light(s, 0, v3(5, 0, 0), err, sizeof err) == 0, "moving the light: %s", err);
    surface_hit h;
    CHECK(scene_intersect(s, v3(5.5f, 5, 0.5f), v3(0, -1, 0), INFINITY, &h) && fabsf(h.p.y - 3.0f) < 1e-5f,
          "the moved emitter is not where it went");
    int bad = 0;
    for (int k = 0; k < 64; k++) {
        float x = ((float)(k % 8) + 0.5f) / 8.0f, z = ((float)(k / 8) + 0.5f) / 8.0f;
        int expect = alphas[4 * k + 3] / 255.0f >= 0.5f;
        bad += scene_occluded(s, v3(x, 2, z), v3(0, -1, 0), 10.0f) != expect;
    }
    CHECK(bad == 0, "after the move, %d texel centres disagree with the mask", bad);
    scene_destroy(s);
}

static int num_warnings;
static char last_warning[512];
static void on_warn(void *user, const char *msg) {
    (void)user;
    if (!strstr(msg, "alpha")) return;
    num_warnings++;
    snprintf(last_warning, sizeof last_warning, "%s", msg);
}

/* From a file: the modes, the cutoff (default 0.5), the factor's alpha; an unknown mode warns
 * and draws opaque; a cutoff that is no number is one line of error. */
static void test_gltf(void) {
    const char *cases[] = {"{\"alphaMode\":\"MASK\",\"alphaCutoff\":0.25}",
                           "{\"alphaMode\":\"BLEND\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,1,1,0.4]}}",
                           "{\"alphaMode\":\"MASK\"}", "{\"alphaMode\":\"GLASS\"}", "{\"alphaCutoff\":-1}"};
    const alpha_mode modes[] = {ALPHA_MASK, ALPHA_BLEND, ALPHA_MASK, ALPHA_OPAQUE};
    const float cutoffs[] = {0.25f, 0.5f, 0.5f, 0.5f}, base[] = {1.0f, 0.4f, 1.0f, 1.0f};
    for (int k = 0; k < 5; k++) {
        char mats[256], err[512] = "";
        snprintf(mats, sizeof mats, "[%s]", cases[k]);
        char *json = gt_gltf(mats, NULL, NULL, NULL, 0, "", "");
        num_warnings = 0;
        scene *s = scene_load_memory(json, strlen(json), ".", "modes.gltf", on_warn, NULL, err, sizeof err);
        if (k < 4) {
            CHECK(s != NULL, "%s: %s", cases[k], err);
            if (s) {
                const material *m = &s->materials[0];
                CHECK(m->alpha == modes[k] && m->alpha_cutoff == cutoffs[k] && m->base_alpha == base[k],
                      "%s: mode %d cutoff %g alpha %g", cases[k], (int)m->alpha, m->alpha_cutoff, m->base_alpha);
                CHECK(num_warnings == (k == 3), "%s: %d warnings about alpha (%s)", cases[k], num_warnings,
                      last_warning);
            }
        } else {
            CHECK(!s && strstr(err, "modes.gltf: ") == err && strstr(err, "alphaCutoff") && one_line(err), "%s: %s",
                  cases[k], s ? "loaded" : err);
        }
        scene_destroy(s);
        free(json);
    }
}

int main(void) {
    test_mask_grid();
    test_mask_shadow();
    test_mask_vlights();
    test_mask_emitter();
    test_blend_statistics();
    test_blend_shadow();
    test_fast_path();
    test_move_light();
    test_gltf();
    return check_exit("test_alpha");
}
