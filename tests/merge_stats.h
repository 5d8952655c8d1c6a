/* glint tests — does a reference (a merge of shards) agree with another render of as many samples
 * and another seed? Each pixel's difference over the standard error the two record (their
 * moments.var channels), and the distance between them against their noise estimates. For
 * test_merge and merge_check (the Slurm test's). */
#ifndef GLINT_MERGE_STATS_H
#define GLINT_MERGE_STATS_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image_io.h"

typedef struct {
    size_t compared;         /* pixel channels with a variance (the rest is dark) */
    size_t pixels;           /* pixel channels */
    double below;            /* fraction of |z| below 0.674: 0.5 for normal errors */
    double measured;         /* relative L2 distance between the two */
    double predicted;        /* what their noise estimates predict for it */
    double noise_a, noise_b; /* their relative noise estimates */
} merge_stats;

/* A number after "KEY": in the description in path's header; NAN when absent. */
static inline double merge_stats_described(const char *path, const char *key) {
    char *text = NULL, err[1024], pat[80];
    size_t len = 0;
    if (exr_header_string(path, "glint.reference", &text, &len, err, sizeof err) != 0) return NAN;
    snprintf(pat, sizeof pat, "\"%s\":", key);
    const char *p = strstr(text, pat);
    double v = p ? strtod(p + strlen(pat), NULL) : NAN;
    free(text);
    return v;
}

/* 0 with *st filled, or -1 after printing why (a file unreadable, channels missing). */
static inline int merge_stats_compare(const char *a_path, const char *b_path, merge_stats *st) {
    char err[1024];
    exr_image a, b;
    memset(st, 0, sizeof *st);
    if (exr_image_load(a_path, &a, err, sizeof err) != 0) return fprintf(stderr, "%s\n", err), -1;
    if (exr_image_load(b_path, &b, err, sizeof err) != 0) {
        exr_image_free(&a);
        return fprintf(stderr, "%s\n", err), -1;
    }
    double na = merge_stats_described(a_path, "spp"), nb = merge_stats_described(b_path, "spp");
    size_t n = (size_t)a.width * (size_t)a.height, lt = 0;
    double d2 = 0.0, norm = 0.0;
    int status = a.width == b.width && a.height == b.height && na > 1 && nb > 1 ? 0 : -1;
    for (int k = 0; k < 3 && status == 0; k++) {
        char mean[2] = {"RGB"[k], 0}, var[32];
        snprintf(var, sizeof var, "moments.var.%c", "RGB"[k]);
        const float *ma = exr_image_channel(&a, mean), *va = exr_image_channel(&a, var);
        const float *mb = exr_image_channel(&b, mean), *vb = exr_image_channel(&b, var);
        if (!ma || !va || !mb || !vb) {
            status = -1;
            break;
        }
        for (size_t i = 0; i < n; i++) {
            /* var is over the count; over count - 1 it estimates one sample's variance */
            double se2 = (double)va[i] / (na - 1.0) + (double)vb[i] / (nb - 1.0), d = (double)ma[i] - (double)mb[i];
            d2 += d * d;
            norm += (double)mb[i] * (double)mb[i];
            st->pixels++;
            if (se2 > 0.0) st->compared++, lt += fabs(d) / sqrt(se2) < 0.674;
        }
    }
    if (status != 0) fprintf(stderr, "%s, %s: not two renders of one size with moments and spp\n", a_path, b_path);
    st->below = st->compared ? (double)lt / (double)st->compared : 0.0;
    st->noise_a = merge_stats_described(a_path, "rel_l2_noise");
    st->noise_b = merge_stats_described(b_path, "rel_l2_noise");
    st->measured = norm > 0.0 ? sqrt(d2 / norm) : 0.0;
    st->predicted = sqrt(st->noise_a * st->noise_a + st->noise_b * st->noise_b);
    exr_image_free(&a);
    exr_image_free(&b);
    return status;
}

/* The verdict: the median |z| no further out than normal errors put it (robust to the few pixels
 * whose variance a handful of samples misjudges; a wrong weight or a shard counted twice moves it
 * far: two sigma of it is about 0.04 with a thousand pixel channels), the distance no more than
 * the noise estimates predict, the two estimates alike. Only the upper sides tell a fault: the
 * estimates take the frames as independent, and the frames' positions in the pixel follow one
 * Sobol run, whose mean errs less than that (doorway's direct light, where next-event estimation
 * leaves little but the position's variance, at edges: 0.3 of the distance they predict).
 * Prints what fails; 1 when all hold. */
static inline int merge_stats_agree(const merge_stats *st) {
    int ok = 1;
    if (st->compared * 2 < st->pixels / 2)
        ok = 0, fprintf(stderr, "only %zu of %zu pixel channels have a variance\n", st->compared, st->pixels);
    if (!(st->below > 0.42))
        ok = 0, fprintf(stderr, "%.3f of |z| below 0.674 (expected 0.5, more with stratified frames)\n", st->below);
    if (!(st->measured < 1.4 * st->predicted))
        ok = 0,
        fprintf(stderr, "relative L2 %.4g between them, their noise predicts %.4g\n", st->measured, st->predicted);
    if (!(st->noise_a > 0.8 * st->noise_b && st->noise_a < 1.25 * st->noise_b))
        ok = 0, fprintf(stderr, "relative noise %.4g and %.4g\n", st->noise_a, st->noise_b);
    return ok;
}

#endif
