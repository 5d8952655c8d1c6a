/* glint info: what a scene holds; its triangles as Wavefront OBJ for other renderers. */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>

#include "camera.h"
#include "choice.h"
#include "cli.h"
#include "commands.h"
#include "image_io.h"
#include "session.h"

static void print_info_help(void) {
    printf("usage: glint info [SCENE] [--env FILE] [--variant NAME] [--method NAME] [--max-depth D]\n"
           "                  [--plan auto|full] [--obj FILE.obj]\n"
           "\n"
           "Prints a summary of SCENE: geometry, materials, lights, material variants, cameras, size\n"
           "(with --variant NAME, of that variant); then what the\n"
           "scene calls for (material classes, emitters, whether indirect and glossy-to-glossy\n"
           "transport exist) and the passes the method would run (vsl+hl has every pass), each with\n"
           "its reason. With --method auto, also what auto chose after a short render from the first\n"
           "camera: a map of its tiles, each the path tracer's or the virtual lights'.\n"
           "\n"
           "options (default in brackets):\n"
           "%s"
           "  --env FILE           environment map, equirectangular .exr or .hdr [none]\n"
           "  --variant NAME       the scene's material variant NAME [the file's default materials]\n"
           "  --obj FILE.obj       the triangles as loaded (world space, with normals) as Wavefront\n"
           "                       OBJ, and beside it FILE.mtl with each material's diffuse colour\n"
           "                       (its base colour or Phong/Ward kd; nothing else of the material):\n"
           "                       the same geometry for another renderer\n"
           "\n",
           params_render_help("method max-depth plan", "method=" DEFAULT_METHOD_NAME));
    cli_print_scenes();
}

/* --method auto's choice, as it stands after AUTO_FRAMES frames at AUTO_W x AUTO_H from camera 0
 * (judged after its probe and frames 1, 2, 4): a character a tile, '#' where the virtual lights
 * took two thirds of its samples or more, '.' where the path tracer did, '+' between. */
#define AUTO_W (20 * CHOICE_TILE)
#define AUTO_H (12 * CHOICE_TILE)
#define AUTO_FRAMES 8
static int print_auto_choice(const scene *s, const render_params *given) {
    render_params p = {.method = METHOD_AUTO, .max_depth = given->max_depth, .plan = given->plan};
    p.width = AUTO_W, p.height = AUTO_H, p.seed = 1;
    camera cam = scene_camera(s, 0, (float)AUTO_W / (float)AUTO_H);
    char err[256];
    render_session *rs = session_create(s, &cam, &p, err, sizeof err);
    float *share = malloc(sizeof(float) * 3 * AUTO_W * AUTO_H);
    int ok = rs && share;
    for (int f = 0; ok && f < AUTO_FRAMES; f++) ok = session_render_frame(rs) == 0;
    if (!ok) {
        cli_error("%s: auto's choice: %s", s->path, rs ? session_error(rs) : err);
        free(share);
        if (rs) session_destroy(rs);
        return -1;
    }
    session_vl_share(rs, share);
    int vl = 0, tiles = (AUTO_W / CHOICE_TILE) * (AUTO_H / CHOICE_TILE);
    double sum = 0.0;
    printf("auto:       after %d frames at %dx%d from the first camera, a tile a character: the share\n"
           "            of its samples the virtual lights took ('#' two thirds or more, '.' a third or less):\n",
           AUTO_FRAMES, AUTO_W, AUTO_H);
    for (int ty = 0; ty < AUTO_H / CHOICE_TILE; ty++) {
        char row[AUTO_W / CHOICE_TILE + 1];
        for (int tx = 0; tx < AUTO_W / CHOICE_TILE; tx++) {
            double t = 0.0;
            for (int y = ty * CHOICE_TILE; y < (ty + 1) * CHOICE_TILE; y++)
                for (int x = tx * CHOICE_TILE; x < (tx + 1) * CHOICE_TILE; x++)
                    t += (double)share[3 * (y * AUTO_W + x)];
            t /= CHOICE_TILE * CHOICE_TILE;
            sum += t;
            vl += t >= 2.0 / 3.0;
            row[tx] = t >= 2.0 / 3.0 ? '#' : t <= 1.0 / 3.0 ? '.' : '+';
        }
        row[AUTO_W / CHOICE_TILE] = '\0';
        printf("            %s\n", row);
    }
    printf("            %d of %d tiles mostly the virtual lights', %.0f%% of all samples\n", vl, tiles,
           100.0 * sum / tiles);
    free(share);
    session_destroy(rs);
    return 0;
}

/* FILE.obj and FILE.mtl (FILE.obj.mtl for another extension), each written atomically. */
static int write_obj(const scene *s, const char *obj_path) {
    char mtl_path[4200], err[4400];
    size_t len = strlen(obj_path);
    if (len > 4 && strcmp(obj_path + len - 4, ".obj") == 0)
        snprintf(mtl_path, sizeof mtl_path, "%.*s.mtl", (int)(len - 4), obj_path);
    else
        snprintf(mtl_path, sizeof mtl_path, "%s.mtl", obj_path);
    const char *slash = strrchr(mtl_path, '/');
    char *buf[2] = {NULL, NULL};
    size_t size[2] = {0, 0};
    FILE *mtl = open_memstream(&buf[0], &size[0]), *obj = open_memstream(&buf[1], &size[1]);
    if (!mtl || !obj) {
        if (mtl) fclose(mtl);
        if (obj) fclose(obj);
        free(buf[0]);
        free(buf[1]);
        return cli_error("%s: out of memory", obj_path), -1;
    }
    for (int m = 0; m < s->num_materials; m++) {
        const material *mat = &s->materials[m];
        vec3 kd = mat->model == MATERIAL_GLTF ? mat->base_color : mat->kd;
        fprintf(mtl, "newmtl m%d\nKd %.6g %.6g %.6g\nKs 0 0 0\n\n", m, (double)kd.x, (double)kd.y, (double)kd.z);
    }
    fprintf(obj, "mtllib %s\n", slash ? slash + 1 : mtl_path);
    for (int i = 0; i < s->num_vertices; i++)
        fprintf(obj, "v %.9g %.9g %.9g\n", (double)s->positions[i].x, (double)s->positions[i].y,
                (double)s->positions[i].z);
    for (int i = 0; i < s->num_vertices; i++)
        fprintf(obj, "vn %.6g %.6g %.6g\n", (double)s->normals[i].x, (double)s->normals[i].y, (double)s->normals[i].z);
    int current = -1;
    for (int t = 0; t < s->num_triangles; t++) {
        if (s->tri_material[t] != current) fprintf(obj, "usemtl m%d\n", current = s->tri_material[t]);
        const uint32_t *v = &s->indices[3 * t];
        fprintf(obj, "f %u//%u %u//%u %u//%u\n", v[0] + 1, v[0] + 1, v[1] + 1, v[1] + 1, v[2] + 1, v[2] + 1);
    }
    fclose(mtl);
    fclose(obj);
    int status = write_file_atomic(mtl_path, buf[0], size[0], WRITE_REPLACE, err, sizeof err);
    if (status == 0) status = write_file_atomic(obj_path, buf[1], size[1], WRITE_REPLACE, err, sizeof err);
    free(buf[0]);
    free(buf[1]);
    if (status) cli_error("%s", err);
    return status;
}

int cmd_info(int argc, char **argv) {
    const char *path = NULL, *env = NULL, *obj = NULL, *variant = NULL;
    render_params p = {.method = DEFAULT_METHOD, .max_depth = DEFAULT_MAX_DEPTH};
    const cli_opt opts[] = {
        {.name = "--env", .kind = CLI_TEXT, .out = &env},   {.name = "--variant", .kind = CLI_TEXT, .out = &variant},
        {.name = "--method", .kind = CLI_PARAM, .out = &p}, {.name = "--max-depth", .kind = CLI_PARAM, .out = &p},
        {.name = "--obj", .kind = CLI_TEXT, .out = &obj},   {.name = "--plan", .kind = CLI_PARAM, .out = &p},
    };
    for (int i = 0; i < argc; i++) {
        int r;
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            print_info_help();
            return EXIT_OK;
        } else if ((r = cli_table_option(argc, argv, &i, opts, (int)(sizeof opts / sizeof opts[0]))) != 0) {
            if (r < 0) return EXIT_USAGE;
        } else if (cli_scene_argument("info", argv[i], &path) != 0) {
            return EXIT_USAGE;
        }
    }
    const cli_file outputs[] = {{"--obj", obj}}, inputs[] = {{"the scene", path}, {"the environment map (--env)", env}};
    if (cli_check_roles(outputs, 1, inputs, 2) != 0) return EXIT_USAGE;
    if (obj && cli_check_output_dir("--obj", obj)) return EXIT_FAILURE_;
    double t0 = cli_now();
    scene *s = load_scene_or_default(path, env, 0.0f, variant);
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
    printf("geometry:   %d triangles, %d vertices", s->num_triangles, s->num_vertices);
    if (s->coincident) printf(", %ld triangles repeating another's corners", s->coincident);
    printf("\n");
    printf("size:       %.4g x %.4g x %.4g (diagonal %.4g), ray offset %.3g\n", (double)ext.x, (double)ext.y,
           (double)ext.z, (double)s->diag, (double)s->ray_eps);
    printf("materials:  %d (%d metallic-roughness, %d Phong, %d Ward; %d emissive)\n", s->num_materials,
           by_model[MATERIAL_GLTF], by_model[MATERIAL_PHONG], by_model[MATERIAL_WARD], emissive);
    printf("textures:   %d (%d images)\n", s->num_textures, s->num_images);
    printf("lights:     %d point, %d spot, %d directional, %d emissive triangles, %s\n", by_type[LIGHT_POINT],
           by_type[LIGHT_SPOT], by_type[LIGHT_DIRECTIONAL], by_type[LIGHT_TRIANGLE],
           s->env ? "an environment map" : "no environment map");
    /* The numbers glint render's --move-light and --light-gain and the viewer's panel take. */
    light_group groups[16];
    int num_groups = scene_light_groups(s, groups, 16);
    if (num_groups > 0) {
        printf("            by number (glint render --move-light, the viewer's panel): ");
        for (int i = 0; i < num_groups && i < 16; i++)
            printf("%s%d '%s' at %.4g %.4g %.4g", i ? ", " : "", i, groups[i].name, (double)groups[i].center.x,
                   (double)groups[i].center.y, (double)groups[i].center.z);
        printf("%s\n", num_groups > 16 ? ", ..." : "");
    }
    if (scene_num_variants(s) > 0) {
        printf("variants:   %d (", scene_num_variants(s));
        for (int i = 0; i < scene_num_variants(s); i++) printf("%s'%s'", i ? ", " : "", scene_variant_name(s, i));
        int v = scene_variant(s);
        printf("); shown: %s%s%s\n", v < 0 ? "the default materials" : "'", v < 0 ? "" : scene_variant_name(s, v),
               v < 0 ? "" : "'");
    }
    printf("cameras:    %d", s->num_cameras);
    for (int i = 0; i < s->num_cameras; i++) printf("%s%d '%s'", i ? ", " : " (", i, s->cameras[i].name);
    printf("%s\n", s->num_cameras ? ")" : " (a framing view is used)");
    /* Load includes parsing, flattening, the light list and the BVH build; ru_maxrss is in KiB. */
    printf("load:       %.3f s, peak memory %.1f MiB\n", load_seconds, (double)ru.ru_maxrss / 1024.0);
    if (s->num_warnings) printf("warnings:   %d (printed above)\n", s->num_warnings);
    if (obj && write_obj(s, obj) != 0) {
        scene_destroy(s);
        return EXIT_FAILURE_;
    }
    scene_analysis a;
    char err[256];
    if (scene_analyse(s, &a, err, sizeof err) != 0) {
        cli_error("%s: %s", s->path, err);
        scene_destroy(s);
        return EXIT_FAILURE_;
    }
    effect_plan plan = plan_make(&a, p.method, p.max_depth, p.plan);
    printf("method:     %s\n", method_name(p.method));
    plan_print(stdout, s, &a, &plan);
    scene_analysis_free(&a);
    int failed = p.method == METHOD_AUTO && print_auto_choice(s, &p) != 0;
    scene_destroy(s);
    return failed ? EXIT_FAILURE_ : EXIT_OK;
}
