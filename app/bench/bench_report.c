/* glint bench: what it writes — results.csv (every render), summary.csv (over the seeds), the
 * error-versus-time and sweep plots (SVG, PNG) and report.md. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "bench.h"
#include "cli.h"
#include "metrics.h"
#include "plot.h"

static void csv_number(FILE *f, double v) {
    if (isnan(v)) return;
    if (isinf(v))
        fputs("inf", f);
    else
        fprintf(f, "%.6g", v);
}

/* Closes the memory stream f and writes its text to DIR/name atomically. */
static int write_text(FILE *f, char **buf, size_t *size, const char *dir, const char *name, write_mode mode) {
    char path[4200], err[4400];
    fclose(f);
    snprintf(path, sizeof path, "%.4096s/%s", dir, name);
    int status = write_file_atomic(path, *buf, *size, mode, err, sizeof err);
    free(*buf);
    if (status) cli_error("%s", err);
    return status;
}

/* A CSV written in memory first (write_text replaces the file in one step), its header line
 * written. NULL: out of memory (said). */
static FILE *open_csv(const char *dir, char **buf, size_t *size, const char *header) {
    *buf = NULL;
    *size = 0;
    FILE *f = open_memstream(buf, size);
    if (!f) return cli_error("%s: out of memory", dir), NULL;
    fputs(header, f);
    return f;
}

int bench_write_csv(const char *dir, const bench_run *runs, int num_runs, int num_times, write_mode mode) {
    char *buf;
    size_t size;
    FILE *f = open_csv(dir, &buf, &size,
                       "method,params,seed,seconds,frames,spp,rays,rel_l2,relmse,direct_rel_l2,direct_relmse,"
                       "indirect_rel_l2,indirect_relmse,highlights_rel_l2,highlights_relmse,threads,paths_s,direct_s,"
                       "virtual_lights_s,gather_s,highlights_s,merge_s\n");
    if (!f) return -1;
    for (int r = 0; r < num_runs; r++)
        for (int i = 0; i < runs[r].seeds_done; i++)
            for (int k = 0; k < num_times; k++) {
                const bench_run *u = &runs[r];
                const bench_point *pt = &u->points[i][k];
                fprintf(f, "%s,%s,%llu,%.6f,%lld,%lld,%.0f", method_name(u->params.method), u->setting,
                        (unsigned long long)(u->params.seed + (uint64_t)i), pt->seconds, pt->frames, pt->frames,
                        pt->rays);
                for (int c = 0; c < ERR_COUNT; c++) {
                    fputc(',', f);
                    csv_number(f, pt->rel_l2[c]);
                    fputc(',', f);
                    csv_number(f, pt->relmse[c]);
                }
                fprintf(f, ",%d", pt->threads);
                for (int q = 0; q < PASS_COUNT; q++) fprintf(f, ",%.6f", pt->pass_s[q]);
                fprintf(f, ",%.6f\n", pt->merge_s);
            }
    return write_text(f, &buf, &size, dir, "results.csv", mode);
}

int bench_write_summary(const bench_options *o, const char *dir, const bench_ref *ref, const bench_run *runs,
                        int num_runs, write_mode mode) {
    char *buf;
    size_t size;
    FILE *f = open_csv(dir, &buf, &size,
                       "method,params,component,budget,seeds,seconds,frames,rel_l2,relmse,noise,bias,ref_noise,"
                       "rel_l2_min,rel_l2_max\n");
    if (!f) return -1;
    for (int r = 0; r < num_runs; r++)
        for (int k = 0; k < runs[r].num_points; k++) {
            const bench_run *u = &runs[r];
            fprintf(f, "%s,%s,%s,%g,%d,%.6f,%.6g,", method_name(u->params.method), u->setting,
                    bench_err_names[o->component], o->times[k], u->seeds_done, u->seconds[k], u->frames[k]);
            const double v[7] = {u->rms[k], u->relmse[k], u->noise[k], u->bias[k], bench_ref_noise(ref, o->component),
                                 u->lo[k],  u->hi[k]};
            for (int j = 0; j < 7; j++) {
                if (j) fputc(',', f);
                csv_number(f, v[j]);
            }
            fputc('\n', f);
        }
    return write_text(f, &buf, &size, dir, "summary.csv", mode);
}

/* Error of run r at budget k in the reported component: the RMS over its seeds. */
static double err_at(const bench_run *r, int k) { return k < r->num_points ? r->rms[k] : (double)NAN; }

/* The relative L2 error is a multiple of the reference's own norm. */
static const char *const error_unit = "fraction of ‖R‖₂";

static int write_plot(const char *dir, const char *stem, const plot_desc *pd) {
    char path[4200], err[4400];
    snprintf(path, sizeof path, "%s/%s.svg", dir, stem);
    if (plot_save_svg(pd, path, WRITE_NO_REPLACE, err, sizeof err) != 0) return cli_error("%s", err), -1;
    snprintf(path, sizeof path, "%s/%s.png", dir, stem);
    if (plot_save_png(pd, path, WRITE_NO_REPLACE, err, sizeof err) != 0) return cli_error("%s", err), -1;
    return 0;
}

/* The best curve at budget k (at the last budget, the equal-error reading is taken at its error). */
static int best_run(const bench_run *runs, int num_runs, int k) {
    int best = -1;
    for (int r = 0; r < num_runs; r++) {
        double e = err_at(&runs[r], k);
        if (isfinite(e) && (best < 0 || e < err_at(&runs[best], k))) best = r;
    }
    return best;
}

static int write_time_plot(const bench_options *o, const char *dir, const bench_run *runs, int num_runs) {
    plot_series series[MAX_RUNS];
    for (int r = 0; r < num_runs; r++) {
        const bench_run *u = &runs[r];
        /* With several seeds, a light band from the best seed to the worst. */
        series[r] = (plot_series){
            u->label, u->num_points, u->seconds, u->rms, o->seeds > 1 ? u->lo : NULL, o->seeds > 1 ? u->hi : NULL};
    }
    int last = o->num_times - 1, best = best_run(runs, num_runs, last);
    char title[160], ylabel[128], band[64], xmark[64], ymark[288];
    snprintf(title, sizeof title, "Relative L2 error (%s) against render time", bench_err_names[o->component]);
    if (o->seeds > 1)
        snprintf(ylabel, sizeof ylabel, "relative L2 error, %s, RMS of %d seeds", bench_err_names[o->component],
                 o->seeds);
    else
        snprintf(ylabel, sizeof ylabel, "relative L2 error, %s", bench_err_names[o->component]);
    snprintf(band, sizeof band, "min–max of %d seeds", o->seeds);
    snprintf(xmark, sizeof xmark, "equal time: %g s", o->times[last]);
    double ey = best >= 0 ? err_at(&runs[best], last) : (double)NAN;
    snprintf(ymark, sizeof ymark, "equal error: %.3g (%s at %g s)", ey, best >= 0 ? runs[best].label : "",
             o->times[last]);
    plot_desc pd = {.title = title,
                    .x_label = "render time",
                    .x_unit = "s",
                    .y_label = ylabel,
                    .y_unit = error_unit,
                    .log_x = 1,
                    .log_y = 1,
                    .series = series,
                    .num_series = num_runs,
                    .band_label = o->seeds > 1 ? band : NULL,
                    .mark_x = o->times[last],
                    .mark_y = ey,
                    .mark_x_label = xmark,
                    .mark_y_label = ymark};
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
    double x[MAX_VALUES], y[MAX_VARIANTS][MAX_VALUES];
    if (!sweep_numbers(sw, x)) return 0;
    plot_series series[MAX_VARIANTS];
    int ns = 0, last = o->num_times - 1, pos = 1;
    for (int v = 0; v < sw->num_values; v++) pos &= x[v] > 0.0;
    for (int k = 0; k < o->num_variants; k++) {
        int any = 0;
        for (int v = 0; v < sw->num_values; v++) {
            y[ns][v] = (double)NAN;
            for (int r = 0; r < num_runs; r++)
                if (runs[r].sweep == w && runs[r].value == v && runs[r].variant == k)
                    y[ns][v] = err_at(&runs[r], last), any = 1;
        }
        if (any)
            series[ns] = (plot_series){.label = o->variants[k].label, .n = sw->num_values, .x = x, .y = y[ns]}, ns++;
    }
    if (ns == 0) return 0;
    char title[160], ylabel[96], stem[64];
    snprintf(title, sizeof title, "Relative L2 error (%s) against %s, %g s each", bench_err_names[o->component],
             sw->name, o->times[last]);
    snprintf(ylabel, sizeof ylabel, "relative L2 error, %s", bench_err_names[o->component]);
    snprintf(stem, sizeof stem, "sweep-%s", sw->name);
    const param_desc *d = param_find(sw->name);
    plot_desc pd = {.title = title,
                    .x_label = sw->name,
                    .x_unit = d ? d->unit : NULL,
                    .y_label = ylabel,
                    .y_unit = error_unit,
                    .log_x = pos,
                    .log_y = 1,
                    .series = series,
                    .num_series = ns,
                    .mark_x = (double)NAN,
                    .mark_y = (double)NAN};
    return write_plot(dir, stem, &pd);
}

static void md_error(FILE *f, double e) {
    if (isnan(e))
        fputs("–", f);
    else if (isinf(e))
        fputs("inf", f);
    else
        fprintf(f, "%.4f", e);
}

static void md_slope(FILE *f, double slope) {
    if (isfinite(slope))
        fprintf(f, " %.2f |", slope);
    else
        fputs(" – |", f);
}

static void report_header(FILE *f, const bench_options *o, const bench_ref *ref, const reference_info *want) {
    char date[64] = "";
    time_t now = time(NULL);
    struct tm tm;
    if (gmtime_r(&now, &tm)) strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", &tm);
    char host[256] = "";
    gethostname(host, sizeof host - 1);
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    const char *comp = bench_err_names[o->component];

    fprintf(f, "# glint bench\n\n");
    if (o->preset) fprintf(f, "- preset: `%s` (`glint bench --help` lists its options)\n", o->preset);
    fprintf(f, "- scene: `%s` (%s)%s%s%s\n", want->scene, want->scene_hash, want->env[0] ? ", environment `" : "",
            want->env, want->env[0] ? "`" : "");
    fprintf(f, "- %dx%d, camera %d, max depth %d, ", want->width, want->height, want->camera_index, want->max_depth);
    if (o->seeds > 1)
        fprintf(f, "%d seeds per method and setting, %llu to %llu", o->seeds, (unsigned long long)want->seed,
                (unsigned long long)(want->seed + (uint64_t)o->seeds - 1));
    else
        fprintf(f, "seed %llu", (unsigned long long)want->seed);
    fprintf(f, ", %d threads (0: one per core)\n", o->threads);
    if (ref->has_info) {
        fprintf(f, "- reference: `%s`, %s, %lld spp, %.0f s", o->ref_path, ref->info.method, ref->info.spp,
                ref->info.seconds);
        if (ref->info.has_noise)
            fprintf(f,
                    "; its own noise, estimated from two halves of its frames: relative L2 %.4f (errors near "
                    "that are the reference's, not the method's)",
                    ref->info.rel_l2_noise);
        fputs("\n", f);
    } else {
        fprintf(f, "- reference: `%s` without a description (--force): scene, camera and size were not checked\n",
                o->ref_path);
    }
    fprintf(f, "- error: relative L2, ‖I − R‖₂ / ‖R‖₂ over all pixels and channels, of the %s%s", comp,
            o->component == ERR_ALL ? " image" : " component");
    if (o->seeds > 1) fprintf(f, "; RMS over the %d seeds (the square root of the mean of its square)", o->seeds);
    fputs("\n", f);
    if (o->base_text[0]) fprintf(f, "- options of every run: `%s`\n", o->base_text);
    fprintf(f, "- measured %s on %s, %ld cores; time is render time only (frames), error measurement excluded\n\n",
            date, host, cores);
}

static void report_errors(FILE *f, const bench_options *o, const bench_run *runs, int num_runs) {
    const char *comp = bench_err_names[o->component];
    if (o->seeds > 1)
        fprintf(f,
                "## Error at each time budget\n\nRMS over %d seeds of the relative L2 error (%s), mean frames in "
                "brackets.\n\n| method |",
                o->seeds, comp);
    else
        fprintf(f, "## Error at each time budget\n\nRelative L2 error (%s), frames in brackets.\n\n| method |", comp);
    for (int k = 0; k < o->num_times; k++) fprintf(f, " %g s |", o->times[k]);
    fputs("\n|---|", f);
    for (int k = 0; k < o->num_times; k++) fputs("---|", f);
    fputs("\n", f);
    for (int r = 0; r < num_runs; r++) {
        fprintf(f, "| %s |", runs[r].label);
        for (int k = 0; k < o->num_times; k++) {
            fputc(' ', f);
            md_error(f, err_at(&runs[r], k));
            if (k < runs[r].num_points) fprintf(f, " (%.0f)", runs[r].frames[k]);
            fputs(" |", f);
        }
        fputs("\n", f);
    }
}

/* Per run, the error at each budget split into noise and bias (two seeds or more). */
static void report_noise_bias(FILE *f, const bench_options *o, const bench_ref *ref, const bench_run *runs,
                              int num_runs) {
    if (o->seeds < 2) return;
    double rn = bench_ref_noise(ref, o->component);
    fprintf(f,
            "\n## Noise and bias\n\nAt each budget the %d renders' error splits into the noise of one render "
            "(their spread about their mean image M) and the bias: what is left of ‖M − R‖² once the mean's "
            "noise (noise²/%d) and the reference's own noise r are taken off, clamped at 0. Relative to ‖R‖₂ "
            "like the error, so RMS² = noise² + bias² + r² (exactly, unless the bias was clamped). Noise falls "
            "as time^−0.5; a consistent estimator's bias falls too, a biased one's stays. With few seeds "
            "the split is itself uncertain (fireflies above all): a bias well below the noise cannot be told "
            "from 0, and more seeds narrow it. ",
            o->seeds, o->seeds);
    if (o->component == ERR_ALL && ref->has_info && ref->info.has_noise)
        fprintf(f, "Here r = %.4f, from the reference's description.\n", rn);
    else if (ref->has_info && ref->info.has_noise)
        fprintf(f,
                "The reference records its noise for the whole image only: for the %s component r is "
                "taken as 0, so the bias includes it.\n",
                bench_err_names[o->component]);
    else
        fputs("The reference's own noise is not known (no estimate in its description): r is taken as 0, so the bias "
              "includes it.\n",
              f);
    for (int r = 0; r < num_runs; r++) {
        const bench_run *u = &runs[r];
        fprintf(f,
                "\n### %s\n\n| budget | time | frames | RMS error | min – max | noise | bias |\n"
                "|---|---|---|---|---|---|---|\n",
                u->label);
        for (int k = 0; k < u->num_points; k++) {
            fprintf(f, "| %g s | %.3g s | %.0f | ", o->times[k], u->seconds[k], u->frames[k]);
            md_error(f, u->rms[k]);
            fputs(" | ", f);
            md_error(f, u->lo[k]);
            fputs(" – ", f);
            md_error(f, u->hi[k]);
            fputs(" | ", f);
            md_error(f, u->noise[k]);
            fputs(" | ", f);
            md_error(f, u->bias[k]);
            fputs(" |\n", f);
        }
    }
}

static void report_winners(FILE *f, const bench_options *o, const bench_run *runs, int num_runs) {
    fputs("\n## Who wins\n\n", f);
    for (int k = 0; k < o->num_times; k++) {
        int best = best_run(runs, num_runs, k), second = -1;
        for (int r = 0; r < num_runs; r++) {
            double e = err_at(&runs[r], k);
            if (r != best && isfinite(e) && (second < 0 || e < err_at(&runs[second], k))) second = r;
        }
        if (best < 0) continue;
        double eb = err_at(&runs[best], k);
        fprintf(f, "- %g s: **%s**, %.4f", o->times[k], runs[best].label, eb);
        if (second >= 0) {
            double es = err_at(&runs[second], k);
            if (eb > 0.0)
                fprintf(f, ", %.2f× lower than the next, %s (%.4f)", es / eb, runs[second].label, es);
            else
                fprintf(f, "; next %s (%.4f)", runs[second].label, es);
        }
        fputs("\n", f);
    }

    const int last = o->num_times - 1;
    int best = best_run(runs, num_runs, last);
    if (best < 0 || num_runs < 2) return;
    double eb = err_at(&runs[best], last), tb = runs[best].seconds[last];
    fprintf(f,
            "\n## Equal error\n\nTime each curve needs to reach %.4f, the error of **%s** at %g s "
            "(interpolated in log–log; `~` extrapolated along the curve's fitted slope).\n\n"
            "| method | time to reach it | × %s's time |\n|---|---|---|\n",
            eb, runs[best].label, o->times[last], runs[best].label);
    for (int r = 0; r < num_runs; r++) {
        const bench_run *u = &runs[r];
        double t = metric_loglog_reach(u->seconds, u->rms, u->num_points, eb);
        const char *approx = "";
        if (!isfinite(t) && u->num_points > 0) {
            double slope = metric_loglog_slope(u->seconds, u->rms, u->num_points), el = u->rms[u->num_points - 1];
            if (slope < -0.05 && el > 0.0 && isfinite(el)) {
                t = u->seconds[u->num_points - 1] * pow(eb / el, 1.0 / slope);
                approx = "~";
            }
        }
        if (isfinite(t))
            fprintf(f, "| %s | %s%.3g s | %s%.2f |\n", u->label, approx, t, approx, t / tb);
        else
            fprintf(f, "| %s | not reached (the curve does not fall) | – |\n", u->label);
    }
}

/* The slopes in log-log: over all budgets, over the last doubling of the time (is the curve
 * still falling at the end?) and, with several seeds, of the noise and the bias. */
static void report_convergence(FILE *f, const bench_options *o, const bench_run *runs, int num_runs) {
    const int last = o->num_times - 1, tail = metric_last_doubling(o->times, o->num_times), split = o->seeds > 1;
    fprintf(f,
            "\n## Convergence\n\nSlope of each curve%s in log–log, least squares over the budgets: unbiased "
            "Monte Carlo falls as time^−0.5; a flatter curve is dominated by bias (or by the reference's own "
            "noise).",
            split ? " (the RMS over seeds)" : "");
    if (tail > 0)
        fprintf(f,
                " The slope over the last doubling of the time, %g s to %g s, tells whether the error still "
                "falls at the end (negative: it does).",
                o->times[tail], o->times[last]);
    if (split)
        fputs(" Noise and bias: the slopes of the two parts of the split over all budgets (budgets where the "
              "bias is 0 left out).",
              f);
    fputs("\n\n| method | slope |", f);
    if (tail > 0) fprintf(f, " %g–%g s |", o->times[tail], o->times[last]);
    if (split) fputs(" noise | bias |", f);
    fputs("\n|---|---|", f);
    if (tail > 0) fputs("---|", f);
    if (split) fputs("---|---|", f);
    fputs("\n", f);
    for (int r = 0; r < num_runs; r++) {
        const bench_run *u = &runs[r];
        fprintf(f, "| %s |", u->label);
        md_slope(f, metric_loglog_slope(u->seconds, u->rms, u->num_points));
        if (tail > 0)
            md_slope(f, u->num_points > tail
                            ? metric_loglog_slope(u->seconds + tail, u->rms + tail, u->num_points - tail)
                            : (double)NAN);
        if (split) {
            md_slope(f, metric_loglog_slope(u->seconds, u->noise, u->num_points));
            md_slope(f, metric_loglog_slope(u->seconds, u->bias, u->num_points));
        }
        fputs("\n", f);
    }
}

/* Whether variant k has runs in sweep w. */
static int variant_swept(const bench_options *o, int k, int w) {
    return (bench_sweep_methods(o->sweeps[w].name) & (1u << o->variants[k].method)) != 0;
}

static void report_sweeps(FILE *f, const bench_options *o, const bench_run *runs, int num_runs) {
    const int last = o->num_times - 1;
    for (int w = 0; w < o->num_sweeps; w++) {
        const sweep *sw = &o->sweeps[w];
        fprintf(f, "\n## Sweep: %s\n\n%s (%s) at %g s against the value of `--%s`.\n\n| %s |", sw->name,
                o->seeds > 1 ? "RMS over seeds of the relative L2 error" : "Relative L2 error",
                bench_err_names[o->component], o->times[last], sw->name, sw->name);
        for (int k = 0; k < o->num_variants; k++)
            if (variant_swept(o, k, w)) fprintf(f, " %s |", o->variants[k].label);
        fputs("\n|---|", f);
        for (int k = 0; k < o->num_variants; k++)
            if (variant_swept(o, k, w)) fputs("---|", f);
        fputs("\n", f);
        for (int v = 0; v < sw->num_values; v++) {
            fprintf(f, "| %s |", sw->values[v]);
            for (int k = 0; k < o->num_variants; k++) {
                if (!variant_swept(o, k, w)) continue;
                for (int r = 0; r < num_runs; r++)
                    if (runs[r].sweep == w && runs[r].value == v && runs[r].variant == k) {
                        fputc(' ', f);
                        md_error(f, err_at(&runs[r], last));
                        fputs(" |", f);
                    }
            }
            fputs("\n", f);
        }
        double x[MAX_VALUES];
        if (sweep_numbers(sw, x)) fprintf(f, "\n![error against %s](sweep-%s.svg)\n", sw->name, sw->name);
    }
}

/* Per run at the last budget, over its seeds: frames, time a frame, each pass's share of the
 * render threads' time and the share spent merging highlight lobes. */
static void report_time(FILE *f, const bench_options *o, const bench_run *runs, int num_runs) {
    const int last = o->num_times - 1;
    fprintf(f,
            "\n## Where the time goes\n\nAt %g s, mean over the seeds: each pass's share of the render threads' "
            "time (threads x render time; the virtual lights' preparation counts its wall time on every "
            "thread, camera rays count to the direct pass) and, of that, the share spent clustering and "
            "merging highlight lobes (the highlight paper's Table 1, column C).\n\n| run | frames | ms a frame |",
            o->times[last]);
    for (int q = 0; q < PASS_COUNT; q++) fprintf(f, " %s |", pass_names[q]);
    fputs(" merging |\n|---|---|---|", f);
    for (int q = 0; q <= PASS_COUNT; q++) fputs("---|", f);
    fputs("\n", f);
    for (int r = 0; r < num_runs; r++) {
        const bench_run *u = &runs[r];
        if (u->seeds_done == 0) continue;
        double share[PASS_COUNT + 1] = {0}, frames = 0.0, secs = 0.0;
        for (int i = 0; i < u->seeds_done; i++) {
            const bench_point *pt = &u->points[i][last];
            double thread_s = pt->seconds * (pt->threads > 0 ? pt->threads : 1);
            for (int q = 0; q < PASS_COUNT; q++)
                share[q] += (q == PASS_VIRTUAL_LIGHTS ? pt->pass_s[q] * pt->threads : pt->pass_s[q]) / thread_s;
            share[PASS_COUNT] += pt->merge_s / thread_s;
            frames += (double)pt->frames;
            secs += pt->seconds;
        }
        fprintf(f, "| %s | %.0f | %.3g |", u->label, frames / u->seeds_done, frames > 0 ? 1e3 * secs / frames : 0.0);
        for (int q = 0; q <= PASS_COUNT; q++) fprintf(f, " %.1f%% |", 100.0 * share[q] / u->seeds_done);
        fputs("\n", f);
    }
}

static int write_report(const bench_options *o, const char *dir, const bench_ref *ref, const reference_info *want,
                        const bench_run *runs, int num_runs) {
    char *buf = NULL;
    size_t size = 0;
    FILE *f = open_memstream(&buf, &size);
    if (!f) return cli_error("%s: out of memory", dir), -1;
    report_header(f, o, ref, want);
    report_errors(f, o, runs, num_runs);
    report_noise_bias(f, o, ref, runs, num_runs);
    report_winners(f, o, runs, num_runs);
    report_convergence(f, o, runs, num_runs);
    report_sweeps(f, o, runs, num_runs);
    report_time(f, o, runs, num_runs);
    fputs("\n## Files\n\n- `results.csv`: every checkpoint of every render (one per seed), all components, each "
          "pass's time\n"
          "- `summary.csv`: per method, setting and budget, over the seeds: the RMS of rel_l2, the mean relMSE, "
          "noise and bias, the reference's own noise, the least and largest rel_l2\n"
          "- `error-vs-time.svg`, `error-vs-time.png`: the curves (log–log); squares mark the equal-time "
          "reading at the last budget, diamonds the equal-error reading (the PNG's legend is numbered in the "
          "SVG's order)\n\n![error against time](error-vs-time.svg)\n",
          f);
    return write_text(f, &buf, &size, dir, "report.md", WRITE_NO_REPLACE);
}

int bench_write_plots_and_report(const bench_options *o, const char *dir, const bench_ref *ref,
                                 const reference_info *want, const bench_run *runs, int num_runs) {
    int status = write_time_plot(o, dir, runs, num_runs);
    for (int w = 0; w < o->num_sweeps && status == 0; w++) status = write_sweep_plot(o, dir, runs, num_runs, w);
    if (status == 0) status = write_report(o, dir, ref, want, runs, num_runs);
    return status;
}
