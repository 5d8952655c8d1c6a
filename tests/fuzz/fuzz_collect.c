/* glint — what `glint bench --collect DIR` reads from a folder of jobs, under a fuzzer: args.txt
 * (bench_read_jobs), the arguments saved there (bench_parse_options, as --collect parses them) and
 * the first run's results.csv and summary.csv (bench_read_job_run). The input is the three files
 * one after the other, each ended by a line "--8<--" (a missing one is not written). Any input must
 * read or be refused, every value read finite (or NaN: not measured) and every count in range; a
 * crash, a sanitizer report, a hang or a runaway allocation is a finding. Built with libFuzzer
 * (clang) as fuzz_collect, and with replay.c's main() in any build. */
#define _GNU_SOURCE /* memmem */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "bench.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define CUT "--8<--\n"
/* Plans larger than this many renders are read (args.txt, the options) but their runs are not: a
 * run's points are the plan's seeds times its budgets, up to 64000, and the fuzzer would spend its
 * time clearing them. */
#define MOST_POINTS 4096

static void bad(const char *what) {
    fprintf(stderr, "fuzz_collect: %s\n", what);
    abort();
}

/* The folder the files go into: one per process, made once, removed at exit. */
static char work[64];
static void remove_folder(void) {
    static const char *const files[] = {"args.txt", "run-0/results.csv", "run-0/summary.csv", "run-0", ""};
    char path[128];
    for (size_t k = 0; k < sizeof files / sizeof files[0]; k++) {
        snprintf(path, sizeof path, "%s/%s", work, files[k]);
        remove(path);
    }
}
static const char *folder(void) {
    if (!work[0]) {
        const char *base = access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp";
        snprintf(work, sizeof work, "%s/fuzz_collect.XXXXXX", base);
        if (!mkdtemp(work)) bad("cannot make a folder");
        char run[96];
        snprintf(run, sizeof run, "%s/run-0", work);
        if (mkdir(run, 0700) != 0) bad("cannot make run-0");
        atexit(remove_folder);
    }
    return work;
}

/* The next file of the input, written to dir/name (or removed when the input has no more). */
static void put(const char *dir, const char *name, const uint8_t **p, const uint8_t *end) {
    char path[128];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    if (*p >= end) {
        unlink(path);
        return;
    }
    const uint8_t *cut = memmem(*p, (size_t)(end - *p), CUT, strlen(CUT));
    const uint8_t *stop = cut ? cut : end;
    FILE *f = fopen(path, "wb");
    size_t n = (size_t)(stop - *p);
    if (!f) bad("cannot write");
    size_t wrote = n ? fwrite(*p, 1, n, f) : 0;
    if (fclose(f) != 0 || wrote != n) bad("cannot write");
    *p = cut ? cut + strlen(CUT) : end;
}

/* What the reader promises of a run it read: every value finite, or NaN where its field was empty
 * (not measured); counts whole and in range. */
static void check_value(double v) {
    if (isinf(v)) bad("an infinite value read");
}

static void check_run(const bench_options *o, const bench_run *run) {
    if (run->seeds_done != o->seeds || run->num_points != o->num_times) bad("a run read in part");
    for (int i = 0; i < o->seeds; i++)
        for (int k = 0; k < o->num_times; k++) {
            const bench_point *pt = &run->points[i][k];
            if (pt->frames < 0 || pt->threads < 0 || pt->threads > (1 << 20)) bad("a count out of range");
            check_value(pt->seconds), check_value(pt->rays), check_value(pt->merge_s);
            for (int e = 0; e < ERR_COUNT; e++) check_value(pt->rel_l2[e]), check_value(pt->relmse[e]);
            for (int q = 0; q < PASS_COUNT; q++) check_value(pt->pass_s[q]);
        }
    for (int k = 0; k < o->num_times; k++) {
        if (!(run->seconds[k] >= 0.0) || !(run->frames[k] >= 0.0)) bad("a summary's seconds or frames negative");
        check_value(run->rms[k]), check_value(run->relmse[k]), check_value(run->noise[k]);
        check_value(run->bias[k]), check_value(run->lo[k]), check_value(run->hi[k]);
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    const char *dir = folder();
    const uint8_t *p = data, *end = data + size;
    put(dir, "args.txt", &p, end);
    put(dir, "run-0/results.csv", &p, end);
    put(dir, "run-0/summary.csv", &p, end);
    int argc;
    char **argv = NULL, cwd[4096];
    if (bench_read_jobs(dir, &argc, &argv, cwd, sizeof cwd) != 0) return 0;
    if (!memchr(cwd, 0, sizeof cwd)) bad("the plan's folder unterminated");
    bench_options o;
    if (bench_parse_options(argc, argv, &o) == 0 && o.num_variants > 0 && o.seeds >= 1 &&
        (long long)o.seeds * o.num_times <= MOST_POINTS) {
        bench_run run;
        memset(&run, 0, sizeof run);
        run.params.method = o.variants[0].method;
        run.params.seed = o.seed_given ? o.seed : 1; /* bench_main: the reference's seed + 1, here none */
        bench_point(*points)[MAX_TIMES] = calloc((size_t)o.seeds, sizeof *points);
        if (!points) bad("out of memory");
        run.points = points;
        if (bench_read_job_run(dir, &o, 0, &run) == 0) check_run(&o, &run);
        free(points);
    }
    free(argv);
    return 0;
}
