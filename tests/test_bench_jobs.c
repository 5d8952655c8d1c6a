/* glint bench as jobs, run as a user would: --jobs DIR writes one command line per run and
 * renders nothing; each line, run by the shell, renders its run alone; --collect DIR builds
 * results.csv, summary.csv, the plots and report.md with the rows and sections a bench run in one
 * process writes (the numbers differ: they are timed renders). Refused: collecting before every
 * job ran, collecting twice, planning into a planned directory, --jobs with --out, a --job
 * beyond the plan, a directory no plan wrote, a FIFO in place of a file --collect reads, a
 * run's CSV holding a value glint never writes (nan, inf, a count of 1e300 or none), an args.txt
 * holding --jobs, --job or --out.
 * Usage: test_bench_jobs PATH_TO_GLINT */
#define _POSIX_C_SOURCE 200809L
#include <stdlib.h>
#include <string.h>

#include "bench_harness.h"
#include "check.h"
#include "cli_harness.h"

#define BENCH "bench builtin:atelier --reference ref.exr --methods pt,vsl --times 0.05,0.1 --seeds 2 --threads 2"

/* The first n comma-separated fields of every line of text, one line each, into out. */
static void columns(const char *text, int n, char *out, size_t cap) {
    size_t o = 0;
    int field = 0;
    for (; *text && o + 2 < cap; text++) {
        if (*text == '\n')
            field = 0;
        else if (*text == ',')
            field++;
        if (field < n || *text == '\n') out[o++] = *text;
    }
    out[o] = '\0';
}

/* The headings of a Markdown text and the first cell of each table row: its sections and rows,
 * not the numbers in them. */
static void skeleton(const char *text, char *out, size_t cap) {
    size_t o = 0;
    for (const char *line = text; *line && o + 2 < cap;) {
        const char *end = strchr(line, '\n');
        size_t len = end ? (size_t)(end - line) : strlen(line);
        if (line[0] == '#' || line[0] == '|') {
            int bars = 0;
            for (size_t i = 0; i < len && o + 2 < cap && bars < 2; i++) {
                bars += line[i] == '|';
                out[o++] = line[i];
            }
            out[o++] = '\n';
        }
        line += len + (end ? 1 : 0);
    }
    out[o] = '\0';
}

int main(int argc, char **argv) {
    int start = harness_start(argc, argv, "bench_jobs");
    if (start != 0) return start;
    CHECK(run("render builtin:atelier --size 24x16 --spp 4 --out ref.exr --quiet") == 0, "%s", err_text);
    CHECK(run(BENCH " --jobs plan") == 0, "--jobs: %s", err_text);
    CHECK(strstr(out_text, "wrote 2 jobs to plan/jobs.txt") != NULL, "%s", out_text);
    CHECK(!exists("plan/results.csv") && !exists("plan/run-0"), "--jobs rendered");
    static char jobs[8192], text[65536], local[65536], a[65536], b[65536];
    read_file("plan/jobs.txt", jobs, sizeof jobs);
    CHECK(count_lines(jobs) == 2 && strstr(jobs, "--job 0 --out") && strstr(jobs, "--job 1 --out"), "jobs.txt: %s",
          jobs);
    expect_refusal("bench --collect plan", "run-0/results.csv");
    expect_refusal(BENCH " --jobs plan", "plan/args.txt");
    expect_refusal(BENCH " --jobs p2 --out x", "--jobs: the jobs choose their own --out");
    expect_usage(BENCH " --job 2 --out j2", "--job 2: the plan has 2 runs (0 to 1)");
    expect_refusal("bench --collect .", "args.txt");
    /* A FIFO in place of a file it reads: refused, not waited on (it used to hang there). */
    char cmd[9000];
    snprintf(cmd, sizeof cmd, "cd '%s' && cp -r plan fifo && rm fifo/args.txt && mkfifo fifo/args.txt", tmp);
    CHECK(system(cmd) == 0, "making a FIFO");
    expect_refusal("bench --collect fifo", "fifo/args.txt: not a regular file");
    /* Each line as a scheduler would run it: a shell command, from anywhere. */
    for (char *line = jobs, *end; (end = strchr(line, '\n')); line = end + 1) {
        *end = '\0';
        snprintf(cmd, sizeof cmd, "cd / && %s >/dev/null 2>&1", line);
        CHECK(system(cmd) == 0, "job failed: %s", line);
    }
    snprintf(cmd, sizeof cmd,
             "cd '%s' && cp -r plan fifo2 && rm fifo2/run-1/summary.csv && mkfifo fifo2/run-1/summary.csv", tmp);
    CHECK(system(cmd) == 0, "making a FIFO");
    expect_refusal("bench --collect fifo2", "fifo2/run-1/summary.csv: not a regular file");
    /* Options --jobs never writes into args.txt: collecting must not plan again or run a job. */
    const char *const appended[] = {"--jobs\nD2", "--job\n0", "--out\nelsewhere"};
    for (size_t k = 0; k < sizeof appended / sizeof appended[0]; k++) {
        snprintf(cmd, sizeof cmd, "cd '%s' && rm -rf bad && cp -r plan bad && printf '%%s\\n' '%s' >>bad/args.txt", tmp,
                 appended[k]);
        CHECK(system(cmd) == 0, "%s", cmd);
        expect_refusal("bench --collect bad", "which glint bench --jobs never writes there");
    }
    /* Values glint never writes: not counts, not finite numbers. */
    const struct {
        const char *file, *field, *value, *error;
    } bad[] = {
        {"results.csv", "5", "nan", "field 5 is not a number"},
        {"results.csv", "5", "1e300", "not counts"},
        {"results.csv", "5", "", "not counts"},
        {"results.csv", "4", "inf", "field 4 is not a number"},
        {"summary.csv", "7", "1e300", "not a run's"},
        {"summary.csv", "8", "-inf", "field 8 is not a number"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        /* field F (1-based) of the file's second line set to the value */
        snprintf(cmd, sizeof cmd,
                 "cd '%s' && rm -rf bad && cp -r plan bad && sed -i '2s/^\\(\\([^,]*,\\)\\{%d\\}\\)[^,]*/\\1%s/' "
                 "bad/run-0/%s",
                 tmp, atoi(bad[k].field) - 1, bad[k].value, bad[k].file);
        CHECK(system(cmd) == 0, "%s", cmd);
        expect_refusal("bench --collect bad", bad[k].error);
    }
    CHECK(run("bench --collect plan") == 0, "--collect: %s", err_text);
    CHECK(run(BENCH " --out local --quiet") == 0, "local: %s", err_text);
    const char *files[] = {"results.csv", "summary.csv", "report.md", "error-vs-time.svg", "error-vs-time.png"};
    for (int k = 0; k < 5; k++) {
        char p[64];
        snprintf(p, sizeof p, "plan/%s", files[k]);
        CHECK(exists(p), "--collect wrote no %s", p);
    }
    /* The same rows: method, settings, seed; component, budget and seeds in the summary. */
    read_file("plan/results.csv", text, sizeof text);
    read_file("local/results.csv", local, sizeof local);
    CHECK(strncmp(text, header, strlen(header)) == 0, "results.csv header: %.200s", text);
    columns(text, 3, a, sizeof a);
    columns(local, 3, b, sizeof b);
    CHECK(strcmp(a, b) == 0 && count_lines(a) == 1 + 2 * 2 * 2, "results.csv rows:\n%s\nlocally:\n%s", a, b);
    read_file("plan/summary.csv", text, sizeof text);
    read_file("local/summary.csv", local, sizeof local);
    columns(text, 5, a, sizeof a);
    columns(local, 5, b, sizeof b);
    CHECK(strcmp(a, b) == 0 && count_lines(a) == 1 + 2 * 2, "summary.csv rows:\n%s\nlocally:\n%s", a, b);
    /* Each run's rows as its job measured them: the noise and bias split holds over its seeds. */
    static row rows[16];
    static summary_row summary[8];
    CHECK(parse_csv("plan/results.csv", rows, 16) == 8, "plan/results.csv: not 8 rows");
    int ns = parse_summary("plan/summary.csv", summary, 8);
    CHECK(ns == 4, "plan/summary.csv: %d rows", ns);
    for (int k = 0; k < ns; k++) check_identity(&summary[k], summary[k].method);
    read_file("plan/report.md", text, sizeof text);
    read_file("local/report.md", local, sizeof local);
    skeleton(text, a, sizeof a);
    skeleton(local, b, sizeof b);
    CHECK(strcmp(a, b) == 0 && count_lines(a) > 10, "report.md's sections:\n%s\nlocally:\n%s", a, b);
    expect_refusal("bench --collect plan", "already holds results.csv");
    /* A bench that draws its plots, run without the suite's LeakSanitizer options (as a user runs a
     * sanitizer build): fontconfig's lasting configuration is no leak report, no failure. */
    snprintf(cmd, sizeof cmd,
             "cd '%s' && env -u LSAN_OPTIONS '%s' bench builtin:atelier --reference ref.exr --methods pt "
             "--times 0.05 --seeds 1 --out plotted --quiet >/dev/null 2>lsan.txt",
             tmp, glint);
    CHECK(system(cmd) == 0, "a bench drawing plots without LSAN_OPTIONS failed (see lsan.txt)");
    return check_exit("test_bench_jobs");
}
