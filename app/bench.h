/* glint bench: what the command's parts share — its options, the runs it plans and measures,
 * the reference it measures against — and the parts' entry points: parsing the options
 * (bench_options.c), running (cmd_bench.c), writing the results, plots and report
 * (bench_report.c). */
#ifndef GLINT_BENCH_H
#define GLINT_BENCH_H

#include <stdint.h>

#include "image_io.h"
#include "reference.h"
#include "session.h"

enum { MAX_METHODS = 8, MAX_TIMES = 32, MAX_SWEEPS = 8, MAX_VALUES = 32, MAX_RUNS = 256 };

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

/* Parses glint bench's arguments. Returns 0 to run, 1 when --help was shown, -1 on a usage error
 * (already reported). */
int bench_parse_options(int argc, char **argv, bench_options *o);

/* The methods a sweepable many-light parameter is live for (bit per render_method). */
unsigned bench_sweep_methods(const char *name);

/* results.csv: every checkpoint of the first num_runs runs (mode: WRITE_NO_REPLACE the first
 * time, then WRITE_REPLACE as runs complete). Returns 0, or -1 after reporting the error. */
int bench_write_csv(const char *dir, const bench_run *runs, int num_runs, write_mode mode);

/* The plots (error-vs-time, one per numeric sweep) and report.md, never replacing a file. want
 * describes what the bench rendered. Returns 0, or -1 after reporting the error. */
int bench_write_plots_and_report(const bench_options *o, const char *dir, const bench_ref *ref,
                                 const reference_info *want, const bench_run *runs, int num_runs);

#endif
