/* glint bench: what the command's parts share — its options, the runs it plans and measures,
 * the reference it measures against — and the parts' entry points: parsing the options and
 * expanding presets (bench_options.c), running (cmd_bench.c), writing the results, plots and
 * report (bench_report.c). */
#ifndef GLINT_BENCH_H
#define GLINT_BENCH_H

#include <stdint.h>

#include "image_io.h"
#include "reference.h"
#include "session.h"

/* MAX_RENDERS bounds runs x seeds (each a render of the last budget's length); MAX_SPLIT_BYTES
 * the sum images the noise and bias split keeps, one per budget (320x240 at 64 budgets takes
 * 113 MiB). */
enum {
    MAX_VARIANTS = 16,
    MAX_SETTINGS = 8,
    MAX_TIMES = 64,
    MAX_SWEEPS = 8,
    MAX_VALUES = 32,
    MAX_RUNS = 256,
    MAX_SEEDS = 1000,
    MAX_RENDERS = 4096
};
#define MAX_SPLIT_BYTES ((double)(512u << 20))

/* The error columns: the image and its components. Indirect always means all light after the
 * first bounce (highlights included), so it means the same for every method; highlights are
 * compared only where both the reference and the method split them off. */
enum { ERR_ALL = 0, ERR_DIRECT, ERR_INDIRECT, ERR_HIGHLIGHTS, ERR_COUNT };
extern const char *const bench_err_names[ERR_COUNT];

typedef struct {
    char name[32];
    int num_values;
    char values[MAX_VALUES][32];
} sweep;

/* A method with settings of its own: --run METHOD:NAME=VALUE,... (--methods gives none). */
typedef struct {
    render_method method;
    int num_settings;
    char names[MAX_SETTINGS][32], values[MAX_SETTINGS][32];
    char label[96]; /* "vsl trace-glossy=off" */
} bench_variant;

typedef struct {
    const char *scene_path, *ref_path, *out_dir, *env_path;
    const char *preset; /* the --preset expanded, or NULL */
    double env_rotation_deg;
    bench_variant variants[MAX_VARIANTS];
    int num_variants;
    double times[MAX_TIMES];
    int num_times;
    sweep sweeps[MAX_SWEEPS];
    int num_sweeps;
    int component;          /* ERR_* */
    int width, height;      /* 0: the reference's */
    long long camera_index; /* -2: the reference's */
    int max_depth;          /* 0: the reference's */
    uint64_t seed;          /* the first seed's */
    int seed_given;
    int seeds; /* renders per run, with seeds seed, seed + 1, ... */
    int threads;
    int plan;      /* PLAN_AUTO, PLAN_FULL: every run's */
    unsigned only; /* render_params.only: every run's; 0: all */
    vl_params vl;  /* the many-light options given: every run's base */
    char base_text[512];
    int force, quiet;
    /* A sweep split into jobs: --jobs DIR writes one command line per run (bench_write_jobs);
     * --job K renders run K alone into --out; --collect DIR (cmd_bench) builds the results from
     * the jobs' outputs. */
    const char *jobs_dir;
    long long job;
    int job_given;
    const char *collect_dir; /* set by cmd_bench, not an option of its own */
} bench_options;

/* One checkpoint of one render. */
typedef struct {
    double seconds, rays;
    long long frames;
    double rel_l2[ERR_COUNT], relmse[ERR_COUNT]; /* NAN: not measured */
    int threads;
    double pass_s[PASS_COUNT]; /* render_stats.pass_ns in seconds: thread time (virtual lights: wall) */
    double merge_s;            /* thread time spent clustering and merging highlight lobes */
} bench_point;

/* A run: one variant with one sweep setting, rendered once per seed. */
typedef struct {
    render_params params; /* params.seed is the first seed's */
    char setting[192];    /* the variant's settings and the sweep's, "trace-glossy=off radius-mult=4" */
    char label[208];      /* "vsl trace-glossy=off radius-mult=4" */
    int variant;          /* index into the options' variants */
    int sweep;            /* index into the options' sweeps, -1 for a base run */
    int value;
    bench_point (*points)[MAX_TIMES]; /* [seed][budget] */
    int seeds_done;                   /* renders measured at every budget */
    /* Over the seeds, per budget, in the reported component; num_points is 0 until every seed
     * is done. */
    int num_points;
    double seconds[MAX_TIMES], frames[MAX_TIMES]; /* means */
    double rms[MAX_TIMES];                        /* RMS of rel_l2: sqrt(mean rel_l2^2) */
    double relmse[MAX_TIMES];                     /* mean: relMSE is a mean of squares already */
    double lo[MAX_TIMES], hi[MAX_TIMES];          /* min and max of rel_l2 */
    double noise[MAX_TIMES], bias[MAX_TIMES];     /* metric_noise_bias; NAN with one seed */
} bench_run;

typedef struct {
    int width, height;
    float *layer[ERR_COUNT]; /* interleaved RGB; NULL when the EXR lacks the layer */
    reference_info info;
    int has_info;
} bench_ref;

/* The reference's own relative noise in a component, as its description records it: known for
 * the whole image only (0 otherwise, and without a description). */
static inline double bench_ref_noise(const bench_ref *r, int component) {
    return component == ERR_ALL && r->has_info && r->info.has_noise ? r->info.rel_l2_noise : 0.0;
}

/* Parses glint bench's arguments. Returns 0 to run, 1 when --help was shown, -1 on a usage error
 * (already reported). */
int bench_parse_options(int argc, char **argv, bench_options *o);

/* The methods a setting (a many-light parameter, or plan) is live for (bit per render_method). */
unsigned bench_sweep_methods(const char *name);

/* Applies a setting by name: plan (auto|full) or a many-light parameter. Returns 1 when applied,
 * 0 when name is none of them, -1 on a bad value (reported). */
int bench_apply_setting(const char *name, const char *value, render_params *p);

/* The film components (1 << COMP_*) an error column compares. */
unsigned bench_err_mask(int component);

/* results.csv: every checkpoint of every render done of the first num_runs runs; summary.csv:
 * the aggregates of the runs done (num_points > 0). mode: WRITE_NO_REPLACE the first time, then
 * WRITE_REPLACE as renders complete. Return 0, or -1 after reporting the error. */
int bench_write_csv(const char *dir, const bench_run *runs, int num_runs, int num_times, write_mode mode);
int bench_write_summary(const bench_options *o, const char *dir, const bench_ref *ref, const bench_run *runs,
                        int num_runs, write_mode mode);

/* The plots (error-vs-time, one per numeric sweep) and report.md, never replacing a file. want
 * describes what the bench rendered. Returns 0, or -1 after reporting the error. */
int bench_write_plots_and_report(const bench_options *o, const char *dir, const bench_ref *ref,
                                 const reference_info *want, const bench_run *runs, int num_runs);

/* --jobs: the arguments argv (argc of them, --jobs DIR left out) saved in DIR/args.txt, with the
 * working directory, for --collect; and DIR/jobs.txt, line K + 1 a shell command that renders run
 * K of num_runs (--job K) into DIR/run-K from that directory. DIR is created; one holding a plan
 * already is refused. Returns 0, or -1 after reporting the error. */
int bench_write_jobs(const char *dir, int argc, char **argv, int num_runs);
/* --collect: the saved arguments of DIR/args.txt (malloc'ed, as one block: free(*argv)) and the
 * directory the jobs ran in, which relative paths in them are relative to. Returns 0, or -1 after
 * reporting the error. */
int bench_read_jobs(const char *dir, int *argc, char ***argv, char *cwd, size_t cwdlen);
/* The figures of run r as job r wrote them in DIR/run-R (results.csv, summary.csv), into run
 * (its points' storage allocated by the caller for o->seeds renders). Returns 0, or -1 after
 * reporting the error. */
int bench_read_job_run(const char *dir, const bench_options *o, int r, bench_run *run);

#endif
