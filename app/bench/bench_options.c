/* glint bench: its options — the help text, the presets, the runs (--methods, --run), budget and
 * sweep lists, and the checks that need nothing but the command line. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench.h"
#include "cli.h"

const char *const bench_err_names[ERR_COUNT] = {"all", "direct", "indirect", "highlights"};

/* The presets: named comparisons, each a list of options that goes before the user's (so an
 * option of the user's that takes one value replaces the preset's, and --run, --sweep add). */
typedef struct {
    const char *name, *what;
    const char *const args[32]; /* NULL-terminated */
} bench_preset;

#define HL_SETTINGS                                                                                                    \
    "--run", "vsl+hl:merge=trace", "--run", "vsl+hl:merge=off", "--run", "vsl+hl:clusters=1", "--run",                 \
        "vsl+hl:clusters=2", "--run", "vsl+hl:clusters=4"
static const bench_preset presets[] = {
    {"headline",
     "every method at equal time, the whole image",
     {"--methods", "pt,vsl,vsl+hl", "--seeds", "2", "--times", "2,10,60", NULL}},
    {"vsl-paper",
     "the VSL paper's comparison: the indirect light of path tracing, clamped VPLs\n"
     "and VSLs as the paper has them (every lobe gathered), VSLs with glint's\n"
     "defaults and two variations",
     {"--run", "pt", "--run", "vpl:trace-glossy=off", "--run", "vsl:trace-glossy=off", "--run", "vsl", "--run",
      "vsl:candidates=4", "--run", "vsl:radius-shrink=0.7", "--component", "indirect", "--seeds", "4", "--times",
      "10,60", NULL}},
    {"fig8",
     "the VSL paper's Fig. 8: the indirect light's error against the radius\n"
     "multiplier and against the cluster count, 4096 lights a frame, every lobe\n"
     "gathered",
     {"--run", "vsl:trace-glossy=off,vsl-count=4096", "--sweep", "radius-mult=1,2,4,8,12,16,24", "--sweep",
      "columns=64,128,256,512,1024", "--component", "indirect", "--times", "5,10", NULL}},
    {"highlights",
     "the highlight estimator alone (camera rays and the highlight pass): each\n"
     "hit's lobe traced, not merged, merged into 1, 2, 4 lobes; 8, 16, 32\n"
     "secondary rays",
     {"--only", "highlights", "--component", "highlights", HL_SETTINGS, "--sweep", "secondary-rays=8,16,32", "--seeds",
      "2", "--times", "15,30", NULL}},
    {"highlights-whole",
     "the whole renderer, its highlights layer compared: path tracing against\n"
     "vsl+hl with the settings of highlights, 8 and 32 secondary rays",
     {"--component", "highlights", "--dim-highlights", "off", "--run", "pt", HL_SETTINGS, "--sweep",
      "secondary-rays=8,32", "--seeds", "2", "--times", "10,30", NULL}},
    {"plan",
     "what the effect plan saves: vsl+hl with the passes the scene calls for\n"
     "against every pass forced on, the indirect light",
     {"--run", "vsl+hl", "--sweep", "plan=auto,full", "--component", "indirect", "--dim-highlights", "off", "--seeds",
      "2", "--times", "15,30", NULL}},
};
#undef HL_SETTINGS
enum { NUM_PRESETS = sizeof presets / sizeof presets[0] };

static void print_bench_help(void) {
    printf("usage: glint bench [SCENE] --reference REF.exr [options]\n"
           "       glint bench --collect DIR\n"
           "\n"
           "Renders SCENE (default: the built-in scene) with each method, progressively, and reads the\n"
           "error against REF.exr at each time budget of one run. REF.exr is a glint render --out\n"
           "(a long pt run), whose header records the scene, camera and size it must match (an older\n"
           "reference's sidecar REF.exr.json is read too).\n"
           "\n"
           "options (default in brackets):\n"
           "  --reference REF.exr  the reference image (required)\n"
           "  --preset NAME        a named comparison (below): its options go before yours, so yours\n"
           "                       that take one value replace its, and --run, --sweep add runs\n"
           "  --methods LIST       comma-separated: pt, vpl, vsl, vsl+hl, auto [pt,vpl,vsl,vsl+hl]\n"
           "  --run METHOD[:NAME=VALUE,...]\n"
           "                       one more run, of METHOD with settings of its own: many-light\n"
           "                       options by name and plan=auto|full (repeatable; --methods A,B is\n"
           "                       --run A --run B), e.g. --run vsl:trace-glossy=off,candidates=4\n"
           "  --times LIST         increasing time budgets in seconds [1,2,4,8]\n"
           "  --sweep NAME=V1,V2   one run per value of a setting (as for --run), for every run it\n"
           "                       applies to (repeatable; each sweep varies its parameter alone):\n"
           "                       radius-mult, columns, vsl-count, clusters, secondary-rays, clamp,\n"
           "                       clamp-value, radius-shrink, rows, per-pixel, candidates, plan, ...\n"
           "  --component C        the error plotted and reported: all, direct, indirect, highlights\n"
           "                       (highlights needs a reference rendered with --highlights-layer) [all]\n"
           "  --plan auto|full     every run's effect plan (glint info shows it) [auto]\n"
           "  --only LIST          the many-light methods render only these components (direct,\n"
           "                       indirect, highlights) and skip the others' passes: what one\n"
           "                       estimator costs alone; the other errors are not measured [all]\n"
           "  --size WxH           must match the reference [the reference's]\n"
           "  --camera INDEX       must match the reference [the reference's]\n"
           "  --max-depth D        [the reference's]\n"
           "  --env FILE           environment map; must match the reference's [none]\n"
           "  --env-rotation DEG   [0]\n"
           "  --seed S             the first seed; none of the bench's may be the reference's\n"
           "                       [the reference's + 1]\n"
           "  --seeds N            renders per run, with seeds S, S+1, ..., S+N-1; the report takes\n"
           "                       the RMS over them and, from 2 on, splits the error into noise and\n"
           "                       bias [1]\n"
           "  --threads N          render threads, 0 = one per core [0]\n"
           "  --out DIR            output directory, created; never overwritten [bench, bench-1, ...]\n"
           "  --jobs DIR           render nothing: write DIR/jobs.txt, one command line per run, to run\n"
           "                       anywhere (scripts/slurm/bench.sbatch); then glint bench --collect\n"
           "                       DIR writes the results, plots and report into DIR\n"
           "  --job K              render run K alone (a line of jobs.txt)\n"
           "  --force              accept a reference that records no scene, camera or size\n"
           "  --quiet              no progress lines\n"
           "  --help               this text\n"
           "\n"
           "Many-light options (see glint render --help) set every run's base parameters.\n"
           "Writes DIR/results.csv (every render), DIR/summary.csv (over the seeds), DIR/report.md,\n"
           "DIR/error-vs-time.svg and .png, and for each numeric sweep DIR/sweep-NAME.svg and .png\n"
           "(error against the value at the last budget).\n"
           "\n"
           "presets:\n");
    for (int k = 0; k < NUM_PRESETS; k++) {
        printf("  %-17s", presets[k].name);
        for (const char *w = presets[k].what; *w; w++) {
            putchar(*w);
            if (*w == '\n') printf("%19s", "");
        }
        printf("\n%19s", "");
        int col = 19;
        for (const char *const *a = presets[k].args; *a; a++) {
            int len = (int)strlen(*a);
            if (col > 19 && col + 1 + len > 95) printf("\n%19s", ""), col = 19;
            col += printf("%s%s", col > 19 ? " " : "", *a);
        }
        printf("\n");
    }
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
    const unsigned many = (1u << METHOD_VPL) | (1u << METHOD_VSL) | (1u << METHOD_VSL_HL) | (1u << METHOD_AUTO);
    if (strcmp(name, "radius-mult") == 0 || strcmp(name, "radius-shrink") == 0)
        return (1u << METHOD_VSL) | (1u << METHOD_VSL_HL) | (1u << METHOD_AUTO);
    if (strcmp(name, "secondary-rays") == 0 || strcmp(name, "clusters") == 0 || strcmp(name, "merge") == 0)
        return 1u << METHOD_VSL_HL;
    if (strcmp(name, "vpl-glossy") == 0 || strcmp(name, "clamp-growth") == 0) return 1u << METHOD_VPL;
    return many; /* the path tracer's plan never drops a pass */
}

int bench_apply_setting(const char *name, const char *value, render_params *p) {
    if (strcmp(name, "plan") == 0) return cli_parse_plan("--plan", value, &p->plan) ? -1 : 1;
    return cli_set_param(name, value, p, PARAM_GROUPS_VL);
}

unsigned bench_err_mask(int component) {
    const unsigned masks[ERR_COUNT] = {COMP_MASK_ALL, 1u << COMP_DIRECT,
                                       (1u << COMP_INDIRECT) | (1u << COMP_HIGHLIGHTS), 1u << COMP_HIGHLIGHTS};
    return masks[component];
}

/* Validates a setting NAME=VALUE for option `what`; 0, or -1 after reporting. */
static int check_setting(const char *what, const char *name, const char *value) {
    render_params scratch = {0};
    int r = bench_apply_setting(name, value, &scratch);
    if (r == 0)
        return cli_error("%s: '%s' is not a many-light option or plan (radius-mult, columns, vsl-count, clusters, "
                         "secondary-rays, clamp, clamp-value, radius-shrink, plan, ...)",
                         what, name),
               -1;
    return r < 0 ? -1 : 0;
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
        if (check_setting("--sweep", sw->name, items[k])) return -1;
        memcpy(sw->values[k], items[k], sizeof sw->values[k]);
    }
    sw->num_values = n;
    return 0;
}

/* METHOD or METHOD:NAME=VALUE,NAME=VALUE into v. */
static int parse_run(const char *text, bench_variant *v) {
    memset(v, 0, sizeof *v);
    const char *colon = strchr(text, ':');
    char method[32];
    size_t len = colon ? (size_t)(colon - text) : strlen(text);
    if (len == 0 || len >= sizeof method || strlen(text) >= sizeof v->label)
        return cli_error("--run: expected METHOD[:NAME=VALUE,...], got '%s'", text), -1;
    memcpy(method, text, len);
    method[len] = '\0';
    int m = method_from_name(method);
    if (m < 0) return cli_error("--run: unknown method '%s' (available: pt, vpl, vsl, vsl+hl, auto)", method), -1;
    v->method = (render_method)m;
    snprintf(v->label, sizeof v->label, "%s", method);
    if (!colon) return 0;
    char items[MAX_SETTINGS][32];
    int n = split_list(colon + 1, items, MAX_SETTINGS);
    if (n < 0)
        return cli_error("--run %s: expected 1 to %d comma-separated NAME=VALUE settings, got '%s'", method,
                         MAX_SETTINGS, colon + 1),
               -1;
    for (int k = 0; k < n; k++) {
        char *eq = strchr(items[k], '=');
        if (!eq || eq == items[k]) return cli_error("--run %s: expected NAME=VALUE, got '%s'", method, items[k]), -1;
        *eq = '\0';
        if (check_setting("--run", items[k], eq + 1)) return -1;
        if (!(bench_sweep_methods(items[k]) & (1u << m)))
            return cli_error("--run %s: %s does not apply to %s", text, items[k], method), -1;
        for (int j = 0; j < k; j++)
            if (strcmp(v->names[j], items[k]) == 0) return cli_error("--run %s: %s set twice", text, items[k]), -1;
        snprintf(v->names[k], sizeof v->names[k], "%s", items[k]);
        snprintf(v->values[k], sizeof v->values[k], "%s", eq + 1);
        size_t at = strlen(v->label);
        snprintf(v->label + at, sizeof v->label - at, " %s=%s", items[k], eq + 1);
    }
    v->num_settings = n;
    return 0;
}

static int add_variant(bench_options *o, const bench_variant *v) {
    if (o->num_variants >= MAX_VARIANTS) return cli_error("--run, --methods: at most %d runs", MAX_VARIANTS), -1;
    for (int k = 0; k < o->num_variants; k++)
        if (strcmp(o->variants[k].label, v->label) == 0) return cli_error("%s is listed twice", v->label), -1;
    o->variants[o->num_variants++] = *v;
    return 0;
}

/* "highlights" or "direct,indirect" into a mask of 1 << COMP_*. */
static int parse_only(const char *text, unsigned *mask) {
    char items[COMP_COUNT + 1][32];
    int n = split_list(text, items, COMP_COUNT + 1);
    *mask = 0;
    for (int k = 0; k < n; k++) {
        int c = -1;
        for (int j = 0; j < COMP_COUNT; j++)
            if (strcmp(items[k], film_component_names[j]) == 0) c = j;
        if (c < 0)
            n = -1;
        else
            *mask |= 1u << c;
    }
    if (n <= 0) return cli_error("--only: expected components among direct, indirect, highlights, got '%s'", text), -1;
    return 0;
}

static void append_base(bench_options *o, const char *a, const char *v) {
    size_t len = strlen(o->base_text);
    snprintf(o->base_text + len, sizeof o->base_text - len, "%s%s%s%s", len ? " " : "", a, v ? " " : "", v ? v : "");
}

/* A many-light option of the table into vl (cli_param_option); the methods, depth, size, seed and
 * plan are bench's own options (--methods, its runs' reference depth and size, --seed S --seeds N). */
static int vl_option(int argc, char **argv, int *i, vl_params *vl) {
    render_params p = {.vl = *vl};
    int r = cli_param_option(argc, argv, i, &p, PARAM_GROUPS_VL);
    if (r > 0) *vl = p.vl;
    return r;
}

/* Parses argv into o. Returns 0, 1 (--help), -1 (reported), or 2 at the first --preset, its
 * index in *preset_at: the caller parses again with the preset's options first. */
static int parse_pass(int argc, char **argv, bench_options *o, int *preset_at, const char **methods, const char **times,
                      const char **only) {
    const cli_opt opts[] = {
        {.name = "--quiet", .kind = CLI_FLAG, .out = &o->quiet},
        {.name = "--force", .kind = CLI_FLAG, .out = &o->force},
        {.name = "--reference", .kind = CLI_TEXT, .out = &o->ref_path},
        {.name = "--methods", .kind = CLI_TEXT, .out = methods},
        {.name = "--times", .kind = CLI_TEXT, .out = times},
        {.name = "--only", .kind = CLI_TEXT, .out = only},
        {.name = "--size", .kind = CLI_SIZE, .out = &o->width, .out2 = &o->height},
        {.name = "--camera", .kind = CLI_LONG, .out = &o->camera_index, .lo = 0, .hi = CLI_CAMERA_MAX},
        {.name = "--max-depth", .kind = CLI_INT, .out = &o->max_depth, .lo = 1, .hi = MAX_DEPTH_LIMIT},
        {.name = "--plan", .kind = CLI_PLAN, .out = &o->plan},
        {.name = "--env", .kind = CLI_TEXT, .out = &o->env_path},
        {.name = "--env-rotation", .kind = CLI_FLOAT, .out = &o->env_rotation_deg, .lo = -36000.0, .hi = 36000.0},
        {.name = "--seed", .kind = CLI_U64, .out = &o->seed, .given = &o->seed_given},
        {.name = "--seeds", .kind = CLI_INT, .out = &o->seeds, .lo = 1, .hi = MAX_SEEDS},
        {.name = "--threads", .kind = CLI_INT, .out = &o->threads, .lo = 0, .hi = CLI_THREADS_MAX},
        {.name = "--out", .kind = CLI_TEXT, .out = &o->out_dir},
        {.name = "--jobs", .kind = CLI_TEXT, .out = &o->jobs_dir},
        {.name = "--job", .kind = CLI_LONG, .out = &o->job, .lo = 0, .hi = MAX_RUNS - 1, .given = &o->job_given},
    };
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i], *v;
        int r, at = i;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            print_bench_help();
            return 1;
        } else if ((r = cli_table_option(argc, argv, &i, opts, (int)(sizeof opts / sizeof opts[0]))) != 0) {
            if (r < 0) return -1;
        } else if (strcmp(a, "--preset") == 0) {
            if (!(v = cli_value(argc, argv, &i))) return -1;
            if (o->preset) return cli_error("--preset: given twice ('%s' and '%s')", o->preset, v), -1;
            for (int k = 0; k < NUM_PRESETS; k++)
                if (strcmp(v, presets[k].name) == 0) o->preset = presets[k].name;
            if (!o->preset)
                return cli_error("--preset: unknown preset '%s' (see glint bench --help: headline, vsl-paper, fig8, "
                                 "highlights, highlights-whole, plan)",
                                 v),
                       -1;
            if (*preset_at < 0) return *preset_at = at, 2;
        } else if (strcmp(a, "--run") == 0) {
            bench_variant run;
            if (!(v = cli_value(argc, argv, &i)) || parse_run(v, &run) || add_variant(o, &run)) return -1;
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
        } else if ((r = vl_option(argc, argv, &i, &o->vl)) != 0) {
            if (r < 0) return -1;
            append_base(o, a, i > at ? argv[i] : NULL);
        } else if (cli_scene_argument("bench", a, &o->scene_path) != 0) {
            return -1;
        }
    }
    return 0;
}

int bench_parse_options(int argc, char **argv, bench_options *o) {
    const char *methods = NULL, *times = "1,2,4,8", *only = NULL;
    int preset_at = -1;
    memset(o, 0, sizeof *o);
    o->camera_index = -2;
    o->seeds = 1;
    int r = parse_pass(argc, argv, o, &preset_at, &methods, &times, &only);
    if (r == 2) { /* again, the preset's options first and --preset NAME left out */
        const bench_preset *pr = NULL;
        for (int k = 0; k < NUM_PRESETS; k++)
            if (strcmp(o->preset, presets[k].name) == 0) pr = &presets[k];
        char *args[64 + 32];
        int n = 0;
        if (argc > 64) return cli_error("glint bench: too many arguments with --preset"), -1;
        for (const char *const *a = pr->args; *a; a++) args[n++] = (char *)(uintptr_t)*a;
        for (int i = 0; i < argc; i++)
            if (i != preset_at && i != preset_at + 1) args[n++] = argv[i];
        methods = NULL, times = "1,2,4,8", only = NULL;
        memset(o, 0, sizeof *o);
        o->camera_index = -2;
        o->seeds = 1;
        o->preset = pr->name;
        r = parse_pass(n, args, o, &preset_at, &methods, &times, &only);
    }
    if (r != 0) return r;
    if (!o->ref_path) return cli_error("glint bench needs --reference REF.exr (see glint bench --help)"), -1;
    if (o->jobs_dir && (o->out_dir || o->job_given))
        return cli_error("--jobs: the jobs choose their own --out and --job"), -1;

    /* --methods first, then the --run variants; all four methods when neither is given. */
    bench_variant runs[MAX_VARIANTS];
    int num_runs = o->num_variants;
    memcpy(runs, o->variants, sizeof runs);
    o->num_variants = 0;
    if (!methods && num_runs == 0) methods = "pt,vpl,vsl,vsl+hl";
    char items[MAX_TIMES][32];
    int n = methods ? split_list(methods, items, MAX_VARIANTS) : 0;
    if (n < 0)
        return cli_error("--methods: expected 1 to %d comma-separated methods, got '%s'", MAX_VARIANTS, methods), -1;
    for (int k = 0; k < n; k++) {
        bench_variant v = {0};
        int m = method_from_name(items[k]);
        if (m < 0)
            return cli_error("--methods: unknown method '%s' (available: pt, vpl, vsl, vsl+hl, auto)", items[k]), -1;
        v.method = (render_method)m;
        snprintf(v.label, sizeof v.label, "%s", items[k]);
        if (add_variant(o, &v)) return -1;
    }
    for (int k = 0; k < num_runs; k++)
        if (add_variant(o, &runs[k])) return -1;
    /* A sweep replaces a variant's own value of its parameter: that would hide one of them. */
    for (int w = 0; w < o->num_sweeps; w++)
        for (int k = 0; k < o->num_variants; k++)
            for (int j = 0; j < o->variants[k].num_settings; j++)
                if (strcmp(o->variants[k].names[j], o->sweeps[w].name) == 0)
                    return cli_error("--sweep %s: the run '%s' sets it already", o->sweeps[w].name,
                                     o->variants[k].label),
                           -1;
    if (o->plan == PLAN_FULL) append_base(o, "--plan", "full");
    if (only) {
        if (parse_only(only, &o->only)) return -1;
        append_base(o, "--only", only);
        for (int k = 0; k < o->num_variants; k++)
            if (o->variants[k].method == METHOD_PT)
                return cli_error("--only: pt renders whole paths, not one component (drop the pt run)"), -1;
        if ((bench_err_mask(o->component) & o->only) != bench_err_mask(o->component))
            return cli_error("--only %s: --component %s compares components it does not render", only,
                             bench_err_names[o->component]),
                   -1;
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
