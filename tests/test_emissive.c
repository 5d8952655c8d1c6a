/* Emissive textures and lights: a triangle whose emissive texture is black all over it is no
 * light, every triangle it lights somewhere is one (brute force over a grid of triangles, with
 * each wrap mode and a texture transform), and a light's power is the texture's integral over the
 * triangle (quadrature), for footprints from part of a texel to a hundred repeats. */
#define _POSIX_C_SOURCE 200809L
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "test_scenes.h"

/* Texture: 16 x 4, the left half black, the right half white except one grey texel. */
static int half_black(scene *s, wrap_mode wrap) {
    unsigned char px[16 * 4 * 4];
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 16; i++) {
            unsigned char v = i < 8 ? 0 : (i == 12 && j == 1 ? 90 : 255);
            unsigned char *p = px + 4 * (16 * j + i);
            p[0] = p[1] = p[2] = v, p[3] = 255;
        }
    int img = scene_add_image(s, 16, 4, 4, 8, px);
    return scene_add_texture(s, (scene_texture){img, wrap, wrap});
}

/* An n x n grid of quads over [0,1]^2 in z = 0 facing +z, uv = a + b (x, 1 - y). */
static void grid(scene *s, int n, int mat, float a, float b) {
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            float x0 = (float)i / n, x1 = (float)(i + 1) / n, y0 = (float)j / n, y1 = (float)(j + 1) / n;
            const vec3 p[4] = {v3(x0, y0, 0), v3(x1, y0, 0), v3(x1, y1, 0), v3(x0, y1, 0)};
            float uv[8];
            for (int k = 0; k < 4; k++) uv[2 * k] = a + b * p[k].x, uv[2 * k + 1] = a + b * (1.0f - p[k].y);
            ts_quad_uv(s, p, uv, mat);
        }
}

/* Brute force over triangle t: whether any point of a fine barycentric lattice (edges included)
 * emits, and the mean emitted luminance over the centroids of the n^2 equal sub-triangles. */
static vec2 bary_uv(const scene *s, const uint32_t *v, float b1, float b2) {
    float b0 = 1.0f - b1 - b2;
    return v2(b0 * s->uv0[v[0]].x + b1 * s->uv0[v[1]].x + b2 * s->uv0[v[2]].x,
              b0 * s->uv0[v[0]].y + b1 * s->uv0[v[1]].y + b2 * s->uv0[v[2]].y);
}

static double emitted(const scene *s, const material *m, vec2 uv) {
    vec4 c = texture_lookup(s, m->emissive_tex, uv, uv, 1);
    return luminance3(mul3(m->emission, v3(c.x, c.y, c.z)));
}

static double triangle_truth(const scene *s, int t, int *emits) {
    const uint32_t *v = &s->indices[3 * t];
    const material *m = &s->materials[s->tri_material[t]];
    const int n = 60;
    *emits = 0;
    for (int i = 0; i <= n; i++)
        for (int j = 0; i + j <= n; j++) *emits |= emitted(s, m, bary_uv(s, v, (float)i / n, (float)j / n)) > 0.0;
    double sum = 0.0;
    for (int i = 0; i < n; i++)
        for (int j = 0; i + j < n; j++) {
            sum += emitted(s, m, bary_uv(s, v, (i + 1.0f / 3.0f) / n, (j + 1.0f / 3.0f) / n));
            if (i + j + 1 < n) sum += emitted(s, m, bary_uv(s, v, (i + 2.0f / 3.0f) / n, (j + 2.0f / 3.0f) / n));
        }
    return sum / ((double)n * n);
}

static float area_of(const scene *s, int t) {
    const uint32_t *v = &s->indices[3 * t];
    vec3 p0 = s->positions[v[0]];
    return 0.5f * length3(cross3(sub3(s->positions[v[1]], p0), sub3(s->positions[v[2]], p0)));
}

/* Lights exactly where the brute force finds emission (every emitting triangle one; with the
 * grid aligned to the texels, none more), and each light's power within 1% of area x pi x the
 * brute-force mean luminance. */
static void check_grid(const char *name, wrap_mode wrap, int transformed, float a, float b, int exact) {
    scene *s = ts_new(name);
    material m = ts_phong(v3s(0), v3s(0), 1.0f);
    m.emission = v3(2.0f, 1.0f, 0.5f);
    m.emissive_tex = (texture_slot){.texture = half_black(s, wrap)};
    if (transformed) { /* u' = u + 0.5: the halves swap under repeat */
        m.emissive_tex.transformed = 1;
        float xf[6] = {1, 0, 0.5f, 0, 1, 0};
        memcpy(m.emissive_tex.uv_xf, xf, sizeof xf);
    }
    grid(s, 8, ts_material(s, m), a, b);
    ts_finalize(s);
    int missing = 0, extra = 0, lights = 0, emitting = 0, bad_power = 0;
    double total = 0.0, total_truth = 0.0;
    for (int t = 0; t < s->num_triangles; t++) {
        int emits;
        double mean = triangle_truth(s, t, &emits);
        int li = s->tri_light[t];
        emitting += emits;
        lights += li >= 0;
        missing += emits && li < 0;
        extra += !emits && li >= 0;
        double truth = area_of(s, t) * PI_F * mean;
        total_truth += truth;
        if (li >= 0) {
            total += s->lights[li].power;
            if (emits && fabs(s->lights[li].power - truth) > 0.01 * truth && bad_power++ < 3)
                fprintf(stderr, "%s: triangle %d: power %g, brute force %g\n", name, t, s->lights[li].power, truth);
        }
    }
    CHECK(emitting > 0 && emitting < s->num_triangles, "%s: %d of %d triangles emit: the case tests nothing", name,
          emitting, s->num_triangles);
    CHECK(missing == 0, "%s: %d emitting triangles are no lights", name, missing);
    CHECK(exact ? extra == 0 : extra <= lights / 10, "%s: %d dark triangles are lights (of %d lights)", name, extra,
          lights);
    CHECK(bad_power == 0, "%s: %d lights' powers off the brute force", name, bad_power);
    CHECK_NEAR(total / total_truth, 1.0, 0.01, "%s: total emitted power against the brute force", name);
    printf("%s: %d lights of %d triangles (%d emit)\n", name, lights, s->num_triangles, emitting);
    scene_destroy(s);
}

/* One triangle over a hundred repeats of a 64 x 64 texture with a single white texel: a light,
 * of the texture's mean power; on a black texture no light at all. */
static void test_large_footprint(void) {
    for (int white = 0; white < 2; white++) {
        scene *s = ts_new("large footprint");
        unsigned char *px = calloc(64 * 64 * 4, 1);
        for (int i = 0; i < 64 * 64; i++) px[4 * i + 3] = 255;
        if (white) px[4 * (64 * 20 + 33)] = px[4 * (64 * 20 + 33) + 1] = px[4 * (64 * 20 + 33) + 2] = 255;
        material m = ts_phong(v3s(0), v3s(0), 1.0f);
        m.emission = v3s(1.0f);
        m.emissive_tex = (texture_slot){.texture = ts_texture(s, 64, 64, px)};
        free(px);
        const vec3 p[4] = {v3(0, 0, 0), v3(10, 0, 0), v3(10, 10, 0), v3(0, 10, 0)};
        const float uv[8] = {0, 0, 100, 0, 100, 100, 0, 100};
        ts_quad_uv(s, p, uv, ts_material(s, m));
        ts_finalize(s);
        int lights = 0;
        double power = 0.0;
        for (int i = 0; i < s->num_lights; i++)
            if (s->lights[i].type == LIGHT_TRIANGLE) lights++, power += s->lights[i].power;
        if (white) {
            /* The texel's bilinear footprint holds one texel's worth: mean 1 / 4096. */
            double expect = 100.0 * PI_F / 4096.0;
            CHECK(lights == 2, "one white texel, a hundred repeats: %d lights, expected 2", lights);
            CHECK_NEAR(power / expect, 1.0, 0.1, "a hundred repeats: power %g, expected %g", power, expect);
        } else {
            CHECK(lights == 0, "a black texture, a hundred repeats: %d lights", lights);
        }
        scene_destroy(s);
    }
}

/* A triangle inside one black texel (next to white ones, whose bilinear tails reach it only
 * beyond its edges) is no light; moved half a texel it is. */
static void test_small_footprint(void) {
    for (int shift = 0; shift < 2; shift++) {
        scene *s = ts_new("small footprint");
        material m = ts_phong(v3s(0), v3s(0), 1.0f);
        m.emission = v3s(1.0f);
        m.emissive_tex = (texture_slot){.texture = half_black(s, WRAP_REPEAT)};
        /* Texel 5 of 16 spans u in [5/16, 6/16]; bilinear reads texel 8 only from u > 7.5/16. */
        float u0 = shift ? 7.6f / 16.0f : 5.2f / 16.0f, u1 = u0 + 0.1f / 16.0f;
        const vec3 p[4] = {v3(0, 0, 0), v3(1, 0, 0), v3(1, 1, 0), v3(0, 1, 0)};
        const float uv[8] = {u0, 0.3f, u1, 0.3f, u1, 0.31f, u0, 0.31f};
        ts_quad_uv(s, p, uv, ts_material(s, m));
        ts_finalize(s);
        int lights = s->num_lights;
        CHECK(lights == (shift ? 2 : 0), "a footprint %s the white texels' reach: %d lights", shift ? "in" : "short of",
              lights);
        scene_destroy(s);
    }
}

int main(void) {
    check_grid("repeat, aligned", WRAP_REPEAT, 0, 0.0f, 1.0f, 1);
    check_grid("repeat, transformed", WRAP_REPEAT, 1, 0.0f, 1.0f, 1);
    check_grid("repeat, twice round", WRAP_REPEAT, 0, -0.3f, 2.0f, 0);
    check_grid("mirror", WRAP_MIRROR, 0, -0.6f, 2.1f, 0);
    check_grid("clamp", WRAP_CLAMP, 0, -0.4f, 1.7f, 0);
    test_large_footprint();
    test_small_footprint();
    return check_exit("test_emissive");
}
