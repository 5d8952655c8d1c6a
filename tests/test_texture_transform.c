/* KHR_texture_transform: the extension's matrix (offset, rotation, scale) in closed form at the
 * one place uv is looked up; the texCoord override; every texture slot of a file transformed; a
 * transformed normal map equal to one on uvs transformed in the mesh; bad values refused in one
 * line. */
#define _POSIX_C_SOURCE 200809L
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "gltf_textured.h"
#include "rng.h"
#include "test_scenes.h"

/* A 4 x 4 texture whose texel (i, j) (column i, row j from the top) has red 60 i, green 60 j. */
static int grid_texture(scene *s) {
    unsigned char px[4 * 4 * 4];
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 4; i++) {
            unsigned char *p = px + 4 * (4 * j + i);
            p[0] = (unsigned char)(60 * i), p[1] = (unsigned char)(60 * j), p[2] = 0, p[3] = 255;
        }
    return ts_texture(s, 4, 4, px);
}

/* The extension's matrix: translation * rotation * scale, rotation [c s; -s c]. */
static texture_slot transformed(int tex, double ox, double oy, double rot, double sx, double sy) {
    texture_slot t = {.texture = tex, .transformed = 1};
    double c = cos(rot), sn = sin(rot);
    float m[6] = {(float)(c * sx), (float)(sn * sy), (float)ox, (float)(-sn * sx), (float)(c * sy), (float)oy};
    memcpy(t.uv_xf, m, sizeof m);
    return t;
}

/* For uv' the centre of texel (i, j), the uv the transform takes there (the matrix inverted by
 * hand), looked up: texel (i, j) exactly. */
static void test_closed_form(void) {
    scene *s = ts_new("transform");
    int tex = grid_texture(s);
    const double cases[][5] = {{0.5, 0.0, 0.0, 1.0, 1.0},     {0.0, 0.5, 0.0, 1.0, 1.0},
                               {0.25, 0.5, 0.0, 2.0, 0.5},    {0.0, 0.0, 0.392699, 1.0, 1.0},
                               {0.1, -0.3, 1.5708, 1.5, 1.5}, {0.7, 0.2, -2.0, -1.0, 3.0}};
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        const double *c = cases[k];
        texture_slot slot = transformed(tex, c[0], c[1], c[2], c[3], c[4]);
        for (int j = 0; j < 4; j++)
            for (int i = 0; i < 4; i++) {
                /* uv' = R S uv + o  =>  uv = S^-1 R^T (uv' - o), R = [cos sin; -sin cos]. */
                double up = (i + 0.5) / 4.0 - c[0], vp = (j + 0.5) / 4.0 - c[1];
                double cr = cos(c[2]), sr = sin(c[2]);
                double u = (cr * up - sr * vp) / c[3], v = (sr * up + cr * vp) / c[4];
                vec4 got = texture_lookup(s, slot, v2((float)u, (float)v), v2(9, 9), 0);
                CHECK(fabsf(got.x - 60.0f * i / 255.0f) < 2e-3f && fabsf(got.y - 60.0f * j / 255.0f) < 2e-3f,
                      "case %zu, texel (%d, %d): got (%g, %g), expected (%g, %g)", k, i, j, got.x * 255.0f,
                      got.y * 255.0f, 60.0f * i, 60.0f * j);
            }
    }
    /* The override reads the other uv set. */
    texture_slot slot = transformed(tex, 0.0, 0.0, 0.0, 1.0, 1.0);
    slot.texcoord = 1;
    vec4 got = texture_lookup(s, slot, v2(0.9f, 0.9f), v2(0.125f, 0.375f), 0);
    CHECK(fabsf(got.x) < 1e-6f && fabsf(got.y - 60.0f / 255.0f) < 1e-6f, "texCoord 1: (%g, %g)", got.x, got.y);
    scene_destroy(s);
}

/* A transformed normal map on the square equals the untransformed map on the square whose uvs
 * were transformed (tangents generated from them): rotations, non-uniform and mirroring scales. */
static void test_normal_map(void) {
    unsigned char px[8 * 8 * 4];
    ts_random_normal_map(px, 8 * 8, 9, 0.6f);
    const double cases[][5] = {
        {0.3, 0.1, 0.7, 1.0, 1.0}, {0.0, 0.0, 2.5, 2.0, 0.5}, {0.2, 0.0, 0.0, -1.0, 1.0}, {0.0, 0.4, -1.0, 1.5, -0.75}};
    const vec3 p[4] = {v3(0, 0, 0), v3(1, 0, 0), v3(1, 1, 0), v3(0, 1, 0)};
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        frame3 frames[2][16];
        for (int baked = 0; baked < 2; baked++) {
            scene *s = ts_new("normal transform");
            int tex = ts_texture(s, 8, 8, px);
            texture_slot slot = transformed(tex, cases[k][0], cases[k][1], cases[k][2], cases[k][3], cases[k][4]);
            float uv[8];
            for (int i = 0; i < 4; i++) {
                float u = p[i].x, v = 1.0f - p[i].y;
                uv[2 * i] = baked ? slot.uv_xf[0] * u + slot.uv_xf[1] * v + slot.uv_xf[2] : u;
                uv[2 * i + 1] = baked ? slot.uv_xf[3] * u + slot.uv_xf[4] * v + slot.uv_xf[5] : v;
            }
            material m = material_default();
            m.normal_tex = baked ? (texture_slot){.texture = tex} : slot;
            ts_quad_uv(s, p, uv, ts_material(s, m));
            ts_finalize(s);
            for (int q = 0; q < 16; q++) {
                surface_hit h;
                vec3 o = v3(0.11f + 0.25f * (float)(q % 4), 0.13f + 0.25f * (float)(q / 4), 2.0f);
                CHECK(scene_intersect(s, o, v3(0, 0, -1), INFINITY, &h), "normal transform: no hit");
                frames[baked][q] = h.shading;
            }
            scene_destroy(s);
        }
        for (int q = 0; q < 16; q++) {
            vec3 a = frames[0][q].n, b = frames[1][q].n;
            CHECK(length3(sub3(a, b)) < 1e-4f, "case %zu, point %d: transformed map (%g %g %g), baked uvs (%g %g %g)",
                  k, q, a.x, a.y, a.z, b.x, b.y, b.z);
        }
    }
}

static int num_warnings;
static char last_warning[512];
static void on_warn(void *user, const char *msg) {
    (void)user;
    if (!strstr(msg, "KHR_texture_transform") && !strstr(msg, "TEXCOORD")) return;
    num_warnings++;
    snprintf(last_warning, sizeof last_warning, "%s", msg);
}

static scene *load_json(const char *json, const char *name, char *err, size_t errlen) {
    num_warnings = 0;
    return scene_load_memory(json, strlen(json), ".", name, on_warn, NULL, err, errlen);
}

/* From a file: each slot carries its own transform and texCoord override; the extension is
 * supported (no warning); the square's base colour follows the transform. */
static void test_gltf(void) {
    unsigned char px[4 * 4 * 4];
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 4; i++) {
            unsigned char *q = px + 4 * (4 * j + i);
            q[0] = (unsigned char)(60 * i), q[1] = (unsigned char)(60 * j), q[2] = 128, q[3] = 255;
        }
    gt_image im = {4, 4, px};
#define TT(o, r, sc) "\"extensions\":{\"KHR_texture_transform\":{\"offset\":" o ",\"rotation\":" r ",\"scale\":" sc "}}"
    const char *materials =
        "[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0,\"extensions\":{\"KHR_texture_transform\":"
        "{\"offset\":[0.25,0],\"rotation\":1.5707963,\"scale\":[1,2],\"texCoord\":1}}},"
        "\"metallicRoughnessTexture\":{\"index\":0," TT(
            "[0.5,0]", "0", "[1,1]") "}},"
                                     "\"normalTexture\":{\"index\":0," TT(
                                         "[0,0.5]", "0",
                                         "[1,1]") "},"
                                                  "\"occlusionTexture\":{\"index\":0," TT(
                                                      "[0,0]", "0",
                                                      "[3,3]") "},"
                                                               "\"emissiveTexture\":{\"index\":0," TT(
                                                                   "[0,0]", "0.5",
                                                                   "[1,1]") "},\"emissiveFactor\":[1,1,1],"
                                                                            "\"extensions\":{\"KHR_materials_"
                                                                            "anisotropy\":{\"anisotropyStrength\":0.5,"
                                                                            "\"anisotropyTexture\":{\"index\":0,"
                                                                            "\"texCoord\":0," TT("[0,0]", "0",
                                                                                                 "[4,4]") "}}}}]";
#undef TT
    char *json = gt_gltf(materials, "[{\"source\":0}]", NULL, &im, 1, "",
                         "\"extensionsUsed\":[\"KHR_texture_transform\",\"KHR_materials_anisotropy\"]");
    char err[512] = "";
    scene *s = load_json(json, "transform.gltf", err, sizeof err);
    CHECK(s != NULL, "transform.gltf: %s", err);
    CHECK(num_warnings == 0, "transform.gltf: %d warnings, the last: %s", num_warnings, last_warning);
    if (s) {
        const material *m = &s->materials[0];
        const texture_slot *b = &m->base_color_tex;
        CHECK(b->transformed && b->texcoord == 1, "base colour: transformed %d, texCoord %d", b->transformed,
              b->texcoord);
        /* rotation pi/2, scale (1, 2), offset (0.25, 0): u' = 2 v + 0.25, v' = -u. */
        CHECK(fabsf(b->uv_xf[0]) < 1e-6f && fabsf(b->uv_xf[1] - 2.0f) < 1e-6f && b->uv_xf[2] == 0.25f &&
                  fabsf(b->uv_xf[3] + 1.0f) < 1e-6f && fabsf(b->uv_xf[4]) < 1e-6f && b->uv_xf[5] == 0.0f,
              "base colour matrix (%g %g %g; %g %g %g)", b->uv_xf[0], b->uv_xf[1], b->uv_xf[2], b->uv_xf[3],
              b->uv_xf[4], b->uv_xf[5]);
        CHECK(m->metal_rough_tex.transformed && m->metal_rough_tex.uv_xf[2] == 0.5f, "metallic-roughness transform");
        CHECK(m->normal_tex.transformed && m->normal_tex.uv_xf[5] == 0.5f, "normal transform");
        CHECK(m->emissive_tex.transformed && fabsf(m->emissive_tex.uv_xf[1] - sinf(0.5f)) < 1e-6f,
              "emissive transform");
        CHECK(m->anisotropy_tex.transformed && m->anisotropy_tex.uv_xf[0] == 4.0f, "anisotropy transform");
        /* At (x, y) = (0.3, 0.6) uv1 = (0.7, 0.6): u' = 1.45, v' = -0.7, with repeat texel
         * coordinates (1.3, 0.7): red 60 x 1.3, green 60 x 0.7. */
        surface_hit h;
        CHECK(scene_intersect(s, v3(0.3f, 0.6f, 2), v3(0, 0, -1), INFINITY, &h), "transform.gltf: no hit");
        vec4 c = texture_lookup(s, *b, h.uv0, h.uv1, 0);
        CHECK(fabsf(c.x * 255.0f - 78.0f) < 0.5f && fabsf(c.y * 255.0f - 42.0f) < 0.5f,
              "base colour at the hit: (%g, %g), expected (78, 42)", c.x * 255.0f, c.y * 255.0f);
        scene_destroy(s);
    }
    free(json);

    /* Values that are no numbers, too large, or of the wrong shape: one line naming the file. */
    const char *bad[] = {
        "\"offset\":[1e300,0]", "\"scale\":[1,2,3]", "\"rotation\":1e9", "\"scale\":\"big\"", "\"texCoord\":-1",
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        char mat[256];
        snprintf(mat, sizeof mat,
                 "[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0,\"extensions\":"
                 "{\"KHR_texture_transform\":{%s}}}}}]",
                 bad[k]);
        json = gt_gltf(mat, "[{\"source\":0}]", NULL, &im, 1, "", "");
        s = load_json(json, "bad.gltf", err, sizeof err);
        CHECK(!s && strstr(err, "bad.gltf: ") == err && strstr(err, "KHR_texture_transform") && one_line(err), "%s: %s",
              bad[k], s ? "loaded" : err);
        scene_destroy(s);
        free(json);
    }
}

int main(void) {
    test_closed_form();
    test_normal_map();
    test_gltf();
    return check_exit("test_texture_transform");
}
