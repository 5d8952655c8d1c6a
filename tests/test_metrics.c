/* The error metrics and the error-curve numerics of glint bench, against hand-computed values:
 * relative L2 and relMSE (including no pixels and an all-zero reference), the two-halves
 * variance of a progressive mean (by hand, and on Gaussian samples of known variance), the noise
 * and bias split over seeds (by hand, one seed, a zero reference, and on Gaussian runs of known
 * noise and bias), log-log slopes, the last doubling and interpolation. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "check.h"
#include "metrics.h"

static void test_errors(void) {
    const float img[3] = {1, 2, 3}, ref[3] = {1, 1, 1};
    /* ||(0,1,2)||^2 = 5 against ||(1,1,1)||^2 = 3 */
    CHECK_NEAR(metric_rel_l2(img, ref, 3), sqrt(5.0 / 3.0), 1e-12, "rel_l2");
    CHECK_NEAR(metric_relmse(img, ref, 3), (1.0 + 4.0) / (1.0 + METRIC_RELMSE_EPS) / 3.0, 1e-12, "relmse");
    CHECK(metric_rel_l2(img, img, 3) == 0.0 && metric_relmse(img, img, 3) == 0.0, "identical images");
    /* A scaled image: rel_l2 is the scale's deviation, whatever the reference. */
    const float r2[4] = {0.5f, 4.0f, 0.0f, 2.0f}, i2[4] = {0.55f, 4.4f, 0.0f, 2.2f};
    CHECK_NEAR(metric_rel_l2(i2, r2, 4), 0.1, 1e-6, "10%% everywhere");

    /* No pixels: nothing differs. */
    CHECK(metric_rel_l2(img, ref, 0) == 0.0 && metric_relmse(img, ref, 0) == 0.0, "n = 0");
    /* An all-zero reference: 0 for a zero image, INFINITY (never NaN) otherwise; relMSE stays
     * finite through its epsilon. */
    const float zero[3] = {0, 0, 0};
    CHECK(metric_rel_l2(zero, zero, 3) == 0.0, "zero against zero: %g", metric_rel_l2(zero, zero, 3));
    double e = metric_rel_l2(img, zero, 3);
    CHECK(isinf(e) && e > 0.0, "nonzero against zero: %g", e);
    CHECK_NEAR(metric_relmse(img, zero, 3), (1.0 + 4.0 + 9.0) / METRIC_RELMSE_EPS / 3.0, 1e-9, "relmse, zero ref");
    CHECK(metric_relmse(zero, zero, 3) == 0.0, "relmse zero/zero");
}

/* Standard normal samples, deterministic (xorshift + Box-Muller). */
static uint64_t state = 88172645463325252ull;
static double uniform(void) {
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    return ((double)(state >> 11) + 0.5) / 9007199254740992.0;
}
static double gauss(void) { return sqrt(-2.0 * log(uniform())) * cos(6.283185307179586 * uniform()); }

static void test_variance(void) {
    /* By hand: first half (1 pass) 1 and 3, the mean of 2 passes 2 and 2, so the second halves
     * are 3 and 1; (a - b)^2 = 4 estimates sigma^2 (1 + 1), the mean's variance is sigma^2 / 2 = 1. */
    const float first[2] = {1, 3}, all[2] = {2, 2};
    double noise = -1.0;
    CHECK_NEAR(metric_mean_variance_halves(first, all, 2, 1, 2, &noise), 1.0, 1e-12, "two values");
    CHECK_NEAR(noise, sqrt(2.0 / 8.0), 1e-12, "relative noise: sqrt(sum var / sum mean^2)");
    CHECK(metric_mean_variance_halves(first, all, 2, 2, 2, &noise) == 0.0 && noise == 0.0, "m = total: no estimate");
    CHECK(metric_mean_variance_halves(first, all, 0, 1, 2, NULL) == 0.0, "no values");

    /* Gaussian samples of variance 4 around 10, 20000 values, 12 passes split 5 + 7: the mean of
     * 12 has variance 1/3. The estimate's own relative spread is sqrt(2/20000) = 1%. */
    enum { N = 20000, M = 5, T = 12 };
    float *a = malloc(sizeof(float) * N), *b = malloc(sizeof(float) * N);
    for (int i = 0; i < N; i++) {
        double s1 = 0.0, s2 = 0.0;
        for (int k = 0; k < M; k++) s1 += 10.0 + 2.0 * gauss();
        for (int k = M; k < T; k++) s2 += 10.0 + 2.0 * gauss();
        a[i] = (float)(s1 / M);
        b[i] = (float)((s1 + s2) / T);
    }
    double v = metric_mean_variance_halves(a, b, N, M, T, &noise);
    CHECK_NEAR(v, 4.0 / T, 0.05 * 4.0 / T, "Gaussian samples");
    CHECK_NEAR(noise, sqrt(4.0 / T) / 10.0, 0.03 * sqrt(4.0 / T) / 10.0, "relative noise of a mean of 10");
    free(a);
    free(b);
}

/* Accumulates the runs imgs[k] (n values each) as glint bench does and splits their error. */
static void split(const float *imgs, int count, const float *ref, size_t n, double ref_noise, double *noise,
                  double *bias, double *sum_err2) {
    double sum[8] = {0};
    *sum_err2 = 0.0;
    for (int k = 0; k < count; k++) *sum_err2 += metric_accumulate(sum, imgs + (size_t)k * n, ref, n);
    metric_noise_bias(*sum_err2, metric_mean_err2(sum, count, ref, n), metric_norm2(ref, n), count, ref_noise, noise,
                      bias);
}

static void test_noise_bias(void) {
    /* By hand: R = (1, 1), I_1 = (3, 2), I_2 = (3, 0). M = (3, 1): ||M - R||^2 = 4, each run's
     * ||I_k - R||^2 = 5, ||I_k - M||^2 = 1, ||R||^2 = 2. noise^2 = (1 + 1) / 1 / 2 = 1; bias^2 =
     * 4/2 - 1/2 = 1.5; the RMS of the runs' rel_l2 is sqrt(5/2) = sqrt(noise^2 + bias^2). */
    const float ref[2] = {1, 1}, imgs[4] = {3, 2, 3, 0};
    double sum[2] = {0, 0};
    CHECK_NEAR(metric_accumulate(sum, imgs, ref, 2), 5.0, 0, "||I_1 - R||^2");
    CHECK_NEAR(metric_accumulate(sum, imgs + 2, ref, 2), 5.0, 0, "||I_2 - R||^2");
    CHECK(sum[0] == 6.0 && sum[1] == 2.0, "sum image %g %g", sum[0], sum[1]);
    CHECK_NEAR(metric_mean_err2(sum, 2, ref, 2), 4.0, 1e-15, "||M - R||^2");
    CHECK_NEAR(metric_norm2(ref, 2), 2.0, 0, "||R||^2");
    double noise, bias, se;
    split(imgs, 2, ref, 2, 0.0, &noise, &bias, &se);
    CHECK_NEAR(noise, 1.0, 1e-15, "noise");
    CHECK_NEAR(bias, sqrt(1.5), 1e-15, "bias");
    CHECK_NEAR(se / 2 / 2, noise * noise + bias * bias, 1e-15, "rms^2 = noise^2 + bias^2");
    /* The reference's own noise 0.5 comes off the bias: bias^2 = 1.5 - 0.25, and rms^2 = noise^2
     * + bias^2 + ref_noise^2; a larger one than the bias clamps it at 0. */
    split(imgs, 2, ref, 2, 0.5, &noise, &bias, &se);
    CHECK_NEAR(noise, 1.0, 1e-15, "noise with a noisy reference");
    CHECK_NEAR(bias, sqrt(1.25), 1e-15, "bias less the reference's noise");
    CHECK_NEAR(se / 2 / 2, noise * noise + bias * bias + 0.25, 1e-15, "rms^2 with the reference's noise");
    split(imgs, 2, ref, 2, 2.0, &noise, &bias, &se);
    CHECK(noise == 1.0 && bias == 0.0, "bias clamped at 0: %g", bias);
    /* Swapped roles must show: all runs equal (no noise, all bias), and runs symmetric about R (all
     * noise, no bias). I = (2, 2) twice: noise 0, bias ||(1,1)|| / ||R|| = 1. */
    const float same[4] = {2, 2, 2, 2}, around[4] = {2, 1, 0, 1};
    split(same, 2, ref, 2, 0.0, &noise, &bias, &se);
    CHECK(noise == 0.0 && bias == 1.0, "equal runs: noise %g, bias %g", noise, bias);
    /* I = (2, 1), (0, 1): M = R, each ||I_k - M||^2 = 1, noise^2 = 2 / 1 / 2 = 1, bias 0. */
    split(around, 2, ref, 2, 0.0, &noise, &bias, &se);
    CHECK(noise == 1.0 && bias == 0.0, "runs about R: noise %g, bias %g", noise, bias);
    /* Three runs: R = (2), I = 1, 2, 6: M = 3, ||M - R||^2 = 1, sum ||I_k - M||^2 = 4 + 1 + 9 = 14,
     * ||R||^2 = 4: noise^2 = 14 / 2 / 4 = 1.75, bias^2 = 1/4 - 1.75/3 < 0 -> 0. */
    const float r1[1] = {2}, three[3] = {1, 2, 6};
    split(three, 3, r1, 1, 0.0, &noise, &bias, &se);
    CHECK_NEAR(noise, sqrt(1.75), 1e-15, "three runs: noise");
    CHECK(bias == 0.0, "three runs: bias %g", bias);

    /* One run: noise and bias cannot be told apart. */
    split(imgs, 1, ref, 2, 0.0, &noise, &bias, &se);
    CHECK(isnan(noise) && isnan(bias) && se == 5.0, "one run: noise %g, bias %g", noise, bias);

    /* A zero reference: zero runs are exact; equal nonzero runs are all bias (infinite relative);
     * runs symmetric about zero are all noise. */
    const float z[2] = {0, 0}, zeros[4] = {0, 0, 0, 0}, ones[4] = {1, 0, 1, 0}, pm[4] = {1, 0, -1, 0};
    split(zeros, 2, z, 2, 0.0, &noise, &bias, &se);
    CHECK(noise == 0.0 && bias == 0.0, "zero against zero: noise %g, bias %g", noise, bias);
    split(ones, 2, z, 2, 0.0, &noise, &bias, &se);
    CHECK(noise == 0.0 && isinf(bias), "equal runs against zero: noise %g, bias %g", noise, bias);
    split(pm, 2, z, 2, 0.0, &noise, &bias, &se);
    CHECK(isinf(noise) && bias == 0.0, "runs about zero: noise %g, bias %g", noise, bias);

    /* Gaussian runs of known bias and noise: 4000 values of R = 1, each run R + 0.1 + N(0, 0.2^2)
     * per value, 6 runs. Relative to ||R||: noise 0.2, bias 0.1. */
    enum { N = 4000, K = 6 };
    float *runs = malloc(sizeof(float) * N * K), *flat = malloc(sizeof(float) * N);
    double *acc = calloc(N, sizeof(double));
    double sum_err2 = 0.0;
    for (int i = 0; i < N; i++) flat[i] = 1.0f;
    for (int k = 0; k < K; k++) {
        for (int i = 0; i < N; i++) runs[k * N + i] = (float)(1.1 + 0.2 * gauss());
        sum_err2 += metric_accumulate(acc, runs + k * N, flat, N);
    }
    metric_noise_bias(sum_err2, metric_mean_err2(acc, K, flat, N), metric_norm2(flat, N), K, 0.0, &noise, &bias);
    CHECK_NEAR(noise, 0.2, 0.01, "Gaussian runs: noise");
    CHECK_NEAR(bias, 0.1, 0.01, "Gaussian runs: bias");
    free(runs);
    free(flat);
    free(acc);
}

static void test_curves(void) {
    const double t[4] = {1, 2, 4, 8};
    double e[4];
    for (int k = 0; k < 4; k++) e[k] = 0.3 / sqrt(t[k]);
    CHECK_NEAR(metric_loglog_slope(t, e, 4), -0.5, 1e-12, "1/sqrt(t)");
    const double flat[4] = {0.2, 0.2, 0.2, 0.2};
    CHECK_NEAR(metric_loglog_slope(t, flat, 4), 0.0, 1e-12, "bias only");
    CHECK(isnan(metric_loglog_slope(t, e, 1)), "one point");
    const double same_t[3] = {2, 2, 2};
    CHECK(isnan(metric_loglog_slope(same_t, e, 3)), "no spread in time");
    /* Unusable points are skipped: a zero error, an infinite one. */
    const double holes[4] = {0.3, 0.0, INFINITY, 0.3 / sqrt(8.0)};
    CHECK_NEAR(metric_loglog_slope(t, holes, 4), -0.5, 1e-12, "skipping 0 and inf");

    /* The last doubling: 4..8 of 1, 2, 4, 8; 300..600 of 2, 10, 60, 300, 600; the last step when it
     * is more than a doubling; the whole curve when it spans less than one. */
    const double budgets[5] = {2, 10, 60, 300, 600}, wide[2] = {10, 60}, narrow[3] = {1, 1.5, 2};
    CHECK(metric_last_doubling(t, 4) == 2, "1, 2, 4, 8: %d", metric_last_doubling(t, 4));
    CHECK(metric_last_doubling(budgets, 5) == 3, "up to 600 s: %d", metric_last_doubling(budgets, 5));
    CHECK(metric_last_doubling(budgets, 3) == 1, "2, 10, 60: %d", metric_last_doubling(budgets, 3));
    CHECK(metric_last_doubling(wide, 2) == 0 && metric_last_doubling(narrow, 3) == 0,
          "two points, or less than a doubling");
    CHECK(metric_last_doubling(t, 1) == 0 && metric_last_doubling(t, 0) == 0, "fewer than two points");

    /* Log-log interpolation: between (1, 1) and (4, 0.5), at 2 (halfway in log) sqrt(0.5). */
    const double x[2] = {1, 4}, y[2] = {1, 0.5};
    CHECK_NEAR(metric_loglog_at(x, y, 2, 2.0), sqrt(0.5), 1e-12, "at 2");
    CHECK_NEAR(metric_loglog_at(x, y, 2, 4.0), 0.5, 1e-12, "at the end");
    CHECK(isnan(metric_loglog_at(x, y, 2, 8.0)) && isnan(metric_loglog_at(x, y, 2, 0.5)), "outside");
    CHECK_NEAR(metric_loglog_reach(x, y, 2, sqrt(0.5)), 2.0, 1e-12, "reaching sqrt(0.5)");
    CHECK_NEAR(metric_loglog_reach(x, y, 2, 2.0), 1.0, 1e-12, "already below at the start");
    CHECK(isnan(metric_loglog_reach(x, y, 2, 0.25)), "never reached");
    CHECK(isnan(metric_loglog_reach(x, y, 2, 0.0)), "zero error is never reached");
    /* A curve that rises again: the first time it comes down counts. */
    const double xs[4] = {1, 2, 4, 8}, ys[4] = {1, 0.25, 0.5, 0.1};
    CHECK_NEAR(metric_loglog_reach(xs, ys, 4, 0.5), sqrt(2.0), 1e-12, "first crossing");
}

int main(void) {
    test_errors();
    test_variance();
    test_noise_bias();
    test_curves();
    return check_exit("test_metrics");
}
