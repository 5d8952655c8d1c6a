/* Hostile scenes: each class of malformed input a tester found gets one line "PATH: problem" (or
 * one warning where the scene still makes sense), never a crash, a hang, a runaway allocation or
 * a non-finite value. Every input is made here, small: the GLB whose image lies past its buffer,
 * JSON nested 20,000 deep, coordinates beyond 1e15, shared node graphs, FIFOs and devices,
 * images declaring huge sizes, factors beyond float, URIs leaving the scene's folder. */
#define _POSIX_C_SOURCE 200809L
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "image_io.h"
#include "scene.h"
#include "scratch.h"

static char dir[1100]; /* the scenes' folder, inside the scratch directory */

/* ---- making inputs ------------------------------------------------------------------------- */

/* The quad's buffer: positions (48 bytes), normals (48), uint16 indices (12). */
enum { BIN_SIZE = 108 };
static unsigned char bin[BIN_SIZE];

static void make_bin(const float pos[12]) {
    const float nrm[12] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
    const uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
    memcpy(bin, pos, 48);
    memcpy(bin + 48, nrm, 48);
    memcpy(bin + 96, idx, 12);
}

static const float UNIT_QUAD[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};

/* A glTF of the quad (mesh 0, material mat_index or none when < 0), with nodes (default: one
 * holding the mesh), the buffer at uri (NULL: embedded; "": none, for a GLB) and extra members. */
static char *quad_json(const char *nodes, int mat_index, const char *uri, const char *extra) {
    static char b64[BIN_SIZE * 2];
    base64(bin, BIN_SIZE, b64);
    size_t cap = 8192 + (nodes ? strlen(nodes) : 0) + (extra ? strlen(extra) : 0);
    char *json = malloc(cap), mat[32] = "", buffer_uri[400] = "";
    if (mat_index >= 0) snprintf(mat, sizeof mat, ",\"material\":%d", mat_index);
    if (!uri)
        snprintf(buffer_uri, sizeof buffer_uri, ",\"uri\":\"data:application/octet-stream;base64,%s\"", b64);
    else if (uri[0])
        snprintf(buffer_uri, sizeof buffer_uri, ",\"uri\":\"%s\"", uri);
    snprintf(json, cap,
             "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],%s,"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},\"indices\":2%s}]}],"
             "\"buffers\":[{\"byteLength\":%d%s}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":48},"
             "{\"buffer\":0,\"byteOffset\":48,\"byteLength\":48},{\"buffer\":0,\"byteOffset\":96,\"byteLength\":12}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
             "{\"bufferView\":1,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
             "{\"bufferView\":2,\"componentType\":5123,\"count\":6,\"type\":\"SCALAR\"}]%s%s}",
             nodes ? nodes : "\"nodes\":[{\"mesh\":0}]", mat, BIN_SIZE, buffer_uri, extra && *extra ? "," : "",
             extra ? extra : "");
    return json;
}

static const char *path_of(const char *name) {
    static char paths[4][1200];
    static int next;
    char *p = paths[next++ & 3];
    snprintf(p, 1200, "%s/%s", dir, name);
    return p;
}

/* Writes text (taken over) as dir/name; returns the path. */
static const char *write_text(const char *name, char *text) {
    const char *p = path_of(name);
    CHECK(put_file(p, text, strlen(text)) == 0, "cannot write %s", p);
    free(text);
    return p;
}

/* A GLB of json (padded) and the quad's buffer plus `extra` bytes after it as its BIN chunk. */
static const char *write_glb(const char *name, char *json, const unsigned char *extra, size_t extra_n) {
    size_t jlen = strlen(json), jpad = (jlen + 3) & ~(size_t)3, blen = (BIN_SIZE + extra_n + 3) & ~(size_t)3;
    size_t total = 28 + jpad + blen;
    unsigned char *buf = calloc(1, total);
    uint32_t h[5] = {0x46546C67u, 2, (uint32_t)total, (uint32_t)jpad, 0x4E4F534Au};
    memcpy(buf, h, 20);
    memcpy(buf + 20, json, jlen);
    memset(buf + 20 + jlen, ' ', jpad - jlen);
    uint32_t bc[2] = {(uint32_t)blen, 0x004E4942u};
    memcpy(buf + 20 + jpad, bc, 8);
    memcpy(buf + 28 + jpad, bin, BIN_SIZE);
    if (extra_n) memcpy(buf + 28 + jpad + BIN_SIZE, extra, extra_n);
    const char *p = path_of(name);
    CHECK(put_file(p, buf, total) == 0, "cannot write %s", p);
    free(buf);
    free(json);
    return p;
}

/* A PNG header declaring w x h RGBA pixels, with a few bytes of (not decodable) image data. */
static size_t png_header(unsigned char *out, uint32_t w, uint32_t h) {
    static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    unsigned char ihdr[25] = {0, 0, 0, 13, 'I', 'H', 'D', 'R'};
    for (int i = 0; i < 4; i++) {
        ihdr[8 + i] = (unsigned char)(w >> (24 - 8 * i));
        ihdr[12 + i] = (unsigned char)(h >> (24 - 8 * i));
    }
    ihdr[16] = 8; /* bit depth */
    ihdr[17] = 6; /* RGBA */
    /* CRC left zero: stb does not check it. */
    static const unsigned char idat[16] = {0, 0, 0, 4, 'I', 'D', 'A', 'T', 0x78, 0x9c, 0, 0};
    memcpy(out, sig, 8);
    memcpy(out + 8, ihdr, 25);
    memcpy(out + 33, idat, 16);
    return 49;
}

/* ---- loading and expectations --------------------------------------------------------------- */

static int num_warnings;
static char warnings[2048];

static void on_warn(void *user, const char *msg) {
    (void)user;
    num_warnings++;
    size_t n = strlen(warnings);
    snprintf(warnings + n, sizeof warnings - n, "%s\n", msg);
}

static scene *load(const char *path, char *err, size_t errlen) {
    num_warnings = 0;
    warnings[0] = 0;
    err[0] = 0;
    return scene_load(path, on_warn, NULL, err, errlen);
}

/* The load fails with exactly "path: problem". */
static void expect_error(const char *what, const char *path, const char *problem) {
    char err[1024], want[1400];
    scene *s = load(path, err, sizeof err);
    CHECK(s == NULL, "%s: loaded, expected '%s'", what, problem);
    scene_destroy(s);
    snprintf(want, sizeof want, "%s: %s", path, problem);
    CHECK(strcmp(err, want) == 0, "%s:\n  got      '%s'\n  expected '%s'", what, err, want);
}

/* The load succeeds with a warning containing `warning`; the scene is returned. */
static scene *expect_warning(const char *what, const char *path, const char *warning) {
    char err[1024];
    scene *s = load(path, err, sizeof err);
    CHECK(s != NULL, "%s: %s", what, err);
    CHECK(strstr(warnings, warning) != NULL, "%s: no warning '%s' among:\n%s", what, warning, warnings);
    return s;
}

/* ---- the classes ---------------------------------------------------------------------------- */

/* A GLB image whose bufferView lies past its buffer: an unused one is a warning, a used one the
 * error; neither is read. */
static void test_image_past_buffer(void) {
    const char *images = "\"images\":[{\"bufferView\":3,\"mimeType\":\"image/png\"}],\"textures\":[{\"source\":0}]";
    char *json = quad_json(NULL, -1, "", images);
    /* a fourth bufferView, far past the buffer's end */
    char *views = strstr(json, "\"byteLength\":12}");
    char *fixed = malloc(strlen(json) + 100);
    size_t head = (size_t)(views - json) + strlen("\"byteLength\":12}");
    memcpy(fixed, json, head);
    sprintf(fixed + head, ",{\"buffer\":0,\"byteOffset\":100,\"byteLength\":100000}%s", json + head);
    free(json);
    char *used = malloc(strlen(fixed) + 1);
    strcpy(used, fixed);
    const char *p = write_glb("unused-image.glb", fixed, NULL, 0);
    scene_destroy(expect_warning("unused image past its buffer", p,
                                 "unused image 0 not read: its bufferView 3 extends past the end of its buffer "
                                 "(108 bytes)"));
    /* the same image used by a material */
    char *with_mat = malloc(strlen(used) + 100);
    strcpy(with_mat, used);
    strcpy(with_mat + strlen(used) - 1,
           ",\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}}}]}");
    free(used);
    expect_error("used image past its buffer", write_glb("used-image.glb", with_mat, NULL, 0),
                 "texture image 0: its bufferView 3 extends past the end of its buffer (108 bytes)");
}

/* JSON nested 20,000 deep is refused before the (recursive) parser sees it; brackets inside
 * strings do not count. */
static void test_json_depth(void) {
    const int depth = 20000;
    char *deep = malloc(2 * (size_t)depth + 100);
    size_t n = (size_t)sprintf(deep, "{\"asset\":{\"version\":\"2.0\"},\"extras\":");
    for (int i = 0; i < depth; i++) deep[n++] = '[';
    for (int i = 0; i < depth; i++) deep[n++] = ']';
    strcpy(deep + n, "}");
    expect_error("JSON nested 20000 deep", write_text("deep.gltf", deep), "JSON nests deeper than 64 levels");

    char *brackets = malloc(2 * (size_t)depth + 200);
    n = (size_t)sprintf(brackets, "\"asset\":{\"version\":\"2.0\"},\"extras\":{\"note\":\"");
    for (int i = 0; i < depth; i++) brackets[n++] = (char)(i % 2 ? '{' : '[');
    strcpy(brackets + n, "\\\"\"}");
    char *json = quad_json(NULL, -1, NULL, brackets + strlen("\"asset\":{\"version\":\"2.0\"},"));
    free(brackets);
    char err[1024];
    scene *s = load(write_text("brackets-in-string.gltf", json), err, sizeof err);
    CHECK(s != NULL, "brackets inside a string: %s", err);
    scene_destroy(s);

    /* The same in a GLB's JSON chunk. */
    deep = malloc(2 * (size_t)depth + 100);
    n = (size_t)sprintf(deep, "{\"asset\":{\"version\":\"2.0\"},\"extras\":");
    for (int i = 0; i < depth; i++) deep[n++] = '{', deep[n++] = '}';
    memset(deep + n - 2 * depth, '[', depth);
    memset(deep + n - depth, ']', depth);
    strcpy(deep + n, "}");
    expect_error("GLB JSON nested 20000 deep", write_glb("deep.glb", deep, NULL, 0),
                 "JSON nests deeper than 64 levels");
}

/* Coordinates: within 1e15 after transforms loads (and rays stay finite); beyond, or not finite
 * as float, is the error, for vertices, node transforms, lights and cameras. */
static void test_coordinates(void) {
    char err[1024];
    const char *far_node = "\"nodes\":[{\"mesh\":0,\"translation\":[9e14,0,0],\"scale\":[1e9,1e9,1]}]";
    scene *s = load(write_text("far-ok.gltf", quad_json(far_node, -1, NULL, NULL)), err, sizeof err);
    CHECK(s != NULL, "9e14 away: %s", err);
    if (s) {
        surface_hit h;
        int hit = scene_intersect(s, v3(9e14f + 5e8f, 5e8f, 1e14f), v3(0, 0, -1), INFINITY, &h);
        CHECK(hit && is_finite3(h.p), "a ray 9e14 away: hit %d", hit);
        scene_destroy(s);
    }
    const char *huge_node = "\"nodes\":[{\"mesh\":0,\"translation\":[1e19,0,0]}]";
    expect_error("node translation 1e19", write_text("far-node.gltf", quad_json(huge_node, -1, NULL, NULL)),
                 "mesh 0 primitive 0: vertex 0 lies at (1e+19, 0, 0) after its transforms; coordinates must be "
                 "finite and within +-1e+15");
    const char *overflow = "\"nodes\":[{\"mesh\":0,\"scale\":[1e300,1,1]}]";
    expect_error("node scale beyond float", write_text("inf-node.gltf", quad_json(overflow, -1, NULL, NULL)),
                 "mesh 0 primitive 0: vertex 0 lies at (-nan, -nan, -nan) after its transforms; coordinates must be "
                 "finite and within +-1e+15");
    const float far_quad[12] = {0, 0, 0, 1e19f, 0, 0, 1, 1, 0, 0, 1, 0};
    make_bin(far_quad);
    expect_error("vertex at 1e19", write_text("far-vertex.gltf", quad_json(NULL, -1, NULL, NULL)),
                 "mesh 0 primitive 0: vertex 1 lies at (1e+19, 0, 0) after its transforms; coordinates must be "
                 "finite and within +-1e+15");
    make_bin(UNIT_QUAD);
    const char *light_node = "\"nodes\":[{\"mesh\":0,\"children\":[1]},{\"translation\":[0,-2e19,0],"
                             "\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}}]";
    const char *lights = "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[{\"type\":\"point\"}]}}";
    expect_error("light at -2e19", write_text("far-light.gltf", quad_json(light_node, -1, NULL, lights)),
                 "light 'light 0' lies at (0, -2e+19, 0) after its transforms; coordinates must be finite and "
                 "within +-1e+15");
    const char *cam = "\"nodes\":[{\"mesh\":0,\"children\":[1]},{\"translation\":[0,0,1e16],\"camera\":0}]";
    const char *cams = "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.8,\"znear\":0.1}}]";
    expect_error("camera at 1e16", write_text("far-camera.gltf", quad_json(cam, -1, NULL, cams)),
                 "camera 0 lies at (0, 0, 1e+16) after its transforms; coordinates must be finite and within "
                 "+-1e+15");
}

/* Node graphs: shared children are instances, bounded in number; depth is bounded, and a deep
 * chain is not a cycle. */
static void test_node_graphs(void) {
    char *nodes = malloc(64 * 60);
    size_t n = (size_t)sprintf(nodes, "\"nodes\":[");
    for (int i = 0; i < 40; i++)
        n += (size_t)sprintf(nodes + n, "%s{\"mesh\":0,\"children\":[%d,%d]}", i ? "," : "", i + 1, i + 1);
    sprintf(nodes + n, ",{}]");
    expect_error("2^40 instances", write_text("shared.gltf", quad_json(nodes, -1, NULL, NULL)),
                 "node hierarchy has more than 1000000 node instances (nodes shared by several parents count once "
                 "per parent)");
    free(nodes);

    for (int k = 0; k < 2; k++) {
        int len = k == 0 ? 1002 : 5000;
        char *chain = malloc((size_t)len * 40 + 64);
        n = (size_t)sprintf(chain, "\"nodes\":[");
        for (int i = 0; i < len; i++)
            n += (size_t)sprintf(chain + n, i + 1 < len ? "%s{\"children\":[%d]}" : "%s{\"mesh\":0}", i ? "," : "",
                                 i + 1);
        sprintf(chain + n, "]");
        const char *p = write_text(k == 0 ? "chain1002.gltf" : "chain5000.gltf", quad_json(chain, -1, NULL, NULL));
        free(chain);
        if (k == 0) {
            char err[1024];
            scene *s = load(p, err, sizeof err);
            CHECK(s != NULL && s->num_triangles == 2, "a 1002-deep chain: %s", s ? "wrong triangles" : err);
            scene_destroy(s);
        } else {
            expect_error("a 5000-deep chain", p, "node hierarchy is deeper than 4096 levels (at node 4096)");
        }
    }
    expect_error("a cycle",
                 write_text("cycle.gltf",
                            quad_json("\"nodes\":[{\"mesh\":0,\"children\":[1]},{\"children\":[0]}]", -1, NULL, NULL)),
                 "node hierarchy has a cycle at node 0");
}

/* One quad placed five times where it is and once beside: eight of the twelve triangles repeat
 * another's corners, and the load says so (a million such made every ray test them all). */
static void test_coincident(void) {
    const char *nodes = "\"nodes\":[{\"children\":[1,2,3,4,5,6]},{\"mesh\":0},{\"mesh\":0},{\"mesh\":0},"
                        "{\"mesh\":0},{\"mesh\":0},{\"mesh\":0,\"translation\":[2,0,0]}]";
    char *json = quad_json(nodes, -1, NULL, NULL);
    scene *s =
        expect_warning("coincident", write_text("coincident.gltf", json), "8 triangles repeat another's three corners");
    CHECK(s && s->num_triangles == 12 && s->coincident == 8, "coincident: %d triangles, %ld repeating",
          s ? s->num_triangles : 0, s ? s->coincident : 0L);
    scene_destroy(s);
}

/* FIFOs and devices, as the scene or behind a URI, are refused without being opened for long;
 * so are directories. */
static void test_special_files(void) {
    const char *fifo = path_of("fifo.gltf");
    CHECK(mkfifo(fifo, 0600) == 0, "mkfifo %s", fifo);
    expect_error("a FIFO as the scene", fifo, "is not a regular file (a pipe or a device?)");
    expect_error("/dev/zero as the scene", "/dev/zero", "is not a regular file (a pipe or a device?)");
    expect_error("a directory as the scene", dir, "is a directory");

    CHECK(mkfifo(path_of("fifo.bin"), 0600) == 0, "mkfifo fifo.bin");
    expect_error("a FIFO as a buffer", write_text("fifo-buffer.gltf", quad_json(NULL, -1, "fifo.bin", NULL)),
                 "buffer 'fifo.bin': is not a regular file (a pipe or a device?)");
    CHECK(symlink("/dev/zero", path_of("zero.bin")) == 0, "symlink zero.bin");
    expect_error("/dev/zero as a buffer", write_text("zero-buffer.gltf", quad_json(NULL, -1, "zero.bin", NULL)),
                 "buffer 'zero.bin': is not a regular file (a pipe or a device?)");
    CHECK(mkdir(path_of("folder.bin"), 0700) == 0, "mkdir folder.bin");
    expect_error("a directory as a buffer", write_text("dir-buffer.gltf", quad_json(NULL, -1, "folder.bin", NULL)),
                 "buffer 'folder.bin': is a directory");

    const char *tex = "\"images\":[{\"uri\":\"%s\"}],\"textures\":[{\"source\":0}],"
                      "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}}}]";
    char extra[512];
    CHECK(mkfifo(path_of("fifo.png"), 0600) == 0, "mkfifo fifo.png");
    snprintf(extra, sizeof extra, tex, "fifo.png");
    expect_error("a FIFO as an image", write_text("fifo-image.gltf", quad_json(NULL, 0, NULL, extra)),
                 "texture image 'fifo.png': is not a regular file (a pipe or a device?)");
    snprintf(extra, sizeof extra, tex, "folder.bin");
    expect_error("a directory as an image", write_text("dir-image.gltf", quad_json(NULL, 0, NULL, extra)),
                 "texture image 'folder.bin': is a directory");

    /* The same for an environment map and a reference image (opened with O_NONBLOCK: a FIFO
     * without a writer would otherwise block the open itself). */
    CHECK(mkfifo(path_of("fifo.exr"), 0600) == 0, "mkfifo fifo.exr");
    const char *specials[] = {path_of("fifo.exr"), "/dev/zero", path_of("folder.bin")};
    const char *problems[] = {"not a regular file (a pipe or a device?)", "not a regular file (a pipe or a device?)",
                              "is a directory"};
    for (int k = 0; k < 3; k++) {
        char err[1024] = "", want[1200];
        snprintf(want, sizeof want, "%s: %s", specials[k], problems[k]);
        scene *s = scene_create(NULL, NULL);
        CHECK(scene_set_env(s, specials[k], 0.0f, err, sizeof err) != 0 && strcmp(err, want) == 0,
              "environment map %s: '%s', expected '%s'", specials[k], err, want);
        scene_destroy(s);
        exr_image img;
        err[0] = 0;
        CHECK(exr_image_load(specials[k], &img, err, sizeof err) != 0 && strcmp(err, want) == 0,
              "reference image %s: '%s', expected '%s'", specials[k], err, want);
    }
}

/* Images declaring more pixels than the budget are refused from their header. */
static void test_image_budget(void) {
    unsigned char png[64];
    size_t n = png_header(png, 12000, 12000);
    CHECK(put_file(path_of("huge.png"), png, n) == 0, "write huge.png");
    const char *tex = "\"images\":[{\"uri\":\"huge.png\"}],\"textures\":[{\"source\":0}],"
                      "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}}}]";
    expect_error("12000 x 12000 PNG", write_text("huge-image.gltf", quad_json(NULL, 0, NULL, tex)),
                 "texture image 'huge.png': 12000 x 12000 pixels take 550 MiB decoded, more than the 256 MiB one "
                 "image may");
    n = png_header(png, 20000, 10);
    CHECK(put_file(path_of("wide.png"), png, n) == 0, "write wide.png");
    const char *wide = "\"images\":[{\"uri\":\"wide.png\"}],\"textures\":[{\"source\":0}],"
                       "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}}}]";
    expect_error("20000-wide PNG", write_text("wide-image.gltf", quad_json(NULL, 0, NULL, wide)),
                 "texture image 'wide.png': 20000 x 10 pixels: more than 16384 on a side");
    /* A truncated data URI says why it cannot be decoded. */
    char b64[128], extra[512];
    n = png_header(png, 4, 4);
    base64(png, 20, b64);
    snprintf(extra, sizeof extra,
             "\"images\":[{\"uri\":\"data:image/png;base64,%s\"}],\"textures\":[{\"source\":0}],"
             "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}}}]",
             b64);
    expect_error("truncated data: image", write_text("truncated-image.gltf", quad_json(NULL, 0, NULL, extra)),
                 "texture image 0: cannot be decoded: unknown image type");
}

/* Factors and intensities: beyond float or negative is the error; glTF's [0, 1] factors above 1
 * are clamped with one warning. */
static void test_factors(void) {
    const char *cases[][2] = {
        {"\"materials\":[{\"name\":\"m\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[1e300,0,0,1]}}]",
         "material 'm': baseColorFactor 1e+300 is not a finite number up to 1e+20"},
        {"\"materials\":[{\"name\":\"m\",\"emissiveFactor\":[1,-1,0]}]", "material 'm': emissiveFactor -1 is negative"},
        {"\"materials\":[{\"name\":\"m\",\"emissiveFactor\":[1,1,1],\"extensions\":{"
         "\"KHR_materials_emissive_strength\":{\"emissiveStrength\":-3}}}]",
         "material 'm': emissiveStrength -3 is negative"},
        {"\"materials\":[{\"name\":\"m\",\"pbrMetallicRoughness\":{\"roughnessFactor\":-0.5}}]",
         "material 'm': roughnessFactor -0.5 is negative"},
        {"\"materials\":[{\"name\":\"m\",\"extras\":{\"glint\":{\"model\":\"phong\",\"exponent\":1e39}}}]",
         "material 'm': exponent 1e+39 is not a finite number up to 1e+20"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
        expect_error(cases[i][1], write_text("factor.gltf", quad_json(NULL, 0, NULL, cases[i][0])), cases[i][1]);

    const char *light_nodes = "\"nodes\":[{\"mesh\":0,\"children\":[1]},"
                              "{\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}}]";
    const char *light_cases[][2] = {
        {"{\"type\":\"point\",\"name\":\"l\",\"intensity\":-5}", "light 'l': intensity -5 is negative"},
        {"{\"type\":\"point\",\"name\":\"l\",\"color\":[1,1,-0.25]}", "light 'l': color -0.25 is negative"},
        {"{\"type\":\"point\",\"name\":\"l\",\"intensity\":1e300}",
         "light 'l': intensity 1e+300 is not a finite number up to 1e+20"},
    };
    for (size_t i = 0; i < sizeof light_cases / sizeof light_cases[0]; i++) {
        char extra[256];
        snprintf(extra, sizeof extra, "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[%s]}}", light_cases[i][0]);
        expect_error(light_cases[i][1], write_text("light.gltf", quad_json(light_nodes, -1, NULL, extra)),
                     light_cases[i][1]);
    }
    const char *index = "\"nodes\":[{\"mesh\":0,\"children\":[1]},"
                        "{\"extensions\":{\"KHR_lights_punctual\":{\"light\":1e20}}}]";
    expect_error("light index 1e20",
                 write_text("light-index.gltf",
                            quad_json(index, -1, NULL,
                                      "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[{\"type\":\"point\"}]}}")),
                 "KHR_lights_punctual: light 1e+20 is not a valid index");

    scene *s =
        expect_warning("base colour above 1",
                       write_text("bright.gltf", quad_json(NULL, 0, NULL,
                                                           "\"materials\":[{\"name\":\"m\",\"emissiveFactor\":[1,"
                                                           "1,1],\"pbrMetallicRoughness\":{\"baseColorFactor\":"
                                                           "[1.5,0.5,0.5,1]}}]")),
                       "material 'm': a colour or factor above 1 (glTF's range is 0 to 1), clamped to 1");
    if (s) {
        const material *m = &s->materials[0];
        CHECK(m->base_color.x == 1.0f && m->base_color.y == 0.5f && num_warnings == 1,
              "clamped to (%g %g %g), %d warnings", m->base_color.x, m->base_color.y, m->base_color.z, num_warnings);
        scene_destroy(s);
    }
}

/* URIs: the scene's folder and below; absolute paths and '..' above it are refused, with a message
 * that says so (not "file not found"). A scene without light says it renders black. */
static void test_uris_and_messages(void) {
    CHECK(put_file(path_of("quad.bin"), bin, BIN_SIZE) == 0, "write quad.bin");
    char outside[1200];
    snprintf(outside, sizeof outside, "%s/outside.bin", scratch_dir);
    CHECK(put_file(outside, bin, BIN_SIZE) == 0, "write outside.bin");
    char err[1024];
    scene *s = load(write_text("inside.gltf", quad_json(NULL, -1, "quad.bin", NULL)), err, sizeof err);
    CHECK(s != NULL, "a buffer beside the scene: %s", err);
    scene_destroy(s);
    CHECK(mkdir(path_of("sub"), 0700) == 0 && put_file(path_of("sub/quad.bin"), bin, BIN_SIZE) == 0, "sub/quad.bin");
    s = load(write_text("below.gltf", quad_json(NULL, -1, "sub/../sub/./quad.bin", NULL)), err, sizeof err);
    CHECK(s != NULL, "a buffer below the scene: %s", err);
    scene_destroy(s);

    expect_error("'..' above the folder", write_text("dotdot.gltf", quad_json(NULL, -1, "../outside.bin", NULL)),
                 "buffer '../outside.bin': '..' leads out of the scene's folder (only files in it and below are read)");
    expect_error("'..' percent-encoded",
                 write_text("dotdot2.gltf", quad_json(NULL, -1, "sub/%2E%2E/../outside.bin", NULL)),
                 "buffer 'sub/../../outside.bin': '..' leads out of the scene's folder (only files in it and below "
                 "are read)");
    char *json = quad_json(NULL, -1, outside, NULL), want[1400];
    snprintf(want, sizeof want, "buffer '%s': absolute paths are not read (URIs are relative to the scene's folder)",
             outside);
    expect_error("an existing absolute path", write_text("absolute.gltf", json), want);
    expect_error("a missing buffer", write_text("missing.gltf", quad_json(NULL, -1, "nowhere.bin", NULL)),
                 "buffer 'nowhere.bin': No such file or directory");

    s = expect_warning("no light", write_text("dark.gltf", quad_json(NULL, -1, NULL, NULL)),
                       "no light (no punctual light, no emissive material): the image is black without an "
                       "environment map");
    CHECK(num_warnings == 1, "dark scene: %d warnings:\n%s", num_warnings, warnings);
    scene_destroy(s);
}

int main(void) {
    if (scratch_open("test_hostile") != 0) return 1;
    snprintf(dir, sizeof dir, "%s/scene", scratch_dir);
    if (mkdir(dir, 0700) != 0) return 1;
    make_bin(UNIT_QUAD);
    test_image_past_buffer();
    test_json_depth();
    test_coordinates();
    test_node_graphs();
    test_coincident();
    test_special_files();
    test_image_budget();
    test_factors();
    test_uris_and_messages();
    return scratch_close(check_exit("test_hostile"));
}
