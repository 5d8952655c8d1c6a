/* glint bench: its options — the help text, the method, budget and sweep lists, and the checks
 * that need nothing but the command line. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench.h"
#include "cli.h"

const char *const bench_err_names[ERR_COUNT] = {"all", "direct", "indirect", "highlights"};

static void print_bench_help(void) {
    printf("usage: glint bench [SCENE] --reference REF.exr [options]\n"
           "\n"
           "Renders SCENE (default: the built-in scene) with each method, progressively, and reads the\n"
           "error against REF.exr at each time budget of one run. REF.exr is a glint render --out\n"
           "(a long pt run), whose header records the scene, camera and size it must match (an older\n"
           "reference's sidecar REF.exr.json is read too).\n"
           "\n"
           "options (default in brackets):\n"
           "  --reference REF.exr  the reference image (required)\n"
           "  --methods LIST       comma-separated: pt, vpl, vsl, vsl+hl [pt,vpl,vsl,vsl+hl]\n"
           "  --times LIST         increasing time budgets in seconds [1,2,4,8]\n"
           "  --sweep NAME=V1,V2   one run per value of a many-light option, for every method it\n"
           "                       applies to (repeatable; each sweep varies its parameter alone):\n"
           "                       radius-mult, columns, vsl-count, clusters, secondary-rays, clamp,\n"
           "                       clamp-value, radius-shrink, rows, per-pixel, candidates, ...\n"
           "  --component C        the error plotted and reported: all, direct, indirect, highlights\n"
           "                       (highlights needs a reference rendered with --highlights-layer) [all]\n"
           "  --size WxH           must match the reference [the reference's]\n"
           "  --camera INDEX       must match the reference [the reference's]\n"
           "  --max-depth D        [the reference's]\n"
           "  --env FILE           environment map; must match the reference's [none]\n"
           "  --env-rotation DEG   [0]\n"
           "  --seed S             the first seed; none of the bench's may be the reference's\n"
           "                       [the reference's + 1]\n"
           "  --seeds N            renders per method and setting, with seeds S, S+1, ..., S+N-1; the\n"
           "                       report takes the RMS over them and, from 2 on, splits the error\n"
           "                       into noise and bias [1]\n"
           "  --threads N          render threads, 0 = one per core [0]\n"
           "  --out DIR            output directory, created; never overwritten [bench, bench-1, ...]\n"
           "  --force              accept a reference that records no scene, camera or size\n"
           "  --quiet              no progress lines\n"
           "  --help               this text\n"
           "\n"
           "Many-light options (see glint render --help) set every run's base parameters.\n"
           "Writes DIR/results.csv (every render), DIR/summary.csv (over the seeds), DIR/report.md,\n"
           "DIR/error-vs-time.svg and .png, and for each numeric sweep DIR/sweep-NAME.svg and .png\n"
           "(error against the value at the last budget).\n");
}

/* Splits a comma-separated list into at most max items of up to 31 characters. -1 when empty,
 * too long or with an empty item. */
static int split_list(const char *text, char items[][32], int max) {
    int n = 0;
    const char *p = text;
    for (;;) {
        const char *c = strchr(p, ',');
        size_t len = c ? (size_t)(c - p) : strlen(p);
        if (len == 0 || len >= 32 || n >= max) return -1;
        memcpy(items[n], p, len);
        items[n++][len] = '\0';
        if (!c) return n;
        p = c + 1;
    }
}

unsigned bench_sweep_methods(const char *name) {
    const unsigned many = (1u << METHOD_VPL) | (1u << METHOD_VSL) | (1u << METHOD_VSL_HL);
    if (strcmp(name, "radius-mult") == 0 || strcmp(name, "radius-shrink") == 0)
        return (1u << METHOD_VSL) | (1u << METHOD_VSL_HL);
    if (strcmp(name, "secondary-rays") == 0 || strcmp(name, "clusters") == 0 || strcmp(name, "merge") == 0)
        return 1u << METHOD_VSL_HL;
    if (strcmp(name, "vpl-glossy") == 0 || strcmp(name, "clamp-growth") == 0) return 1u << METHOD_VPL;
    return many;
}

static int parse_sweep(const char *text, sweep *sw) {
    const char *eq = strchr(text, '=');
    if (!eq || eq == text || (size_t)(eq - text) >= sizeof sw->name)
        return cli_error("--sweep: expected NAME=V1,V2,..., got '%s'", text), -1;
    snprintf(sw->name, sizeof sw->name, "%.*s", (int)(eq - text), text);
    char items[MAX_VALUES][32];
    int n = split_list(eq + 1, items, MAX_VALUES);
    if (n < 0)
        return cli_error("--sweep %s: expected 1 to %d comma-separated values, got '%s'", sw->name, MAX_VALUES, eq + 1),
               -1;
    for (int k = 0; k < n; k++) {
        vl_params scratch = {0};
        int r = cli_set_vl_param(sw->name, items[k], &scratch);
        if (r == 0)
            return cli_error("--sweep: '%s' is not a many-light option (radius-mult, columns, vsl-count, clusters, "
                             "secondary-rays, clamp, clamp-value, radius-shrink, ...)",
                             sw->name),
                   -1;
        if (r < 0) return -1;
        memcpy(sw->values[k], items[k], sizeof sw->values[k]);
    }
    sw->num_values = n;
    return 0;
}

static void append_base(bench_options *o, const char *a, const char *v) {
    size_t len = strlen(o->base_text);
    snprintf(o->base_text + len, sizeof o->base_text - len, "%s%s%s%s", len ? " " : "", a, v ? " " : "", v ? v : "");
}

int bench_parse_options(int argc, char **argv, bench_options *o) {
    memset(o, 0, sizeof *o);
    o->camera_index = -2;
    o->seeds = 1;
    const char *methods = "pt,vpl,vsl,vsl+hl", *times = "1,2,4,8";
    const cli_opt opts[] = {
        {.name = "--quiet", .kind = CLI_FLAG, .out = &o->quiet},
        {.name = "--force", .kind = CLI_FLAG, .out = &o->force},
        {.name = "--reference", .kind = CLI_TEXT, .out = &o->ref_path},
        {.name = "--methods", .kind = CLI_TEXT, .out = &methods},
        {.name = "--times", .kind = CLI_TEXT, .out = &times},
        {.name = "--size", .kind = CLI_SIZE, .out = &o->width, .out2 = &o->height},
        {.name = "--camera", .kind = CLI_LONG, .out = &o->camera_index, .lo = 0, .hi = CLI_CAMERA_MAX},
        {.name = "--max-depth", .kind = CLI_INT, .out = &o->max_depth, .lo = 1, .hi = CLI_MAX_DEPTH_MAX},
        {.name = "--env", .kind = CLI_TEXT, .out = &o->env_path},
        {.name = "--env-rotation", .kind = CLI_FLOAT, .out = &o->env_rotation_deg, .lo = -36000.0, .hi = 36000.0},
        {.name = "--seed", .kind = CLI_U64, .out = &o->seed, .given = &o->seed_given},
        {.name = "--seeds", .kind = CLI_INT, .out = &o->seeds, .lo = 1, .hi = MAX_SEEDS},
        {.name = "--threads", .kind = CLI_INT, .out = &o->threads, .lo = 0, .hi = CLI_THREADS_MAX},
        {.name = "--out", .kind = CLI_TEXT, .out = &o->out_dir},
    };
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i], *v;
        int r, at = i;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            print_bench_help();
            return 1;
        } else if ((r = cli_table_option(argc, argv, &i, opts, (int)(sizeof opts / sizeof opts[0]))) != 0) {
            if (r < 0) return -1;
        } else if (strcmp(a, "--sweep") == 0) {
            if (!(v = cli_value(argc, argv, &i))) return -1;
            if (o->num_sweeps >= MAX_SWEEPS) return cli_error("--sweep: at most %d sweeps", MAX_SWEEPS), -1;
            if (parse_sweep(v, &o->sweeps[o->num_sweeps])) return -1;
            for (int k = 0; k < o->num_sweeps; k++)
                if (strcmp(o->sweeps[k].name, o->sweeps[o->num_sweeps].name) == 0)
                    return cli_error("--sweep: %s is swept twice", o->sweeps[k].name), -1;
            o->num_sweeps++;
        } else if (strcmp(a, "--component") == 0) {
            if (!(v = cli_value(argc, argv, &i))) return -1;
            int c = -1;
            for (int k = 0; k < ERR_COUNT; k++)
                if (strcmp(v, bench_err_names[k]) == 0) c = k;
            if (c < 0) return cli_error("--component: expected all, direct, indirect or highlights, got '%s'", v), -1;
            o->component = c;
        } else if ((r = cli_vl_option(argc, argv, &i, &o->vl)) != 0) {
            if (r < 0) return -1;
            append_base(o, a, i > at ? argv[i] : NULL);
        } else if (cli_scene_argument("bench", a, &o->scene_path) != 0) {
            return -1;
        }
    }
    if (!o->ref_path) return cli_error("glint bench needs --reference REF.exr (see glint bench --help)"), -1;

    char items[MAX_TIMES][32];
    int n = split_list(methods, items, MAX_METHODS);
    if (n < 0)
        return cli_error("--methods: expected 1 to %d comma-separated methods, got '%s'", MAX_METHODS, methods), -1;
    for (int k = 0; k < n; k++) {
        int m = method_from_name(items[k]);
        if (m < 0) return cli_error("--methods: unknown method '%s' (available: pt, vpl, vsl, vsl+hl)", items[k]), -1;
        for (int j = 0; j < o->num_methods; j++)
            if (o->methods[j] == (render_method)m) return cli_error("--methods: %s is listed twice", items[k]), -1;
        o->methods[o->num_methods++] = (render_method)m;
    }
    n = split_list(times, items, MAX_TIMES);
    if (n < 0) return cli_error("--times: expected 1 to %d comma-separated seconds, got '%s'", MAX_TIMES, times), -1;
    for (int k = 0; k < n; k++) {
        if (cli_parse_float("--times", items[k], 1e-3, 1e7, &o->times[k])) return -1;
        if (k > 0 && !(o->times[k] > o->times[k - 1]))
            return cli_error("--times: the budgets must increase, got '%s'", times), -1;
    }
    o->num_times = n;
    return 0;
}
