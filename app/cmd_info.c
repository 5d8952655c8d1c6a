/* glint info: what a scene holds. */
#include <stdio.h>
#include <string.h>
#include <sys/resource.h>

#include "cli.h"
#include "commands.h"

static void print_info_help(void) {
    printf("usage: glint info [SCENE] [--env FILE] [--method NAME] [--max-depth D] [--plan auto|full]\n"
           "\n"
           "Prints a summary of SCENE: geometry, materials, lights, cameras, size; then what the\n"
           "scene calls for (material classes, emitters, whether indirect and glossy-to-glossy\n"
           "transport exist) and the passes method NAME would run (default vsl+hl, which has them\n"
           "all), each with its reason.\n"
           "\n");
    cli_print_scenes();
}

int cmd_info(int argc, char **argv) {
    const char *path = NULL, *env = NULL;
    int method = METHOD_VSL_HL, max_depth = DEFAULT_MAX_DEPTH, plan_mode = PLAN_AUTO;
    for (int i = 0; i < argc; i++) {
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            print_info_help();
            return EXIT_OK;
        } else if (strcmp(argv[i], "--env") == 0) {
            if (!(env = cli_value(argc, argv, &i))) return EXIT_USAGE;
        } else if (strcmp(argv[i], "--method") == 0) {
            const char *v = cli_value(argc, argv, &i);
            if (!v) return EXIT_USAGE;
            if ((method = method_from_name(v)) < 0) {
                cli_error("--method: expected pt, vpl, vsl or vsl+hl, got '%s'", v);
                return EXIT_USAGE;
            }
        } else if (strcmp(argv[i], "--max-depth") == 0) {
            const char *v = cli_value(argc, argv, &i);
            long long n;
            if (!v || cli_parse_int("--max-depth", v, 1, 10000, &n)) return EXIT_USAGE;
            max_depth = (int)n;
        } else if (strcmp(argv[i], "--plan") == 0) {
            const char *v = cli_value(argc, argv, &i);
            if (!v || cli_parse_plan("--plan", v, &plan_mode)) return EXIT_USAGE;
        } else if (cli_scene_argument("info", argv[i], &path) != 0) {
            return EXIT_USAGE;
        }
    }
    double t0 = cli_now();
    scene *s = load_scene_or_default(path, env, 0.0f);
    if (!s) return EXIT_FAILURE_;
    double load_seconds = cli_now() - t0;
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    int by_model[3] = {0, 0, 0}, emissive = 0;
    for (int i = 0; i < s->num_materials; i++) {
        by_model[s->materials[i].model]++;
        emissive += max_comp3(s->materials[i].emission) > 0.0f;
    }
    int by_type[5] = {0, 0, 0, 0, 0};
    for (int i = 0; i < s->num_lights; i++) by_type[s->lights[i].type]++;
    vec3 ext = sub3(s->bounds.hi, s->bounds.lo);
    printf("scene:      %s\n", s->path);
    printf("geometry:   %d triangles, %d vertices\n", s->num_triangles, s->num_vertices);
    printf("size:       %.4g x %.4g x %.4g (diagonal %.4g), ray offset %.3g\n", (double)ext.x, (double)ext.y,
           (double)ext.z, (double)s->diag, (double)s->ray_eps);
    printf("materials:  %d (%d metallic-roughness, %d Phong, %d Ward; %d emissive)\n", s->num_materials,
           by_model[MATERIAL_GLTF], by_model[MATERIAL_PHONG], by_model[MATERIAL_WARD], emissive);
    printf("textures:   %d (%d images)\n", s->num_textures, s->num_images);
    printf("lights:     %d point, %d spot, %d directional, %d emissive triangles, %s\n", by_type[LIGHT_POINT],
           by_type[LIGHT_SPOT], by_type[LIGHT_DIRECTIONAL], by_type[LIGHT_TRIANGLE],
           s->env ? "an environment map" : "no environment map");
    printf("cameras:    %d", s->num_cameras);
    for (int i = 0; i < s->num_cameras; i++) printf("%s%d '%s'", i ? ", " : " (", i, s->cameras[i].name);
    printf("%s\n", s->num_cameras ? ")" : " (a framing view is used)");
    /* Load includes parsing, flattening, the light list and the BVH build; ru_maxrss is in KiB. */
    printf("load:       %.3f s, peak memory %.1f MiB\n", load_seconds, (double)ru.ru_maxrss / 1024.0);
    if (s->num_warnings) printf("warnings:   %d (printed above)\n", s->num_warnings);
    scene_analysis a;
    char err[256];
    if (scene_analyse(s, &a, err, sizeof err) != 0) {
        cli_error("%s: %s", s->path, err);
        scene_destroy(s);
        return EXIT_FAILURE_;
    }
    effect_plan plan = plan_make(&a, method, max_depth, plan_mode);
    printf("method:     %s\n", method_name(method));
    plan_print(stdout, s, &a, &plan);
    scene_analysis_free(&a);
    scene_destroy(s);
    return EXIT_OK;
}
