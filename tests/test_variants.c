/* KHR_materials_variants: the names read, every instance of a primitive switched with it, what
 * depends on materials rebuilt (an emissive variant makes lights, a masked-away one leaves the
 * BVH, intensity edits start over), malformed mappings refused in one line; and on the command
 * line: glint info lists them, --variant picks one for info and render (an unknown name is one
 * line of error), a reference records it and glint bench renders it again.
 * Usage: test_variants PATH_TO_GLINT */
#define _POSIX_C_SOURCE 200809L
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "cli_harness.h"
#include "gltf_textured.h"
#include "scene.h"

/* Four materials (grey, red, glowing, cut away entirely), three variants mapping the square to
 * the last three; the square twice, the second instance at x + 2. */
static const char *MATERIALS =
    "[{\"name\":\"grey\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.5,0.5,0.5,1]}},"
    "{\"name\":\"red\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,0,0,1]}},"
    "{\"name\":\"glow\",\"emissiveFactor\":[1,1,1],\"doubleSided\":true},"
    "{\"name\":\"cut\",\"alphaMode\":\"MASK\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,1,1,0.2]}}]";
static const char *VARIANTS =
    "\"extensionsUsed\":[\"KHR_materials_variants\"],\"extensions\":{\"KHR_materials_variants\":"
    "{\"variants\":[{\"name\":\"red\"},{\"name\":\"glow\"},{\"name\":\"cut\"}]}}";
static const char *MAPPINGS =
    "\"extensions\":{\"KHR_materials_variants\":{\"mappings\":[{\"material\":1,\"variants\":[0]},"
    "{\"material\":2,\"variants\":[1]},{\"material\":3,\"variants\":[2]}]}}";
static const char *NODES = "[{\"mesh\":0},{\"mesh\":0,\"translation\":[2,0,0]}]";

static char *variants_gltf(const char *mappings, const char *top) {
    return gt_gltf_nodes(NODES, "[0,1]", MATERIALS, NULL, NULL, NULL, 0, mappings, top);
}

static int triangle_lights(const scene *s) {
    int n = 0;
    for (int i = 0; i < s->num_lights; i++) n += s->lights[i].type == LIGHT_TRIANGLE;
    return n;
}

/* Every triangle has material m, and a ray down onto each instance meets it (or nothing). */
static void check_materials(const scene *s, int m, const char *what) {
    int bad = 0;
    for (int t = 0; t < s->num_triangles; t++) bad += s->tri_material[t] != m;
    CHECK(bad == 0 && s->num_triangles == 4, "%s: %d of %d triangles with another material than %d", what, bad,
          s->num_triangles, m);
    for (int k = 0; k < 2; k++) {
        surface_hit h;
        int hit = scene_intersect(s, v3(0.5f + 2.0f * k, 0.5f, 3), v3(0, 0, -1), INFINITY, &h);
        CHECK(m == 3 ? !hit : hit && h.material == m, "%s: instance %d: hit %d, material %d", what, k, hit,
              hit ? h.material : -1);
    }
}

static void test_switching(void) {
    char *json = variants_gltf(MAPPINGS, VARIANTS);
    char err[512] = "";
    scene *s = scene_load_memory(json, strlen(json), ".", "variants.gltf", NULL, NULL, err, sizeof err);
    free(json);
    CHECK(s != NULL, "variants.gltf: %s", err);
    if (!s) return;
    CHECK(scene_num_variants(s) == 3 && !strcmp(scene_variant_name(s, 0), "red") &&
              !strcmp(scene_variant_name(s, 2), "cut") && scene_variant(s) == -1,
          "variants read: %d", scene_num_variants(s));
    check_materials(s, 0, "as loaded");
    CHECK(scene_select_variant(s, "red", err, sizeof err) == 0 && scene_variant(s) == 0, "red: %s", err);
    check_materials(s, 1, "red");
    CHECK(triangle_lights(s) == 0, "red: %d lights", triangle_lights(s));
    CHECK(scene_select_variant(s, "glow", err, sizeof err) == 0, "glow: %s", err);
    check_materials(s, 2, "glow");
    CHECK(triangle_lights(s) == 4, "glow: %d emissive triangles are lights, expected 4", triangle_lights(s));
    /* An intensity edit, then another variant: the file's emission comes back. */
    CHECK(scene_set_light_gain(s, 0, 5.0f, err, sizeof err) == 0 && s->materials[2].emission.x == 5.0f, "gain: %s",
          err);
    CHECK(scene_select_variant(s, "cut", err, sizeof err) == 0, "cut: %s", err);
    check_materials(s, 3, "cut");
    CHECK(s->materials[2].emission.x == 1.0f, "the glow's gain outlived the switch: emission %g",
          s->materials[2].emission.x);
    CHECK(scene_set_variant(s, -1, err, sizeof err) == 0 && scene_variant(s) == -1, "back: %s", err);
    check_materials(s, 0, "back to the default");
    CHECK(scene_select_variant(s, "blue", err, sizeof err) != 0 && strstr(err, "variants.gltf: ") == err &&
              strstr(err, "'blue'") && strstr(err, "'red', 'glow', 'cut'") && one_line(err),
          "an unknown variant: %s", err);
    CHECK(scene_set_variant(s, 3, err, sizeof err) != 0 && scene_variant(s) == -1, "variant 3 of 3 accepted");
    scene_destroy(s);
}

/* Files whose variants or mappings are malformed: one line naming the file and the extension. */
static void test_malformed(void) {
    const char *cases[][2] = {
        {"\"extensions\":{\"KHR_materials_variants\":{\"mappings\":[{\"material\":1,\"variants\":[3]}]}}", NULL},
        {"\"extensions\":{\"KHR_materials_variants\":{\"mappings\":[{\"material\":9,\"variants\":[0]}]}}", NULL},
        {"\"extensions\":{\"KHR_materials_variants\":{\"mappings\":[{\"material\":1,\"variants\":\"all\"}]}}", NULL},
        {"\"extensions\":{\"KHR_materials_variants\":{\"mappings\":{\"material\":1}}}", NULL},
        {"\"extensions\":{\"KHR_materials_variants\":{\"mappings\":[{\"material\":1,\"variants\":[0.5]}]}}", NULL},
        {"", "\"extensions\":{\"KHR_materials_variants\":{\"variants\":\"red\"}}"},
        {"\"extensions\":{\"KHR_materials_variants\":{\"mappings\":[{\"material\":1,\"variants\":[0]}]}}",
         "\"extensions\":{\"KHR_materials_variants\":{}}"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        char *json = variants_gltf(cases[k][0], cases[k][1] ? cases[k][1] : VARIANTS);
        char err[512] = "";
        scene *s = scene_load_memory(json, strlen(json), ".", "bad.gltf", NULL, NULL, err, sizeof err);
        CHECK(!s && strstr(err, "bad.gltf: ") == err && strstr(err, "KHR_materials_variants") && one_line(err),
              "case %zu: %s", k, s ? "loaded" : err);
        scene_destroy(s);
        free(json);
    }
    /* Variants without a usable name get one; a file without mappings still lists them. */
    char *json =
        variants_gltf("", "\"extensions\":{\"KHR_materials_variants\":{\"variants\":[{\"name\":5},{\"name\":\"b\"}]}}");
    char err[512] = "";
    scene *s = scene_load_memory(json, strlen(json), ".", "unnamed.gltf", NULL, NULL, err, sizeof err);
    CHECK(s && scene_num_variants(s) == 2 && !strcmp(scene_variant_name(s, 0), "variant 0"), "unnamed: %s",
          s ? scene_variant_name(s, 0) : err);
    CHECK(s && scene_select_variant(s, "b", err, sizeof err) == 0, "a variant without mappings: %s", err);
    scene_destroy(s);
    free(json);
}

static void write_text(const char *name, const char *text) {
    char p[1024];
    snprintf(p, sizeof p, "%s/%s", tmp, name);
    FILE *f = fopen(p, "wb");
    if (!f || fputs(text, f) < 0 || fclose(f) != 0) {
        fprintf(stderr, "cannot write %s\n", p);
        exit(1);
    }
}

static int lines(const char *s) {
    int n = 0;
    for (; *s; s++) n += *s == '\n';
    return n;
}

static void test_cli(void) {
    char *json = variants_gltf(MAPPINGS, VARIANTS);
    write_text("v.gltf", json);
    free(json);
    CHECK(run("info v.gltf") == 0 && strstr(out_text, "variants:   3 ('red', 'glow', 'cut'); shown: the default"),
          "info lists the variants: %s", out_text);
    CHECK(run("info v.gltf --variant glow") == 0 && strstr(out_text, "shown: 'glow'") &&
              strstr(out_text, "4 emissive triangles"),
          "info --variant glow: %s", out_text);
    /* A variant can light the scene: no warning that it has no light, but for a variant without. */
    CHECK(!strstr(err_text, "no light"), "info --variant glow warns: %s", err_text);
    CHECK(run("info v.gltf --variant red") == 0 && strstr(err_text, "no light"), "info --variant red: %s", err_text);
    CHECK(run("render --help") == 0 && strstr(out_text, "--variant NAME"), "render --help lacks --variant");
    CHECK(run("view --help") == 0 && strstr(out_text, "--variant NAME"), "view --help lacks --variant");
    const char *bad[] = {"info v.gltf --variant blue", "render v.gltf --variant blue --spp 1 --quiet",
                         "view v.gltf --variant blue"};
    for (int k = 0; k < 3; k++) {
        int rc = run(bad[k]);
        const char *line = strstr(err_text, "glint: error: ");
        CHECK(rc == 1 && line && strncmp(line, "glint: error: v.gltf: no material variant 'blue'", 48) == 0 &&
                  strstr(line, "'red', 'glow', 'cut'") && lines(line) == 1,
              "'%s': exit %d, stderr %s", bad[k], rc, err_text);
    }
    /* The glowing square seen head on: radiance 1 where it is, and the reference says which variant. */
    CHECK(run("render v.gltf --variant glow --spp 2 --size 16x16 --out glow.exr --quiet") == 0, "render glow: %s",
          err_text);
    char path[1024], e[512];
    snprintf(path, sizeof path, "%s/glow.exr", tmp);
    image_rgb img = {0};
    CHECK(image_rgb_load(path, &img, e, sizeof e) == 0, "%s", e);
    float peak = 0.0f;
    for (int i = 0; img.rgb && i < 3 * img.width * img.height; i++) peak = img.rgb[i] > peak ? img.rgb[i] : peak;
    CHECK(fabsf(peak - 1.0f) < 1e-4f, "the glowing variant's brightest pixel %g, expected 1", peak);
    image_rgb_free(&img);
    char desc[8192];
    CHECK(read_reference("glow.exr", desc, sizeof desc) && strstr(desc, "\"variant\": \"glow\""),
          "the reference does not record its variant: %s", desc);
    CHECK(run("bench v.gltf --reference glow.exr --methods pt --times 0.05 --seeds 1 --out bench --quiet") == 0,
          "bench of a variant's reference: %s", err_text);
}

int main(int argc, char **argv) {
    int start = harness_start(argc, argv, "variants");
    if (start != 0) return start;
    test_switching();
    test_malformed();
    test_cli();
    return check_exit("test_variants");
}
