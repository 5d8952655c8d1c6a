/* The glTF loader: what it must read (hierarchy and transforms, every index type, non-indexed
 * meshes, missing normals, KHR_lights_punctual units, cameras, the papers' material extras,
 * emissive strength, GLB) and every malformed input the foundation issue lists, each of which must
 * fail with one clear line naming the file. The test writes its glTF files itself, from a small
 * binary buffer whose contents it knows. */
#define _POSIX_C_SOURCE 200809L
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "lights.h"
#include "rng.h"
#include "sampling.h"
#include "scene.h"
#include "scratch.h"

static char tmp_dir[512];

/* ---- building test files ------------------------------------------------------------------ */

/* The shared binary buffer (152 bytes):
 *   0  positions: unit quad in z = 0 (4 x vec3)       48  normals (+z)
 *   96 uint16 indices 0 1 2 0 2 3                     108 uint8 indices (6, padded to 116)
 *   116 uint32 indices                                140 uint16 indices with 9 (out of range) */
enum { BIN_SIZE = 152 };
static unsigned char bin[BIN_SIZE];

static void make_bin(void) {
    const float pos[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    const float nrm[12] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
    const uint16_t i16[6] = {0, 1, 2, 0, 2, 3};
    const uint8_t i8[6] = {0, 1, 2, 0, 2, 3};
    const uint32_t i32[6] = {0, 1, 2, 0, 2, 3};
    const uint16_t bad[6] = {0, 1, 9, 0, 2, 3};
    memset(bin, 0, sizeof bin);
    memcpy(bin + 0, pos, 48);
    memcpy(bin + 48, nrm, 48);
    memcpy(bin + 96, i16, 12);
    memcpy(bin + 108, i8, 6);
    memcpy(bin + 116, i32, 24);
    memcpy(bin + 140, bad, 12);
}

static const char *VIEWS_AND_ACCESSORS =
    "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":48},"
    "{\"buffer\":0,\"byteOffset\":48,\"byteLength\":48},{\"buffer\":0,\"byteOffset\":96,\"byteLength\":12},"
    "{\"buffer\":0,\"byteOffset\":108,\"byteLength\":6},{\"buffer\":0,\"byteOffset\":116,\"byteLength\":24},"
    "{\"buffer\":0,\"byteOffset\":140,\"byteLength\":12}],"
    "\"accessors\":["
    "{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[1,1,0]},"
    "{\"bufferView\":1,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
    "{\"bufferView\":2,\"componentType\":5123,\"count\":6,\"type\":\"SCALAR\"},"
    "{\"bufferView\":3,\"componentType\":5121,\"count\":6,\"type\":\"SCALAR\"},"
    "{\"bufferView\":4,\"componentType\":5125,\"count\":6,\"type\":\"SCALAR\"},"
    "{\"bufferView\":5,\"componentType\":5123,\"count\":6,\"type\":\"SCALAR\"},"
    "{\"bufferView\":0,\"componentType\":5126,\"count\":400,\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[1,1,0]},"
    "{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[1,1,0]}]";

/* Accessor numbers in VIEWS_AND_ACCESSORS. */
enum { ACC_POS = 0, ACC_NRM, ACC_I16, ACC_I8, ACC_I32, ACC_BAD_INDEX, ACC_POS_OVERRUN, ACC_POS_TRI };

static const char *DEFAULT_MESH =
    "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},\"indices\":2}]}]";
static const char *DEFAULT_NODES = "\"nodes\":[{\"mesh\":0}]";

static void write_bytes(const char *path, const void *data, size_t size) {
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(data, 1, size, f) != size) {
        fprintf(stderr, "cannot write %s\n", path);
        exit(1);
    }
    fclose(f);
}

/* The JSON of a glTF using the shared buffer (embedded as a data URI unless uri is given),
 * with nodes, meshes and any extra top-level members. Returns a static buffer. */
static const char *gltf_json(const char *nodes, const char *meshes, const char *extra, const char *uri) {
    static char json[16384];
    char b64[256], data_uri[300];
    base64(bin, BIN_SIZE, b64);
    snprintf(data_uri, sizeof data_uri, "data:application/octet-stream;base64,%s", b64);
    snprintf(json, sizeof json,
             "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],%s,%s,"
             "\"buffers\":[{\"byteLength\":%d,\"uri\":\"%s\"}],%s%s%s}",
             nodes ? nodes : DEFAULT_NODES, meshes ? meshes : DEFAULT_MESH, BIN_SIZE, uri ? uri : data_uri,
             VIEWS_AND_ACCESSORS, extra && *extra ? "," : "", extra ? extra : "");
    return json;
}

static const char *tmp_path(const char *name) {
    static char paths[4][1024];
    static int next = 0;
    char *p = paths[next++ & 3];
    snprintf(p, 1024, "%s/%s", tmp_dir, name);
    return p;
}

static const char *write_gltf(const char *name, const char *json) {
    const char *path = tmp_path(name);
    write_bytes(path, json, strlen(json));
    return path;
}

/* A GLB: header, JSON chunk (space-padded), BIN chunk. Returns its size in buf. */
static size_t make_glb(const char *json, unsigned char *buf, size_t cap) {
    size_t jlen = strlen(json), jpad = (jlen + 3) & ~(size_t)3;
    size_t total = 12 + 8 + jpad + 8 + BIN_SIZE;
    if (total > cap) exit(1);
    uint32_t h[3] = {0x46546C67u, 2, (uint32_t)total};
    memcpy(buf, h, 12);
    uint32_t jc[2] = {(uint32_t)jpad, 0x4E4F534Au};
    memcpy(buf + 12, jc, 8);
    memcpy(buf + 20, json, jlen);
    memset(buf + 20 + jlen, ' ', jpad - jlen);
    uint32_t bc[2] = {BIN_SIZE, 0x004E4942u};
    memcpy(buf + 20 + jpad, bc, 8);
    memcpy(buf + 28 + jpad, bin, BIN_SIZE);
    return total;
}

/* ---- loading ------------------------------------------------------------------------------ */

static int num_warnings;
static char last_warning[512];

static char all_warnings[4096];

static void on_warn(void *user, const char *msg) {
    (void)user;
    num_warnings++;
    snprintf(last_warning, sizeof last_warning, "%s", msg);
    size_t n = strlen(all_warnings);
    snprintf(all_warnings + n, sizeof all_warnings - n, "%s\n", msg);
}

static scene *load(const char *path, char *err, size_t errlen) {
    num_warnings = 0;
    last_warning[0] = 0;
    all_warnings[0] = 0;
    err[0] = 0;
    return scene_load(path, on_warn, NULL, err, errlen);
}

/* The load must fail with one line naming the file and containing `expect` (case-sensitive). */
static void expect_error(const char *what, const char *path, const char *expect) {
    char err[512];
    scene *s = load(path, err, sizeof err);
    CHECK(s == NULL, "%s: loaded, expected an error", what);
    if (s) scene_destroy(s);
    const char *base = strrchr(path, '/') ? strrchr(path, '/') + 1 : path;
    CHECK(strstr(err, base) != NULL, "%s: error does not name the file: '%s'", what, err);
    CHECK(strchr(err, '\n') == NULL, "%s: error is not one line: '%s'", what, err);
    CHECK(expect == NULL || strstr(err, expect) != NULL, "%s: error '%s' lacks '%s'", what, err, expect);
}

static int has_vertex(const scene *s, vec3 p) {
    for (int i = 0; i < s->num_vertices; i++)
        if (length3(sub3(s->positions[i], p)) < 1e-5f) return 1;
    return 0;
}

static void test_hierarchy(void) {
    char err[512];
    /* Parent: translate (1,2,3), scale 2; child: 90 degrees about +z. (1,0,0) -> (0,1,0) -> (0,2,0)
     * -> (1,4,3). A second root uses a column-major matrix for the same translation. */
    const char *nodes = "\"nodes\":[{\"children\":[1,3]},"
                        "{\"children\":[2],\"translation\":[1,2,3],\"scale\":[2,2,2]},"
                        "{\"mesh\":0,\"rotation\":[0,0,0.70710678,0.70710678]},"
                        "{\"mesh\":0,\"matrix\":[1,0,0,0, 0,1,0,0, 0,0,1,0, 10,20,30,1]}]";
    const char *buf = gltf_json(nodes, NULL, NULL, NULL);
    scene *s = load(write_gltf("hierarchy.gltf", buf), err, sizeof err);
    CHECK(s != NULL, "hierarchy: %s", err);
    if (!s) return;
    CHECK(s->num_triangles == 4, "hierarchy: %d triangles", s->num_triangles);
    CHECK(has_vertex(s, v3(1, 2, 3)) && has_vertex(s, v3(1, 4, 3)) && has_vertex(s, v3(-1, 4, 3)) &&
              has_vertex(s, v3(-1, 2, 3)),
          "hierarchy: child transform wrong");
    CHECK(has_vertex(s, v3(10, 20, 30)) && has_vertex(s, v3(11, 21, 30)), "hierarchy: matrix node wrong");
    /* Normals follow the rotation (still +z). */
    CHECK(fabsf(s->normals[0].z - 1.0f) < 1e-5f, "hierarchy: normal (%g %g %g)", s->normals[0].x, s->normals[0].y,
          s->normals[0].z);
    scene_destroy(s);
}

static void test_index_types(void) {
    char err[512];
    const int acc[3] = {ACC_I8, ACC_I16, ACC_I32};
    for (int k = 0; k < 3; k++) {
        char meshes[256];
        snprintf(meshes, sizeof meshes,
                 "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},\"indices\":%d}]}]",
                 acc[k]);
        scene *s = load(write_gltf("indices.gltf", gltf_json(NULL, meshes, NULL, NULL)), err, sizeof err);
        CHECK(s != NULL && s->num_triangles == 2, "index accessor %d: %s", acc[k], s ? "wrong triangle count" : err);
        if (s) {
            /* Both triangles span the quad: total area 1. */
            double area = 0.0;
            for (int t = 0; t < s->num_triangles; t++) {
                const uint32_t *v = &s->indices[3 * t];
                area += 0.5 * length3(cross3(sub3(s->positions[v[1]], s->positions[v[0]]),
                                             sub3(s->positions[v[2]], s->positions[v[0]])));
            }
            CHECK_NEAR(area, 1.0, 1e-5, "index accessor %d: area", acc[k]);
            scene_destroy(s);
        }
    }
    /* Non-indexed, and without normals: flat normals from the winding (+z). */
    char meshes[128];
    snprintf(meshes, sizeof meshes, "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":%d}}]}]", ACC_POS_TRI);
    scene *s = load(write_gltf("nonindexed.gltf", gltf_json(NULL, meshes, NULL, NULL)), err, sizeof err);
    CHECK(s != NULL && s->num_triangles == 1, "non-indexed: %s", s ? "wrong triangle count" : err);
    if (s) {
        for (int i = 0; i < s->num_vertices; i++)
            CHECK(fabsf(s->normals[i].z - 1.0f) < 1e-5f, "generated normal %d = (%g %g %g)", i, s->normals[i].x,
                  s->normals[i].y, s->normals[i].z);
        scene_destroy(s);
    }
}

static void test_lights_cameras(void) {
    char err[512];
    /* Node 0 holds the mesh; nodes 1-3 the lights; node 4 the camera. The spot node turns -z
     * (a light's direction) into -y: rotation of -90 degrees... +90 about +x maps -z to +y, so
     * use -90 about x: q = (-sin 45, 0, 0, cos 45). */
    const char *nodes = "\"nodes\":[{\"mesh\":0,\"children\":[1,2,3,4]},"
                        "{\"translation\":[0,5,0],\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}},"
                        "{\"translation\":[1,2,3],\"rotation\":[-0.70710678,0,0,0.70710678],"
                        "\"extensions\":{\"KHR_lights_punctual\":{\"light\":1}}},"
                        "{\"extensions\":{\"KHR_lights_punctual\":{\"light\":2}}},"
                        "{\"translation\":[0,1,5],\"camera\":0}]";
    const char *extra =
        "\"extensionsUsed\":[\"KHR_lights_punctual\"],"
        "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":["
        "{\"type\":\"point\",\"intensity\":10,\"color\":[1,0.5,0.25]},"
        "{\"type\":\"spot\",\"intensity\":20,\"spot\":{\"innerConeAngle\":0.2,\"outerConeAngle\":0.5}},"
        "{\"type\":\"directional\",\"intensity\":3}]}},"
        "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.8,\"znear\":0.1,\"aspectRatio\":1.5}}]";
    scene *s = load(write_gltf("lights.gltf", gltf_json(nodes, NULL, extra, NULL)), err, sizeof err);
    CHECK(s != NULL, "lights: %s", err);
    if (!s) return;
    int found = 0;
    for (int i = 0; i < s->num_lights; i++) {
        const light *l = &s->lights[i];
        if (l->type == LIGHT_POINT) {
            found |= 1;
            CHECK(length3(sub3(l->color, v3(10, 5, 2.5f))) < 1e-4f, "point light colour x intensity");
            CHECK(length3(sub3(l->position, v3(0, 5, 0))) < 1e-5f, "point light position");
        } else if (l->type == LIGHT_SPOT) {
            found |= 2;
            CHECK(length3(sub3(l->position, v3(1, 2, 3))) < 1e-5f, "spot position");
            CHECK(length3(sub3(l->direction, v3(0, -1, 0))) < 1e-5f, "spot direction (%g %g %g)", l->direction.x,
                  l->direction.y, l->direction.z);
            CHECK_NEAR(l->cos_inner, cos(0.2), 1e-6, "spot inner cone");
            CHECK_NEAR(l->cos_outer, cos(0.5), 1e-6, "spot outer cone");
            CHECK_NEAR(l->color.x, 20.0, 1e-5, "spot intensity (candela)");
        } else if (l->type == LIGHT_DIRECTIONAL) {
            found |= 4;
            CHECK(length3(sub3(l->direction, v3(0, 0, -1))) < 1e-5f, "directional light shines along -z");
            CHECK_NEAR(l->color.y, 3.0, 1e-6, "directional illuminance (lux)");
        }
    }
    CHECK(found == 7, "lights: found mask %d of 7", found);
    CHECK(s->num_cameras == 1, "cameras: %d", s->num_cameras);
    if (s->num_cameras == 1) {
        const camera *c = &s->cameras[0];
        CHECK_NEAR(c->yfov, 0.8, 1e-6, "camera yfov");
        CHECK(length3(sub3(c->position, v3(0, 1, 5))) < 1e-5f, "camera position");
        CHECK(length3(sub3(c->forward, v3(0, 0, -1))) < 1e-5f, "camera looks along -z");
    }
    scene_destroy(s);
}

static void test_materials(void) {
    char err[512];
    const char *meshes = "\"meshes\":[{\"primitives\":["
                         "{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},\"indices\":2,\"material\":0},"
                         "{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},\"indices\":3,\"material\":1},"
                         "{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},\"indices\":4,\"material\":2},"
                         "{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},\"indices\":2,\"material\":3}]}]";
    const char *extra =
        "\"extensionsUsed\":[\"KHR_materials_emissive_strength\",\"KHR_materials_clearcoat\",\"EXT_made_up\","
        "\"KHR_materials_sheen\",\"KHR_materials_specular\",\"KHR_materials_ior\",\"KHR_materials_transmission\","
        "\"KHR_materials_volume\"],"
        "\"materials\":["
        "{\"name\":\"phong\",\"extras\":{\"glint\":{\"model\":\"phong\",\"kd\":[0.1,0.2,0.3],\"ks\":[0.5,0.5,0.5],"
        "\"exponent\":250}}},"
        "{\"name\":\"ward\",\"extras\":{\"glint\":{\"model\":\"ward\",\"kd\":[0,0,0],\"ks\":[0.9,0.8,0.7],"
        "\"alpha_x\":0.05,\"alpha_y\":0.3,\"rotation\":0.5}}},"
        "{\"name\":\"lamp\",\"emissiveFactor\":[1,0.5,0.5],"
        "\"extensions\":{\"KHR_materials_emissive_strength\":{\"emissiveStrength\":40}}},"
        "{\"name\":\"coated\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.5,0.5,0.5,1],\"metallicFactor\":1,"
        "\"roughnessFactor\":0.2},\"extensions\":{\"KHR_materials_clearcoat\":{\"clearcoatFactor\":1,"
        "\"clearcoatRoughnessFactor\":0.3},"
        "\"KHR_materials_sheen\":{\"sheenColorFactor\":[0.1,0.2,1.5],\"sheenRoughnessFactor\":0.4},"
        "\"KHR_materials_specular\":{\"specularFactor\":0.5,\"specularColorFactor\":[2,1,0.5]},"
        "\"KHR_materials_ior\":{\"ior\":1.33},\"KHR_materials_transmission\":{\"transmissionFactor\":1.5},"
        "\"KHR_materials_volume\":{\"thicknessFactor\":0.1,\"attenuationDistance\":2,"
        "\"attenuationColor\":[0.5,1.2,0.25]}}}]";
    scene *s = load(write_gltf("materials.gltf", gltf_json(NULL, meshes, extra, NULL)), err, sizeof err);
    CHECK(s != NULL, "materials: %s", err);
    if (!s) return;
    CHECK(s->num_materials >= 4, "materials: %d", s->num_materials);
    int seen = 0;
    for (int i = 0; i < s->num_materials; i++) {
        const material *m = &s->materials[i];
        if (!strcmp(m->name, "phong")) {
            seen |= 1;
            CHECK(m->model == MATERIAL_PHONG && m->exponent == 250.0f && fabsf(m->kd.z - 0.3f) < 1e-6f, "phong extras");
        } else if (!strcmp(m->name, "ward")) {
            seen |= 2;
            CHECK(m->model == MATERIAL_WARD && fabsf(m->alpha_x - 0.05f) < 1e-6f && fabsf(m->alpha_y - 0.3f) < 1e-6f &&
                      fabsf(m->anisotropy_rotation - 0.5f) < 1e-6f,
                  "ward extras");
        } else if (!strcmp(m->name, "lamp")) {
            seen |= 4;
            CHECK(length3(sub3(m->emission, v3(40, 20, 20))) < 1e-4f, "emissive strength: (%g %g %g)", m->emission.x,
                  m->emission.y, m->emission.z);
        } else if (!strcmp(m->name, "coated")) {
            seen |= 8;
            CHECK(m->metallic == 1.0f && fabsf(m->roughness - 0.2f) < 1e-6f, "metallic-roughness factors");
            const material_ext *x = &m->ext;
            CHECK(x->clearcoat == 1.0f && fabsf(x->clearcoat_roughness - 0.3f) < 1e-6f, "clearcoat %g %g",
                  (double)x->clearcoat, (double)x->clearcoat_roughness);
            /* sheen colour is a 0-1 factor (clamped); specular colour may exceed 1 */
            CHECK(fabsf(x->sheen_color.z - 1.0f) < 1e-6f && fabsf(x->sheen_roughness - 0.4f) < 1e-6f, "sheen");
            CHECK(x->specular == 0.5f && x->specular_color.x == 2.0f && fabsf(x->ior - 1.33f) < 1e-6f,
                  "specular %g (%g), ior %g", (double)x->specular, (double)x->specular_color.x, (double)x->ior);
            /* transmission and the attenuation colour are 0-1 factors (clamped, with a warning) */
            CHECK(x->transmission == 1.0f && fabsf(x->thickness - 0.1f) < 1e-6f && x->attenuation_distance == 2.0f &&
                      x->attenuation_color.y == 1.0f && x->attenuation_color.z == 0.25f && material_is_volume(m),
                  "transmission %g, volume %g %g (%g %g %g)", (double)x->transmission, (double)x->thickness,
                  (double)x->attenuation_distance, (double)x->attenuation_color.x, (double)x->attenuation_color.y,
                  (double)x->attenuation_color.z);
            CHECK(fabsf(material_absorption(m).x - logf(2.0f) / 2.0f) < 1e-6f, "absorption %g",
                  (double)material_absorption(m).x);
        } else if (m->ext.ior != 1.5f) {
            CHECK(0, "material %s: ior %g without KHR_materials_ior", m->name, (double)m->ext.ior);
        }
    }
    CHECK(seen == 15, "materials seen: %d of 15", seen);
    /* The emissive primitive became two triangle lights; unsupported extensions only warned. */
    int tri_lights = 0;
    for (int i = 0; i < s->num_lights; i++) tri_lights += s->lights[i].type == LIGHT_TRIANGLE;
    CHECK(tri_lights == 2, "emissive triangles as lights: %d", tri_lights);
    CHECK(num_warnings >= 1 && strstr(last_warning, "materials.gltf"),
          "unsupported extension: no warning naming the file");
    CHECK(strstr(all_warnings, "EXT_made_up") && !strstr(all_warnings, "extension KHR_"),
          "only the unsupported extension warns by name: %s", all_warnings);
    scene_destroy(s);
}

/* A material number of the wrong type, or an ior below 1, loads with a warning naming the key and
 * takes a value that makes sense: the default where the value is not a number (or a colour not
 * three numbers), 1 for an ior below it. */
static void test_bad_material_numbers(void) {
    const struct {
        const char *ext; /* the material's extensions */
        const char *warning;
        float ior, sheen; /* what the material gets */
    } cases[] = {
        {"\"KHR_materials_ior\":{\"ior\":0}", "ior 0 is below 1, clamped to 1", 1.0f, 0.0f},
        {"\"KHR_materials_ior\":{\"ior\":1e-30}", "is below 1, clamped to 1", 1.0f, 0.0f},
        {"\"KHR_materials_ior\":{\"ior\":\"NaN\"}", "ior is not a number, using 1.5", 1.5f, 0.0f},
        {"\"KHR_materials_ior\":{\"ior\":\"1.5\"}", "ior is not a number, using 1.5", 1.5f, 0.0f},
        /* tinygltf drops a null member: absent, the default (as the schema's default for a missing one) */
        {"\"KHR_materials_ior\":{\"ior\":null}", NULL, 1.5f, 0.0f},
        {"\"KHR_materials_ior\":{\"ior\":[1.33]}", "ior is not a number, using 1.5", 1.5f, 0.0f},
        {"\"KHR_materials_sheen\":{\"sheenColorFactor\":[0.5]}", "sheenColorFactor is not three numbers", 1.5f, 0.0f},
        {"\"KHR_materials_sheen\":{\"sheenColorFactor\":[0.5,\"x\",0.5]}", "sheenColorFactor is not three numbers",
         1.5f, 0.0f},
        {"\"KHR_materials_sheen\":{\"sheenColorFactor\":[0.5,0.5,0.5]}", NULL, 1.5f, 0.5f},
    };
    const char *meshes = "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},\"indices\":2,"
                         "\"material\":0}]}]";
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        char extra[512], err[512];
        snprintf(extra, sizeof extra,
                 "\"extensionsUsed\":[\"KHR_materials_ior\",\"KHR_materials_sheen\"],"
                 "\"materials\":[{\"name\":\"odd\",\"extensions\":{%s}}]",
                 cases[k].ext);
        scene *s = load(write_gltf("odd.gltf", gltf_json(NULL, meshes, extra, NULL)), err, sizeof err);
        CHECK(s != NULL, "%s: %s", cases[k].ext, err);
        if (!s) continue;
        const material *m = &s->materials[0];
        if (cases[k].warning)
            CHECK(strstr(all_warnings, cases[k].warning) && strstr(all_warnings, "odd.gltf"), "%s: no warning '%s': %s",
                  cases[k].ext, cases[k].warning, all_warnings);
        else /* (the scene has no light: that warning only) */
            CHECK(!strstr(all_warnings, "ior") && !strstr(all_warnings, "sheen"), "%s warns: %s", cases[k].ext,
                  all_warnings);
        CHECK(m->ext.ior == cases[k].ior && m->ext.sheen_color.y == cases[k].sheen, "%s: ior %g, sheen %g",
              cases[k].ext, (double)m->ext.ior, (double)m->ext.sheen_color.y);
        scene_destroy(s);
    }
}

static void test_glb(void) {
    char err[512];
    unsigned char buf[20000];
    /* A GLB's buffer 0 has no uri: it is the BIN chunk. */
    char json[17000];
    snprintf(json, sizeof json, "%s", gltf_json(NULL, NULL, NULL, NULL));
    char *uri = strstr(json, ",\"uri\":\"");
    char *end = strchr(uri + 8, '"');
    memmove(uri, end + 1, strlen(end + 1) + 1);
    size_t n = make_glb(json, buf, sizeof buf);
    const char *path = tmp_path("quad.glb");
    write_bytes(path, buf, n);
    scene *s = load(path, err, sizeof err);
    CHECK(s != NULL && s->num_triangles == 2, "glb: %s", s ? "wrong triangle count" : err);
    if (s) scene_destroy(s);
    /* Truncations at every interesting place: header, JSON chunk, BIN chunk. */
    const size_t cuts[] = {5, 12, 30, n / 2, n - 10, n - 1};
    for (size_t i = 0; i < sizeof cuts / sizeof cuts[0]; i++) {
        write_bytes(tmp_path("truncated.glb"), buf, cuts[i]);
        expect_error("truncated glb", tmp_path("truncated.glb"), NULL);
    }
}

static void test_malformed(void) {
    expect_error("missing file", tmp_path("does-not-exist.gltf"), "No such file");
    const char *empty = tmp_path("empty.gltf");
    write_bytes(empty, "", 0);
    expect_error("empty file", empty, NULL);
    expect_error("bad json", write_gltf("bad.gltf", "{\"asset\":{\"version\":\"2.0\"}, \"nodes\":[{"), NULL);
    expect_error("not json", write_gltf("binary.gltf", "\x01\x02\x03 hello"), NULL);

    char meshes[256];
    snprintf(meshes, sizeof meshes,
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},\"indices\":%d}]}]",
             ACC_BAD_INDEX);
    expect_error("index out of range", write_gltf("badindex.gltf", gltf_json(NULL, meshes, NULL, NULL)), "ind");
    snprintf(meshes, sizeof meshes, "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":%d}}]}]",
             ACC_POS_OVERRUN);
    expect_error("accessor past its buffer", write_gltf("overrun.gltf", gltf_json(NULL, meshes, NULL, NULL)), NULL);
    expect_error("mesh index out of range",
                 write_gltf("badmesh.gltf", gltf_json("\"nodes\":[{\"mesh\":7}]", NULL, NULL, NULL)), NULL);
    expect_error("node cycle",
                 write_gltf("cycle.gltf", gltf_json("\"nodes\":[{\"mesh\":0,\"children\":[1]},{\"children\":[0]}]",
                                                    NULL, NULL, NULL)),
                 NULL);
    expect_error("missing buffer file", write_gltf("nobin.gltf", gltf_json(NULL, NULL, NULL, "missing.bin")),
                 "missing.bin");

    const char *tex_extra = "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}}}],"
                            "\"textures\":[{\"source\":0}],\"images\":[{\"uri\":\"no-such-texture.png\"}]";
    const char *tex_mesh =
        "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},\"indices\":2,\"material\":0}]}]";
    expect_error("missing texture", write_gltf("notex.gltf", gltf_json(NULL, tex_mesh, tex_extra, NULL)),
                 "no-such-texture.png");
    const char *bad_volume[][2] = {
        {"{\"KHR_materials_volume\":{\"attenuationDistance\":0}}", "attenuationDistance 0 is below"},
        {"{\"KHR_materials_volume\":{\"thicknessFactor\":-1}}", "thicknessFactor -1 is below"},
        {"{\"KHR_materials_volume\":{\"attenuationColor\":[1,1]}}", "attenuationColor is not three numbers"},
        {"{\"KHR_materials_transmission\":{\"transmissionFactor\":\"x\"}}", "transmissionFactor is not a"},
        {"{\"KHR_materials_transmission\":{\"transmissionTexture\":{\"index\":9}}}", "texture 9"}};
    for (int i = 0; i < 5; i++) {
        char extra[512];
        snprintf(extra, sizeof extra, "\"materials\":[{\"extensions\":%s}]", bad_volume[i][0]);
        expect_error(bad_volume[i][1], write_gltf("badvolume.gltf", gltf_json(NULL, tex_mesh, extra, NULL)),
                     bad_volume[i][1]);
    }

    /* An external .bin that is too short for its declared byteLength. */
    write_bytes(tmp_path("short.bin"), bin, 100);
    expect_error("short buffer file", write_gltf("shortbin.gltf", gltf_json(NULL, NULL, NULL, "short.bin")), NULL);
}

static void test_env_errors(void) {
    char err[512];
    scene *s = load(write_gltf("env.gltf", gltf_json(NULL, NULL, NULL, NULL)), err, sizeof err);
    CHECK(s != NULL, "env base scene: %s", err);
    if (!s) return;
    const char *garbage = tmp_path("garbage.exr");
    write_bytes(garbage, "v/1\x01 this is not an exr file at all", 36);
    CHECK(scene_set_env(s, garbage, 0.0f, err, sizeof err) != 0 && strstr(err, "garbage.exr"), "garbage env map: '%s'",
          err);
    CHECK(scene_set_env(s, tmp_path("none.hdr"), 0.0f, err, sizeof err) != 0 && strstr(err, "none.hdr"),
          "missing env map: '%s'", err);
    CHECK(s->env == NULL, "a failed env map must leave the scene without one");
    scene_destroy(s);
}

/* Every built-in scene loads without a warning, has a camera and a light, glossy materials, and
 * is closed: no ray from its camera escapes, so no light leaves the room. builtin:NAME names it;
 * an unknown name is one error listing the scenes there are. */
static void test_builtin_scenes(void) {
    char err[512], want[512], names[256] = "";
    int n;
    const builtin_scene *all = scene_builtins(&n);
    CHECK(n >= 3, "%d built-in scenes", n);
    for (int i = 0; i < n; i++) {
        CHECK(scene_builtin_find(all[i].name) == &all[i] && strlen(all[i].description) > 10,
              "built-in %s: lookup or description", all[i].name);
        snprintf(names + strlen(names), sizeof names - strlen(names), "%s%s", i ? ", " : "", all[i].name);
        char path[64];
        snprintf(path, sizeof path, "builtin:%s", all[i].name);
        num_warnings = 0;
        scene *s = scene_load(path, on_warn, NULL, err, sizeof err);
        CHECK(s != NULL, "%s: %s", path, err);
        if (!s) continue;
        CHECK(num_warnings == 0, "%s warns: %s", path, last_warning);
        CHECK(strcmp(s->path, path) == 0, "%s loaded as '%s'", path, s->path);
        CHECK(s->num_cameras >= 1 && s->num_lights >= 1, "%s: %d cameras, %d lights", path, s->num_cameras,
              s->num_lights);
        int glossy = 0;
        for (int m = 0; m < s->num_materials; m++)
            glossy += s->materials[m].model != MATERIAL_GLTF || s->materials[m].metallic > 0.5f;
        CHECK(glossy >= 3, "%s: %d glossy materials", path, glossy);
        if (s->num_cameras >= 1) {
            rng_state rng = rng_make(5, (uint64_t)i);
            int escaped = 0;
            for (int k = 0; k < 4000; k++) {
                surface_hit h;
                vec3 d = sample_uniform_sphere(v2(rng_float(&rng), rng_float(&rng)));
                escaped += !scene_intersect(s, s->cameras[0].position, d, INFINITY, &h);
            }
            CHECK(escaped == 0, "%s is not closed: %d of 4000 rays from the camera escape", path, escaped);
        }
        scene_destroy(s);
    }

    /* The default is the first, and is what scene_load_default loads. */
    scene *s = scene_load_default(NULL, NULL, err, sizeof err);
    CHECK(s != NULL && strncmp(s->path, "builtin:", 8) == 0 && strcmp(s->path + 8, all[0].name) == 0,
          "the default scene: %s", s ? s->path : err);
    scene_destroy(s);

    /* The former default keeps what the tests built on it rely on: both kinds of light, metals,
     * anisotropy. */
    s = scene_load("builtin:showcase", NULL, NULL, err, sizeof err);
    CHECK(s != NULL, "builtin:showcase: %s", err);
    if (s) {
        int area = 0, punctual = 0, aniso = 0;
        for (int i = 0; i < s->num_lights; i++) {
            area += s->lights[i].type == LIGHT_TRIANGLE;
            punctual += s->lights[i].type <= LIGHT_DIRECTIONAL;
        }
        for (int i = 0; i < s->num_materials; i++)
            aniso += s->materials[i].model == MATERIAL_WARD || s->materials[i].anisotropy_strength > 0.0f;
        CHECK(area > 0 && punctual > 0 && aniso >= 2, "showcase: %d area, %d punctual lights, %d anisotropic", area,
              punctual, aniso);
        scene_destroy(s);
    }

    snprintf(want, sizeof want, "builtin:nosuch: no such built-in scene (have: %s)", names);
    s = scene_load("builtin:nosuch", NULL, NULL, err, sizeof err);
    CHECK(s == NULL && strcmp(err, want) == 0, "unknown built-in: '%s', expected '%s'", err, want);
    scene_destroy(s);
}

int main(void) {
    const char *t = getenv("GLINT_TEST_TMP");
    snprintf(tmp_dir, sizeof tmp_dir, "%s", t ? t : "/tmp");
    make_bin();
    test_hierarchy();
    test_index_types();
    test_lights_cameras();
    test_materials();
    test_bad_material_numbers();
    test_glb();
    test_malformed();
    test_env_errors();
    test_builtin_scenes();
    return check_exit("test_loader");
}
