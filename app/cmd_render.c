/* glint render: headless progressive rendering to EXR, PNG and JSON statistics. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#include "camera.h"
#include "choice.h"
#include "cli.h"
#include "commands.h"
#include "display.h"
#include "film.h"
#include "highlights.h"
#include "image_io.h"
#include "reference.h"
#include "session.h"

typedef struct {
    const char *scene_path;
    render_params params;
    long long spp; /* frames to render; 0 with seconds > 0 means "until time is up" */
    double seconds;
    const char *env_path;
    double env_rotation_deg;
    const char *variant; /* NULL: the file's default materials */
    long long camera_index;
    const char *camera_from;                      /* --camera-from: a glint EXR whose description gives the camera */
    light_edit lights[REFERENCE_MAX_LIGHT_EDITS]; /* --move-light, --light-gain: one per group */
    int gain_given[REFERENCE_MAX_LIGHT_EDITS];
    int num_lights;
    const char *out_exr, *out_png, *out_stats;
    const char *shard;   /* --shard I/N as given; its numbers are in params */
    long long spp_total; /* a shard's: the whole render's --spp (spp is the shard's share) */
    int quiet;
} render_options;

#define DEFAULT_SPP 64

static void print_render_help(void) {
    printf("usage: glint render [SCENE] [options]\n"
           "\n"
           "Renders SCENE (a .gltf/.glb or builtin:NAME, see glint --help; default: the default\n"
           "built-in scene) progressively, one sample per pixel per frame, and writes the running mean.\n"
           "\n"
           "options (default in brackets):\n"
           "%s"
           "  --spp N              samples per pixel (frames) [%d]\n"
           "  --time SECONDS       render until this much time has passed instead of --spp\n"
           "  --env FILE           environment map, equirectangular .exr or .hdr [none]\n"
           "  --env-rotation DEG   rotate the environment about +Y [0]\n"
           "  --variant NAME       the scene's material variant NAME (KHR_materials_variants;\n"
           "                       glint info lists them) [the file's default materials]\n"
           "  --camera INDEX       glTF camera to render from [0; a framing view without cameras]\n"
           "  --camera-from FILE.exr  the camera recorded in a glint EXR's description (a\n"
           "                       reference, a merge, a viewer's capture) of this scene\n"
           "  --move-light G,DX,DY,DZ  move light G (as glint info numbers them) by a world-space\n"
           "                       offset, as the viewer does; repeatable, moves add up\n"
           "  --light-gain G,X     light G's intensity times X (as the viewer's panel sets it)\n"
           "  --threads N          render threads, 0 = one per core [0]\n"
           "  --out FILE.exr       float EXR: R,G,B plus direct.*, indirect.* layers, and in its\n"
           "                       header the scene hash, camera, size, spp, noise: a reference\n"
           "                       for glint bench [none]\n"
           "  --shard I/N          render shard I (from 0) of N: its share of the frames of the\n"
           "                       render --spp asks for, in a row, with the moments glint merge\n"
           "                       needs, to --out\n"
           "  --highlights-layer   camera-glossy-glossy-light paths (the highlight estimator's share)\n"
           "                       go to their own highlights.* layer, not indirect.*: pt, vsl+hl\n"
           "  --png FILE.png       tone-mapped 8-bit sRGB PNG (--tonemap, --exposure) [none]\n"
           "  --stats FILE.json    statistics: frames, spp, seconds, rays by kind, rejected samples [none]\n"
           "  --quiet              no progress line\n"
           "  --help               this text\n",
           params_render_help("method max-depth seed size plan", NULL), DEFAULT_SPP);
    /* the look's entries after the outputs they shape (the help's text is the table's, static) */
    printf("%s\n%s\nNamed outputs are replaced atomically. Without --out, --png or --stats, the PNG goes to a\n"
           "new file render.png (render-1.png, ... if taken).\n",
           params_render_help("exposure tonemap denoise", NULL), cli_vl_help());
}

/* Whether name ends in suffix, in either case. */
static int has_suffix(const char *name, const char *suffix) {
    size_t n = strlen(name), k = strlen(suffix);
    return n > k && strcasecmp(name + n - k, suffix) == 0;
}

/* --shard I/N: shard I's share of the render --spp asks for, which is then the whole render's
 * (as many frames as I, I + N, ... below it, in a row: shard_frame_index). 0, or -1 after a usage
 * error. */
static int parse_shard(render_options *o) {
    long long i, n;
    char first[32];
    const char *slash = strchr(o->shard, '/');
    if (!slash || slash - o->shard >= (long)sizeof first)
        return cli_error("--shard: '%s' is not I/N (shard I of N, from 0)", o->shard), -1;
    snprintf(first, sizeof first, "%.*s", (int)(slash - o->shard), o->shard);
    if (cli_parse_int("--shard", slash + 1, 1, REFERENCE_MAX_SHARDS, &n) != 0 ||
        cli_parse_int("--shard", first, 0, n - 1, &i) != 0)
        return -1;
    if (!o->out_exr) return cli_error("--shard: a shard is its EXR: name it with --out FILE.exr"), -1;
    o->params.shard_index = (int)i;
    o->params.shard_count = (int)n;
    o->spp_total = o->spp;
    o->params.shard_spp_total = o->spp;
    if (o->spp > 0) {
        if (o->spp <= i) return cli_error("--shard %s: --spp %lld leaves shard %lld no frame", o->shard, o->spp, i), -1;
        o->spp = shard_share(o->spp, (int)i, (int)n);
    }
    return 0;
}

/* The edit of light group g, added when new; NULL (reported) when there are too many. */
static light_edit *light_edit_for(render_options *o, int g) {
    for (int i = 0; i < o->num_lights; i++)
        if (o->lights[i].group == g) return &o->lights[i];
    if (o->num_lights == REFERENCE_MAX_LIGHT_EDITS)
        return cli_error("more than %d lights edited", REFERENCE_MAX_LIGHT_EDITS), NULL;
    o->gain_given[o->num_lights] = 0;
    o->lights[o->num_lights] = (light_edit){g, v3(0, 0, 0), 1.0f};
    return &o->lights[o->num_lights++];
}

/* n numbers separated by commas, nothing else. 0, or -1. */
static int parse_numbers(const char *text, double *v, int n) {
    const char *p = text;
    for (int k = 0; k < n; k++) {
        char *end;
        v[k] = strtod(p, &end);
        if (end == p || !isfinite(v[k]) || *end != (k < n - 1 ? ',' : '\0')) return -1;
        p = end + 1;
    }
    return 0;
}

/* --move-light G,DX,DY,DZ (moves of one light add up) and --light-gain G,X (once a light). 0, or
 * -1 after a usage error. */
static int parse_light_option(render_options *o, const char *option, const char *value) {
    int gain = strcmp(option, "--light-gain") == 0;
    double v[4];
    if (parse_numbers(value, v, gain ? 2 : 4) != 0)
        return cli_error("%s: '%s' is not %s", option, value,
                         gain ? "G,X (a light and a factor)" : "G,DX,DY,DZ (a light and an offset)"),
               -1;
    if (v[0] < 0 || v[0] >= 1e6 || v[0] != floor(v[0]))
        return cli_error("%s: '%s': the light is a whole number from 0 (glint info lists them)", option, value), -1;
    if (gain && !(v[1] >= 1e-6 && v[1] <= 1e6))
        return cli_error("%s: '%s': the factor is 1e-6 to 1e6", option, value), -1;
    light_edit *e = light_edit_for(o, (int)v[0]);
    if (!e) return -1;
    if (!gain) {
        e->offset = add3(e->offset, v3((float)v[1], (float)v[2], (float)v[3]));
        return 0;
    }
    int *given = &o->gain_given[e - o->lights];
    if (*given) return cli_error("%s: light %d given twice", option, e->group), -1;
    *given = 1;
    e->gain = (float)v[1];
    return 0;
}

/* Returns 0 to render, 1 when --help was shown, -1 on a usage error (already reported). */
static int parse_render_options(int argc, char **argv, render_options *o) {
    memset(o, 0, sizeof *o);
    o->spp = -1;
    o->camera_index = -1;
    int spp_given = 0, time_given = 0;
    render_params *p = &o->params;
    const cli_opt opts[] = {
        {.name = "--quiet", .kind = CLI_FLAG, .out = &o->quiet},
        {.name = "--highlights-layer", .kind = CLI_FLAG, .out = &p->pt_highlights},
        {.name = "--spp", .kind = CLI_LONG, .out = &o->spp, .lo = 1, .hi = 100000000, .given = &spp_given},
        {.name = "--time", .kind = CLI_FLOAT, .out = &o->seconds, .lo = 1e-3, .hi = 1e7, .given = &time_given},
        {.name = "--env", .kind = CLI_TEXT, .out = &o->env_path},
        {.name = "--variant", .kind = CLI_TEXT, .out = &o->variant},
        {.name = "--env-rotation", .kind = CLI_FLOAT, .out = &o->env_rotation_deg, .lo = -36000.0, .hi = 36000.0},
        {.name = "--camera", .kind = CLI_LONG, .out = &o->camera_index, .lo = 0, .hi = CLI_CAMERA_MAX},
        {.name = "--threads", .kind = CLI_INT, .out = &p->threads, .lo = 0, .hi = CLI_THREADS_MAX},
        {.name = "--out", .kind = CLI_TEXT, .out = &o->out_exr},
        {.name = "--png", .kind = CLI_TEXT, .out = &o->out_png},
        {.name = "--stats", .kind = CLI_TEXT, .out = &o->out_stats},
        {.name = "--shard", .kind = CLI_TEXT, .out = &o->shard},
        {.name = "--camera-from", .kind = CLI_TEXT, .out = &o->camera_from},
    };
    for (int i = 0; i < argc; i++) {
        int r;
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            print_render_help();
            return 1;
        } else if (strcmp(argv[i], "--move-light") == 0 || strcmp(argv[i], "--light-gain") == 0) {
            const char *option = argv[i], *value = cli_value(argc, argv, &i);
            if (!value || parse_light_option(o, option, value) != 0) return -1;
        } else if ((r = cli_table_option(argc, argv, &i, opts, (int)(sizeof opts / sizeof opts[0]))) != 0 ||
                   (r = cli_param_option(argc, argv, &i, p, PARAM_GROUPS_ALL)) != 0) {
            if (r < 0) return -1;
        } else if (cli_scene_argument("render", argv[i], &o->scene_path) != 0) {
            return -1;
        }
    }
    if (spp_given && time_given) return cli_error("--spp and --time exclude each other"), -1;
    if (o->camera_from && o->camera_index >= 0) return cli_error("--camera and --camera-from exclude each other"), -1;
    if (o->params.pt_highlights && o->params.method != METHOD_PT && o->params.method != METHOD_VSL_HL)
        return cli_error("--highlights-layer: only pt and vsl+hl split highlights off (vpl and vsl count them "
                         "as indirect)"),
               -1;
    /* The format follows the option, not the name: an EXR named .png would fool every viewer. */
    if (o->out_exr && !has_suffix(o->out_exr, ".exr"))
        return cli_error("%s: --out writes OpenEXR: name it .exr (--png writes a PNG)", o->out_exr), -1;
    if (o->out_png && !has_suffix(o->out_png, ".png"))
        return cli_error("%s: --png writes a PNG: name it .png (--out writes OpenEXR)", o->out_png), -1;
    if (p->look.denoise && !o->out_exr)
        return cli_error("--denoise: the filtered image is a layer of --out FILE.exr"), -1;
    if (p->look.denoise && o->shard)
        return cli_error("--denoise: a shard is part of a render; filter the merged reference's render instead"), -1;
    if (!spp_given) o->spp = time_given ? 0 : DEFAULT_SPP;
    if (o->shard) return parse_shard(o);
    return 0;
}

/* Progress: one updating line on a terminal, a plain line every few seconds otherwise. */
typedef struct {
    int enabled, tty;
    double start, last;
} progress;

static void progress_update(progress *pg, const render_options *o, long long frames, double now, int final) {
    if (!pg->enabled) return;
    double elapsed = now - pg->start;
    double total = o->spp > 0 ? elapsed * (double)o->spp / (double)(frames > 0 ? frames : 1) : o->seconds;
    double left = fmax(total - elapsed, 0.0);
    if (pg->tty) {
        if (!final && now - pg->last < 0.1) return;
        if (o->spp > 0)
            fprintf(stderr, "\r\033[Kglint: frame %lld/%lld  %lld spp  %.1f s elapsed  %.1f s left", frames, o->spp,
                    frames, elapsed, left);
        else
            fprintf(stderr, "\r\033[Kglint: frame %lld  %lld spp  %.1f s elapsed  %.1f s left", frames, frames, elapsed,
                    left);
        if (final) fputc('\n', stderr);
    } else {
        if (!final && now - pg->last < 5.0) return;
        fprintf(stderr, "glint: frame %lld  %lld spp  %.1f s elapsed  %.1f s left%s\n", frames, frames, elapsed, left,
                final ? "  (done)" : "");
    }
    fflush(stderr);
    pg->last = now;
}

/* The counters of one section of the list (params.h, RENDER_COUNTERS), each after sep. */
static void json_counters(FILE *f, const render_stats *st, stats_section section, const char *sep) {
#define JSON_COUNTER(field, name, in, scale)                                                                           \
    if ((in) == section) {                                                                                             \
        if ((scale) == 1.0)                                                                                            \
            fprintf(f, "%s\"%s\": %llu", sep, name, (unsigned long long)st->field);                                    \
        else                                                                                                           \
            fprintf(f, "%s\"%s\": %.6f", sep, name, (scale) * (double)st->field);                                      \
    }
    RENDER_COUNTERS(JSON_COUNTER)
#undef JSON_COUNTER
}

/* Highlights are a layer of their own when they are split off (vsl+hl, --highlights-layer). */
static unsigned exr_layers(const render_options *o) {
    int split = o->params.pt_highlights || o->params.method == METHOD_VSL_HL;
    return (1u << COMP_DIRECT) | (1u << COMP_INDIRECT) | (split ? 1u << COMP_HIGHLIGHTS : 0u);
}

static int write_stats(const char *path, const render_options *o, const render_session *rs, const scene *s,
                       const camera *cam, double seconds, size_t clamped) {
    char *buf = NULL;
    size_t size = 0;
    FILE *f = open_memstream(&buf, &size);
    if (!f) return cli_error("%s: out of memory", path), -1;
    const render_params *p = session_params(rs);
    render_stats st = session_stats(rs);
    long long frames = session_frames(rs);
    uint64_t total = 0;
    for (int k = 0; k < RAY_KIND_COUNT; k++) total += st.rays[k];
    fprintf(f, "{\n  \"method\": \"%s\",\n  \"scene\": ", method_name(p->method));
    reference_json_string(f, s->path);
    fprintf(f, ",\n  \"width\": %d,\n  \"height\": %d,\n  \"frames\": %lld,\n  \"spp\": %lld,\n", p->width, p->height,
            frames, frames);
    fprintf(f, "  \"seconds\": %.6f,\n  \"max_depth\": %d,\n  \"seed\": %llu,\n  \"threads\": %d,\n", seconds,
            p->max_depth, (unsigned long long)p->seed, p->threads);
    const vec3 *axis[3] = {&cam->position, &cam->forward, &cam->up};
    const char *axis_name[3] = {"position", "forward", "up"};
    fprintf(f, "  \"camera\": {");
    for (int k = 0; k < 3; k++)
        fprintf(f, "\"%s\": [%.9g, %.9g, %.9g], ", axis_name[k], (double)axis[k]->x, (double)axis[k]->y,
                (double)axis[k]->z);
    fprintf(f, "\"yfov_degrees\": %.9g},\n", (double)cam->yfov * 180.0 / 3.14159265358979323846);
    fprintf(f, "  \"rays\": {");
    for (int k = 0; k < RAY_KIND_COUNT; k++)
        fprintf(f, "\"%s\": %llu, ", ray_kind_names[k], (unsigned long long)st.rays[k]);
    fprintf(f, "\"total\": %llu},\n", (unsigned long long)total);
    fprintf(f, "  \"rays_per_second\": %.1f,\n", seconds > 0 ? (double)total / seconds : 0.0);
    fprintf(f, "  \"values_clamped_to_float\": %zu", clamped);
    json_counters(f, &st, STATS_ALL, ",\n  ");
    if (p->method != METHOD_PT) {
        const vl_params vp = vl_params_resolve(&p->vl); /* the values the frames used */
        fprintf(f, ",\n  \"virtual_lights_per_frame\": %d,\n  \"rows\": %d,\n  \"columns\": %d", vp.count,
                vp.columns > 0 ? vp.rows : 0, vp.columns);
        json_counters(f, &st, STATS_MANY_LIGHT, ",\n  ");
    }
    if (p->method == METHOD_VSL_HL) {
        hl_setup hl = hl_setup_from(s, &p->vl, NULL);
        fprintf(f, ",\n  \"highlights\": {\"secondary_rays\": %d, \"clusters\": %d, \"merge\": %s", hl.secondary_rays,
                hl.clusters,
                hl.mode == HL_MERGED     ? (hl.choose ? "\"auto\"" : "\"on\"")
                : hl.mode == HL_UNMERGED ? "\"off\""
                                         : "\"trace\"");
        json_counters(f, &st, STATS_HIGHLIGHTS, ", ");
        fputc('}', f);
    }
    if (p->method == METHOD_AUTO) {
        fprintf(f, ",\n  \"auto\": {\"tile\": %d", CHOICE_TILE);
        json_counters(f, &st, STATS_AUTO, ", ");
        fputc('}', f);
    }
    /* The effect plan and what each pass cost: a skipped pass shows zero seconds. */
    const effect_plan *plan = session_plan(rs);
    fprintf(f,
            ",\n  \"plan\": {\"mode\": \"%s\", \"max_depth\": %d, \"virtual_lights\": %s, "
            "\"vsl_all_strategies\": %s, \"highlights\": %s, \"env_prefilter\": %s},\n",
            plan->full ? "full" : "auto", plan->max_depth, plan->virtual_lights ? "true" : "false",
            plan->vsl_all_strategies ? "true" : "false", plan->highlights ? "true" : "false",
            plan->env_prefilter ? "true" : "false");
    fprintf(f, "  \"pass_seconds\": {");
    for (int k = 0; k < PASS_COUNT; k++)
        fprintf(f, "%s\"%s\": %.6f", k ? ", " : "", pass_names[k], 1e-9 * (double)st.pass_ns[k]);
    fprintf(f, "}");
    fprintf(f, "\n}\n");
    fclose(f);
    char err[1024];
    int status = write_file_atomic(path, buf, size, WRITE_REPLACE, err, sizeof err);
    free(buf);
    if (status) cli_error("%s", err);
    return status;
}

/* What makes the EXR a reference (reference.h), as JSON for its header; glint bench checks a
 * reference by it. cam, cam_index: the camera rendered from (--camera-from's may be a free one,
 * -1). NULL after printing the error. */
static char *describe_reference(const render_options *o, const render_session *rs, const scene *s, const camera *cam,
                                int cam_index, double seconds, reference_noise *rn) {
    char err[1024];
    reference_info info;
    const render_params *p = session_params(rs);
    if (reference_describe(&info, o->scene_path, o->env_path, o->env_rotation_deg, s, cam_index, p, err, sizeof err) !=
        0)
        return cli_error("%s", err), NULL;
    if (o->camera_from) {
        info.cam = *cam;
        info.camera_index = cam_index;
    }
    if (reference_lights_text(o->lights, o->num_lights, info.lights, sizeof info.lights) != 0)
        return cli_error("%s: too many light edits to describe", o->out_exr), NULL;
    info.spp = session_frames(rs);
    info.spp_total = o->spp_total;
    info.seconds = seconds;
    reference_noise_finish(rn, rs, &info);
    char *json = reference_json(&info);
    if (!json) cli_error("%s: out of memory", o->out_exr);
    return json;
}

/* denoised: --denoise's image (NULL without), the layer denoised.* after the film's; with --method
 * auto, the layer vsl_share.* (session_vl_share) after it. */
static int write_outputs(const render_options *o, const render_session *rs, const scene *s, const camera *cam,
                         int cam_index, double seconds, reference_noise *rn, size_t clamped, const float *denoised) {
    const film *fm = session_film(rs);
    char err[1024];
    const unsigned layers = exr_layers(o);
    if (o->out_exr) {
        char *json = describe_reference(o, rs, s, cam, cam_index, seconds, rn);
        if (!json) return -1;
        exr_text_attr attr = {REFERENCE_ATTR, json};
        exr_layer extra[2];
        int n = 0;
        if (denoised) extra[n++] = (exr_layer){"denoised", denoised};
        float *share = NULL;
        if (o->params.method == METHOD_AUTO) {
            if (!(share = malloc(sizeof(float) * 3 * (size_t)fm->width * (size_t)fm->height))) {
                free(json);
                return cli_error("%s: out of memory", o->out_exr), -1;
            }
            session_vl_share(rs, share);
            extra[n++] = (exr_layer){"vsl_share", share};
        }
        int st = film_save_exr_extra(fm, layers, o->out_exr, &attr, 1, extra, n, WRITE_REPLACE, err, sizeof err);
        free(share);
        free(json);
        if (st != 0) {
            cli_error("%s", err);
            return -1;
        }
    }
    const char *png = o->out_png;
    char fallback[4096];
    if (!o->out_exr && !o->out_png && !o->out_stats) {
        if (unique_path("render.png", fallback, sizeof fallback) != 0) {
            cli_error("render.png: no free file name");
            return -1;
        }
        png = fallback;
    }
    if (png) {
        tonemap_params tp = {o->params.look.exposure, 0.0f, 0.0f, (tonemap_op)o->params.look.tonemap};
        if (film_save_png(fm, COMP_MASK_ALL, &tp, png, png == fallback ? WRITE_NO_REPLACE : WRITE_REPLACE, err,
                          sizeof err) != 0) {
            cli_error("%s", err);
            return -1;
        }
        if (png == fallback) printf("wrote %s\n", png);
    }
    if (o->out_stats) return write_stats(o->out_stats, o, rs, s, cam, seconds, clamped);
    return 0;
}

scene *load_scene_or_default(const char *path, const char *env_path, float env_rotation, const char *variant) {
    char err[1024];
    scene *s = path ? scene_load(path, cli_print_warning, NULL, err, sizeof err)
                    : scene_load_default(cli_print_warning, NULL, err, sizeof err);
    if (!s) {
        cli_error("%s", err);
        return NULL;
    }
    if ((env_path && scene_set_env(s, env_path, env_rotation, err, sizeof err) != 0) ||
        (variant && scene_select_variant(s, variant, err, sizeof err) != 0)) {
        cli_error("%s", err);
        scene_destroy(s);
        return NULL;
    }
    return s;
}

/* --camera-from: the camera FILE's description records, a view of scene s; *index the scene's
 * camera it is, else -1 (a free camera). 0, or -1 after printing the error. */
static int camera_from(const render_options *o, const scene *s, camera *cam, int *index) {
    reference_info r;
    char err[1200], hash[64];
    int st = reference_load(o->camera_from, &r, err, sizeof err);
    if (st < 0) return cli_error("%s", err), -1;
    if (st > 0)
        return cli_error("%s: --camera-from: no glint description in its header, so no camera to take", o->camera_from),
               -1;
    const char *scene_path = o->scene_path ? o->scene_path : s->path;
    if (reference_hash_file(scene_path, hash, err, sizeof err) != 0) return cli_error("%s", err), -1;
    if (strcmp(hash, r.scene_hash) != 0)
        return cli_error("%s: --camera-from: a view of another scene ('%s', %s), not '%s' (%s)", o->camera_from,
                         r.scene, r.scene_hash, scene_path, hash),
               -1;
    *cam = r.cam;
    *index = -1;
    for (int i = 0; i < s->num_cameras && *index < 0; i++)
        if (camera_same_view(cam, &s->cameras[i], s->diag)) *index = i;
    return 0;
}

/* --move-light and --light-gain on s, as the viewer edits its lights. 0, or -1 after printing the
 * error. */
static int edit_lights(const render_options *o, scene *s) {
    char err[512];
    int groups = scene_light_groups(s, NULL, 0);
    for (int i = 0; i < o->num_lights; i++) {
        const light_edit *e = &o->lights[i];
        if (e->group >= groups)
            return cli_error("%s: no light %d to edit (the scene has %d; glint info lists them)", s->path, e->group,
                             groups),
                   -1;
        if ((!is_black3(e->offset) && scene_move_light(s, e->group, e->offset, err, sizeof err) != 0) ||
            (e->gain != 1.0f && scene_set_light_gain(s, e->group, e->gain, err, sizeof err) != 0))
            return cli_error("%s: %s", s->path, err), -1;
    }
    return 0;
}

int cmd_render(int argc, char **argv) {
    render_options o;
    int parsed = parse_render_options(argc, argv, &o);
    if (parsed != 0) return parsed > 0 ? EXIT_OK : EXIT_USAGE;
    const cli_file outputs[] = {{"--out", o.out_exr}, {"--png", o.out_png}, {"--stats", o.out_stats}};
    const cli_file inputs[] = {
        {"the scene", o.scene_path}, {"the environment map (--env)", o.env_path}, {"--camera-from", o.camera_from}};
    if (cli_check_roles(outputs, 3, inputs, 3) != 0) return EXIT_USAGE;
    if ((o.out_exr && cli_check_output_dir("--out", o.out_exr)) ||
        (o.out_png && cli_check_output_dir("--png", o.out_png)) ||
        (o.out_stats && cli_check_output_dir("--stats", o.out_stats)))
        return EXIT_FAILURE_;

    scene *s = load_scene_or_default(o.scene_path, o.env_path, (float)(o.env_rotation_deg * 3.14159265358979 / 180.0),
                                     o.variant);
    if (!s) return EXIT_FAILURE_;
    if (o.camera_index >= 0 && o.camera_index >= s->num_cameras) {
        cli_error("%s: --camera %lld: the scene has %d camera%s", s->path, o.camera_index, s->num_cameras,
                  s->num_cameras == 1 ? "" : "s");
        scene_destroy(s);
        return EXIT_USAGE;
    }
    render_params p = render_params_resolve_frame(&o.params);
    camera cam = scene_camera(s, (int)o.camera_index, (float)p.width / (float)p.height);
    int cam_index = (int)o.camera_index;
    if (edit_lights(&o, s) != 0) {
        scene_destroy(s);
        return EXIT_USAGE;
    }
    if (o.camera_from && camera_from(&o, s, &cam, &cam_index) != 0) {
        scene_destroy(s);
        return EXIT_FAILURE_;
    }
    char err[1024];
    render_session *rs = session_create(s, &cam, &p, err, sizeof err);
    if (!rs) {
        cli_error("%s", err);
        scene_destroy(s);
        return EXIT_FAILURE_;
    }

    /* --denoise: the display takes every frame's samples as the viewer's does, and filters at the end */
    display *disp = NULL;
    float *denoised = NULL;
    if (o.params.look.denoise) {
        disp = display_create(p.width, p.height, p.threads, err, sizeof err);
        denoised = disp ? malloc(sizeof(float) * 3 * (size_t)p.width * (size_t)p.height) : NULL;
        if (!denoised) {
            cli_error("--denoise: %s", disp ? "out of memory" : err);
            display_destroy(disp);
            session_destroy(rs);
            scene_destroy(s);
            return EXIT_FAILURE_;
        }
        session_set_sink(rs, display_sink(disp));
        display_change_view(disp, s, &cam, DISPLAY_RESTART);
    }
    /* Only a reference (an EXR) pays for the noise estimate's snapshots. */
    reference_noise rn = {0};
    if (o.out_exr && reference_noise_init(&rn, p.width, p.height) != 0)
        cli_warning("%s: out of memory for the noise estimate; the reference will lack it", o.out_exr);
    progress pg = {!o.quiet, isatty(STDERR_FILENO), cli_now(), 0.0};
    pg.last = pg.start;
    double elapsed = 0.0;
    int status = -1;
    for (long long frame = 0;; frame++) {
        if (o.spp > 0 ? frame >= o.spp : (frame > 0 && elapsed >= o.seconds)) break;
        if (session_render_frame(rs) != 0) {
            cli_error("%s: %s", s->path, session_error(rs));
            goto done;
        }
        if (disp) display_take_samples(disp);
        double now = cli_now();
        elapsed = now - pg.start;
        reference_noise_frame(&rn, rs);
        progress_update(&pg, &o, frame + 1, now, 0);
    }
    progress_update(&pg, &o, session_frames(rs), cli_now(), 1);
    render_stats st = session_stats(rs);
    if (st.rejected_samples) cli_warning("%llu NaN/Inf samples were rejected", (unsigned long long)st.rejected_samples);
    size_t clamped = film_count_clamped(session_film(rs), exr_layers(&o));
    if (clamped) cli_warning("%zu pixel values beyond float's range were written as the largest float", clamped);
    if (disp) display_resolve(disp, COMP_MASK_ALL, 1, denoised);

    status = write_outputs(&o, rs, s, &cam, cam_index, elapsed, &rn, clamped, denoised);
done:
    reference_noise_deinit(&rn);
    session_destroy(rs);
    display_destroy(disp);
    free(denoised);
    scene_destroy(s);
    return status == 0 ? EXIT_OK : EXIT_FAILURE_;
}
