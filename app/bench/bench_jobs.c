/* glint bench as jobs: a sweep written as one command line per run (--jobs DIR), each run
 * rendered alone (--job K) wherever a scheduler puts it, and the runs' CSVs read back to build
 * the same results, plots and report (--collect DIR). The jobs find everything through the
 * arguments saved once in DIR/args.txt, so planning and collecting parse the same command. */
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
#include "cli.h"
#include "image_io.h"

#define ARGS_MAGIC "glint bench jobs 1"
enum { MAX_ARGS_BYTES = 1 << 20 };

/* s in single quotes for the shell, a quote inside as '\'' */
static void shell_word(FILE *f, const char *s) {
    fputc('\'', f);
    for (; *s; s++)
        if (*s == '\'')
            fputs("'\\''", f);
        else
            fputc(*s, f);
    fputc('\'', f);
}

/* Writes the text of the memory stream f (over *buf, *size) to dir/name, never replacing a file. */
static int save(FILE *f, char **buf, size_t *size, const char *dir, const char *name) {
    char path[PATH_MAX + 64], err[PATH_MAX + 256];
    int bad = ferror(f);
    if (fclose(f) != 0 || bad) { /* *buf and *size are only final once it is closed */
        free(*buf);
        return cli_error("%s: out of memory", dir), -1;
    }
    snprintf(path, sizeof path, "%s/%s", dir, name);
    int st = write_file_atomic(path, *buf, *size, WRITE_NO_REPLACE, err, sizeof err);
    free(*buf);
    if (st != 0) cli_error("%s", err);
    return st;
}

int bench_write_jobs(const char *dir, int argc, char **argv, int num_runs) {
    char cwd[PATH_MAX], abs_dir[PATH_MAX], self[PATH_MAX];
    for (int i = 0; i < argc; i++)
        if (strchr(argv[i], '\n')) return cli_error("--jobs: an argument holds a line break: '%s'", argv[i]), -1;
    if (mkdir(dir, 0777) != 0 && errno != EEXIST)
        return cli_error("--jobs: %s: cannot create the directory: %s", dir, strerror(errno)), -1;
    if (!getcwd(cwd, sizeof cwd) || !realpath(dir, abs_dir))
        return cli_error("--jobs: %s: %s", dir, strerror(errno)), -1;
    /* The program that planned runs the jobs: on a cluster, the same path on a shared file system. */
    ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
    if (n <= 0) return cli_error("--jobs: cannot tell where this glint is: %s", strerror(errno)), -1;
    self[n] = '\0';
    char *buf = NULL;
    size_t size = 0;
    FILE *f = open_memstream(&buf, &size);
    if (!f) return cli_error("%s: out of memory", dir), -1;
    fprintf(f, "%s\n%s\n", ARGS_MAGIC, cwd);
    for (int i = 0; i < argc; i++) fprintf(f, "%s\n", argv[i]);
    if (save(f, &buf, &size, abs_dir, "args.txt") != 0) return -1;
    if (!(f = open_memstream(&buf, &size))) return cli_error("%s: out of memory", dir), -1;
    for (int k = 0; k < num_runs; k++) {
        fputs("cd ", f);
        shell_word(f, cwd);
        fputs(" && ", f);
        shell_word(f, self);
        fputs(" bench", f);
        for (int i = 0; i < argc; i++) fputc(' ', f), shell_word(f, argv[i]);
        char out[PATH_MAX + 32];
        snprintf(out, sizeof out, "%s/run-%d", abs_dir, k);
        fprintf(f, " --quiet --job %d --out ", k);
        shell_word(f, out);
        fputc('\n', f);
    }
    return save(f, &buf, &size, abs_dir, "jobs.txt");
}

int bench_read_jobs(const char *dir, int *argc, char ***argv, char *cwd, size_t cwdlen) {
    char path[PATH_MAX + 64];
    snprintf(path, sizeof path, "%s/args.txt", dir);
    FILE *f = open_regular_file(path);
    if (!f) return cli_error("%s: %s (not a directory of glint bench --jobs)", path, open_regular_problem(errno)), -1;
    /* One block: the pointers, then the text they point into. */
    char *text = malloc(MAX_ARGS_BYTES + 1);
    size_t n = text ? fread(text, 1, MAX_ARGS_BYTES + 1, f) : 0;
    fclose(f);
    if (!text) return cli_error("%s: out of memory", path), -1;
    if (n > MAX_ARGS_BYTES || memchr(text, '\0', n)) {
        free(text);
        return cli_error("%s: not a list of arguments", path), -1;
    }
    text[n] = '\0';
    size_t lines = 0;
    for (size_t i = 0; i < n; i++) lines += text[i] == '\n';
    char **v = malloc(sizeof(char *) * (lines + 1) + n + 1);
    if (!v) {
        free(text);
        return cli_error("%s: out of memory", path), -1;
    }
    char *copy = (char *)(v + lines + 1);
    memcpy(copy, text, n + 1);
    free(text);
    int count = 0;
    for (char *line = copy, *end; (end = strchr(line, '\n')); line = end + 1) {
        *end = '\0';
        v[count++] = line;
    }
    if (count < 2 || strcmp(v[0], ARGS_MAGIC) != 0 || strlen(v[1]) >= cwdlen) {
        free(v);
        return cli_error("%s: not written by glint bench --jobs", path), -1;
    }
    /* --jobs takes the plan's own options out of what it writes: there they would make --collect
     * plan again, or run one job, in place of collecting */
    static const char *const never[] = {"--jobs", "--job", "--collect", "--out"};
    for (int i = 2; i < count; i++)
        for (size_t k = 0; k < sizeof never / sizeof never[0]; k++)
            if (strcmp(v[i], never[k]) == 0) {
                free(v);
                return cli_error("%s: holds %s, which glint bench --jobs never writes there", path, never[k]), -1;
            }
    snprintf(cwd, cwdlen, "%s", v[1]);
    memmove(v, v + 2, sizeof(char *) * (size_t)(count - 2));
    *argc = count - 2;
    *argv = v;
    return 0;
}

/* ---- the runs' CSVs ---------------------------------------------------------------------------- */

/* Splits a CSV line (no quoting: glint's fields hold no commas) into at most max fields. */
static int split_fields(char *line, char **fields, int max) {
    int n = 0;
    for (char *p = line;; p++) {
        if (n < max) fields[n] = p;
        n++;
        p = strchr(p, ',');
        if (!p) break;
        *p = '\0';
    }
    return n;
}

/* An empty field is a value not measured (NAN); any other is a finite number (glint writes no
 * "nan" or "inf": such a field was not written by it). */
static int field_number(const char *s, double *out) {
    char *end;
    if (!*s) return *out = (double)NAN, 0;
    errno = 0;
    *out = strtod(s, &end);
    return *end || errno == ERANGE || !isfinite(*out) ? -1 : 0;
}

/* A count read as a number: whole, from 0 to most (a NAN, 1e300 or -1 would wrap when converted);
 * frames at most 2^53, the doubles that are all whole numbers. */
#define MAX_FRAMES 9007199254740992.0
static int whole(double v, double most) { return v >= 0.0 && v <= most && v == floor(v); }

typedef struct {
    FILE *f;
    char path[PATH_MAX + 64];
    char line[4096];
    int number;
} csv_reader;

/* The next line of the file, without its newline: 1, or 0 at the end. */
static int next_line(csv_reader *c) {
    if (!fgets(c->line, sizeof c->line, c->f)) return 0;
    c->number++;
    c->line[strcspn(c->line, "\n")] = '\0';
    return 1;
}

static int open_csv_of(csv_reader *c, const char *dir, int r, const char *name) {
    snprintf(c->path, sizeof c->path, "%s/run-%d/%s", dir, r, name);
    c->number = 0;
    if (!(c->f = open_regular_file(c->path)))
        return cli_error("%s: %s (has job %d, line %d of jobs.txt, run?)", c->path, open_regular_problem(errno), r,
                         r + 1),
               -1;
    if (!next_line(c)) {
        fclose(c->f);
        return cli_error("%s: empty", c->path), -1;
    }
    return 0;
}

/* The line is run's (method and settings), for the expected number of fields. */
static int line_of_run(csv_reader *c, const bench_run *run, char **fields, int want) {
    int n = split_fields(c->line, fields, want);
    if (n != want || strcmp(fields[0], method_name(run->params.method)) != 0 || strcmp(fields[1], run->setting) != 0)
        return cli_error("%s: line %d: not a row of run '%s' as this plan has it", c->path, c->number, run->label), -1;
    return 0;
}

enum { RESULT_FIELDS = 7 + 2 * ERR_COUNT + 1 + PASS_COUNT + 1, SUMMARY_FIELDS = 14 };

static int read_results(csv_reader *c, const bench_options *o, bench_run *run) {
    char *f[RESULT_FIELDS];
    for (int i = 0; i < o->seeds; i++)
        for (int k = 0; k < o->num_times; k++) {
            bench_point *pt = &run->points[i][k];
            double v[RESULT_FIELDS];
            if (!next_line(c)) return cli_error("%s: ends before seed %d's budget %d", c->path, i + 1, k + 1), -1;
            if (line_of_run(c, run, f, RESULT_FIELDS) != 0) return -1;
            for (int j = 2; j < RESULT_FIELDS; j++)
                if (field_number(f[j], &v[j]) != 0)
                    return cli_error("%s: line %d: field %d is not a number", c->path, c->number, j + 1), -1;
            if (v[2] != (double)(run->params.seed + (uint64_t)i))
                return cli_error("%s: line %d: seed %s, this plan's is %llu", c->path, c->number, f[2],
                                 (unsigned long long)(run->params.seed + (uint64_t)i)),
                       -1;
            if (!whole(v[4], MAX_FRAMES) || !whole(v[7 + 2 * ERR_COUNT], 1 << 20))
                return cli_error("%s: line %d: frames %s, threads %s: not counts", c->path, c->number, f[4],
                                 f[7 + 2 * ERR_COUNT]),
                       -1;
            pt->seconds = v[3];
            pt->frames = (long long)v[4];
            pt->rays = v[6];
            for (int e = 0; e < ERR_COUNT; e++) pt->rel_l2[e] = v[7 + 2 * e], pt->relmse[e] = v[8 + 2 * e];
            pt->threads = (int)v[7 + 2 * ERR_COUNT];
            for (int q = 0; q < PASS_COUNT; q++) pt->pass_s[q] = v[8 + 2 * ERR_COUNT + q];
            pt->merge_s = v[RESULT_FIELDS - 1];
        }
    run->seeds_done = o->seeds;
    return 0;
}

static int read_summary(csv_reader *c, const bench_options *o, bench_run *run) {
    char *f[SUMMARY_FIELDS];
    for (int k = 0; k < o->num_times; k++) {
        double v[SUMMARY_FIELDS];
        if (!next_line(c)) return cli_error("%s: ends before budget %d", c->path, k + 1), -1;
        if (line_of_run(c, run, f, SUMMARY_FIELDS) != 0) return -1;
        for (int j = 3; j < SUMMARY_FIELDS; j++)
            if (field_number(f[j], &v[j]) != 0)
                return cli_error("%s: line %d: field %d is not a number", c->path, c->number, j + 1), -1;
        if (strcmp(f[2], bench_err_names[o->component]) != 0 || v[3] != o->times[k] || v[4] != o->seeds)
            return cli_error("%s: line %d: not %s at %g s over %d seeds, as this plan has it", c->path, c->number,
                             bench_err_names[o->component], o->times[k], o->seeds),
                   -1;
        if (!(v[5] >= 0.0) || !(v[6] >= 0.0 && v[6] <= MAX_FRAMES))
            return cli_error("%s: line %d: seconds %s, frames %s: not a run's", c->path, c->number, f[5], f[6]), -1;
        run->seconds[k] = v[5];
        run->frames[k] = v[6];
        run->rms[k] = v[7];
        run->relmse[k] = v[8];
        run->noise[k] = v[9];
        run->bias[k] = v[10];
        run->lo[k] = v[12];
        run->hi[k] = v[13];
    }
    run->num_points = o->num_times;
    return 0;
}

int bench_read_job_run(const char *dir, const bench_options *o, int r, bench_run *run) {
    csv_reader c;
    if (open_csv_of(&c, dir, r, "results.csv") != 0) return -1;
    int st = read_results(&c, o, run);
    if (st == 0 && next_line(&c)) {
        cli_error("%s: line %d: more rows than the plan's", c.path, c.number);
        st = -1;
    }
    fclose(c.f);
    if (st != 0 || open_csv_of(&c, dir, r, "summary.csv") != 0) return -1;
    st = read_summary(&c, o, run);
    fclose(c.f);
    return st;
}
