/* glint tests — glint bench's outputs parsed (results.csv, summary.csv) and checked: refusals as
 * one error line, the noise and bias split's identity. For test_bench and test_bench_presets,
 * after cli_harness.h. */
#ifndef GLINT_BENCH_HARNESS_H
#define GLINT_BENCH_HARNESS_H

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "check.h"
#include "cli_harness.h"

static const char *const header =
    "method,params,seed,seconds,frames,spp,rays,rel_l2,relmse,direct_rel_l2,direct_relmse,indirect_rel_l2,"
    "indirect_relmse,highlights_rel_l2,highlights_relmse,threads,paths_s,direct_s,virtual_lights_s,gather_s,"
    "highlights_s,merge_s";
static const char *const summary_header = "method,params,component,budget,seeds,seconds,frames,rel_l2,relmse,noise,"
                                          "bias,ref_noise,rel_l2_min,rel_l2_max";

static int count_lines(const char *s) {
    int n = 0;
    for (; *s; s++) n += *s == '\n';
    return n;
}

/* A non-zero exit (usage: exactly 2) and stderr exactly one "glint: error: ..." line containing
 * needle. */
static void expect_exit(const char *args, const char *needle, int usage) {
    int rc = run(args);
    CHECK(usage ? rc == 2 : rc > 0, "'%s': exit %d, expected %s", args, rc, usage ? "2 (usage)" : "a failure");
    CHECK(strncmp(err_text, "glint: error: ", 14) == 0 && count_lines(err_text) == 1,
          "'%s': stderr is not one error line: '%s'", args, err_text);
    CHECK(strstr(err_text, needle) != NULL, "'%s': error '%s' lacks '%s'", args, err_text, needle);
}
static void expect_refusal(const char *args, const char *needle) { expect_exit(args, needle, 0); }
static void expect_usage(const char *args, const char *needle) { expect_exit(args, needle, 1); }

static int exists(const char *name) {
    char p[1024];
    snprintf(p, sizeof p, "%s/%s", tmp, name);
    struct stat st;
    return stat(p, &st) == 0;
}

/* One parsed results.csv row. */
typedef struct {
    char method[16], params[192];
    double seconds, rel_l2, highlights_rel_l2;
    long long frames, seed;
    int fields, has_highlights;
    double err[4]; /* rel_l2 of all, direct, indirect, highlights; NAN when not measured */
    int threads;
    double pass_s[5]; /* paths, direct, virtual lights, gather, highlights */
    double merge_s;
} row;

/* Splits a CSV line in place (empty fields count: no strtok); returns the number of fields. */
static int split_fields(char *line, char **field, int cap) {
    int k = 0;
    for (char *p = line;; p++) {
        if (k < cap) field[k++] = p;
        p = strchr(p, ',');
        if (!p) break;
        *p = 0;
    }
    return k;
}

static double number_or_nan(const char *field) { return field[0] ? atof(field) : NAN; }

/* Parses results.csv: the header must be exact; returns the number of rows (-1: bad header). */
static int parse_csv(const char *name, row *rows, int cap) {
    static char text[1 << 16];
    read_file(name, text, sizeof text);
    char *line = text, *nl = strchr(line, '\n');
    if (!nl) return -1;
    *nl = 0;
    if (strcmp(line, header) != 0) return -1;
    int n = 0;
    for (line = nl + 1; *line && n < cap; line = nl + 1) {
        nl = strchr(line, '\n');
        if (!nl) break;
        *nl = 0;
        row *r = &rows[n++];
        memset(r, 0, sizeof *r);
        char *field[32];
        int k = split_fields(line, field, 32);
        r->fields = k;
        if (k != 22) continue;
        snprintf(r->method, sizeof r->method, "%s", field[0]);
        snprintf(r->params, sizeof r->params, "%s", field[1]);
        r->seed = atoll(field[2]);
        r->seconds = atof(field[3]);
        r->frames = atoll(field[4]);
        r->rel_l2 = number_or_nan(field[7]);
        r->has_highlights = field[13][0] != 0;
        r->highlights_rel_l2 = number_or_nan(field[13]);
        for (int c = 0; c < 4; c++) r->err[c] = number_or_nan(field[7 + 2 * c]);
        r->threads = atoi(field[15]);
        for (int q = 0; q < 5; q++) r->pass_s[q] = number_or_nan(field[16 + q]);
        r->merge_s = number_or_nan(field[21]);
    }
    return n;
}

/* One parsed summary.csv row: over the seeds of one method and setting at one budget. */
typedef struct {
    char method[16], component[16];
    double budget, seconds, frames, rel_l2, relmse, noise, bias, ref_noise, lo, hi;
    int seeds, fields;
} summary_row;

/* Parses summary.csv: the header must be exact; returns the number of rows (-1: bad header). */
static int parse_summary(const char *name, summary_row *rows, int cap) {
    static char text[1 << 16];
    read_file(name, text, sizeof text);
    char *line = text, *nl = strchr(line, '\n');
    if (!nl) return -1;
    *nl = 0;
    if (strcmp(line, summary_header) != 0) return -1;
    int n = 0;
    for (line = nl + 1; *line && n < cap; line = nl + 1) {
        nl = strchr(line, '\n');
        if (!nl) break;
        *nl = 0;
        summary_row *r = &rows[n++];
        memset(r, 0, sizeof *r);
        char *field[32];
        r->fields = split_fields(line, field, 32);
        if (r->fields != 14) continue;
        snprintf(r->method, sizeof r->method, "%s", field[0]);
        snprintf(r->component, sizeof r->component, "%s", field[2]);
        r->budget = atof(field[3]);
        r->seeds = atoi(field[4]);
        r->seconds = atof(field[5]);
        r->frames = atof(field[6]);
        double *v[7] = {&r->rel_l2, &r->relmse, &r->noise, &r->bias, &r->ref_noise, &r->lo, &r->hi};
        for (int k = 0; k < 7; k++) *v[k] = number_or_nan(field[7 + k]);
    }
    return n;
}

/* Every summary row with two seeds or more must satisfy the split's identity: RMS^2 = noise^2 +
 * bias^2 + ref_noise^2, or, where the bias was clamped at 0, RMS^2 <= noise^2 + ref_noise^2. A
 * split that forgets the mean's noise (noise^2 / N), the reference's noise or divides by N where
 * N - 1 belongs breaks it. The CSV's 6 digits allow 1e-4 relative. */
static void check_identity(const summary_row *r, const char *what) {
    double rms2 = r->rel_l2 * r->rel_l2, parts = r->noise * r->noise + r->bias * r->bias + r->ref_noise * r->ref_noise;
    CHECK(isfinite(r->noise) && isfinite(r->bias) && r->bias >= 0.0, "%s at %g s: noise %g, bias %g", what, r->budget,
          r->noise, r->bias);
    if (r->bias > 0.0)
        CHECK(fabs(rms2 - parts) <= 1e-4 * rms2, "%s at %g s: RMS^2 %g != noise^2 + bias^2 + ref_noise^2 = %g", what,
              r->budget, rms2, parts);
    else
        CHECK(rms2 <= parts * (1.0 + 1e-4), "%s at %g s: bias clamped, yet RMS^2 %g > noise^2 + ref_noise^2 = %g", what,
              r->budget, rms2, parts);
    CHECK(r->lo <= r->rel_l2 * (1.0 + 1e-5) && r->rel_l2 <= r->hi * (1.0 + 1e-5), "%s at %g s: RMS %g outside %g..%g",
          what, r->budget, r->rel_l2, r->lo, r->hi);
}

#endif
