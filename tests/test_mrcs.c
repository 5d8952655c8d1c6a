/* Matrix row-column sampling: the reconstruction from representatives is unbiased over the rng,
 * exact when every column is its own cluster or the clusters are proportional groups, zero columns
 * are never used, the outputs are consistent (weights, sizes, scales) even for norms from 1e-30 to
 * 1e30, and a paper-sized problem runs. */
#include <float.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "check.h"
#include "mrcs.h"

/* ---- helpers --------------------------------------------------------------------------------- */

static double column_norm(const float *m, int rows, int n, int j) {
    double s = 0.0;
    for (int i = 0; i < rows; i++)
        s += (double)m[(size_t)i * (size_t)n + (size_t)j] * (double)m[(size_t)i * (size_t)n + (size_t)j];
    return sqrt(s);
}

/* A rows x n matrix: each column zero with probability zero_cols, else a random scale (e^-3..e^3)
 * times squared uniforms, a fifth of the entries zero (at least one entry non-zero). */
static float *random_matrix(int rows, int n, double zero_cols, rng_state *rng) {
    float *m = calloc((size_t)rows * (size_t)n, sizeof(float));
    for (int j = 0; j < n; j++) {
        if (rng_double(rng) < zero_cols) continue;
        double scale = exp(6.0 * rng_double(rng) - 3.0);
        int any = 0;
        for (int i = 0; i < rows; i++) {
            double u = rng_double(rng);
            if (rng_double(rng) < 0.2) continue;
            m[(size_t)i * (size_t)n + (size_t)j] = (float)(scale * (0.05 + u * u));
            any = 1;
        }
        if (!any) m[(size_t)(rng_next_u32(rng) % (uint32_t)rows) * (size_t)n + (size_t)j] = (float)scale;
    }
    return m;
}

/* est[p] = sum over clusters of scale * mat[p][representative]. */
static void reconstruct(const float *mat, int rows, int n, const mrcs_cluster *cl, int k, double *est) {
    for (int p = 0; p < rows; p++) {
        double s = 0.0;
        for (int c = 0; c < k; c++)
            s += (double)cl[c].scale * (double)mat[(size_t)p * (size_t)n + (size_t)cl[c].representative];
        est[p] = s;
    }
}

static double row_sum(const float *mat, int n, int p) {
    double s = 0.0;
    for (int j = 0; j < n; j++) s += (double)mat[(size_t)p * (size_t)n + (size_t)j];
    return s;
}

/* The invariants of any result; returns NULL, or what is wrong. */
static const char *cluster_problem(const float *m, int rows, int n, int C, const mrcs_cluster *cl, int k) {
    int nonzero = 0;
    double total = 0.0;
    for (int j = 0; j < n; j++) {
        double nj = column_norm(m, rows, n, j);
        nonzero += nj > 0.0;
        total += nj;
    }
    if (k < 0) return "out of memory";
    if (k > C) return "more clusters than C";
    if (nonzero == 0) return k == 0 ? NULL : "clusters from an all-zero matrix";
    if (k == 0) return "no clusters from a non-zero matrix";
    char *used = calloc((size_t)n, 1);
    const char *problem = NULL;
    int sizes = 0;
    double weights = 0.0;
    for (int c = 0; c < k && !problem; c++) {
        int j = cl[c].representative;
        if (j < 0 || j >= n)
            problem = "representative out of range";
        else if (used[j])
            problem = "a representative twice";
        else if (column_norm(m, rows, n, j) == 0.0)
            problem = "a zero column as representative";
        else if (!isfinite(cl[c].scale) || !(cl[c].scale >= 1.0f))
            problem = "scale not finite or below 1";
        else if (!isfinite(cl[c].weight) || !(cl[c].weight > 0.0f))
            problem = "weight not finite and positive";
        else if (cl[c].size < 1)
            problem = "empty cluster";
        else if (cl[c].size == 1 && cl[c].scale != 1.0f)
            problem = "a lone column scaled";
        if (j >= 0 && j < n) used[j] = 1;
        sizes += cl[c].size;
        weights += (double)cl[c].weight;
    }
    free(used);
    if (problem) return problem;
    if (sizes != nonzero) return "sizes do not add up to the non-zero column count";
    if (!(fabs(weights - total) <= 1e-5 * total)) return "weights do not add up to the total norm";
    return NULL;
}

/* ---- (a) unbiasedness --------------------------------------------------------------------------- */

/* Clusters the reduced matrix red (R x n) `runs` times with independent seeds and shades the
 * pixel matrix pix (P x n, every column non-zero in red if it is non-zero in pix) from the
 * representatives: the mean of each pixel's estimate, and of their total, must match the row sums
 * within 5 standard errors (rows whose estimate never varies: within rounding). random: most rows
 * must vary, or the test could not see a bias. Returns the mean relative standard error. */
static double check_unbiased(const char *name, const float *red, int R, const float *pix, int P, int n, int C, int runs,
                             uint64_t seed, int random) {
    mrcs_cluster *cl = malloc(sizeof(mrcs_cluster) * (size_t)C);
    double *est = malloc(sizeof(double) * (size_t)P), *sum = calloc((size_t)P, sizeof(double)),
           *sum2 = calloc((size_t)P, sizeof(double));
    double tsum = 0.0, tsum2 = 0.0;
    int bad_runs = 0;
    for (int run = 0; run < runs; run++) {
        rng_state rng = rng_for((uint64_t)run, 0, seed);
        int k = mrcs_cluster_columns(red, R, n, C, &rng, cl);
        if (cluster_problem(red, R, n, C, cl, k)) bad_runs++;
        if (k < 0) break;
        reconstruct(pix, P, n, cl, k, est);
        double t = 0.0;
        for (int p = 0; p < P; p++) sum[p] += est[p], sum2[p] += est[p] * est[p], t += est[p];
        tsum += t;
        tsum2 += t * t;
    }
    CHECK(bad_runs == 0, "%s: %d runs broke an invariant", name, bad_runs);
    int outliers = 0, random_rows = 0;
    double rel_se = 0.0, total = 0.0;
    for (int p = 0; p < P; p++) {
        double truth = row_sum(pix, n, p), mean = sum[p] / runs;
        double var = (sum2[p] - (double)runs * mean * mean) / (runs - 1);
        double se = sqrt(fmax(var, 0.0) / runs), tol = fmax(5.0 * se, 1e-6 * truth);
        if (!(fabs(mean - truth) <= tol) && outliers++ < 3)
            fprintf(stderr, "%s: row %d mean %.9g truth %.9g se %.3g\n", name, p, mean, truth, se);
        random_rows += se > 1e-6 * truth;
        rel_se += truth > 0.0 ? se / truth : 0.0;
        total += truth;
    }
    CHECK(outliers == 0, "%s: %d of %d rows off by more than 5 standard errors", name, outliers, P);
    double tmean = tsum / runs, tse = sqrt(fmax((tsum2 - (double)runs * tmean * tmean) / (runs - 1), 0.0) / runs);
    CHECK_NEAR(tmean, total, fmax(5.0 * tse, 1e-6 * total), "%s: all rows together", name);
    if (random)
        CHECK(random_rows > P / 2, "%s: only %d of %d rows vary: the test would not see a bias", name, random_rows, P);
    free(cl);
    free(est);
    free(sum);
    free(sum2);
    return rel_se / P;
}

static void test_unbiased(void) {
    struct {
        int R, P, n, C;
        double zero_cols;
        int runs;
    } cases[] = {
        {6, 40, 120, 12, 0.0, 3000},  /* a few rows, clusters of ~10 */
        {20, 60, 300, 30, 0.3, 1500}, /* zero columns among them */
        {1, 30, 60, 6, 0.0, 3000},    /* one sampled row: every column the same direction */
        {8, 30, 100, 1, 0.0, 3000},   /* one cluster */
    };
    for (int t = 0; t < (int)(sizeof cases / sizeof cases[0]); t++) {
        int R = cases[t].R, P = cases[t].P, n = cases[t].n, C = cases[t].C;
        rng_state rng = rng_for(77 + (uint64_t)t, 0, 5);
        float *red = random_matrix(R, n, cases[t].zero_cols, &rng);
        /* The pixel matrix: the sampled rows themselves, then unsampled rows that follow the
         * sampled ones loosely (a blend of two of them plus noise), zero where the column is. */
        float *pix = malloc(sizeof(float) * (size_t)P * (size_t)n);
        memcpy(pix, red, sizeof(float) * (size_t)R * (size_t)n);
        for (int p = R; p < P; p++) {
            int a = (int)(rng_next_u32(&rng) % (uint32_t)R), b = (int)(rng_next_u32(&rng) % (uint32_t)R);
            float f = rng_float(&rng);
            for (int j = 0; j < n; j++) {
                float v =
                    f * red[(size_t)a * (size_t)n + (size_t)j] + (1.0f - f) * red[(size_t)b * (size_t)n + (size_t)j];
                int zero = column_norm(red, R, n, j) == 0.0;
                pix[(size_t)p * (size_t)n + (size_t)j] = zero ? 0.0f : v + 0.3f * rng_float(&rng);
            }
        }
        char name[64];
        snprintf(name, sizeof name, "unbiased R=%d N=%d C=%d", R, n, C);
        /* The reduced matrix as pixels (the row sums), and the larger pixel matrix. */
        check_unbiased(name, red, R, red, R, n, C, cases[t].runs, 11, R > 1); /* R = 1: exact */
        double rel = check_unbiased(name, red, R, pix, P, n, C, cases[t].runs, 12, 1);
        printf("%s: mean relative standard error %.2g\n", name, rel);
        free(red);
        free(pix);
    }
}

/* ---- (b) every column its own cluster -------------------------------------------------------- */

static void test_exact_when_c_large(void) {
    int R = 10, n = 100;
    rng_state g = rng_for(3, 0, 3);
    float *m = random_matrix(R, n, 0.25, &g);
    int nonzero = 0;
    for (int j = 0; j < n; j++) nonzero += column_norm(m, R, n, j) > 0.0;
    mrcs_cluster cl[200];
    int Cs[] = {nonzero, nonzero + 1, n, 200};
    for (int t = 0; t < 4; t++) {
        rng_state rng = rng_for((uint64_t)t, 0, 9);
        int k = mrcs_cluster_columns(m, R, n, Cs[t], &rng, cl);
        const char *problem = cluster_problem(m, R, n, Cs[t], cl, k);
        CHECK(!problem, "C=%d: %s", Cs[t], problem);
        CHECK(k == nonzero, "C=%d: %d clusters, expected %d (one per non-zero column)", Cs[t], k, nonzero);
        int seen[100] = {0}, wrong = 0;
        for (int c = 0; c < k && k >= 0; c++) {
            int j = cl[c].representative;
            if (j < 0 || j >= n) {
                wrong++;
                continue;
            }
            seen[j]++;
            double nj = column_norm(m, R, n, j);
            wrong += cl[c].scale != 1.0f || cl[c].size != 1 || !(fabs((double)cl[c].weight - nj) <= 1e-6 * nj);
        }
        for (int j = 0; j < n; j++) wrong += seen[j] != (column_norm(m, R, n, j) > 0.0);
        CHECK(wrong == 0, "C=%d: %d columns not exactly once with scale 1, size 1, weight = norm", Cs[t], wrong);
        double est[10];
        reconstruct(m, R, n, cl, k > 0 ? k : 0, est);
        for (int p = 0; p < R; p++)
            CHECK_NEAR(est[p], row_sum(m, n, p), 1e-6 * row_sum(m, n, p), "C=%d row %d", Cs[t], p);
    }
    free(m);
}

/* ---- (c) proportional groups are recovered exactly -------------------------------------------- */

/* K groups of columns, each a positive multiple (e^-5..e^5) of its group's base vector, mixed
 * with zero columns; C = K must give one cluster per group for every seed. */
static void check_groups(int R, int K, int n, uint64_t seed, int seeds) {
    rng_state g = rng_for(seed, 1, 21);
    float *base = calloc((size_t)K * (size_t)R, sizeof(float));
    for (int k = 0; k < K; k++) {
        for (int r = 0; r < R; r++) base[k * R + r] = rng_double(&g) < 0.3 ? 0.0f : rng_float(&g);
        base[k * R + (int)(rng_next_u32(&g) % (uint32_t)R)] = 0.5f + rng_float(&g);
    }
    int *group = malloc(sizeof(int) * (size_t)n);
    float *m = calloc((size_t)R * (size_t)n, sizeof(float));
    int *group_size = calloc((size_t)K, sizeof(int));
    double *group_norm = calloc((size_t)K, sizeof(double));
    for (int j = 0; j < n; j++)
        group[j] = j < K ? j : (rng_double(&g) < 0.1 ? -1 : (int)(rng_next_u32(&g) % (uint32_t)K));
    for (int j = n - 1; j > 0; j--) { /* shuffle so groups interleave */
        int i = (int)(rng_next_u32(&g) % (uint32_t)(j + 1)), t = group[i];
        group[i] = group[j];
        group[j] = t;
    }
    for (int j = 0; j < n; j++) {
        if (group[j] < 0) continue;
        double a = exp(10.0 * rng_double(&g) - 5.0);
        for (int r = 0; r < R; r++) m[(size_t)r * (size_t)n + (size_t)j] = (float)(a * (double)base[group[j] * R + r]);
        group_size[group[j]]++;
        group_norm[group[j]] += column_norm(m, R, n, j);
    }
    mrcs_cluster *cl = malloc(sizeof(mrcs_cluster) * (size_t)K);
    double *est = malloc(sizeof(double) * (size_t)R);
    int *hit = malloc(sizeof(int) * (size_t)K);
    int bad_count = 0, bad_groups = 0, bad_sums = 0;
    for (int s = 0; s < seeds; s++) {
        rng_state rng = rng_for((uint64_t)s, 2, seed);
        int k = mrcs_cluster_columns(m, R, n, K, &rng, cl);
        if (k != K || cluster_problem(m, R, n, K, cl, k)) {
            bad_count++;
            continue;
        }
        memset(hit, 0, sizeof(int) * (size_t)K);
        int wrong = 0;
        for (int c = 0; c < k; c++) {
            int gr = group[cl[c].representative];
            if (gr < 0 || hit[gr]++) {
                wrong++;
                continue;
            }
            wrong +=
                cl[c].size != group_size[gr] || !(fabs((double)cl[c].weight - group_norm[gr]) <= 1e-5 * group_norm[gr]);
        }
        bad_groups += wrong > 0;
        reconstruct(m, R, n, cl, k, est);
        int off = 0;
        for (int p = 0; p < R; p++) off += !(fabs(est[p] - row_sum(m, n, p)) <= 1e-5 * row_sum(m, n, p));
        bad_sums += off > 0;
    }
    CHECK(bad_count == 0, "groups R=%d K=%d: %d of %d seeds gave the wrong cluster count or broke an invariant", R, K,
          bad_count, seeds);
    CHECK(bad_groups == 0, "groups R=%d K=%d: %d of %d seeds did not recover the groups", R, K, bad_groups, seeds);
    CHECK(bad_sums == 0, "groups R=%d K=%d: %d of %d seeds did not reconstruct the row sums exactly", R, K, bad_sums,
          seeds);
    free(base);
    free(group);
    free(m);
    free(group_size);
    free(group_norm);
    free(cl);
    free(est);
    free(hit);
}

/* Identical columns (cost 0 everywhere) and one sampled row (every column the same direction):
 * any C splits into non-empty clusters, and the reconstruction is exact. */
static void check_same_direction(int R, int n, int C, int identical) {
    rng_state g = rng_for((uint64_t)(R * 1000 + C), 3, 4);
    float *m = calloc((size_t)R * (size_t)n, sizeof(float));
    float *col = malloc(sizeof(float) * (size_t)R);
    for (int r = 0; r < R; r++) col[r] = 0.1f + rng_float(&g);
    for (int j = 0; j < n; j++) {
        if (j % 5 == 3) continue; /* some zero columns */
        float a = identical ? 1.0f : (float)exp(8.0 * rng_double(&g) - 4.0);
        for (int r = 0; r < R; r++) m[(size_t)r * (size_t)n + (size_t)j] = a * col[r];
    }
    int nonzero = n - (n + 1) / 5;
    mrcs_cluster *cl = malloc(sizeof(mrcs_cluster) * (size_t)C);
    double *est = malloc(sizeof(double) * (size_t)R);
    int bad = 0, off = 0;
    for (int s = 0; s < 20; s++) {
        rng_state rng = rng_for((uint64_t)s, 4, 4);
        int k = mrcs_cluster_columns(m, R, n, C, &rng, cl);
        int expect = C < nonzero ? C : nonzero;
        if (k != expect || cluster_problem(m, R, n, C, cl, k)) {
            bad++;
            continue;
        }
        reconstruct(m, R, n, cl, k, est);
        for (int p = 0; p < R; p++) off += !(fabs(est[p] - row_sum(m, n, p)) <= 1e-5 * row_sum(m, n, p));
    }
    CHECK(bad == 0, "%s R=%d N=%d C=%d: %d of 20 seeds gave the wrong count or broke an invariant",
          identical ? "identical" : "proportional", R, n, C, bad);
    CHECK(off == 0, "%s R=%d N=%d C=%d: %d rows not reconstructed exactly", identical ? "identical" : "proportional", R,
          n, C, off);
    free(m);
    free(col);
    free(cl);
    free(est);
}

static void test_groups(void) {
    check_groups(16, 7, 140, 1, 200);
    check_groups(40, 30, 600, 2, 60);
    check_groups(3, 3, 90, 3, 200);
    check_groups(8, 1, 50, 4, 50);
    check_same_direction(8, 50, 1, 1);
    check_same_direction(8, 50, 7, 1);
    check_same_direction(8, 60, 100, 1);
    check_same_direction(1, 200, 9, 0);
    check_same_direction(5, 200, 9, 0);
}

/* ---- (d) zero columns ------------------------------------------------------------------------- */

static void test_zero_columns(void) {
    int R = 12, n = 150;
    rng_state g = rng_for(8, 0, 8);
    float *m = random_matrix(R, n, 0.4, &g);
    mrcs_cluster cl[60];
    int Cs[] = {1, 3, 10, 40, 60};
    int bad = 0;
    for (int t = 0; t < 5; t++)
        for (int s = 0; s < 40; s++) {
            rng_state rng = rng_for((uint64_t)s, (uint64_t)t, 8);
            int k = mrcs_cluster_columns(m, R, n, Cs[t], &rng, cl);
            const char *problem = cluster_problem(m, R, n, Cs[t], cl, k);
            if (problem && bad++ < 3) fprintf(stderr, "C=%d seed %d: %s\n", Cs[t], s, problem);
            for (int c = 0; c < k; c++) bad += column_norm(m, R, n, cl[c].representative) == 0.0;
        }
    CHECK(bad == 0, "%d results used a zero column or broke an invariant", bad);

    float *zero = calloc((size_t)R * (size_t)n, sizeof(float));
    for (int t = 0; t < 5; t++) {
        rng_state rng = rng_for(0, 0, 0);
        CHECK(mrcs_cluster_columns(zero, R, n, Cs[t], &rng, cl) == 0, "all-zero matrix, C=%d: clusters", Cs[t]);
    }
    rng_state rng = rng_for(0, 0, 0);
    CHECK(mrcs_cluster_columns(m, 0, n, 5, &rng, cl) == 0, "no rows");
    CHECK(mrcs_cluster_columns(m, R, 0, 5, &rng, cl) == 0, "no columns");
    CHECK(mrcs_cluster_columns(m, R, n, 0, &rng, cl) == 0, "C = 0");
    free(m);
    free(zero);
}

/* ---- (e) consistency and extreme norms ---------------------------------------------------------- */

static void test_invariants(void) {
    /* Ordinary matrices, several shapes. */
    struct {
        int R, n, C;
    } shapes[] = {{1, 80, 10}, {2, 200, 20}, {30, 400, 50}, {64, 300, 299}, {5, 1000, 3}};
    int bad = 0;
    for (int t = 0; t < 5; t++) {
        rng_state g = rng_for((uint64_t)t, 9, 9);
        float *m = random_matrix(shapes[t].R, shapes[t].n, 0.1, &g);
        mrcs_cluster *cl = malloc(sizeof(mrcs_cluster) * (size_t)shapes[t].C);
        for (int s = 0; s < 10; s++) {
            rng_state rng = rng_for((uint64_t)s, 10, 9);
            int k = mrcs_cluster_columns(m, shapes[t].R, shapes[t].n, shapes[t].C, &rng, cl);
            const char *problem = cluster_problem(m, shapes[t].R, shapes[t].n, shapes[t].C, cl, k);
            if (problem && bad++ < 3) fprintf(stderr, "shape %d seed %d: %s\n", t, s, problem);
        }
        free(m);
        free(cl);
    }
    CHECK(bad == 0, "%d results broke an invariant", bad);

    /* Norms from 1e-30 to 1e30 in one matrix: the columns of random_matrix scaled by 1e-30, 1, or
     * 1e30 (entries up to ~1e31: their squares overflow float, not double). */
    int R = 20, n = 400, C = 40;
    rng_state g = rng_for(99, 9, 9);
    float *m = random_matrix(R, n, 0.1, &g);
    for (int j = 0; j < n; j++) {
        double f = j % 3 == 0 ? 1e-30 : (j % 3 == 1 ? 1e30 : 1.0);
        for (int i = 0; i < R; i++)
            m[(size_t)i * (size_t)n + (size_t)j] = (float)((double)m[(size_t)i * (size_t)n + (size_t)j] * f);
    }
    mrcs_cluster cl[40];
    double est[20];
    int bad_extreme = 0, non_finite = 0;
    for (int s = 0; s < 40; s++) {
        rng_state rng = rng_for((uint64_t)s, 11, 9);
        int k = mrcs_cluster_columns(m, R, n, C, &rng, cl);
        const char *problem = cluster_problem(m, R, n, C, cl, k);
        if (problem && bad_extreme++ < 3) fprintf(stderr, "extreme norms seed %d: %s\n", s, problem);
        if (k <= 0) continue;
        reconstruct(m, R, n, cl, k, est);
        for (int p = 0; p < R; p++) non_finite += !isfinite(est[p]);
    }
    CHECK(bad_extreme == 0, "extreme norms: %d results broke an invariant", bad_extreme);
    CHECK(non_finite == 0, "extreme norms: %d non-finite reconstructions", non_finite);
    /* The tiny columns are not dropped (the sizes above count them); with C = N each is its own. */
    mrcs_cluster *all = malloc(sizeof(mrcs_cluster) * (size_t)n);
    rng_state rng_all = rng_for(0, 11, 10);
    int k_all = mrcs_cluster_columns(m, R, n, n, &rng_all, all), tiny = 0, tiny_kept = 0;
    for (int j = 0; j < n; j += 3) tiny += column_norm(m, R, n, j) > 0.0;
    for (int c = 0; c < k_all; c++) tiny_kept += all[c].representative % 3 == 0 && all[c].scale == 1.0f;
    CHECK(tiny_kept == tiny, "extreme norms, C = N: %d of %d tiny columns kept", tiny_kept, tiny);
    free(all);

    /* Only tiny columns: everything scales down together. */
    for (size_t i = 0; i < (size_t)R * (size_t)n; i++) m[i] = (float)((double)m[i] > 1e-20 ? 0.0 : (double)m[i]);
    int bad_tiny = 0;
    for (int s = 0; s < 10; s++) {
        rng_state rng = rng_for((uint64_t)s, 12, 9);
        int k = mrcs_cluster_columns(m, R, n, C, &rng, cl);
        const char *problem = cluster_problem(m, R, n, C, cl, k);
        if (problem && bad_tiny++ < 3) fprintf(stderr, "tiny norms seed %d: %s\n", s, problem);
    }
    CHECK(bad_tiny == 0, "tiny norms only: %d results broke an invariant", bad_tiny);
    free(m);
}

/* ---- (f) the paper's size ----------------------------------------------------------------------- */

/* N lights and R pixels scattered over a unit square; a light lights a pixel with 1 / (d^2 + 0.01)
 * times a cosine-like falloff, unless an occluder (a random 30% of light-pixel pairs, more for far
 * pairs) is in the way. */
static void test_large(void) {
    int R = 300, n = 20000, C = 1000;
    rng_state g = rng_for(1, 13, 13);
    float *lx = malloc(sizeof(float) * (size_t)n * 2), *px = malloc(sizeof(float) * (size_t)R * 2);
    for (int j = 0; j < 2 * n; j++) lx[j] = rng_float(&g);
    for (int i = 0; i < 2 * R; i++) px[i] = rng_float(&g);
    float *m = malloc(sizeof(float) * (size_t)R * (size_t)n);
    for (int i = 0; i < R; i++)
        for (int j = 0; j < n; j++) {
            float dx = lx[2 * j] - px[2 * i], dy = lx[2 * j + 1] - px[2 * i + 1], d2 = dx * dx + dy * dy;
            int blocked = rng_float(&g) < 0.3f + 0.5f * d2;
            m[(size_t)i * (size_t)n + (size_t)j] = blocked || j % 50 == 7 ? 0.0f : (0.5f + 0.5f * dx) / (d2 + 0.01f);
        }
    mrcs_cluster *cl = malloc(sizeof(mrcs_cluster) * (size_t)C);
    rng_state rng = rng_for(0, 14, 14);
    clock_t t0 = clock();
    int k = mrcs_cluster_columns(m, R, n, C, &rng, cl);
    double secs = (double)(clock() - t0) / CLOCKS_PER_SEC;
    printf("large: N=%d R=%d C=%d: %d clusters in %.3f s\n", n, R, C, k, secs);
    const char *problem = cluster_problem(m, R, n, C, cl, k);
    CHECK(!problem, "large: %s", problem);
    CHECK(k == C, "large: %d clusters, expected %d", k, C);
    free(lx);
    free(px);
    free(m);
    free(cl);
}

int main(void) {
    test_unbiased();
    test_exact_when_c_large();
    test_groups();
    test_zero_columns();
    test_invariants();
    test_large();
    return check_exit("test_mrcs");
}
