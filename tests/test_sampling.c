/* Sampling routines against the densities they claim: chi-square tests over equal-solid-angle or
 * equal-probability bins, pdfs that integrate to 1, exactness for tiny cones and sharp lobes. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "check.h"
#include "rng.h"
#include "sampling.h"
#include "stat_tests.h"

#define PI_D 3.14159265358979323846
#define SAMPLES 200000L
#define NUM_CHI2_TESTS 25

static double significance;

static void check_chi2(chi2_result r, const char *what) {
    CHECK(r.non_finite == 0, "%s: %d non-finite or non-unit samples", what, r.non_finite);
    CHECK(r.outside_support == 0, "%s: %d samples where the pdf is 0", what, r.outside_support);
    CHECK(r.p_value > significance, "%s: chi2 = %.1f, dof %d, p = %.3g < %.3g", what, r.chi2, r.dof, r.p_value,
          significance);
}

/* ---- the test machinery itself ---------------------------------------------------------------- */

static void test_chi2_machinery(void) {
    /* Tabulated 95% quantiles. */
    CHECK_NEAR(chi2_upper_tail(3.841459, 1), 0.05, 1e-6, "dof 1");
    CHECK_NEAR(chi2_upper_tail(18.307038, 10), 0.05, 1e-6, "dof 10");
    CHECK_NEAR(chi2_upper_tail(124.342113, 100), 0.05, 1e-6, "dof 100");
    CHECK_NEAR(chi2_upper_tail(0.0, 5), 1.0, 1e-12, "x = 0");
    CHECK(chi2_upper_tail(1e4, 10) < 1e-100, "far tail");
}

/* ---- direction samplers --------------------------------------------------------------------- */

typedef struct {
    int kind; /* 0 cosine, 1 sphere, 2 cone, 3 power cosine */
    float param;
} dir_ctx;

static int dir_sample(void *c, float u_lobe, vec2 u, vec3 *w) {
    (void)u_lobe;
    const dir_ctx *d = c;
    switch (d->kind) {
    case 0: *w = sample_cosine_hemisphere(u); break;
    case 1: *w = sample_uniform_sphere(u); break;
    case 2: *w = sample_uniform_cone(u, d->param); break;
    default: *w = sample_power_cosine(u, d->param); break;
    }
    return 1;
}

static double dir_pdf(void *c, vec3 w) {
    const dir_ctx *d = c;
    switch (d->kind) {
    case 0: return pdf_cosine_hemisphere(w);
    case 1: return pdf_uniform_sphere();
    case 2: return (1.0 - w.z) <= d->param ? pdf_uniform_cone(d->param) : 0.0;
    default: return w.z > 0.0f ? pdf_power_cosine(1.0f - w.z, d->param) : 0.0;
    }
}

/* A sampler that lies about its pdf: cosine-distributed, claiming uniform over the hemisphere. */
static double wrong_pdf(void *c, vec3 w) {
    (void)c;
    return w.z > 0.0f ? 1.0 / (2.0 * PI_D) : 0.0;
}

static void test_directions(void) {
    char what[96];
    struct {
        int kind;
        float param;
    } cases[] = {{0, 0}, {1, 0}, {2, 0.3f}, {2, 1.0f}, {2, 2.0f}, {3, 0.0f}, {3, 1.0f}, {3, 20.0f}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        dir_ctx c = {cases[i].kind, cases[i].param};
        chi2_result r = chi2_directions(dir_sample, dir_pdf, &c, v3(0, 0, 1), 32, 64, SAMPLES, 100 + i);
        snprintf(what, sizeof what, "direction sampler %d (%g)", c.kind, (double)c.param);
        check_chi2(r, what);
        CHECK_NEAR(r.pdf_integral, 1.0, 0.01, "%s: pdf integral", what);
    }
    /* The machinery catches a wrong pdf. */
    dir_ctx cos_ctx = {0, 0};
    chi2_result bad = chi2_directions(dir_sample, wrong_pdf, &cos_ctx, v3(0, 0, 1), 32, 64, SAMPLES, 9);
    CHECK(bad.p_value < 1e-6, "a cosine sampler passed as uniform: p = %.3g", bad.p_value);
}

/* 1D chi-square on equal-probability bins of a scalar statistic t in [0,1) that should be uniform. */
static chi2_result uniform_bins(const double *t, long n, int bins) {
    double *o = calloc((size_t)bins, sizeof(double)), *e = malloc(sizeof(double) * (size_t)bins);
    for (int b = 0; b < bins; b++) e[b] = (double)n / bins;
    for (long k = 0; k < n; k++) {
        int b = (int)(t[k] * bins);
        o[b < 0 ? 0 : (b >= bins ? bins - 1 : b)] += 1.0;
    }
    chi2_result r = chi2_counts(o, e, bins);
    free(o);
    free(e);
    return r;
}

/* Sharp power-cosine lobes and tiny cones are too narrow for a sphere grid: test the radial CDF
 * instead. For the lobe P(z <= c) = c^(n+1); for the cone 1 - cos is uniform on [0, 1 - cos max]. */
static void test_sharp(void) {
    char what[96];
    const long n = 100000;
    double *t = malloc(sizeof(double) * (size_t)n);
    float exps[] = {1e2f, 1e4f, 1e6f};
    for (int e = 0; e < 3; e++) {
        rng_state rng = rng_make(77, (uint64_t)e);
        int bad = 0;
        for (long k = 0; k < n; k++) {
            vec3 w = sample_power_cosine(rng_vec2(&rng), exps[e]);
            bad += !is_finite3(w) || w.z <= 0.0f;
            /* 1 - z from the chord for precision, then the CDF in logs: z^(n+1). */
            double s2 = (double)w.x * w.x + (double)w.y * w.y;
            double omz = s2 / (1.0 + sqrt(fmax(0.0, 1.0 - s2)));
            t[k] = exp(((double)exps[e] + 1.0) * log1p(-omz));
        }
        snprintf(what, sizeof what, "power cosine n = %g", (double)exps[e]);
        CHECK(bad == 0, "%s: %d bad samples", what, bad);
        check_chi2(uniform_bins(t, n, 50), what);
        /* The pdf integrates to 1: over theta with a grid fine enough for the lobe. */
        double tmax = fmin(PI_D / 2, 12.0 / sqrt((double)exps[e])), sum = 0.0;
        int steps = 20000;
        for (int i = 0; i < steps; i++) {
            double th = tmax * (i + 0.5) / steps;
            sum += pdf_power_cosine((float)(2.0 * sin(0.5 * th) * sin(0.5 * th)), exps[e]) * sin(th);
        }
        CHECK_NEAR(sum * 2.0 * PI_D * tmax / steps, 1.0, 2e-3, "%s: pdf integral", what);
    }
    float omcs[] = {1e-7f, 1e-4f};
    for (int c = 0; c < 2; c++) {
        rng_state rng = rng_make(78, (uint64_t)c);
        int outside = 0;
        for (long k = 0; k < n; k++) {
            vec3 w = sample_uniform_cone(rng_vec2(&rng), omcs[c]);
            double s2 = (double)w.x * w.x + (double)w.y * w.y;
            double omz = s2 / (1.0 + sqrt(fmax(0.0, 1.0 - s2)));
            outside += !(w.z > 0.0f) || omz > omcs[c] * 1.001;
            t[k] = omz / omcs[c];
        }
        snprintf(what, sizeof what, "cone 1 - cos = %g", (double)omcs[c]);
        CHECK(outside == 0, "%s: %d samples outside", what, outside);
        check_chi2(uniform_bins(t, n, 50), what);
        CHECK_NEAR(pdf_uniform_cone(omcs[c]) * 2.0 * PI_D * omcs[c], 1.0, 1e-5, "%s: pdf x solid angle", what);
    }
    free(t);
}

static void test_cone_one_minus_cos(void) {
    double s[] = {1e-6, 1e-3, 0.1, 0.5, 0.9, 0.999};
    for (int i = 0; i < 6; i++) {
        double want = 1.0 - sqrt(1.0 - s[i] * s[i]); /* double: exact enough for the comparison */
        if (s[i] < 1e-3) want = 0.5 * s[i] * s[i] + 0.125 * pow(s[i], 4);
        double got = cone_one_minus_cos((float)s[i]);
        CHECK(fabs(got - want) <= 1e-5 * want, "s = %g: %.9g, want %.9g", s[i], got, want);
    }
    CHECK(cone_one_minus_cos(1.0f) == 1.0f && cone_one_minus_cos(3.0f) == 1.0f, "inside the sphere: a hemisphere");
}

/* ---- points --------------------------------------------------------------------------------- */

static void test_triangle(void) {
    /* 8 x 8 subdivision into 64 congruent sub-triangles: each should get 1/64 of the samples. */
    const int m = 8;
    double o[64] = {0}, e[64];
    for (int i = 0; i < 64; i++) e[i] = (double)SAMPLES / 64;
    rng_state rng = rng_make(5, 5);
    int outside = 0;
    for (long k = 0; k < SAMPLES; k++) {
        vec2 b = sample_uniform_triangle(rng_vec2(&rng));
        if (!(b.x >= 0.0f && b.y >= 0.0f && b.x + b.y <= 1.0f)) {
            outside++;
            continue;
        }
        double x = b.x * m, y = b.y * m;
        int i = (int)x, j = (int)y;
        if (i >= m) i = m - 1;
        if (j >= m) j = m - 1;
        if (i + j >= m) i = m - 1 - j; /* rounding onto the hypotenuse */
        int upper = (x - i) + (y - j) > 1.0;
        /* Row j holds 2 (m - j) - 1 triangles; index them in order. */
        int index = 0;
        for (int r = 0; r < j; r++) index += 2 * (m - r) - 1;
        index += 2 * i + upper;
        o[index < 64 ? index : 63] += 1.0;
    }
    CHECK(outside == 0, "triangle: %d samples outside", outside);
    check_chi2(chi2_counts(o, e, 64), "triangle");
}

static void test_disk(void) {
    const int nr = 16, np = 32;
    double *o = calloc((size_t)(nr * np), sizeof(double)), *e = malloc(sizeof(double) * (size_t)(nr * np));
    for (int i = 0; i < nr * np; i++) e[i] = (double)SAMPLES / (nr * np);
    rng_state rng = rng_make(6, 6);
    int outside = 0;
    for (long k = 0; k < SAMPLES; k++) {
        vec2 p = sample_concentric_disk(rng_vec2(&rng));
        double r2 = (double)p.x * p.x + (double)p.y * p.y;
        if (!(r2 <= 1.0 + 1e-6)) {
            outside++;
            continue;
        }
        double phi = atan2(p.y, p.x);
        if (phi < 0) phi += 2 * PI_D;
        int i = (int)(r2 * nr), j = (int)(phi / (2 * PI_D) * np);
        i = i >= nr ? nr - 1 : i;
        j = j >= np ? np - 1 : j;
        o[i * np + j] += 1.0;
    }
    CHECK(outside == 0, "disk: %d samples outside", outside);
    check_chi2(chi2_counts(o, e, nr * np), "concentric disk");
    free(o);
    free(e);
}

/* ---- tabulated distributions ------------------------------------------------------------------ */

static void test_dist1d(void) {
    float func[10] = {1.0f, 0.0f, 3.0f, NAN, 0.5f, -2.0f, INFINITY, 7.0f, 0.25f, 2.0f};
    /* Non-finite and negative entries count as 0. */
    double valid[10] = {1, 0, 3, 0, 0.5, 0, 0, 7, 0.25, 2}, total = 13.75;
    dist1d d;
    CHECK(dist1d_init(&d, func, 10) == 0, "init");
    double pmf_sum = 0.0;
    for (int i = 0; i < 10; i++) {
        pmf_sum += dist1d_pmf(&d, i);
        CHECK_NEAR(dist1d_pmf(&d, i), valid[i] / total, 1e-6, "pmf %d", i);
    }
    CHECK_NEAR(pmf_sum, 1.0, 1e-6, "pmf sums to 1");
    double o[10] = {0}, e[10], ou[20] = {0}, eu[20], oc[40] = {0}, ec[40];
    for (int i = 0; i < 10; i++) e[i] = SAMPLES * valid[i] / total;
    for (int i = 0; i < 20; i++) eu[i] = SAMPLES / 20.0;
    for (int i = 0; i < 40; i++) ec[i] = SAMPLES * valid[i / 4] / total / 4.0;
    rng_state rng = rng_make(8, 8);
    int pmf_mismatch = 0, pdf_mismatch = 0;
    for (long k = 0; k < SAMPLES; k++) {
        float pmf, ur;
        int i = dist1d_sample_discrete(&d, rng_float(&rng), &pmf, &ur);
        o[i] += 1.0;
        pmf_mismatch += fabsf(pmf - dist1d_pmf(&d, i)) > 1e-6f;
        int b = (int)(ur * 20.0f);
        ou[b < 0 ? 0 : (b > 19 ? 19 : b)] += 1.0; /* the remapped u is uniform again */
        float pdf;
        float x = dist1d_sample_continuous(&d, rng_float(&rng), &pdf, NULL);
        int c = (int)(x * 40.0f);
        oc[c < 0 ? 0 : (c > 39 ? 39 : c)] += 1.0;
        pdf_mismatch += fabsf(pdf - dist1d_pdf(&d, x)) > 1e-4f * pdf;
    }
    check_chi2(chi2_counts(o, e, 10), "dist1d discrete");
    check_chi2(chi2_counts(ou, eu, 20), "dist1d remapped u");
    check_chi2(chi2_counts(oc, ec, 40), "dist1d continuous");
    CHECK(pmf_mismatch == 0 && pdf_mismatch == 0, "returned pmf/pdf differ from the queries: %d, %d", pmf_mismatch,
          pdf_mismatch);
    double integral = 0.0;
    for (int i = 0; i < 10000; i++) integral += dist1d_pdf(&d, (i + 0.5f) / 10000.0f) / 10000.0;
    CHECK_NEAR(integral, 1.0, 1e-4, "dist1d pdf integrates to 1");
    dist1d_deinit(&d);

    /* All zero: uniform, never a division by zero. */
    float zeros[4] = {0, 0, 0, 0};
    CHECK(dist1d_init(&d, zeros, 4) == 0, "init zeros");
    for (int i = 0; i < 4; i++) CHECK_NEAR(dist1d_pmf(&d, i), 0.25, 1e-6, "uniform fallback %d", i);
    float pdf;
    float x = dist1d_sample_continuous(&d, 0.7f, &pdf, NULL);
    CHECK(isfinite(x) && fabsf(pdf - 1.0f) < 1e-5f, "uniform fallback pdf %g", (double)pdf);
    dist1d_deinit(&d);
}

/* The alias table draws each bin with its probability, whatever the weights' spread. */
static void test_alias(void) {
    float func[10] = {1.0f, 0.0f, 3.0f, NAN, 0.5f, -2.0f, INFINITY, 7.0f, 0.25f, 2.0f};
    double valid[10] = {1, 0, 3, 0, 0.5, 0, 0, 7, 0.25, 2}, total = 13.75;
    alias_table a;
    CHECK(alias_init(&a, func, 10) == 0, "init");
    double o[10] = {0}, e[10];
    for (int i = 0; i < 10; i++) {
        CHECK_NEAR(a.pmf[i], valid[i] / total, 1e-6, "alias pmf %d", i);
        e[i] = SAMPLES * valid[i] / total;
    }
    rng_state rng = rng_make(9, 9);
    int mismatch = 0;
    for (long k = 0; k < SAMPLES; k++) {
        float pmf;
        int i = alias_sample(&a, rng_float(&rng), &pmf);
        o[i] += 1.0;
        mismatch += pmf != a.pmf[i];
    }
    check_chi2(chi2_counts(o, e, 10), "alias table");
    CHECK(mismatch == 0, "the returned pmf differs from the table's %d times", mismatch);
    alias_deinit(&a);
    /* Weights over twelve orders of magnitude, and all zero (uniform). */
    float wide[64];
    double wtotal = 0.0, ow[64] = {0}, ew[64];
    for (int i = 0; i < 64; i++) wtotal += wide[i] = powf(10.0f, (float)(i % 13) - 6.0f);
    CHECK(alias_init(&a, wide, 64) == 0, "init wide");
    for (long k = 0; k < SAMPLES; k++) ow[alias_sample(&a, rng_float(&rng), NULL)] += 1.0;
    for (int i = 0; i < 64; i++) ew[i] = SAMPLES * wide[i] / wtotal;
    check_chi2(chi2_counts(ow, ew, 64), "alias table, wide weights");
    alias_deinit(&a);
    float zeros[4] = {0, 0, 0, 0};
    CHECK(alias_init(&a, zeros, 4) == 0, "init zeros");
    for (int i = 0; i < 4; i++) CHECK_NEAR(a.pmf[i], 0.25, 1e-7, "uniform fallback %d", i);
    CHECK(alias_sample(&a, 0x1.fffffep-1f, NULL) < 4, "u just below 1 stays in range");
    alias_deinit(&a);
}

static void test_dist2d(void) {
    enum { NU = 8, NV = 6 };
    float func[NU * NV];
    double total = 0.0;
    for (int v = 0; v < NV; v++)
        for (int u = 0; u < NU; u++) {
            func[v * NU + u] = (u == 3) ? 0.0f : (float)(1 + (u * 7 + v * 3) % 5) * (v == 2 ? 10.0f : 1.0f);
            total += func[v * NU + u];
        }
    dist2d d;
    CHECK(dist2d_init(&d, func, NU, NV) == 0, "init");
    double o[NU * NV] = {0}, e[NU * NV];
    for (int i = 0; i < NU * NV; i++) e[i] = SAMPLES * func[i] / total;
    rng_state rng = rng_make(9, 9);
    int mismatch = 0;
    for (long k = 0; k < SAMPLES; k++) {
        float pdf;
        vec2 p = dist2d_sample(&d, rng_vec2(&rng), &pdf);
        int u = (int)(p.x * NU), v = (int)(p.y * NV);
        u = u >= NU ? NU - 1 : u;
        v = v >= NV ? NV - 1 : v;
        o[v * NU + u] += 1.0;
        mismatch += fabsf(pdf - dist2d_pdf(&d, p)) > 1e-4f * pdf;
        /* The density of a cell is its value over the mean. */
        mismatch += fabs(pdf - func[v * NU + u] / (total / (NU * NV))) > 1e-3 * pdf;
    }
    check_chi2(chi2_counts(o, e, NU * NV), "dist2d");
    CHECK(mismatch == 0, "dist2d: %d pdf mismatches", mismatch);
    dist2d_deinit(&d);
}

/* Russian roulette keeps a weight's expectation: over u on a fine grid, the survivors' weights
 * average to the weight, and the share that survives is min(0.95, largest component). */
static void test_russian_roulette(void) {
    const vec3 ws[3] = {v3(0.3f, 0.2f, 0.1f), v3(0.01f, 0.0f, 0.004f), v3(2.0f, 0.5f, 0.0f)};
    for (int k = 0; k < 3; k++) {
        const int n = 100000;
        double sum[3] = {0, 0, 0};
        int survived = 0;
        for (int i = 0; i < n; i++) {
            vec3 w = ws[k];
            if (!russian_roulette(&w, ((float)i + 0.5f) / (float)n)) continue;
            survived++;
            sum[0] += w.x, sum[1] += w.y, sum[2] += w.z;
        }
        CHECK(fabs(sum[0] / n - ws[k].x) < 1e-3 * ws[k].x + 1e-7 &&
                  fabs(sum[1] / n - ws[k].y) < 1e-3 * ws[k].y + 1e-7 &&
                  fabs(sum[2] / n - ws[k].z) < 1e-3 * ws[k].z + 1e-7,
              "roulette: weight %d's mean (%g %g %g) against (%g %g %g)", k, sum[0] / n, sum[1] / n, sum[2] / n,
              (double)ws[k].x, (double)ws[k].y, (double)ws[k].z);
        double q = fmin(0.95, max_comp3(ws[k]));
        CHECK(fabs((double)survived / n - q) < 2.0 / n, "roulette: weight %d survives %d of %d, expected %g", k,
              survived, n, q);
    }
}

static void test_mis(void) {
    float pdfs[] = {0.0f, 1e-30f, 0.5f, 1.0f, 3.0f, 1e20f, 3e38f};
    int bad = 0;
    for (int i = 0; i < 7; i++)
        for (int j = 0; j < 7; j++) {
            float a = pdfs[i], b = pdfs[j];
            float wb = mis_balance(a, b) + mis_balance(b, a), wp = mis_power(a, b) + mis_power(b, a);
            if (a == 0.0f && b == 0.0f) {
                bad += wb != 0.0f || wp != 0.0f;
                continue;
            }
            bad += !(fabsf(wb - 1.0f) < 1e-5f) || !(fabsf(wp - 1.0f) < 1e-5f);
        }
    CHECK(bad == 0, "MIS weights: %d pairs do not sum to 1 (or are not finite)", bad);
}

/* gmath.h's inline fmaxf and fminf keep C's meaning (C11 F.10.9.2): of a NaN and a number, the
 * number; of two NaNs, a NaN; infinities ordered. */
static void test_fmax_fmin(void) {
    const float v[] = {NAN, -INFINITY, -3.5f, -0.0f, 0.0f, 1e-38f, 2.0f, INFINITY};
    int n = (int)(sizeof v / sizeof v[0]), bad = 0;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            float a = v[i], b = v[j], mx = gm_fmaxf(a, b), mn = gm_fminf(a, b);
            float ex = isnan(a) ? b : isnan(b) ? a : a > b ? a : b, en = isnan(a) ? b : isnan(b) ? a : a < b ? a : b;
            /* Signed zeros compare equal; C lets either come back. */
            bad += !(mx == ex || (isnan(mx) && isnan(ex))) || !(mn == en || (isnan(mn) && isnan(en)));
        }
    CHECK(bad == 0, "gm_fmaxf / gm_fminf: %d of %d pairs differ from C's fmaxf / fminf", bad, n * n);
}

/* ---- a pixel's run over frames ---------------------------------------------------------------- */

/* Every block of 2^m points starting at a multiple of 2^m is a net, whatever the scramble: each
 * elementary box of area 2^-m (2^a by 2^(m-a) cells) holds exactly one point. */
static void test_qmc_run_nets(void) {
    rng_state rng = rng_for(11, 0, 0);
    for (int trial = 0; trial < 20; trial++) {
        enum { M = 6, N = 1 << M };
        qmc_run run = {(uint32_t)N * (rng_next_u32(&rng) >> 12), rng_next_u32(&rng), rng_next_u32(&rng)};
        for (int a = 0; a <= M; a++) {
            int count[N] = {0}, nx = 1 << a, ny = N >> a;
            for (uint32_t k = 0; k < N; k++) {
                vec2 u = qmc_run_point(run, k);
                CHECK(u.x >= 0.0f && u.x < 1.0f && u.y >= 0.0f && u.y < 1.0f, "point outside [0,1)^2");
                count[(int)(u.y * (float)ny) * nx + (int)(u.x * (float)nx)]++;
            }
            int bad = 0;
            for (int c = 0; c < N; c++) bad += count[c] != 1;
            CHECK(bad == 0, "trial %d: %d of the %d x %d boxes do not hold exactly one point", trial, bad, nx, ny);
        }
    }
}

/* Over scrambles, any one point of a run is uniform (chi-square over 16 x 16 cells). */
static void test_qmc_run_uniform(void) {
    enum { CELLS = 16 };
    static double counts[CELLS * CELLS];
    rng_state rng = rng_for(12, 0, 0);
    for (long i = 0; i < SAMPLES; i++) {
        qmc_run run = {1234567u, rng_next_u32(&rng), rng_next_u32(&rng)};
        vec2 u = qmc_run_point(run, 5);
        counts[(int)(u.y * CELLS) * CELLS + (int)(u.x * CELLS)] += 1.0;
    }
    double chi2 = 0.0, expect = (double)SAMPLES / (CELLS * CELLS);
    for (int c = 0; c < CELLS * CELLS; c++) chi2 += (counts[c] - expect) * (counts[c] - expect) / expect;
    double p = chi2_upper_tail(chi2, CELLS * CELLS - 1);
    CHECK(p > significance, "one point over scrambles: chi2 = %.1f, p = %.3g", chi2, p);
}

/* A pixel's positions follow R2 over frames and its directions its run, both indexed by the frame:
 * together they must still fill [0,1)^4, or the pixel converges to an average over a slice of its
 * domain. The share of frames whose four coordinates fall in one of the 16 half-space boxes must tend
 * to 1/16 for every scramble and shift (two R2 runs give 0 to 1/4: each direction a shifted
 * position). */
static void test_qmc_run_independent_of_positions(void) {
    rng_state rng = rng_for(13, 0, 0);
    double worst = 0.0;
    for (int trial = 0; trial < 16; trial++) {
        vec2 shift = rng_vec2(&rng);
        qmc_run run = {0, rng_next_u32(&rng), rng_next_u32(&rng)};
        enum { FRAMES = 1 << 14 };
        int both = 0;
        for (int f = 0; f < FRAMES; f++) {
            vec2 pos = sample_r2(f, shift), dir = qmc_run_point(run, (uint32_t)f);
            both += pos.x < 0.5f && dir.x < 0.5f && pos.y < 0.5f && dir.y >= 0.5f;
        }
        worst = fmax(worst, fabs((double)both / FRAMES - 1.0 / 16.0));
    }
    printf("positions and directions over 16384 frames: largest error of a 1/16 share %.5f\n", worst);
    CHECK(worst < 0.004, "positions and directions over frames are tied: a share of 1/16 off by %.4f", worst);
}

/* Several paths a frame (--method auto's path-traced tiles): path j of a frame takes direction
 * t + j of a Sobol run and, for j > 0, position t + j - 1 of a run of positions (qmc_run_r2), t
 * growing by the paths a frame. Within a frame the paths' directions are stratified (slot j's lie
 * in one quarter); the positions paired with each quarter of the directions must cover the pixel,
 * a quarter of them in each quarter of it. Positions from a second Sobol run fail it: slot j's low
 * index bits fix the top bits of both, and each quarter of directions meets one of the pixel. */
static double worst_pairing_share(int sobol_positions) {
    enum { PATHS = 4, FRAMES = 1 << 12 };
    rng_state rng = rng_for(17, 0, 0);
    double worst = 0.0;
    for (int trial = 0; trial < 8; trial++) {
        qmc_run dirs = {0, rng_next_u32(&rng), rng_next_u32(&rng)};
        qmc_run points = {0, rng_next_u32(&rng), rng_next_u32(&rng)};
        int cells[4][4] = {{0}}, column[4] = {0};
        for (uint32_t t = 0; t < PATHS * FRAMES; t += PATHS)
            for (uint32_t j = 1; j < PATHS; j++) {
                vec2 dir = qmc_run_point(dirs, t + j);
                vec2 pos = sobol_positions ? qmc_run_point(points, t + j - 1) : qmc_run_r2(points, t + j - 1);
                int b = (int)(4.0f * dir.x);
                cells[(int)(4.0f * pos.x)][b]++, column[b]++;
            }
        for (int b = 0; b < 4; b++) /* slot 0's quarter of directions has no position here */
            for (int a = 0; a < 4 && column[b]; a++) worst = fmax(worst, fabs((double)cells[a][b] / column[b] - 0.25));
    }
    return worst;
}

static void test_qmc_runs_of_several_paths(void) {
    double worst = worst_pairing_share(0), tied = worst_pairing_share(1);
    printf("4 paths a frame over 4096 frames: largest error of a quarter's share %.5f (Sobol positions %.5f)\n", worst,
           tied);
    CHECK(worst < 0.01, "a path's position is tied to its direction: a share of 1/4 off by %.4f", worst);
    CHECK(tied > 0.5, "the check cannot see two Sobol runs' tie (off by only %.4f)", tied);
}

int main(void) {
    test_fmax_fmin();
    significance = chi2_significance(0.01, NUM_CHI2_TESTS);
    test_chi2_machinery();
    test_russian_roulette();
    test_directions();
    test_sharp();
    test_cone_one_minus_cos();
    test_triangle();
    test_disk();
    test_dist1d();
    test_alias();
    test_dist2d();
    test_mis();
    test_qmc_run_nets();
    test_qmc_run_uniform();
    test_qmc_run_independent_of_positions();
    test_qmc_runs_of_several_paths();
    return check_exit("test_sampling");
}
