/* glint tests — scenes made in code, with answers known in closed form. */
#ifndef GLINT_TEST_SCENES_H
#define GLINT_TEST_SCENES_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "camera.h"
#include "lights.h"
#include "rng.h"
#include "scene.h"
#include "session.h"

static inline scene *ts_new(const char *name) {
    scene *s = scene_create(NULL, NULL);
    snprintf(s->path, sizeof s->path, "%s", name);
    return s;
}

/* Pure Lambert (a Phong material without a glossy lobe), optionally emissive. */
static inline int ts_lambert(scene *s, vec3 albedo, vec3 emission, int double_sided) {
    material m = material_default();
    m.model = MATERIAL_PHONG;
    m.kd = albedo;
    m.ks = v3s(0.0f);
    m.exponent = 1.0f;
    m.emission = emission;
    m.double_sided = double_sided;
    return scene_add_material(s, &m);
}

static inline int ts_material(scene *s, material m) { return scene_add_material(s, &m); }

/* Lambert kd plus modified Phong with ks and exponent n. */
static inline material ts_phong(vec3 kd, vec3 ks, float n) {
    material m = material_default();
    m.model = MATERIAL_PHONG;
    m.kd = kd;
    m.ks = ks;
    m.exponent = n;
    return m;
}

/* Quad p[0..3] (counter-clockwise seen from its front) with the given uvs (8 floats) and normals
 * along its winding normal; tangents generated. */
static inline void ts_quad_uv(scene *s, const vec3 p[4], const float uv[8], int mat) {
    float pos[12], nrm[12];
    vec3 n = normalize3(cross3(sub3(p[1], p[0]), sub3(p[2], p[0])));
    for (int i = 0; i < 4; i++) {
        pos[3 * i] = p[i].x, pos[3 * i + 1] = p[i].y, pos[3 * i + 2] = p[i].z;
        nrm[3 * i] = n.x, nrm[3 * i + 1] = n.y, nrm[3 * i + 2] = n.z;
    }
    uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    mesh_desc md = {.num_vertices = 4,
                    .positions = pos,
                    .normals = nrm,
                    .uv0 = uv,
                    .num_indices = 6,
                    .indices = idx,
                    .material = mat};
    mat4 id = mat4_identity();
    char err[256];
    if (scene_add_mesh(s, &md, &id, err, sizeof err) != 0) {
        fprintf(stderr, "ts_quad: %s\n", err);
        abort();
    }
}

/* Quad p0 p1 p2 p3 (counter-clockwise seen from its front), flat-shaded, uvs 0..1. */
static inline void ts_quad(scene *s, vec3 p0, vec3 p1, vec3 p2, vec3 p3, int mat) {
    const vec3 p[4] = {p0, p1, p2, p3};
    const float uv[8] = {0, 0, 1, 0, 1, 1, 0, 1};
    ts_quad_uv(s, p, uv, mat);
}

/* A tangent-space normal map of n texels (RGBA8), each normal tilted by a random angle up to
 * max_tilt (radians) in a random direction. */
static inline void ts_random_normal_map(unsigned char *rgba, int n, uint64_t seed, float max_tilt) {
    rng_state rng = rng_for(seed, 0, 0);
    for (int i = 0; i < n; i++) {
        float a = 2.0f * PI_F * rng_float(&rng), t = max_tilt * rng_float(&rng);
        rgba[4 * i] = (unsigned char)(127.5f + 127.5f * sinf(t) * cosf(a));
        rgba[4 * i + 1] = (unsigned char)(127.5f + 127.5f * sinf(t) * sinf(a));
        rgba[4 * i + 2] = (unsigned char)(127.5f + 127.5f * cosf(t));
        rgba[4 * i + 3] = 255;
    }
}

/* A texture of w x h 8-bit RGBA texels (repeat wrapping); returns its index. */
static inline int ts_texture(scene *s, int w, int h, const unsigned char *rgba) {
    int img = scene_add_image(s, w, h, 4, 8, rgba);
    int t = img < 0 ? -1 : scene_add_texture(s, (scene_texture){img, WRAP_REPEAT, WRAP_REPEAT});
    if (t < 0) {
        fprintf(stderr, "ts_texture: out of memory\n");
        abort();
    }
    return t;
}

/* Axis-aligned box [lo, hi]; faces point inward (a closed room) or outward (a solid). */
static inline void ts_box(scene *s, vec3 lo, vec3 hi, int inward, int mat) {
    vec3 c[8];
    for (int i = 0; i < 8; i++) c[i] = v3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
    /* outward-facing faces, counter-clockwise seen from outside */
    int f[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (int k = 0; k < 6; k++) {
        if (inward)
            ts_quad(s, c[f[k][3]], c[f[k][2]], c[f[k][1]], c[f[k][0]], mat);
        else
            ts_quad(s, c[f[k][0]], c[f[k][1]], c[f[k][2]], c[f[k][3]], mat);
    }
}

static inline void ts_finalize(scene *s) {
    char err[256];
    if (scene_finalize(s, err, sizeof err) != 0) {
        fprintf(stderr, "ts_finalize: %s\n", err);
        abort();
    }
}

/* A white point light of intensity 1 at position. */
static inline void ts_point_light(scene *s, vec3 position) {
    light l;
    memset(&l, 0, sizeof l);
    l.type = LIGHT_POINT;
    l.color = v3s(1.0f);
    l.position = position;
    scene_add_light(s, &l);
}

/* A constant sky of radiance value (a 4x2 image). */
static inline void ts_constant_env(scene *s, float value) {
    image_rgb img = {4, 2, malloc(sizeof(float) * 3 * 8)};
    for (int i = 0; i < 24; i++) img.rgb[i] = value;
    char err[256];
    if (scene_set_env_image(s, &img, 0.0f, err, sizeof err) != 0) {
        fprintf(stderr, "ts_constant_env: %s\n", err);
        abort();
    }
}

/* Renders spp frames with the given parameters once; out[k] is the per-pixel mean image of the
 * components in masks[k] (caller frees each). */
static inline void ts_render_layers(const scene *s, const camera *cam, const render_params *p, int spp, int n,
                                    const unsigned *masks, float **out) {
    char err[256];
    render_session *rs = session_create(s, cam, p, err, sizeof err);
    if (!rs) {
        fprintf(stderr, "ts_render: %s\n", err);
        abort();
    }
    for (int i = 0; i < spp; i++)
        if (session_render_frame(rs) != 0) {
            fprintf(stderr, "ts_render: %s\n", session_error(rs));
            abort();
        }
    for (int k = 0; k < n; k++) {
        out[k] = malloc(sizeof(float) * 3 * (size_t)p->width * (size_t)p->height);
        film_resolve(session_film(rs), masks[k], out[k]);
    }
    render_stats st = session_stats(rs);
    if (st.rejected_samples)
        fprintf(stderr, "ts_render: %llu rejected samples\n", (unsigned long long)st.rejected_samples);
    session_destroy(rs);
}

/* Renders spp frames with the given parameters; returns the per-pixel mean image of the
 * components in mask (caller frees). */
static inline float *ts_render_with(const scene *s, const camera *cam, const render_params *p, int spp, unsigned mask) {
    float *img;
    ts_render_layers(s, cam, p, spp, 1, &mask, &img);
    return img;
}

/* Path-traced: spp frames of w x h at max_depth. */
static inline float *ts_render(const scene *s, const camera *cam, int w, int h, int spp, int max_depth, uint64_t seed,
                               unsigned mask) {
    render_params p = {.width = w, .height = h, .max_depth = max_depth, .seed = seed};
    return ts_render_with(s, cam, &p, spp, mask);
}

/* Mean and standard error of the mean over pixels of channel-averaged values. */
static inline void ts_stats(const float *img, int n, double *mean, double *sem) {
    double s = 0, s2 = 0;
    for (int i = 0; i < n; i++) {
        double v = (img[3 * i] + img[3 * i + 1] + img[3 * i + 2]) / 3.0;
        s += v;
        s2 += v * v;
    }
    *mean = s / n;
    double var = n > 1 ? (s2 - s * s / n) / (n - 1) : 0.0;
    *sem = sqrt(var > 0 ? var / n : 0.0);
}

/* vsl and vsl+hl against the path tracer's mean over a w x h image at max_depth (pt 1024 frames;
 * the virtual-light methods 128 frames of 1024 lights, 32 resampled a pixel, radius multiplier 1):
 * ratios[0] for vsl, ratios[1] for vsl+hl. */
static inline void ts_vsl_mean_ratios(const scene *s, const camera *cam, int w, int h, int max_depth,
                                      double ratios[2]) {
    double ref_mean, mean, sem;
    render_params pp = {.width = w, .height = h, .max_depth = max_depth, .seed = 1};
    float *ref = ts_render_with(s, cam, &pp, 1024, ~0u);
    ts_stats(ref, w * h, &ref_mean, &sem);
    for (int k = 0; k < 2; k++) {
        render_params p = {
            .width = w, .height = h, .method = k ? METHOD_VSL_HL : METHOD_VSL, .max_depth = max_depth, .seed = 2};
        p.vl.count = 1024;
        p.vl.per_pixel = 32;
        p.vl.radius_mult = 1.0f;
        float *img = ts_render_with(s, cam, &p, 128, ~0u);
        ts_stats(img, w * h, &mean, &sem);
        ratios[k] = mean / ref_mean;
        printf("%s, %s: mean ratio to PT %.4f (PT mean %.4f)\n", s->path, method_name(p.method), ratios[k], ref_mean);
        free(img);
    }
    free(ref);
}

#endif
