/* glint bench: what accuracy costs in time. Renders each run (a method with its settings, once
 * per setting of a sweep) progressively against a reference, once per seed, reads the error and
 * each pass's time at each time budget of every render, splits the error into noise and bias
 * over the seeds, and writes results.csv, summary.csv, error-versus-time plots (SVG, PNG) and
 * report.md into a directory. This file loads the reference, plans, runs and measures the
 * renders; bench_options.c parses the command line and expands presets, bench_report.c writes
 * the outputs. */
#define _XOPEN_SOURCE 700 /* realpath */
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "bench.h"
#include "camera.h"
#include "cli.h"
#include "commands.h"
#include "film.h"
#include "image_io.h"
#include "metrics.h"
#include "reference.h"
#include "session.h"

/* ---- the reference ----------------------------------------------------------------------------- */

static void ref_free(bench_ref *r) {
    for (int k = 0; k < ERR_COUNT; k++) free(r->layer[k]);
    memset(r, 0, sizeof *r);
}

static int ref_load(const bench_options *o, bench_ref *r) {
    memset(r, 0, sizeof *r);
    char err[1200];
    exr_image ex;
    if (exr_image_load(o->ref_path, &ex, err, sizeof err) != 0) return cli_error("%s", err), -1;
    r->width = ex.width;
    r->height = ex.height;
    r->layer[ERR_ALL] = exr_image_layer_rgb(&ex, "");
    r->layer[ERR_DIRECT] = exr_image_layer_rgb(&ex, "direct");
    r->layer[ERR_INDIRECT] = exr_image_layer_rgb(&ex, "indirect");
    r->layer[ERR_HIGHLIGHTS] = exr_image_layer_rgb(&ex, "highlights");
    exr_image_free(&ex);
    if (!r->layer[ERR_ALL]) {
        ref_free(r);
        return cli_error("%s: no R, G, B channels (or out of memory)", o->ref_path), -1;
    }
    /* A NaN in the reference would make every error NaN (or, summed away, 0): no answer at all. */
    static const char *const layer_names[ERR_COUNT] = {"R,G,B", "direct.*", "indirect.*", "highlights.*"};
    for (int k = 0; k < ERR_COUNT; k++) {
        size_t bad = 0, n = 3 * (size_t)r->width * (size_t)r->height;
        for (size_t i = 0; r->layer[k] && i < n; i++) bad += !isfinite(r->layer[k][i]);
        if (bad) {
            ref_free(r);
            return cli_error("%s: %zu values of %s are not finite (NaN or Inf): not a usable reference", o->ref_path,
                             bad, layer_names[k]),
                   -1;
        }
    }
    /* Indirect means everything after the first bounce, whether or not highlights were split off. */
    if (r->layer[ERR_INDIRECT] && r->layer[ERR_HIGHLIGHTS])
        for (size_t i = 0; i < 3 * (size_t)r->width * (size_t)r->height; i++)
            r->layer[ERR_INDIRECT][i] += r->layer[ERR_HIGHLIGHTS][i];
    int st = reference_load(o->ref_path, &r->info, err, sizeof err);
    if (st < 0) {
        ref_free(r);
        return cli_error("%s", err), -1;
    }
    if (st > 0 && !o->force) {
        ref_free(r);
        return cli_error("%s: no %s header attribute nor sidecar %s.json, so its scene, camera and size are unknown "
                         "(render references with glint render --out; --force uses it anyway)",
                         o->ref_path, REFERENCE_ATTR, o->ref_path),
               -1;
    }
    r->has_info = st == 0;
    if (r->has_info && (r->info.width != r->width || r->info.height != r->height)) {
        ref_free(r);
        return cli_error("%s: the image is %dx%d but its description says %dx%d", o->ref_path, r->width, r->height,
                         r->info.width, r->info.height),
               -1;
    }
    return 0;
}

/* ---- measuring --------------------------------------------------------------------------------- */

/* What measuring needs: the reference, a scratch image and, with two seeds or more, what the
 * noise and bias split keeps of the reported component per budget over a run's seeds (a sum
 * image and the sum of squared errors, not the images). */
typedef struct {
    const bench_ref *ref;
    int component;
    unsigned only; /* the components rendered; 0: all */
    float *img;
    size_t n;
    double *sum;            /* [budget][value]; NULL with one seed */
    double err2[MAX_TIMES]; /* sum over the seeds of ||I - R||^2 */
} meter;

static void measure(meter *m, const render_session *rs, bench_point *pt, int k) {
    const film *f = session_film(rs);
    const render_params *p = session_params(rs);
    int splits = p->pt_highlights || p->method == METHOD_VSL_HL;
    for (int c = 0; c < ERR_COUNT; c++) {
        unsigned mask = bench_err_mask(c);
        pt->rel_l2[c] = pt->relmse[c] = (double)NAN;
        if (!m->ref->layer[c] || (c == ERR_HIGHLIGHTS && !splits) || (m->only && (mask & m->only) != mask)) continue;
        film_resolve(f, mask, m->img);
        pt->rel_l2[c] = metric_rel_l2(m->img, m->ref->layer[c], m->n);
        pt->relmse[c] = metric_relmse(m->img, m->ref->layer[c], m->n);
        if (c == m->component && m->sum)
            m->err2[k] += metric_accumulate(m->sum + (size_t)k * m->n, m->img, m->ref->layer[c], m->n);
    }
}

/* Renders run with its seed-th seed, measuring at every budget. */
static int render_seed(const bench_options *o, const scene *s, const camera *cam, meter *m, bench_run *run, int seed,
                       int index, int total) {
    char err[1024];
    render_params params = run->params;
    params.seed = run->params.seed + (uint64_t)seed;
    render_session *rs = session_create(s, cam, &params, err, sizeof err);
    if (!rs) return cli_error("%s", err), -1;
    const effect_plan *plan = session_plan(rs);
    if ((params.only & (1u << COMP_HIGHLIGHTS)) && params.method == METHOD_VSL_HL &&
        !(plan->highlights && plan->max_depth > 1)) {
        session_destroy(rs);
        return cli_error("%s: --only highlights: the effect plan runs no highlight pass here (glint info --method "
                         "vsl+hl shows why)",
                         s->path),
               -1;
    }
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
        bench_point *pt = &run->points[seed][k];
        pt->rays = 0.0;
        for (int r = 0; r < RAY_KIND_COUNT; r++) pt->rays += (double)st.rays[r];
        pt->seconds = rendered;
        pt->frames = session_frames(rs);
        pt->threads = session_params(rs)->threads;
        for (int q = 0; q < PASS_COUNT; q++) pt->pass_s[q] = 1e-9 * (double)st.pass_ns[q];
        pt->merge_s = 1e-9 * (double)st.hl_merge_ns;
        measure(m, rs, pt, k);
        if (o->quiet) continue;
        char which[64] = "";
        if (o->seeds > 1)
            snprintf(which, sizeof which, ", seed %llu (%d of %d)", (unsigned long long)params.seed, seed + 1,
                     o->seeds);
        fprintf(stderr, "glint: bench %d/%d %s%s: %.2f s, %lld frames, %s rel. L2 %.4g\n", index + 1, total, run->label,
                which, rendered, pt->frames, bench_err_names[o->component], pt->rel_l2[o->component]);
    }
    session_destroy(rs);
    return 0;
}

/* The run's figures over its seeds, per budget, in the reported component. */
static void aggregate(const bench_options *o, const meter *m, bench_run *run) {
    const int c = o->component, n = run->seeds_done;
    const float *ref = m->ref->layer[c];
    double ref_norm2 = metric_norm2(ref, m->n), ref_noise = bench_ref_noise(m->ref, c);
    for (int k = 0; k < o->num_times; k++) {
        double secs = 0.0, frames = 0.0, sq = 0.0, relmse = 0.0, lo = INFINITY, hi = -INFINITY;
        for (int i = 0; i < n; i++) {
            const bench_point *pt = &run->points[i][k];
            secs += pt->seconds;
            frames += (double)pt->frames;
            sq += pt->rel_l2[c] * pt->rel_l2[c];
            relmse += pt->relmse[c];
            lo = fmin(lo, pt->rel_l2[c]);
            hi = fmax(hi, pt->rel_l2[c]);
        }
        run->seconds[k] = secs / n;
        run->frames[k] = frames / n;
        run->rms[k] = sqrt(sq / n); /* NAN when the component was not measured */
        run->relmse[k] = relmse / n;
        run->lo[k] = isnan(run->rms[k]) ? (double)NAN : lo;
        run->hi[k] = isnan(run->rms[k]) ? (double)NAN : hi;
        run->noise[k] = run->bias[k] = (double)NAN;
        if (m->sum && !isnan(run->rms[k]))
            metric_noise_bias(m->err2[k], metric_mean_err2(m->sum + (size_t)k * m->n, n, ref, m->n), ref_norm2, n,
                              ref_noise, &run->noise[k], &run->bias[k]);
    }
    run->num_points = o->num_times;
}

/* Renders and measures every seed of one run, writing the CSVs as renders complete (first: the
 * bench's first run, whose files must not exist yet). */
static int run_seeds(const bench_options *o, const scene *s, const camera *cam, meter *m, const char *dir,
                     bench_run *runs, int r, int num_runs, int first_run) {
    bench_run *run = &runs[r];
    if (m->sum) {
        memset(m->sum, 0, sizeof(double) * m->n * (size_t)o->num_times);
        memset(m->err2, 0, sizeof m->err2);
    }
    for (int i = 0; i < o->seeds; i++) {
        if (render_seed(o, s, cam, m, run, i, r, num_runs) != 0) return -1;
        run->seeds_done = i + 1;
        /* Written after every render, so an interrupted bench keeps what it measured. */
        int first = r == first_run && i == 0;
        if (bench_write_csv(dir, runs, r + 1, o->num_times, first ? WRITE_NO_REPLACE : WRITE_REPLACE) != 0) return -1;
    }
    aggregate(o, m, run);
    return bench_write_summary(o, dir, m->ref, runs, r + 1, r == first_run ? WRITE_NO_REPLACE : WRITE_REPLACE);
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
        char names[5 + 2 * MAX_SWEEPS][64] = {"results.csv", "summary.csv", "report.md", "error-vs-time.svg",
                                              "error-vs-time.png"};
        int n = 5;
        for (int w = 0; w < o->num_sweeps; w++) {
            snprintf(names[n++], 64, "sweep-%s.svg", o->sweeps[w].name);
            snprintf(names[n++], 64, "sweep-%s.png", o->sweeps[w].name);
        }
        for (int k = 0; k < n; k++) {
            char p[4200];
            snprintf(p, sizeof p, "%.4096s/%.64s", dir, names[k]);
            if (lstat(p, &st) == 0)
                return cli_error("--out: %s: already holds %s (nothing is overwritten; choose another directory)", dir,
                                 names[k]),
                       -1;
        }
        if (access(dir, W_OK | X_OK) != 0) return cli_error("--out: %s: not writable (%s)", dir, strerror(errno)), -1;
        return 0;
    }
    if (mkdir(dir, 0777) != 0) return cli_error("--out: %s: cannot create the directory: %s", dir, strerror(errno)), -1;
    return 0;
}

/* ---- the command ----------------------------------------------------------------------------- */

/* Appends " name=value" (without the space when empty) to text. */
static void append_setting(char *text, size_t len, const char *name, const char *value) {
    size_t at = strlen(text);
    snprintf(text + at, len - at, "%s%s=%s", at ? " " : "", name, value);
}

/* One run per variant and sweep setting; a variant no sweep applies to runs once, with its own
 * settings. */
static int plan_runs(const bench_options *o, const render_params *base, int split_highlights, bench_run *runs) {
    int n = 0;
    for (int k = 0; k < o->num_variants; k++) {
        const bench_variant *var = &o->variants[k];
        render_params p = *base;
        p.method = var->method;
        p.pt_highlights = p.method == METHOD_PT && split_highlights;
        char own[192] = "";
        for (int j = 0; j < var->num_settings; j++) {
            bench_apply_setting(var->names[j], var->values[j], &p); /* validated */
            append_setting(own, sizeof own, var->names[j], var->values[j]);
        }
        int swept = 0;
        for (int w = 0; w <= o->num_sweeps; w++) {
            const sweep *sw = w < o->num_sweeps ? &o->sweeps[w] : NULL;
            if (sw && !(bench_sweep_methods(sw->name) & (1u << p.method))) continue;
            if (!sw && swept) break; /* the base run only when no sweep applies */
            for (int v = 0; v < (sw ? sw->num_values : 1); v++, swept++) {
                if (n++ >= MAX_RUNS) continue; /* counted, so the caller can refuse */
                bench_run *r = &runs[n - 1];
                memset(r, 0, sizeof *r);
                r->params = p;
                r->variant = k;
                r->sweep = sw ? w : -1;
                r->value = v;
                snprintf(r->setting, sizeof r->setting, "%s", own);
                if (sw) {
                    bench_apply_setting(sw->name, sw->values[v], &r->params); /* validated */
                    append_setting(r->setting, sizeof r->setting, sw->name, sw->values[v]);
                }
                snprintf(r->label, sizeof r->label, "%s%s%s", method_name(p.method), r->setting[0] ? " " : "",
                         r->setting);
            }
        }
    }
    return n;
}

/* Renders the runs (all, or --job's alone) or, with --collect, reads them from the jobs'
 * directories; then writes the results (a job: its CSVs only). 0, or -1 after the error. */
static int measure_runs(const bench_options *o, const scene *s, const camera *cam, meter *m, const char *dir,
                        bench_run *runs, int num_runs) {
    int first = o->job_given ? (int)o->job : 0, end = o->job_given ? first + 1 : num_runs;
    for (int r = first; r < end; r++)
        if (o->collect_dir ? bench_read_job_run(o->collect_dir, o, r, &runs[r])
                           : run_seeds(o, s, cam, m, dir, runs, r, num_runs, first))
            return -1;
    if (o->collect_dir && (bench_write_csv(dir, runs, num_runs, o->num_times, WRITE_NO_REPLACE) != 0 ||
                           bench_write_summary(o, dir, m->ref, runs, num_runs, WRITE_NO_REPLACE) != 0))
        return -1;
    return 0;
}

/* argc, argv: the bench's arguments, which --jobs saves for its jobs and --collect. */
static int bench_main(const bench_options *o, bench_ref *ref, bench_run *runs, int argc, char **argv) {
    /* What the bench renders: the reference's size, camera and depth unless given (and then they
     * must match). */
    const reference_info *have = ref->has_info ? &ref->info : NULL;
    int width = o->width ? o->width : ref->width, height = o->width ? o->height : ref->height;
    if (width != ref->width || height != ref->height)
        return cli_error("%s: rendered at %dx%d, not %dx%d", o->ref_path, ref->width, ref->height, width, height),
               EXIT_FAILURE_;
    int cam_index = o->camera_index >= 0 ? (int)o->camera_index : have ? have->camera_index : -1;
    render_params base = {
        .width = width, .height = height, .threads = o->threads, .plan = o->plan, .only = o->only, .vl = o->vl};
    base.max_depth = o->max_depth ? o->max_depth : have ? have->max_depth : 0;
    if (have && o->max_depth && o->max_depth != have->max_depth)
        cli_warning("%s: rendered with --max-depth %d, the bench uses %d: the errors include that difference",
                    o->ref_path, have->max_depth, o->max_depth);
    /* The reference's own seed would replay its samples: pt would look converged. The seeds are
     * seed, seed + 1, ... (wrapping at 2^64, as the renderer's arithmetic does); a range that
     * holds the reference's is refused rather than skipped, so seed k is always base + k. */
    base.seed = o->seed_given ? o->seed : have ? have->seed + 1 : 1;
    if (have && have->seed - base.seed < (uint64_t)o->seeds) {
        if (o->seeds == 1)
            return cli_error("--seed %llu: is the reference's seed; the bench would repeat its samples",
                             (unsigned long long)base.seed),
                   EXIT_USAGE;
        return cli_error("--seeds %d: the seeds %llu to %llu hold the reference's seed %llu; the bench would repeat "
                         "its samples (choose another --seed)",
                         o->seeds, (unsigned long long)base.seed,
                         (unsigned long long)(base.seed + (uint64_t)o->seeds - 1), (unsigned long long)have->seed),
               EXIT_USAGE;
    }
    /* The split keeps one sum image of doubles per budget; refuse what would not fit in memory
     * before rendering anything. */
    size_t values = 3 * (size_t)width * (size_t)height;
    double split_bytes = o->seeds > 1 ? (double)values * sizeof(double) * o->num_times : 0.0;
    if (split_bytes > MAX_SPLIT_BYTES)
        return cli_error("--seeds %d: the noise and bias split keeps a %dx%d image of doubles per budget, %.0f MiB for "
                         "%d budgets, more than %.0f MiB (use fewer --times or a smaller size)",
                         o->seeds, width, height, split_bytes / (1 << 20), o->num_times, MAX_SPLIT_BYTES / (1 << 20)),
               EXIT_USAGE;
    if (o->component != ERR_ALL && !ref->layer[o->component])
        return cli_error("%s: no %s layer%s", o->ref_path, bench_err_names[o->component],
                         o->component == ERR_HIGHLIGHTS ? " (render the reference with --highlights-layer)" : ""),
               EXIT_FAILURE_;

    int num_runs = plan_runs(o, &base, ref->layer[ERR_HIGHLIGHTS] != NULL, runs);
    if (num_runs > MAX_RUNS)
        return cli_error("more than %d runs (runs x sweep values); split the bench", MAX_RUNS), EXIT_USAGE;
    if (o->job_given && o->job >= num_runs)
        return cli_error("--job %lld: the plan has %d run%s (0 to %d)", o->job, num_runs, num_runs == 1 ? "" : "s",
                         num_runs - 1),
               EXIT_USAGE;
    if (num_runs * o->seeds > MAX_RENDERS)
        return cli_error("--seeds %d: %d runs x %d seeds = %d renders, more than %d; split the bench", o->seeds,
                         num_runs, o->seeds, num_runs * o->seeds, MAX_RENDERS),
               EXIT_USAGE;

    scene *s =
        load_scene_or_default(o->scene_path, o->env_path, (float)(o->env_rotation_deg * 3.14159265358979 / 180.0),
                              have && have->variant[0] ? have->variant : NULL);
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
        cli_warning("%s: rendered with %s, not pt: its bias, if any, is in every error", o->ref_path, have->method);
    camera cam = scene_camera(s, cam_index, (float)width / (float)height);

    if (o->jobs_dir) {
        int st = bench_write_jobs(o->jobs_dir, argc, argv, num_runs);
        if (st == 0 && !o->quiet)
            printf("wrote %d job%s to %s/jobs.txt; once they have run, glint bench --collect %s\n", num_runs,
                   num_runs == 1 ? "" : "s", o->jobs_dir, o->jobs_dir);
        scene_destroy(s);
        return st == 0 ? EXIT_OK : EXIT_FAILURE_;
    }
    char dir[4096];
    if (prepare_dir(o, dir, sizeof dir) != 0) {
        scene_destroy(s);
        return EXIT_FAILURE_;
    }
    int renders = num_runs * o->seeds;
    double last = o->times[o->num_times - 1];
    if (!o->quiet && !o->collect_dir)
        fprintf(stderr, "glint: bench: %d run%s x %d seed%s of %g s, about %.0f s; writing into %s\n", num_runs,
                num_runs == 1 ? "" : "s", o->seeds, o->seeds == 1 ? "" : "s", last, renders * last, dir);
    meter m = {.ref = ref, .component = o->component, .only = o->only, .n = values};
    m.img = malloc(sizeof(float) * m.n);
    if (o->seeds > 1) m.sum = malloc((size_t)split_bytes);
    bench_point(*points)[MAX_TIMES] = calloc((size_t)renders, sizeof *points);
    int status = m.img && (m.sum || o->seeds == 1) && points ? 0 : (cli_error("out of memory"), -1);
    for (int r = 0; r < num_runs; r++) runs[r].points = points + (size_t)r * (size_t)o->seeds;
    if (status == 0) status = measure_runs(o, s, &cam, &m, dir, runs, num_runs);
    free(m.img);
    free(m.sum);
    if (status == 0 && !o->job_given) status = bench_write_plots_and_report(o, dir, ref, &want, runs, num_runs);
    if (status == 0 && !o->quiet)
        printf("wrote %s/results.csv, %s/summary.csv%s\n", dir, dir,
               o->job_given ? " (one job's)" : ", report.md and the plots");
    free(points);
    scene_destroy(s);
    return status == 0 ? EXIT_OK : EXIT_FAILURE_;
}

/* glint bench --collect DIR: the arguments --jobs saved, parsed again in the directory the jobs
 * ran in, writing into DIR. */
static int collect(int argc, char **argv, bench_options *o, char ***saved) {
    char dir[PATH_MAX], cwd[PATH_MAX];
    int n;
    if (argc != 2) return cli_error("--collect DIR takes no other option (the plan's are in DIR/args.txt)"), -1;
    if (!realpath(argv[1], dir)) return cli_error("--collect: %s: %s", argv[1], strerror(errno)), -1;
    if (bench_read_jobs(dir, &n, saved, cwd, sizeof cwd) != 0) return -1;
    if (chdir(cwd) != 0) return cli_error("--collect: %s (where the plan was made): %s", cwd, strerror(errno)), -1;
    int parsed = bench_parse_options(n, *saved, o);
    if (parsed != 0) return -1;
    o->collect_dir = o->out_dir = strdup(dir);
    if (!o->out_dir) return cli_error("out of memory"), -1;
    return 0;
}

int cmd_bench(int argc, char **argv) {
    bench_options o;
    char **saved = NULL;
    if (argc > 0 && strcmp(argv[0], "--collect") == 0) {
        int st = collect(argc, argv, &o, &saved);
        if (st != 0) {
            free(saved);
            return EXIT_FAILURE_;
        }
    } else {
        int parsed = bench_parse_options(argc, argv, &o);
        if (parsed != 0) return parsed > 0 ? EXIT_OK : EXIT_USAGE;
    }
    /* What the jobs run: these arguments less --jobs DIR */
    char **args = calloc((size_t)argc + 1, sizeof *args);
    int num_args = 0;
    for (int i = 0; args && i < argc; i++) {
        if (strcmp(argv[i], "--jobs") == 0 && i + 1 < argc)
            i++;
        else
            args[num_args++] = argv[i];
    }
    bench_ref ref;
    int status = EXIT_FAILURE_;
    if (args && ref_load(&o, &ref) == 0) {
        bench_run *runs = calloc(MAX_RUNS, sizeof *runs);
        status = runs ? bench_main(&o, &ref, runs, num_args, args) : (cli_error("out of memory"), EXIT_FAILURE_);
        free(runs);
        ref_free(&ref);
    } else if (!args) {
        cli_error("out of memory");
    }
    if (o.collect_dir) free((void *)o.collect_dir);
    free(args);
    free(saved);
    return status;
}
