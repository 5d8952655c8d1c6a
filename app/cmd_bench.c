/* glint bench: what accuracy costs in time. Renders each method (and each setting of a parameter
 * sweep) progressively against a reference, reads the error at each time budget of one run, and
 * writes results.csv, error-versus-time plots (SVG, PNG) and report.md into a directory. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "camera.h"
#include "cli.h"
#include "commands.h"
#include "film.h"
#include "image_io.h"
#include "metrics.h"
#include "plot.h"
#include "reference.h"
#include "session.h"

enum { MAX_METHODS = 8, MAX_TIMES = 32, MAX_SWEEPS = 8, MAX_VALUES = 32, MAX_RUNS = 256 };

/* The error columns: the image and its components. Indirect always means all light after the
 * first bounce (highlights included), so it means the same for every method; highlights are
 * compared only where both the reference and the method split them off. */
enum { ERR_ALL = 0, ERR_DIRECT, ERR_INDIRECT, ERR_HIGHLIGHTS, ERR_COUNT };
static const char *const err_names[ERR_COUNT] = {"all", "direct", "indirect", "highlights"};

typedef struct {
    char name[32];
    int num_values;
    char values[MAX_VALUES][32];
} sweep;

typedef struct {
    const char *scene_path, *ref_path, *out_dir, *env_path;
    double env_rotation_deg;
    render_method methods[MAX_METHODS];
    int num_methods;
    double times[MAX_TIMES];
    int num_times;
    sweep sweeps[MAX_SWEEPS];
    int num_sweeps;
    int component; /* ERR_* */
    int width, height;      /* 0: the reference's */
    long long camera_index; /* -2: the reference's */
    int max_depth;          /* 0: the reference's */
    uint64_t seed;
    int seed_given;
    int threads;
    vl_params vl; /* the many-light options given: every run's base */
    char base_text[512];
    int force, quiet;
} bench_options;

typedef struct {
    render_params params;
    char setting[64]; /* "radius-mult=4", or "" for the base parameters */
    char label[96];   /* "vsl radius-mult=4" */
    int sweep;        /* index into the options' sweeps, -1 for a base run */
    int value;
    int num_points;
    double seconds[MAX_TIMES];
    long long frames[MAX_TIMES];
    double rays[MAX_TIMES];
    double rel_l2[ERR_COUNT][MAX_TIMES], relmse[ERR_COUNT][MAX_TIMES]; /* NAN: not measured */
} bench_run;

typedef struct {
    int width, height;
    float *layer[ERR_COUNT]; /* interleaved RGB; NULL when the EXR lacks the layer */
    reference_info info;
    int has_info;
} bench_ref;

static void print_bench_help(void) {
    printf("usage: glint bench [SCENE] --reference REF.exr [options]\n"
           "\n"
           "Renders SCENE (default: the built-in scene) with each method, progressively, and reads the\n"
           "error against REF.exr at each time budget of one run. REF.exr is a glint render --out\n"
           "(a long pt run); its sidecar REF.exr.json must match the scene, camera and size.\n"
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
           "  --seed S             random seed; must differ from the reference's [the reference's + 1]\n"
           "  --threads N          render threads, 0 = one per core [0]\n"
           "  --out DIR            output directory, created; never overwritten [bench, bench-1, ...]\n"
           "  --force              accept a reference without a sidecar\n"
           "  --quiet              no progress lines\n"
           "  --help               this text\n"
           "\n"
           "Many-light options (see glint render --help) set every run's base parameters.\n"
           "Writes DIR/results.csv, DIR/error-vs-time.svg and .png, DIR/report.md, and for each\n"
           "numeric sweep DIR/sweep-NAME.svg and .png (error against the value at the last budget).\n");
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

/* The methods each sweepable parameter is live for (bit per render_method). */
static unsigned sweep_methods(const char *name) {
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
    if (n < 0) return cli_error("--sweep %s: expected 1 to %d comma-separated values, got '%s'", sw->name, MAX_VALUES, eq + 1), -1;
    for (int k = 0; k < n; k++) {
        vl_params scratch = {0};
        int r = cli_set_vl_param(sw->name, items[k], &scratch);
        if (r == 0)
            return cli_error("--sweep: '%s' is not a many-light option (radius-mult, columns, vsl-count, clusters, "
                             "secondary-rays, clamp, clamp-value, radius-shrink, ...)", sw->name), -1;
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

/* Returns 0 to run, 1 when --help was shown, -1 on a usage error (already reported). */
static int parse_bench_options(int argc, char **argv, bench_options *o) {
    memset(o, 0, sizeof *o);
    o->camera_index = -2;
    const char *methods = "pt,vpl,vsl,vsl+hl", *times = "1,2,4,8";
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i], *v = NULL;
        long long n;
        int vl, at = i;
#define VALUE() \
    if (!(v = cli_value(argc, argv, &i))) return -1
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            print_bench_help();
            return 1;
        } else if (strcmp(a, "--quiet") == 0) {
            o->quiet = 1;
        } else if (strcmp(a, "--force") == 0) {
            o->force = 1;
        } else if (strcmp(a, "--reference") == 0) {
            VALUE();
            o->ref_path = v;
        } else if (strcmp(a, "--methods") == 0) {
            VALUE();
            methods = v;
        } else if (strcmp(a, "--times") == 0) {
            VALUE();
            times = v;
        } else if (strcmp(a, "--sweep") == 0) {
            VALUE();
            if (o->num_sweeps >= MAX_SWEEPS) return cli_error("--sweep: at most %d sweeps", MAX_SWEEPS), -1;
            if (parse_sweep(v, &o->sweeps[o->num_sweeps])) return -1;
            for (int k = 0; k < o->num_sweeps; k++)
                if (strcmp(o->sweeps[k].name, o->sweeps[o->num_sweeps].name) == 0)
                    return cli_error("--sweep: %s is swept twice", o->sweeps[k].name), -1;
            o->num_sweeps++;
        } else if (strcmp(a, "--component") == 0) {
            VALUE();
            int c = -1;
            for (int k = 0; k < ERR_COUNT; k++)
                if (strcmp(v, err_names[k]) == 0) c = k;
            if (c < 0) return cli_error("--component: expected all, direct, indirect or highlights, got '%s'", v), -1;
            o->component = c;
        } else if (strcmp(a, "--size") == 0) {
            VALUE();
            if (cli_parse_size(a, v, &o->width, &o->height)) return -1;
        } else if (strcmp(a, "--camera") == 0) {
            VALUE();
            if (cli_parse_int(a, v, 0, 1000000, &o->camera_index)) return -1;
        } else if (strcmp(a, "--max-depth") == 0) {
            VALUE();
            if (cli_parse_int(a, v, 1, 10000, &n)) return -1;
            o->max_depth = (int)n;
        } else if (strcmp(a, "--env") == 0) {
            VALUE();
            o->env_path = v;
        } else if (strcmp(a, "--env-rotation") == 0) {
            VALUE();
            if (cli_parse_float(a, v, -36000.0, 36000.0, &o->env_rotation_deg)) return -1;
        } else if (strcmp(a, "--seed") == 0) {
            VALUE();
            if (cli_parse_u64(a, v, &o->seed)) return -1;
            o->seed_given = 1;
        } else if (strcmp(a, "--threads") == 0) {
            VALUE();
            if (cli_parse_int(a, v, 0, 1024, &n)) return -1;
            o->threads = (int)n;
        } else if (strcmp(a, "--out") == 0) {
            VALUE();
            o->out_dir = v;
        } else if ((vl = cli_vl_option(argc, argv, &i, &o->vl)) != 0) {
            if (vl < 0) return -1;
            append_base(o, a, i > at ? argv[i] : NULL);
        } else if (cli_scene_argument("bench", a, &o->scene_path) != 0) {
            return -1;
        }
#undef VALUE
    }
    if (!o->ref_path) return cli_error("glint bench needs --reference REF.exr (see glint bench --help)"), -1;

    char items[MAX_TIMES][32];
    int n = split_list(methods, items, MAX_METHODS);
    if (n < 0) return cli_error("--methods: expected 1 to %d comma-separated methods, got '%s'", MAX_METHODS, methods), -1;
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

/* ---- the reference ----------------------------------------------------------------------------- */

static void ref_free(bench_ref *r) {
    for (int k = 0; k < ERR_COUNT; k++) free(r->layer[k]);
    memset(r, 0, sizeof *r);
}

/* Interleaves the EXR layer with the given prefix ("" for R,G,B); NULL when absent. */
static float *ref_layer(const exr_image *ex, const char *prefix) {
    const float *c[3];
    const char *ch[3] = {"R", "G", "B"};
    for (int k = 0; k < 3; k++) {
        char name[64];
        snprintf(name, sizeof name, "%s%s%s", prefix, prefix[0] ? "." : "", ch[k]);
        if (!(c[k] = exr_image_channel(ex, name))) return NULL;
    }
    size_t n = (size_t)ex->width * (size_t)ex->height;
    float *rgb = malloc(sizeof(float) * 3 * n);
    if (!rgb) return NULL;
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) rgb[3 * i + (size_t)k] = c[k][i];
    return rgb;
}

static int ref_load(const bench_options *o, bench_ref *r) {
    memset(r, 0, sizeof *r);
    char err[1200], side[4200];
    exr_image ex;
    if (exr_image_load(o->ref_path, &ex, err, sizeof err) != 0) return cli_error("%s", err), -1;
    r->width = ex.width;
    r->height = ex.height;
    r->layer[ERR_ALL] = ref_layer(&ex, "");
    r->layer[ERR_DIRECT] = ref_layer(&ex, "direct");
    r->layer[ERR_INDIRECT] = ref_layer(&ex, "indirect");
    r->layer[ERR_HIGHLIGHTS] = ref_layer(&ex, "highlights");
    exr_image_free(&ex);
    if (!r->layer[ERR_ALL]) {
        ref_free(r);
        return cli_error("%s: no R, G, B channels (or out of memory)", o->ref_path), -1;
    }
    /* Indirect means everything after the first bounce, whether or not highlights were split off. */
    if (r->layer[ERR_INDIRECT] && r->layer[ERR_HIGHLIGHTS])
        for (size_t i = 0; i < 3 * (size_t)r->width * (size_t)r->height; i++)
            r->layer[ERR_INDIRECT][i] += r->layer[ERR_HIGHLIGHTS][i];
    if (reference_sidecar_path(o->ref_path, side, sizeof side) != 0) {
        ref_free(r);
        return cli_error("%s: file name too long", o->ref_path), -1;
    }
    int st = reference_load(side, &r->info, err, sizeof err);
    if (st < 0) {
        ref_free(r);
        return cli_error("%s", err), -1;
    }
    if (st > 0 && !o->force) {
        ref_free(r);
        return cli_error("%s: no sidecar %s, so its scene, camera and size are unknown (render references with "
                         "glint render --out; --force uses it anyway)", o->ref_path, side), -1;
    }
    r->has_info = st == 0;
    if (r->has_info && (r->info.width != r->width || r->info.height != r->height)) {
        ref_free(r);
        return cli_error("%s: the image is %dx%d but its sidecar says %dx%d", o->ref_path, r->width, r->height,
                         r->info.width, r->info.height), -1;
    }
    return 0;
}

/* ---- measuring --------------------------------------------------------------------------------- */

typedef struct {
    const bench_ref *ref;
    float *img;
    size_t n;
} meter;

static void measure(meter *m, const render_session *rs, bench_run *run, int k) {
    const film *f = session_film(rs);
    const render_params *p = session_params(rs);
    int splits = p->pt_highlights || p->method == METHOD_VSL_HL;
    const unsigned masks[ERR_COUNT] = {COMP_MASK_ALL, 1u << COMP_DIRECT,
                                       (1u << COMP_INDIRECT) | (1u << COMP_HIGHLIGHTS), 1u << COMP_HIGHLIGHTS};
    for (int c = 0; c < ERR_COUNT; c++) {
        run->rel_l2[c][k] = run->relmse[c][k] = (double)NAN;
        if (!m->ref->layer[c] || (c == ERR_HIGHLIGHTS && !splits)) continue;
        film_resolve(f, masks[c], m->img);
        run->rel_l2[c][k] = metric_rel_l2(m->img, m->ref->layer[c], m->n);
        run->relmse[c][k] = metric_relmse(m->img, m->ref->layer[c], m->n);
    }
}

static int run_one(const bench_options *o, const scene *s, const camera *cam, meter *m, bench_run *run, int index,
                   int total) {
    char err[1024];
    render_session *rs = session_create(s, cam, &run->params, err, sizeof err);
    if (!rs) return cli_error("%s", err), -1;
    double rendered = 0.0;
    for (int k = 0; k < o->num_times; k++) {
        /* Only frame time counts: measuring the error in between is not the method's cost. */
        while (rendered < o->times[k] || session_frames(rs) == 0) {
            double t0 = cli_now();
            if (session_render_frame(rs) != 0) {
                cli_error("%s: %s", s->path, session_error(rs));
                session_destroy(rs);
                return -1;
            }
            rendered += cli_now() - t0;
        }
        render_stats st = session_stats(rs);
        double rays = 0.0;
        for (int r = 0; r < RAY_KIND_COUNT; r++) rays += (double)st.rays[r];
        run->seconds[k] = rendered;
        run->frames[k] = session_frames(rs);
        run->rays[k] = rays;
        measure(m, rs, run, k);
        run->num_points = k + 1;
        if (!o->quiet)
            fprintf(stderr, "glint: bench %d/%d %s: %.2f s, %lld frames, %s rel. L2 %.4g\n", index + 1, total,
                    run->label, rendered, run->frames[k], err_names[o->component], run->rel_l2[o->component][k]);
    }
    session_destroy(rs);
    return 0;
}

/* ---- outputs ----------------------------------------------------------------------------------- */

static void csv_number(FILE *f, double v) {
    if (isnan(v)) return;
    if (isinf(v)) fputs("inf", f);
    else fprintf(f, "%.6g", v);
}

static int write_csv(const char *dir, const bench_run *runs, int num_runs, write_mode mode) {
    char *buf = NULL, path[4200], err[4400];
    size_t size = 0;
    FILE *f = open_memstream(&buf, &size);
    if (!f) return cli_error("%s: out of memory", dir), -1;
    fputs("method,params,seconds,frames,spp,rays,rel_l2,relmse,direct_rel_l2,direct_relmse,indirect_rel_l2,"
          "indirect_relmse,highlights_rel_l2,highlights_relmse\n", f);
    for (int r = 0; r < num_runs; r++)
        for (int k = 0; k < runs[r].num_points; k++) {
            const bench_run *u = &runs[r];
            fprintf(f, "%s,%s,%.6f,%lld,%lld,%.0f", method_name(u->params.method), u->setting, u->seconds[k],
                    u->frames[k], u->frames[k], u->rays[k]);
            for (int c = 0; c < ERR_COUNT; c++) {
                fputc(',', f);
                csv_number(f, u->rel_l2[c][k]);
                fputc(',', f);
                csv_number(f, u->relmse[c][k]);
            }
            fputc('\n', f);
        }
    fclose(f);
    snprintf(path, sizeof path, "%s/results.csv", dir);
    int status = write_file_atomic(path, buf, size, mode, err, sizeof err);
    free(buf);
    if (status) cli_error("%s", err);
    return status;
}

/* Error of run r at budget k in the reported component. */
static double err_at(const bench_options *o, const bench_run *r, int k) {
    return k < r->num_points ? r->rel_l2[o->component][k] : (double)NAN;
}

static int write_plot(const char *dir, const char *stem, const plot_desc *pd) {
    char path[4200], err[4400];
    snprintf(path, sizeof path, "%s/%s.svg", dir, stem);
    if (plot_save_svg(pd, path, WRITE_NO_REPLACE, err, sizeof err) != 0) return cli_error("%s", err), -1;
    snprintf(path, sizeof path, "%s/%s.png", dir, stem);
    if (plot_save_png(pd, path, WRITE_NO_REPLACE, err, sizeof err) != 0) return cli_error("%s", err), -1;
    return 0;
}

/* The best curve at the last budget: the equal-error reading is taken at its error. */
static int best_run(const bench_options *o, const bench_run *runs, int num_runs, int k) {
    int best = -1;
    for (int r = 0; r < num_runs; r++) {
        double e = err_at(o, &runs[r], k);
        if (isfinite(e) && (best < 0 || e < err_at(o, &runs[best], k))) best = r;
    }
    return best;
}

static int write_time_plot(const bench_options *o, const char *dir, const bench_run *runs, int num_runs) {
    plot_series series[MAX_RUNS];
    double err[MAX_RUNS][MAX_TIMES];
    int ns = 0;
    for (int r = 0; r < num_runs; r++) {
        for (int k = 0; k < runs[r].num_points; k++) err[r][k] = err_at(o, &runs[r], k);
        series[ns++] = (plot_series){runs[r].label, runs[r].num_points, runs[r].seconds, err[r]};
    }
    int last = o->num_times - 1, best = best_run(o, runs, num_runs, last);
    char title[160], ylabel[96], xmark[64], ymark[192];
    snprintf(title, sizeof title, "Relative L2 error (%s) against render time", err_names[o->component]);
    snprintf(ylabel, sizeof ylabel, "relative L2 error, %s", err_names[o->component]);
    snprintf(xmark, sizeof xmark, "equal time: %g s", o->times[last]);
    double ey = best >= 0 ? err_at(o, &runs[best], last) : (double)NAN;
    snprintf(ymark, sizeof ymark, "equal error: %.3g (%s at %g s)", ey, best >= 0 ? runs[best].label : "", o->times[last]);
    plot_desc pd = {title, "render time (s)", ylabel, 1, 1, series, ns, o->times[last], ey, xmark, ymark};
    return write_plot(dir, "error-vs-time", &pd);
}

/* A sweep's values as numbers, when they all are (on/off sweeps get a table only). */
static int sweep_numbers(const sweep *sw, double *x) {
    for (int v = 0; v < sw->num_values; v++) {
        char *end;
        x[v] = strtod(sw->values[v], &end);
        if (end == sw->values[v] || *end) return 0;
    }
    return 1;
}

static int write_sweep_plot(const bench_options *o, const char *dir, const bench_run *runs, int num_runs, int w) {
    const sweep *sw = &o->sweeps[w];
    double x[MAX_VALUES], y[MAX_METHODS][MAX_VALUES];
    if (!sweep_numbers(sw, x)) return 0;
    plot_series series[MAX_METHODS];
    int ns = 0, last = o->num_times - 1, pos = 1;
    for (int v = 0; v < sw->num_values; v++) pos &= x[v] > 0.0;
    for (int m = 0; m < o->num_methods; m++) {
        int any = 0;
        for (int v = 0; v < sw->num_values; v++) {
            y[ns][v] = (double)NAN;
            for (int r = 0; r < num_runs; r++)
                if (runs[r].sweep == w && runs[r].value == v && runs[r].params.method == o->methods[m])
                    y[ns][v] = err_at(o, &runs[r], last), any = 1;
        }
        if (any) series[ns] = (plot_series){method_name(o->methods[m]), sw->num_values, x, y[ns]}, ns++;
    }
    if (ns == 0) return 0;
    char title[160], ylabel[96], stem[64];
    snprintf(title, sizeof title, "Relative L2 error (%s) against %s, %g s each", err_names[o->component], sw->name,
             o->times[last]);
    snprintf(ylabel, sizeof ylabel, "relative L2 error, %s", err_names[o->component]);
    snprintf(stem, sizeof stem, "sweep-%s", sw->name);
    plot_desc pd = {title, sw->name, ylabel, pos, 1, series, ns, (double)NAN, (double)NAN, "", ""};
    return write_plot(dir, stem, &pd);
}

static void md_error(FILE *f, double e) {
    if (isnan(e)) fputs("–", f);
    else if (isinf(e)) fputs("inf", f);
    else fprintf(f, "%.4f", e);
}

static int write_report(const bench_options *o, const char *dir, const bench_ref *ref,
                        const reference_info *want, const bench_run *runs, int num_runs) {
    char *buf = NULL, path[4200], err[4400];
    size_t size = 0;
    FILE *f = open_memstream(&buf, &size);
    if (!f) return cli_error("%s: out of memory", dir), -1;
    char date[64] = "";
    time_t now = time(NULL);
    struct tm tm;
    if (gmtime_r(&now, &tm)) strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", &tm);
    char host[256] = "";
    gethostname(host, sizeof host - 1);
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    const int last = o->num_times - 1;
    const char *comp = err_names[o->component];

    fprintf(f, "# glint bench\n\n");
    fprintf(f, "- scene: `%s` (%s)%s%s%s\n", want->scene, want->scene_hash, want->env[0] ? ", environment `" : "",
            want->env, want->env[0] ? "`" : "");
    fprintf(f, "- %dx%d, camera %d, max depth %d, seed %llu, %d threads (0: one per core)\n", want->width,
            want->height, want->camera_index, want->max_depth, (unsigned long long)want->seed, o->threads);
    if (ref->has_info) {
        fprintf(f, "- reference: `%s`, %s, %lld spp, %.0f s", o->ref_path, ref->info.method, ref->info.spp,
                ref->info.seconds);
        if (ref->info.has_noise)
            fprintf(f, "; its own noise, estimated from two halves of its frames: relative L2 %.4f (errors near "
                       "that are the reference's, not the method's)", ref->info.rel_l2_noise);
        fputs("\n", f);
    } else {
        fprintf(f, "- reference: `%s` without a sidecar (--force): scene, camera and size were not checked\n",
                o->ref_path);
    }
    fprintf(f, "- error: relative L2, ‖I − R‖₂ / ‖R‖₂ over all pixels and channels, of the %s%s\n", comp,
            o->component == ERR_ALL ? " image" : " component");
    if (o->base_text[0]) fprintf(f, "- options of every run: `%s`\n", o->base_text);
    fprintf(f, "- measured %s on %s, %ld cores; time is render time only (frames), error measurement excluded\n\n",
            date, host, cores);

    fprintf(f, "## Error at each time budget\n\nRelative L2 error (%s), frames in brackets.\n\n| method |", comp);
    for (int k = 0; k < o->num_times; k++) fprintf(f, " %g s |", o->times[k]);
    fputs("\n|---|", f);
    for (int k = 0; k < o->num_times; k++) fputs("---|", f);
    fputs("\n", f);
    for (int r = 0; r < num_runs; r++) {
        fprintf(f, "| %s |", runs[r].label);
        for (int k = 0; k < o->num_times; k++) {
            fputc(' ', f);
            md_error(f, err_at(o, &runs[r], k));
            if (k < runs[r].num_points) fprintf(f, " (%lld)", runs[r].frames[k]);
            fputs(" |", f);
        }
        fputs("\n", f);
    }

    fputs("\n## Who wins\n\n", f);
    for (int k = 0; k < o->num_times; k++) {
        int best = best_run(o, runs, num_runs, k), second = -1;
        for (int r = 0; r < num_runs; r++) {
            double e = err_at(o, &runs[r], k);
            if (r != best && isfinite(e) && (second < 0 || e < err_at(o, &runs[second], k))) second = r;
        }
        if (best < 0) continue;
        double eb = err_at(o, &runs[best], k);
        fprintf(f, "- %g s: **%s**, %.4f", o->times[k], runs[best].label, eb);
        if (second >= 0) {
            double es = err_at(o, &runs[second], k);
            if (eb > 0.0) fprintf(f, ", %.2f× lower than the next, %s (%.4f)", es / eb, runs[second].label, es);
            else fprintf(f, "; next %s (%.4f)", runs[second].label, es);
        }
        fputs("\n", f);
    }

    int best = best_run(o, runs, num_runs, last);
    if (best >= 0 && num_runs > 1) {
        double eb = err_at(o, &runs[best], last), tb = runs[best].seconds[last];
        fprintf(f, "\n## Equal error\n\nTime each curve needs to reach %.4f, the error of **%s** at %g s "
                   "(interpolated in log–log; `~` extrapolated along the curve's fitted slope).\n\n"
                   "| method | time to reach it | × %s's time |\n|---|---|---|\n",
                eb, runs[best].label, o->times[last], runs[best].label);
        for (int r = 0; r < num_runs; r++) {
            const bench_run *u = &runs[r];
            double e[MAX_TIMES];
            for (int k = 0; k < u->num_points; k++) e[k] = err_at(o, u, k);
            double t = metric_loglog_reach(u->seconds, e, u->num_points, eb);
            const char *approx = "";
            if (!isfinite(t) && u->num_points > 0) {
                double slope = metric_loglog_slope(u->seconds, e, u->num_points), el = e[u->num_points - 1];
                if (slope < -0.05 && el > 0.0 && isfinite(el)) {
                    t = u->seconds[u->num_points - 1] * pow(eb / el, 1.0 / slope);
                    approx = "~";
                }
            }
            if (isfinite(t)) fprintf(f, "| %s | %s%.3g s | %s%.2f |\n", u->label, approx, t, approx, t / tb);
            else fprintf(f, "| %s | not reached (the curve does not fall) | – |\n", u->label);
        }
    }

    fputs("\n## Convergence\n\nSlope of each curve in log–log (least squares over the budgets): unbiased Monte "
          "Carlo falls as time^−0.5; a flatter curve is dominated by bias (or by the reference's own noise).\n\n"
          "| method | slope |\n|---|---|\n", f);
    for (int r = 0; r < num_runs; r++) {
        double e[MAX_TIMES];
        for (int k = 0; k < runs[r].num_points; k++) e[k] = err_at(o, &runs[r], k);
        double slope = metric_loglog_slope(runs[r].seconds, e, runs[r].num_points);
        if (isfinite(slope)) fprintf(f, "| %s | %.2f |\n", runs[r].label, slope);
        else fprintf(f, "| %s | – |\n", runs[r].label);
    }

    for (int w = 0; w < o->num_sweeps; w++) {
        const sweep *sw = &o->sweeps[w];
        fprintf(f, "\n## Sweep: %s\n\nRelative L2 error (%s) at %g s against the value of `--%s`.\n\n| %s |", sw->name,
                comp, o->times[last], sw->name, sw->name);
        for (int m = 0; m < o->num_methods; m++)
            if (sweep_methods(sw->name) & (1u << o->methods[m])) fprintf(f, " %s |", method_name(o->methods[m]));
        fputs("\n|---|", f);
        for (int m = 0; m < o->num_methods; m++)
            if (sweep_methods(sw->name) & (1u << o->methods[m])) fputs("---|", f);
        fputs("\n", f);
        for (int v = 0; v < sw->num_values; v++) {
            fprintf(f, "| %s |", sw->values[v]);
            for (int m = 0; m < o->num_methods; m++) {
                if (!(sweep_methods(sw->name) & (1u << o->methods[m]))) continue;
                for (int r = 0; r < num_runs; r++)
                    if (runs[r].sweep == w && runs[r].value == v && runs[r].params.method == o->methods[m]) {
                        fputc(' ', f);
                        md_error(f, err_at(o, &runs[r], last));
                        fputs(" |", f);
                    }
            }
            fputs("\n", f);
        }
        double x[MAX_VALUES];
        if (sweep_numbers(sw, x)) fprintf(f, "\n![error against %s](sweep-%s.svg)\n", sw->name, sw->name);
    }
    fputs("\n## Files\n\n- `results.csv`: every checkpoint of every run, all components\n"
          "- `error-vs-time.svg`, `error-vs-time.png`: the curves (log–log); squares mark the equal-time "
          "reading at the last budget, diamonds the equal-error reading (the PNG's legend is numbered in the "
          "SVG's order)\n\n![error against time](error-vs-time.svg)\n", f);
    fclose(f);
    snprintf(path, sizeof path, "%s/report.md", dir);
    int status = write_file_atomic(path, buf, size, WRITE_NO_REPLACE, err, sizeof err);
    free(buf);
    if (status) cli_error("%s", err);
    return status;
}

/* ---- the output directory ------------------------------------------------------------------------ */

/* Creates dir, or accepts an existing directory that holds none of the files this run writes:
 * nothing is ever overwritten. Without --out the first free name of bench, bench-1, ... */
static int prepare_dir(const bench_options *o, char *dir, size_t dirlen) {
    if (!o->out_dir) {
        if (unique_path("bench", dir, dirlen) != 0) return cli_error("bench: no free directory name"), -1;
    } else {
        snprintf(dir, dirlen, "%s", o->out_dir);
    }
    struct stat st;
    if (stat(dir, &st) == 0) {
        if (!S_ISDIR(st.st_mode)) return cli_error("--out: %s: exists and is not a directory", dir), -1;
        char names[4 + 2 * MAX_SWEEPS][64] = {"results.csv", "report.md", "error-vs-time.svg", "error-vs-time.png"};
        int n = 4;
        for (int w = 0; w < o->num_sweeps; w++) {
            snprintf(names[n++], 64, "sweep-%s.svg", o->sweeps[w].name);
            snprintf(names[n++], 64, "sweep-%s.png", o->sweeps[w].name);
        }
        for (int k = 0; k < n; k++) {
            char p[4200];
            snprintf(p, sizeof p, "%.4096s/%.64s", dir, names[k]);
            if (lstat(p, &st) == 0)
                return cli_error("--out: %s: already holds %s (nothing is overwritten; choose another directory)", dir,
                                 names[k]), -1;
        }
        if (access(dir, W_OK | X_OK) != 0) return cli_error("--out: %s: not writable (%s)", dir, strerror(errno)), -1;
        return 0;
    }
    if (mkdir(dir, 0777) != 0) return cli_error("--out: %s: cannot create the directory: %s", dir, strerror(errno)), -1;
    return 0;
}

/* ---- the command ----------------------------------------------------------------------------- */

/* One run per method and sweep setting; a method no sweep applies to runs once, with the base. */
static int plan_runs(const bench_options *o, const render_params *base, int split_highlights, bench_run *runs) {
    int n = 0;
    for (int m = 0; m < o->num_methods; m++) {
        render_params p = *base;
        p.method = o->methods[m];
        p.pt_highlights = p.method == METHOD_PT && split_highlights;
        int swept = 0;
        for (int w = 0; w < o->num_sweeps; w++) {
            if (!(sweep_methods(o->sweeps[w].name) & (1u << p.method))) continue;
            for (int v = 0; v < o->sweeps[w].num_values; v++, swept++) {
                if (n >= MAX_RUNS) { /* counted, so the caller can refuse */
                    n++;
                    continue;
                }
                bench_run *r = &runs[n++];
                memset(r, 0, sizeof *r);
                r->params = p;
                cli_set_vl_param(o->sweeps[w].name, o->sweeps[w].values[v], &r->params.vl); /* validated */
                r->sweep = w;
                r->value = v;
                snprintf(r->setting, sizeof r->setting, "%s=%s", o->sweeps[w].name, o->sweeps[w].values[v]);
                snprintf(r->label, sizeof r->label, "%s %s", method_name(p.method), r->setting);
            }
        }
        if (!swept && n >= MAX_RUNS) {
            n++;
        } else if (!swept) {
            bench_run *r = &runs[n++];
            memset(r, 0, sizeof *r);
            r->params = p;
            r->sweep = -1;
            snprintf(r->label, sizeof r->label, "%s", method_name(p.method));
        }
    }
    return n;
}

static int bench_main(const bench_options *o, bench_ref *ref, bench_run *runs) {
    /* What the bench renders: the reference's size, camera and depth unless given (and then they
     * must match). */
    const reference_info *have = ref->has_info ? &ref->info : NULL;
    int width = o->width ? o->width : ref->width, height = o->width ? o->height : ref->height;
    if (width != ref->width || height != ref->height)
        return cli_error("%s: rendered at %dx%d, not %dx%d", o->ref_path, ref->width, ref->height, width, height),
               EXIT_FAILURE_;
    int cam_index = o->camera_index >= 0 ? (int)o->camera_index : have ? have->camera_index : -1;
    render_params base = {.width = width, .height = height, .threads = o->threads, .vl = o->vl};
    base.max_depth = o->max_depth ? o->max_depth : have ? have->max_depth : 0;
    if (have && o->max_depth && o->max_depth != have->max_depth)
        cli_warning("%s: rendered with --max-depth %d, the bench uses %d: the errors include that difference",
                    o->ref_path, have->max_depth, o->max_depth);
    /* The reference's own seed would replay its samples: pt would look converged. */
    base.seed = o->seed_given ? o->seed : have ? have->seed + 1 : 1;
    if (have && base.seed == have->seed)
        return cli_error("--seed %llu: is the reference's seed; the bench would repeat its samples",
                         (unsigned long long)base.seed), EXIT_USAGE;
    if (o->component != ERR_ALL && !ref->layer[o->component])
        return cli_error("%s: no %s layer%s", o->ref_path, err_names[o->component],
                         o->component == ERR_HIGHLIGHTS ? " (render the reference with --highlights-layer)" : ""),
               EXIT_FAILURE_;

    scene *s = load_scene_or_default(o->scene_path, o->env_path, (float)(o->env_rotation_deg * 3.14159265358979 / 180.0));
    if (!s) return EXIT_FAILURE_;
    if (cam_index >= s->num_cameras && !(cam_index == -1)) {
        cli_error("%s: --camera %d: the scene has %d camera%s", s->path, cam_index, s->num_cameras,
                  s->num_cameras == 1 ? "" : "s");
        scene_destroy(s);
        return EXIT_USAGE;
    }
    char err[4400];
    reference_info want;
    if (reference_describe(&want, o->scene_path, o->env_path, o->env_rotation_deg, s, cam_index, &base, err,
                           sizeof err) != 0 ||
        (have && reference_check(o->ref_path, have, &want, err, sizeof err) != 0)) {
        cli_error("%s", err);
        scene_destroy(s);
        return EXIT_FAILURE_;
    }
    if (have && strcmp(have->method, "pt") != 0)
        cli_warning("%s: rendered with %s, not pt: its bias is in every error", o->ref_path, have->method);
    camera cam = scene_camera(s, cam_index, (float)width / (float)height);

    int num_runs = plan_runs(o, &base, ref->layer[ERR_HIGHLIGHTS] != NULL, runs);
    if (num_runs > MAX_RUNS) {
        cli_error("more than %d runs (methods x sweep values); split the bench", MAX_RUNS);
        scene_destroy(s);
        return EXIT_USAGE;
    }
    char dir[4096];
    if (prepare_dir(o, dir, sizeof dir) != 0) {
        scene_destroy(s);
        return EXIT_FAILURE_;
    }
    if (!o->quiet)
        fprintf(stderr, "glint: bench: %d run%s of %g s, about %.0f s; writing into %s\n", num_runs,
                num_runs == 1 ? "" : "s", o->times[o->num_times - 1], num_runs * o->times[o->num_times - 1], dir);
    meter m = {ref, NULL, 3 * (size_t)width * (size_t)height};
    m.img = malloc(sizeof(float) * m.n);
    int status = m.img ? 0 : (cli_error("out of memory"), -1);
    for (int r = 0; r < num_runs && status == 0; r++) {
        status = run_one(o, s, &cam, &m, &runs[r], r, num_runs);
        /* Written after every run, so an interrupted bench keeps what it measured. */
        if (status == 0) status = write_csv(dir, runs, r + 1, r == 0 ? WRITE_NO_REPLACE : WRITE_REPLACE);
    }
    free(m.img);
    if (status == 0) status = write_time_plot(o, dir, runs, num_runs);
    for (int w = 0; w < o->num_sweeps && status == 0; w++) status = write_sweep_plot(o, dir, runs, num_runs, w);
    if (status == 0) status = write_report(o, dir, ref, &want, runs, num_runs);
    if (status == 0 && !o->quiet) printf("wrote %s/results.csv, %s/report.md and the plots\n", dir, dir);
    scene_destroy(s);
    return status == 0 ? EXIT_OK : EXIT_FAILURE_;
}

int cmd_bench(int argc, char **argv) {
    bench_options o;
    int parsed = parse_bench_options(argc, argv, &o);
    if (parsed != 0) return parsed > 0 ? EXIT_OK : EXIT_USAGE;
    bench_ref ref;
    if (ref_load(&o, &ref) != 0) return EXIT_FAILURE_;
    bench_run *runs = calloc(MAX_RUNS, sizeof *runs);
    int status = runs ? bench_main(&o, &ref, runs) : (cli_error("out of memory"), EXIT_FAILURE_);
    free(runs);
    ref_free(&ref);
    return status;
}
