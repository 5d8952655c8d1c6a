/* Normal maps and tangents: a known texel gives exactly the tilted frame glTF defines (both uv
 * orientations, both faces, the scale); generated tangents follow MikkTSpace with glTF's sign
 * (closed forms, mirrored uvs split, and the files' own tangents on the shared scenes); no
 * texel, however wild, makes a frame that is not finite or lets light through the surface; a flat
 * plane whose map tilts it shades like the plane tilted for real; and virtual lights on mapped
 * surfaces give the path tracer's answer. The clear coat's own map (KHR_materials_clearcoat's
 * clearcoatNormalTexture) likewise: its texel gives the coat's normal, the base's map does not
 * bump the coat, and a coat mapped to a tilt reflects as the coat of the tilted plane. */
#define _POSIX_C_SOURCE 200809L
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "gltf_textured.h"
#include "pt.h"
#include "rng.h"
#include "sampling.h"
#include "scratch.h"
#include "test_scenes.h"

static const unsigned ALL = COMP_MASK_ALL;

/* A material whose normal map is one texel (x, y, z as 8-bit RGB), of the given scale. */
static int mapped_material(scene *s, material m, const unsigned char texel[3], float scale) {
    unsigned char px[4 * 4];
    for (int i = 0; i < 4; i++) memcpy(px + 4 * i, (unsigned char[4]){texel[0], texel[1], texel[2], 255}, 4);
    m.normal_tex = (texture_slot){.texture = ts_texture(s, 2, 2, px)};
    m.normal_scale = scale;
    return ts_material(s, m);
}

/* The tangent-space vector a texel stands for, as glTF defines it. */
static vec3 texel_normal(const unsigned char t[3], float scale) {
    return v3((2.0f * t[0] / 255.0f - 1.0f) * scale, (2.0f * t[1] / 255.0f - 1.0f) * scale,
              2.0f * t[2] / 255.0f - 1.0f);
}

/* The square [-1,1]^2 in z = 0 facing +z, uvs as an image is laid on it (u right, v down: glTF's
 * v runs down the image), or mirrored left to right. */
static void square(scene *s, int mat, int mirrored) {
    const vec3 p[4] = {v3(-1, -1, 0), v3(1, -1, 0), v3(1, 1, 0), v3(-1, 1, 0)};
    float uv[8];
    for (int i = 0; i < 4; i++) {
        uv[2 * i] = mirrored ? (1.0f - p[i].x) / 2.0f : (p[i].x + 1.0f) / 2.0f;
        uv[2 * i + 1] = (1.0f - p[i].y) / 2.0f;
    }
    ts_quad_uv(s, p, uv, mat);
}

static void check_vec(vec3 a, vec3 b, float tol, const char *what) {
    CHECK(fabsf(a.x - b.x) <= tol && fabsf(a.y - b.y) <= tol && fabsf(a.z - b.z) <= tol,
          "%s: (%g, %g, %g), expected (%g, %g, %g)", what, a.x, a.y, a.z, b.x, b.y, b.z);
}

/* The square [-1,1]^2 turned so that its normal is n (uvs as an image laid on it). */
static void tilted_square(scene *s, int mat, vec3 n) {
    vec3 x = normalize3(sub3(v3(1, 0, 0), scale3(n, n.x))), y = cross3(n, x);
    const vec3 p[4] = {sub3(neg3(x), y), sub3(x, y), add3(x, y), add3(neg3(x), y)};
    const float uv[8] = {0, 1, 1, 1, 1, 0, 0, 0};
    ts_quad_uv(s, p, uv, mat);
}

/* glTF: n = normalize(T x + B y + N z), T along increasing u, B = cross(N, T) w pointing up the
 * image. On the square the image's right is +x (or -x mirrored) and its top is +y. */
static void test_known_texel(void) {
    const unsigned char texel[3] = {200, 90, 230};
    const float scales[2] = {1.0f, 0.5f};
    for (int mirrored = 0; mirrored < 2; mirrored++)
        for (int k = 0; k < 2; k++) {
            scene *s = ts_new("known texel");
            material m = material_default();
            m.double_sided = 1;
            int mat = mapped_material(s, m, texel, scales[k]);
            square(s, mat, mirrored);
            ts_finalize(s);
            vec3 t = texel_normal(texel, scales[k]);
            vec3 expect = normalize3(v3(mirrored ? -t.x : t.x, t.y, t.z));
            surface_hit h;
            CHECK(scene_intersect(s, v3(0.1f, 0.2f, 5), v3(0, 0, -1), INFINITY, &h), "front hit");
            char what[96];
            snprintf(what, sizeof what, "front, %s uvs, scale %g", mirrored ? "mirrored" : "plain", scales[k]);
            check_vec(h.shading.n, expect, 1e-5f, what);
            /* The frame's tangent follows u, its bitangent glTF's B. */
            check_vec(h.shading.t,
                      normalize3(sub3(v3(mirrored ? -1 : 1, 0, 0), scale3(expect, mirrored ? -expect.x : expect.x))),
                      1e-5f, what);
            CHECK(dot3(h.shading.b, v3(0, 1, 0)) > 0.9f, "%s: bitangent (%g, %g, %g) is not up the image", what,
                  h.shading.b.x, h.shading.b.y, h.shading.b.z);
            /* From behind (double-sided) the same bumps: the whole normal negated. */
            CHECK(scene_intersect(s, v3(0.1f, 0.2f, -5), v3(0, 0, 1), INFINITY, &h), "back hit");
            snprintf(what, sizeof what, "back, %s uvs, scale %g", mirrored ? "mirrored" : "plain", scales[k]);
            check_vec(h.shading.n, neg3(expect), 1e-5f, what);
            scene_destroy(s);
        }
}

/* Generated tangents in closed form: T along +u, w = +1 where the image lies unmirrored; a vertex
 * shared by a plain and a mirrored quad becomes two, one per orientation (as MikkTSpace does). */
static void test_generated_tangents(void) {
    scene *s = ts_new("tangents");
    int mat = ts_material(s, material_default());
    /* Two quads sharing the edge x = 0; the right one's u runs back (mirrored uvs). */
    float pos[6 * 3] = {-1, -1, 0, 0, -1, 0, 1, -1, 0, -1, 1, 0, 0, 1, 0, 1, 1, 0};
    float nrm[6 * 3], uv[6 * 2];
    for (int i = 0; i < 6; i++) {
        nrm[3 * i] = 0, nrm[3 * i + 1] = 0, nrm[3 * i + 2] = 1;
        uv[2 * i] = 1.0f - fabsf(pos[3 * i]); /* 0 at both sides, 1 on the shared edge */
        uv[2 * i + 1] = (1.0f - pos[3 * i + 1]) / 2.0f;
    }
    uint32_t idx[12] = {0, 1, 4, 0, 4, 3, 1, 2, 5, 1, 5, 4};
    mesh_desc md = {.num_vertices = 6,
                    .positions = pos,
                    .normals = nrm,
                    .uv0 = uv,
                    .num_indices = 12,
                    .indices = idx,
                    .material = mat};
    mat4 id = mat4_identity();
    char err[256];
    CHECK(scene_add_mesh(s, &md, &id, err, sizeof err) == 0, "%s", err);
    CHECK(s->num_vertices == 8, "the two shared vertices split by orientation: %d vertices, expected 8",
          s->num_vertices);
    for (int t = 0; t < s->num_triangles; t++)
        for (int c = 0; c < 3; c++) {
            uint32_t v = s->indices[3 * t + c];
            int right = t >= 2;
            vec4 tg = s->tangents[v];
            char what[64];
            snprintf(what, sizeof what, "triangle %d corner %d tangent", t, c);
            check_vec(v3(tg.x, tg.y, tg.z), v3(right ? -1.0f : 1.0f, 0, 0), 1e-6f, what);
            /* B = cross(N, T) w = +y (up the image) on both sides. */
            CHECK(tg.w == (right ? -1.0f : 1.0f), "%s: w %g", what, tg.w);
        }
    scene_destroy(s);
}

/* The tangents a file brings against the ones generated when its TANGENT attribute is hidden:
 * the frames at many hits must agree (MikkTSpace-compatible, glTF's bitangent sign). */
static void test_file_tangents(const char *rel) {
    const char *base = getenv("GLINT_SHARED_SCENES");
    if (!base || !base[0]) return;
    char path[1024], dir[1024];
    snprintf(path, sizeof path, "%s/%s", base, rel);
    snprintf(dir, sizeof dir, "%s", path);
    char *slash = strrchr(dir, '/');
    *slash = 0;
    size_t size;
    char *json = (char *)get_file(path, &size);
    if (!json) {
        fprintf(stderr, "test_normalmap: %s absent, skipped\n", path);
        return;
    }
    char err[512];
    scene *a = scene_load_memory(json, size, dir, "with tangents", NULL, NULL, err, sizeof err);
    for (char *p = json; (p = memchr(p, '"', size - (size_t)(p - json))) && (size_t)(p - json) + 9 < size; p++)
        if (!memcmp(p, "\"TANGENT\"", 9)) p[1] = 'X'; /* an attribute glint does not read */
    scene *b = scene_load_memory(json, size, dir, "generated", NULL, NULL, err, sizeof err);
    CHECK(a && b, "%s: %s", rel, err);
    if (a && b) {
        rng_state rng = rng_for(7, 0, 0);
        vec3 c = bounds_center(a->bounds);
        int hits = 0, sign_ok = 0, close = 0;
        for (int i = 0; i < 20000; i++) {
            vec3 o = madd3(c, sample_uniform_sphere(rng_vec2(&rng)), a->diag);
            vec3 target = madd3(c, sample_uniform_sphere(rng_vec2(&rng)), 0.3f * a->diag);
            vec3 d = normalize3(sub3(target, o));
            surface_hit ha, hb;
            if (!scene_intersect(a, o, d, INFINITY, &ha) || !scene_intersect(b, o, d, INFINITY, &hb)) continue;
            if (fabsf(ha.t - hb.t) > 1e-5f * a->diag) continue;
            hits++;
            sign_ok += dot3(ha.shading.b, hb.shading.b) > 0.0f;
            close += dot3(ha.shading.t, hb.shading.t) > cosf(5.0f * PI_F / 180.0f);
        }
        CHECK(hits > 1000, "%s: %d hits", rel, hits);
        CHECK(sign_ok >= 0.995 * hits, "%s: bitangent sign agrees at %d of %d hits", rel, sign_ok, hits);
        CHECK(close >= 0.99 * hits, "%s: tangents within 5 degrees at %d of %d hits", rel, close, hits);
        printf("%s: generated tangents agree with the file's: sign %.4f, within 5 degrees %.4f (%d hits)\n", rel,
               (double)sign_ok / hits, (double)close / hits, hits);
    }
    scene_destroy(a);
    scene_destroy(b);
    free(json);
}

/* Texels that point nowhere, sideways or into the surface, seen from any direction: the frame
 * stays finite and orthonormal, its normal above the geometric surface and facing the viewer,
 * and its mirror direction above the surface. */
static void test_degenerate_texels(void) {
    const unsigned char texels[][3] = {{128, 128, 0},   {255, 128, 128}, {0, 0, 0},     {128, 128, 128},
                                       {255, 255, 255}, {0, 128, 1},     {128, 0, 127}, {40, 250, 60}};
    const float scales[] = {1.0f, 0.0f, -3.0f, 1e20f};
    rng_state rng = rng_for(11, 0, 0);
    int bad = 0, total = 0;
    for (size_t k = 0; k < sizeof texels / sizeof texels[0]; k++)
        for (size_t j = 0; j < sizeof scales / sizeof scales[0]; j++) {
            scene *s = ts_new("degenerate");
            material m = material_default();
            m.double_sided = 1;
            square(s, mapped_material(s, m, texels[k], scales[j]), 0);
            ts_finalize(s);
            for (int i = 0; i < 200; i++) {
                vec3 d = sample_uniform_sphere(rng_vec2(&rng));
                if (fabsf(d.z) < 1e-4f) continue;
                vec3 o = madd3(v3(0.3f * (rng_float(&rng) - 0.5f), 0.3f * (rng_float(&rng) - 0.5f), 0), d, -3.0f);
                surface_hit h;
                if (!scene_intersect(s, o, d, INFINITY, &h)) continue;
                frame3 f = h.shading;
                vec3 wo = neg3(d), r = reflect3(wo, f.n);
                int ok = is_finite3(f.n) && is_finite3(f.t) && is_finite3(f.b) && fabsf(length3(f.n) - 1.0f) < 1e-4f &&
                         fabsf(dot3(f.n, f.t)) < 1e-4f && fabsf(dot3(f.n, f.b)) < 1e-4f && dot3(f.n, h.ng) > 0.0f &&
                         dot3(f.n, wo) > 0.0f && dot3(r, h.ng) >= 0.0f;
                frame3 bf;
                bsdf b = material_bsdf(s, &h, &bf);
                vec3 wl = to_local(bf, wo);
                ok = ok && is_finite3(bsdf_eval(&b, wl, v3(0, 0, 1), BSDF_ALL));
                if (!ok && bad++ < 5)
                    fprintf(stderr, "texel (%d %d %d) scale %g: n (%g %g %g), ng (%g %g %g), wo (%g %g %g)\n",
                            texels[k][0], texels[k][1], texels[k][2], scales[j], f.n.x, f.n.y, f.n.z, h.ng.x, h.ng.y,
                            h.ng.z, wo.x, wo.y, wo.z);
                total++;
            }
            scene_destroy(s);
        }
    CHECK(bad == 0 && total > 1000, "%d of %d frames broke a guard", bad, total);
}

/* A plane whose map tilts every normal nearly into it, lit only from below: nothing reaches the
 * camera above, by any method. */
static void test_no_leaks(void) {
    scene *s = ts_new("leaks");
    unsigned char px[16 * 16 * 4];
    rng_state rng = rng_for(5, 0, 0);
    for (int i = 0; i < 16 * 16; i++) {
        px[4 * i] = (unsigned char)(rng_float(&rng) < 0.5f ? 0 : 255);
        px[4 * i + 1] = (unsigned char)(rng_float(&rng) * 255.0f);
        px[4 * i + 2] = (unsigned char)(128 + rng_float(&rng) * 20.0f);
        px[4 * i + 3] = 255;
    }
    material m = ts_phong(v3s(0.5f), v3s(0.4f), 30.0f);
    m.normal_tex = (texture_slot){.texture = ts_texture(s, 16, 16, px)};
    m.normal_scale = 1.0f;
    const vec3 p[4] = {v3(-5, 0, 5), v3(5, 0, 5), v3(5, 0, -5), v3(-5, 0, -5)};
    const float uv[8] = {0, 0, 4, 0, 4, 4, 0, 4};
    ts_quad_uv(s, p, uv, ts_material(s, m));
    light l = {.type = LIGHT_POINT, .color = v3s(50.0f), .position = v3(0.3f, -0.5f, 0.2f)};
    scene_add_light(s, &l);
    light d = {.type = LIGHT_DIRECTIONAL, .color = v3s(5.0f), .direction = normalize3(v3(0.2f, 1.0f, 0.1f))};
    scene_add_light(s, &d);
    ts_finalize(s);
    camera cam = camera_look_at(v3(0.5f, 1.0f, 1.5f), v3(0, 0, 0), v3(0, 1, 0), 1.0f);
    const render_method methods[] = {METHOD_PT, METHOD_VSL, METHOD_VSL_HL};
    for (int k = 0; k < 3; k++) {
        render_params rp = {.width = 24, .height = 16, .max_depth = 4, .method = methods[k], .seed = 1};
        float *img = ts_render_with(s, &cam, &rp, 4, ALL);
        double sum = 0.0;
        for (int i = 0; i < 3 * 24 * 16; i++) sum += fabs(img[i]);
        CHECK(sum == 0.0, "method %d: light from below leaks through the plane: sum %g", (int)methods[k], sum);
        free(img);
    }
    scene_destroy(s);
}

/* Under a directional light, a flat Lambert plane whose map tilts its normal by theta about x
 * shades exactly like the plane tilted by theta: (albedo / pi) E cos(light, normal) at every
 * pixel. */
static void test_tilt_matches_geometry(void) {
    const float theta = 0.5f, albedo = 0.7f, lux = 3.0f;
    const vec3 to_light = normalize3(v3(0.2f, 0.6f, 1.0f));
    const vec3 tilted = v3(0.0f, sinf(theta), cosf(theta));
    /* The texel closest to the tilted normal, and the normal it stands for exactly. */
    unsigned char texel[3] = {128, (unsigned char)lroundf((tilted.y + 1.0f) * 127.5f),
                              (unsigned char)lroundf((tilted.z + 1.0f) * 127.5f)};
    vec3 n_map = normalize3(texel_normal(texel, 1.0f));
    float expect = albedo * INV_PI_F * lux * dot3(n_map, to_light);
    float images[2];
    for (int geometric = 0; geometric < 2; geometric++) {
        scene *s = ts_new("tilt");
        int mat = ts_lambert(s, v3s(albedo), v3s(0), 0);
        if (geometric) {
            tilted_square(s, mat, n_map);
        } else {
            material m = s->materials[mat];
            square(s, mapped_material(s, m, texel, 1.0f), 0);
        }
        light l = {.type = LIGHT_DIRECTIONAL, .color = v3s(lux), .direction = neg3(to_light)};
        scene_add_light(s, &l);
        ts_finalize(s);
        camera cam = camera_look_at(v3(0, 0, 6), v3(0, 0, 0), v3(0, 1, 0), 0.25f);
        const int w = 16, h = 16;
        float *img = ts_render(s, &cam, w, h, 4, 1, 2, ALL);
        int bad = 0;
        for (int i = 0; i < w * h; i++)
            if (fabsf(img[3 * i] - expect) > 1e-4f * expect && bad++ < 3)
                fprintf(stderr, "%s plane: pixel %d: %g, expected %g\n", geometric ? "tilted" : "mapped", i, img[3 * i],
                        expect);
        CHECK(bad == 0, "%s plane: %d of %d pixels differ from the closed form", geometric ? "tilted" : "mapped", bad,
              w * h);
        images[geometric] = img[3 * (w * h / 2 + w / 2)];
        free(img);
        scene_destroy(s);
    }
    CHECK_NEAR(images[0], images[1], 1e-4f * expect, "the mapped plane against the tilted one");
}

/* The direct light along the ray from (0, -1, 4) to the origin, where the test planes pass, under
 * a directional light of radiance 2 travelling along dir; s is finalized and destroyed here. */
static vec3 direct_at_centre(scene *s, vec3 dir, const char *what) {
    light l = {.type = LIGHT_DIRECTIONAL, .color = v3s(2.0f), .direction = dir};
    scene_add_light(s, &l);
    ts_finalize(s);
    vec3 o = v3(0.0f, -1.0f, 4.0f), d = normalize3(neg3(o));
    surface_hit h;
    vec3 comp[COMP_COUNT] = {{0}};
    int hit = scene_intersect(s, o, d, INFINITY, &h);
    CHECK(hit, "%s: no hit", what);
    rng_state rng = rng_for(3, 0, 0);
    uint64_t rays[RAY_KIND_COUNT] = {0};
    if (hit) pt_radiance(s, 1, 0, o, d, &h, (qmc_run){0, 0, 0}, &rng, comp, NULL, rays);
    scene_destroy(s);
    return comp[COMP_DIRECT];
}

/* A glossy lobe sees the mapped normal too: the same ray on the mapped and on the tilted plane
 * (through the centre, where both planes pass) returns the same radiance. */
static void test_glossy_tilt(void) {
    const float theta = 0.3f;
    unsigned char texel[3] = {128, (unsigned char)lroundf((sinf(theta) + 1.0f) * 127.5f),
                              (unsigned char)lroundf((cosf(theta) + 1.0f) * 127.5f)};
    vec3 n_map = normalize3(texel_normal(texel, 1.0f));
    vec3 out[2];
    for (int geometric = 0; geometric < 2; geometric++) {
        scene *s = ts_new("glossy tilt");
        material m = material_default();
        m.base_color = v3(0.9f, 0.8f, 0.6f);
        m.metallic = 1.0f;
        m.roughness = 0.3f;
        if (geometric) {
            tilted_square(s, ts_material(s, m), n_map);
        } else {
            square(s, mapped_material(s, m, texel, 1.0f), 0);
        }
        out[geometric] = direct_at_centre(s, normalize3(v3(-0.1f, 0.2f, -1.0f)), "glossy tilt");
    }
    CHECK(out[0].x > 0.01f, "glossy tilt: the test ray sees no highlight (%g)", out[0].x);
    CHECK_NEAR(out[0].x, out[1].x, 1e-4f * out[1].x, "glossy lobe on the mapped plane against the tilted one");
}

/* m with a clear coat (roughness 0.3 unless m has one) whose normal map is one texel (and, when
 * base_texel, a base normal map of another). */
static int coat_material(scene *s, material m, const unsigned char coat_texel[3], float scale,
                         const unsigned char *base_texel) {
    m.ext.clearcoat = 1.0f;
    if (m.ext.clearcoat_roughness == 0.0f) m.ext.clearcoat_roughness = 0.3f;
    unsigned char px[16];
    for (int i = 0; i < 4; i++)
        memcpy(px + 4 * i, (unsigned char[4]){coat_texel[0], coat_texel[1], coat_texel[2], 255}, 4);
    m.ext.clearcoat_normal_tex = (texture_slot){.texture = ts_texture(s, 2, 2, px)};
    m.ext.clearcoat_normal_scale = scale;
    return base_texel ? mapped_material(s, m, base_texel, 1.0f) : ts_material(s, m);
}

static void test_coat_texel(void) {
    const unsigned char coat[3] = {90, 170, 220}, base[3] = {200, 90, 230};
    for (int mirrored = 0; mirrored < 2; mirrored++)
        for (int with_base = 0; with_base < 2; with_base++) {
            scene *s = ts_new("coat texel");
            material m = material_default();
            m.double_sided = 1;
            square(s, coat_material(s, m, coat, 0.5f, with_base ? base : NULL), mirrored);
            ts_finalize(s);
            vec3 t = texel_normal(coat, 0.5f), b = texel_normal(base, 1.0f);
            vec3 expect = normalize3(v3(mirrored ? -t.x : t.x, t.y, t.z));
            vec3 shading = with_base ? normalize3(v3(mirrored ? -b.x : b.x, b.y, b.z)) : v3(0, 0, 1);
            char what[96];
            snprintf(what, sizeof what, "coat, %s uvs, %s", mirrored ? "mirrored" : "plain",
                     with_base ? "a base map" : "no base map");
            surface_hit h;
            CHECK(scene_intersect(s, v3(0.1f, 0.2f, 5), v3(0, 0, -1), INFINITY, &h), "coat: front hit");
            check_vec(h.coat_n, expect, 1e-5f, what);
            check_vec(h.shading.n, shading, 1e-5f, what);
            CHECK(scene_intersect(s, v3(0.1f, 0.2f, -5), v3(0, 0, 1), INFINITY, &h), "coat: back hit");
            check_vec(h.coat_n, neg3(expect), 1e-5f, what);
            scene_destroy(s);
        }
    /* Without its own map the coat keeps the interpolated normal: the base's map does not bump it
     * (the extension's rule). */
    scene *s = ts_new("coat without a map");
    material m = material_default();
    m.ext.clearcoat = 1.0f;
    square(s, mapped_material(s, m, (const unsigned char[3]){200, 90, 230}, 1.0f), 0);
    ts_finalize(s);
    surface_hit h;
    CHECK(scene_intersect(s, v3(0.1f, 0.2f, 5), v3(0, 0, -1), INFINITY, &h), "coat without a map: hit");
    check_vec(h.coat_n, v3(0, 0, 1), 1e-6f, "coat without a map under a mapped base");
    CHECK(h.shading.n.z < 0.99f, "the base's map is not applied (%g)", h.shading.n.z);
    scene_destroy(s);
}

/* The coat alone (a black base without a specular lobe): on the flat plane whose coat map tilts
 * the coat, the same ray returns what the coat of the plane tilted for real returns, for lights
 * from several directions. */
static void test_coat_tilt(void) {
    const float theta = 0.35f;
    unsigned char texel[3] = {128, (unsigned char)lroundf((sinf(theta) + 1.0f) * 127.5f),
                              (unsigned char)lroundf((cosf(theta) + 1.0f) * 127.5f)};
    vec3 n_map = normalize3(texel_normal(texel, 1.0f));
    const vec3 to_light[3] = {normalize3(v3(0.1f, 0.5f, 1.0f)), normalize3(v3(-0.3f, 0.9f, 0.6f)),
                              normalize3(v3(0.4f, -0.2f, 1.0f))};
    for (int k = 0; k < 3; k++) {
        vec3 out[2];
        for (int geometric = 0; geometric < 2; geometric++) {
            scene *s = ts_new("coat tilt");
            material m = material_default();
            m.base_color = v3s(0.0f);
            m.ext.specular = 0.0f;
            m.ext.clearcoat = 1.0f;
            m.ext.clearcoat_roughness = 0.4f;
            if (geometric)
                tilted_square(s, ts_material(s, m), n_map);
            else
                square(s, coat_material(s, m, texel, 1.0f, NULL), 0);
            out[geometric] = direct_at_centre(s, neg3(to_light[k]), "coat tilt");
        }
        CHECK(out[1].x > 1e-3f, "coat tilt %d: the tilted plane's coat reflects nothing (%g)", k, out[1].x);
        /* 1e-3: near its peak the float GGX moves by a few 1e-4 for float-sized changes of direction
         * (both differ from a double-precision evaluation by 4e-4 at the second light); an untilted
         * coat is off by more than 10%. */
        CHECK_NEAR(out[0].x, out[1].x, 1e-3f * out[1].x, "coat tilt: the mapped coat against the tilted plane's");
    }
}

/* Virtual lights see mapped normals as the path tracer does: light tracing's adjoint with
 * shading normals (vlights.c). A closed room whose walls carry a bumpy map: VSL's indirect light
 * converges to the path tracer's (without the adjoint's factors it came out 4% bright). */
static void test_vsl_matches_pt(void) {
    scene *s = ts_new("bumpy room");
    unsigned char px[32 * 32 * 4];
    ts_random_normal_map(px, 32 * 32, 5, 0.7f);
    material m = ts_phong(v3(0.7f, 0.6f, 0.5f), v3s(0), 1.0f);
    m.normal_tex = (texture_slot){.texture = ts_texture(s, 32, 32, px)};
    int wall = ts_material(s, m);
    int lamp = ts_lambert(s, v3s(0), v3s(3.0f), 0);
    ts_box(s, v3(-1, 0, -1), v3(1, 2, 1), 1, wall);
    ts_quad(s, v3(-0.3f, 1.99f, -0.3f), v3(0.3f, 1.99f, -0.3f), v3(0.3f, 1.99f, 0.3f), v3(-0.3f, 1.99f, 0.3f), lamp);
    ts_finalize(s);
    camera cam = camera_look_at(v3(0, 1.0f, 0.95f), v3(0, 0.6f, 0), v3(0, 1, 0), 1.3f);
    const int w = 32, h = 24;
    double mean[2], sem[2];
    for (int k = 0; k < 2; k++) {
        render_params p = {.width = w, .height = h, .max_depth = 8, .method = k ? METHOD_VSL : METHOD_PT, .seed = 3};
        float *img = ts_render_with(s, &cam, &p, k ? 256 : 1024, 1u << COMP_INDIRECT);
        ts_stats(img, w * h, &mean[k], &sem[k]);
        free(img);
    }
    printf("bumpy room, indirect: pt %.5f, vsl %.5f\n", mean[0], mean[1]);
    CHECK(mean[0] > 0.01, "the room is dark: %g", mean[0]);
    CHECK_NEAR(mean[1] / mean[0], 1.0, 0.015, "vsl's indirect light against the path tracer's in a normal-mapped room");
    scene_destroy(s);
}

static int num_warnings; /* about normal or occlusion maps */
static char last_warning[512];

static void on_warn(void *user, const char *msg) {
    (void)user;
    if (!strstr(msg, "normal map") && !strstr(msg, "normalTexture") && !strstr(msg, "occlusion")) return;
    num_warnings++;
    snprintf(last_warning, sizeof last_warning, "%s", msg);
}

/* From a file: normalTexture's texture, texCoord and scale, tangents generated from that uv set
 * (TEXCOORD_1 lays the image mirrored and upside down), the occlusion map ignored without a word;
 * a scale that is no number is one line of error. */
static void test_gltf(void) {
    const unsigned char texel[3] = {200, 90, 230};
    unsigned char px[16];
    for (int i = 0; i < 4; i++) memcpy(px + 4 * i, (unsigned char[4]){texel[0], texel[1], texel[2], 255}, 4);
    gt_image im = {2, 2, px};
    char *json = gt_gltf("[{\"normalTexture\":{\"index\":0,\"texCoord\":1,\"scale\":0.5},"
                         "\"occlusionTexture\":{\"index\":0}}]",
                         "[{\"source\":0}]", NULL, &im, 1, "", "");
    char err[512] = "";
    num_warnings = 0;
    scene *s = scene_load_memory(json, strlen(json), ".", "normal.gltf", on_warn, NULL, err, sizeof err);
    CHECK(s != NULL, "normal.gltf: %s", err);
    CHECK(num_warnings == 0, "normal.gltf: %d warnings, the last: %s", num_warnings, last_warning);
    if (s) {
        const material *m = &s->materials[0];
        CHECK(m->normal_tex.texture >= 0 && m->normal_tex.texcoord == 1 && m->normal_scale == 0.5f,
              "normalTexture read as texture %d, texCoord %d, scale %g", m->normal_tex.texture, m->normal_tex.texcoord,
              m->normal_scale);
        surface_hit h;
        CHECK(scene_intersect(s, v3(0.3f, 0.6f, 2), v3(0, 0, -1), INFINITY, &h), "normal.gltf: no hit");
        vec3 t = texel_normal(texel, 0.5f);
        check_vec(h.shading.n, normalize3(v3(-t.x, -t.y, t.z)), 1e-5f, "normal map through TEXCOORD_1");
        scene_destroy(s);
    }
    free(json);
    json = gt_gltf("[{\"normalTexture\":{\"index\":0,\"scale\":1e300}}]", "[{\"source\":0}]", NULL, &im, 1, "", "");
    s = scene_load_memory(json, strlen(json), ".", "scale.gltf", on_warn, NULL, err, sizeof err);
    CHECK(!s && strstr(err, "scale.gltf: ") == err && strstr(err, "normalTexture.scale") && one_line(err),
          "a scale of 1e300: %s", s ? "loaded" : err);
    scene_destroy(s);
    free(json);
    /* The coat's own map, read without a warning; its scale checked as normalTexture's. */
    const char *coats[2] = {"0.5", "1e300"};
    for (int k = 0; k < 2; k++) {
        char mats[256];
        snprintf(mats, sizeof mats,
                 "[{\"extensions\":{\"KHR_materials_clearcoat\":{\"clearcoatFactor\":1,"
                 "\"clearcoatNormalTexture\":{\"index\":0,\"scale\":%s}}}}]",
                 coats[k]);
        json = gt_gltf(mats, "[{\"source\":0}]", NULL, &im, 1, "", "\"extensionsUsed\":[\"KHR_materials_clearcoat\"]");
        num_warnings = 0;
        s = scene_load_memory(json, strlen(json), ".", "coat.gltf", on_warn, NULL, err, sizeof err);
        if (k == 0) {
            CHECK(s && num_warnings == 0, "coat.gltf: %s (%d warnings, the last: %s)", s ? "loaded" : err, num_warnings,
                  last_warning);
            if (s)
                CHECK(s->materials[0].ext.clearcoat_normal_tex.texture >= 0 &&
                          s->materials[0].ext.clearcoat_normal_scale == 0.5f,
                      "clearcoatNormalTexture read as texture %d, scale %g",
                      s->materials[0].ext.clearcoat_normal_tex.texture, s->materials[0].ext.clearcoat_normal_scale);
        } else {
            CHECK(!s && strstr(err, "coat.gltf: ") == err && strstr(err, "clearcoatNormalTexture.scale") &&
                      one_line(err),
                  "a coat map's scale of 1e300: %s", s ? "loaded" : err);
        }
        scene_destroy(s);
        free(json);
    }
}

int main(void) {
    test_known_texel();
    test_gltf();
    test_generated_tangents();
    test_degenerate_texels();
    test_no_leaks();
    test_tilt_matches_geometry();
    test_glossy_tilt();
    test_coat_texel();
    test_coat_tilt();
    test_vsl_matches_pt();
    test_file_tangents("water-bottle/glTF/WaterBottle.gltf");
    test_file_tangents("lights-punctual-lamp/glTF/LightsPunctualLamp.gltf");
    test_file_tangents("anisotropy-rotation-test/glTF/AnisotropyRotationTest.gltf");
    return check_exit("test_normalmap");
}
