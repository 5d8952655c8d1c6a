/* The error metrics and the error-curve numerics of glint bench, against hand-computed values:
 * relative L2 and relMSE (including no pixels and an all-zero reference), the two-halves
 * variance of a progressive mean (by hand, and on Gaussian samples of known variance), log-log
 * slopes and interpolation. */
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
    test_curves();
    return check_exit("test_metrics");
}
