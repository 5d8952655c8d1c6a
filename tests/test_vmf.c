/* The vMF toolkit against references that do not come from vmf.c: the normalisation and mean
 * resultant length in long double from their textbook formulas (sinh, coth), the density's
 * integral by quadrature, sampled directions against the density's moments and cdf, products
 * checked pointwise, lobe fits against the BSDF's own sampled lobes, and EM on mixtures with
 * known components. Concentrations from 0 to 1e6, including either side of where sinh overflows. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "check.h"
#include "rng.h"
#include "vmf.h"

#define M_PI 3.14159265358979323846

static const double kappas[] = {0.0, 1e-6, 1e-3, 1.0, 10.0, 700.0, 800.0, 1e4, 1e6};
enum { NK = sizeof kappas / sizeof kappas[0] };

/* c(kappa) e^{kappa (cos - 1)} in long double: sinh directly while it fits, and the identity
 * c e^kappa = kappa / (2 pi (1 - e^{-2 kappa})) beyond (e^{-2 kappa} is 0 there). */
static long double ref_density(long double k, long double one_minus_cos) {
    const long double pi = 3.141592653589793238462643383279L;
    if (k == 0.0L) return 1.0L / (4.0L * pi);
    if (k < 5000.0L) return k / (4.0L * pi * sinhl(k)) * expl(k * (1.0L - one_minus_cos));
    return k / (2.0L * pi) * expl(-k * one_minus_cos);
}

static long double ref_rbar(long double k) {
    if (k == 0.0L) return 0.0L;
    if (k < 1e-2L) return k / 3.0L - k * k * k / 45.0L + 2.0L * k * k * k * k * k / 945.0L;
    return (1.0L + expl(-2.0L * k)) / (-expm1l(-2.0L * k)) - 1.0L / k; /* coth k - 1/k */
}

static int close_rel(double got, long double want, double tol) {
    return fabsl((long double)got - want) <= tol * fabsl(want) + 1e-300L;
}

static void test_density_and_rbar(void) {
    const double omcs[] = {0.0, 1e-9, 1e-7, 1e-3, 0.5, 1.0, 2.0};
    for (int a = 0; a < NK; a++) {
        double k = kappas[a];
        for (size_t b = 0; b < sizeof omcs / sizeof omcs[0]; b++) {
            long double want = ref_density(k, omcs[b]);
            double got = vmf_eval_cos(k, 1.0 - omcs[b]);
            /* cos = 1 - omc is rounded in double first: that limits kappa * omc's precision */
            double tol = 1e-12 + k * 1e-16 * 4.0;
            CHECK(isfinite(got) && close_rel(got, want, tol), "density kappa %g, 1-cos %g: %.17g, expected %.17Lg", k,
                  omcs[b], got, want);
        }
        /* vmf_eval takes directions: a tiny angle keeps its precision through |mu - s|^2 / 2. */
        double theta = 1e-5;
        vmf v = {v3(0, 0, 1), (float)k};
        vec3 s = v3((float)sin(theta), 0.0f, (float)cos(theta));
        long double omc = 1.0L - cosl((long double)theta);
        CHECK(close_rel(vmf_eval(v, s), ref_density((float)k, omc), 1e-5), "vmf_eval near the peak, kappa %g", k);
        long double r = ref_rbar(k);
        CHECK(close_rel(vmf_rbar_from_kappa(k), r, 1e-12), "rbar(%g) = %.17g, expected %.17Lg", k,
              vmf_rbar_from_kappa(k), r);
        CHECK(isfinite(vmf_log_norm(k)), "log c(%g) not finite", k);
    }
    /* The density integrates to one: quadrature in 1 - cos, refined toward the peak. */
    for (int a = 0; a < NK; a++) {
        double k = kappas[a], integral = 0.0;
        double width = k > 1.0 ? 40.0 / k : 2.0; /* e^{-40} beyond */
        if (width > 2.0) width = 2.0;
        int steps = 200000;
        for (int i = 0; i < steps; i++) {
            double t = (i + 0.5) / steps * width;
            integral += 2.0 * M_PI * vmf_eval_cos(k, 1.0 - t) * (width / steps); /* d omega = 2 pi d(1 - cos) */
        }
        CHECK(fabs(integral - 1.0) < 1e-6, "kappa %g: the density integrates to %.9f", k, integral);
    }
}

static void test_kappa_from_rbar(void) {
    for (int a = 0; a < NK; a++) {
        double k = kappas[a], r = vmf_rbar_from_kappa(k);
        double back = vmf_kappa_from_rbar(r);
        CHECK(fabs(back - k) <= 1e-6 * k + 1e-12, "kappa %g -> rbar %.17g -> kappa %.17g", k, r, back);
        /* Banerjee's estimate is close over the whole range, exact in both limits. */
        double est = vmf_kappa_estimate(r);
        CHECK(fabs(est - k) <= 0.05 * k + 1e-12, "estimate for kappa %g: %g", k, est);
    }
    CHECK(vmf_kappa_from_rbar(0.0) == 0.0 && vmf_kappa_estimate(0.0) == 0.0, "rbar 0 is uniform");
    CHECK(vmf_kappa_from_rbar(-0.5) == 0.0, "negative rbar");
    CHECK(vmf_kappa_from_rbar(1.0) == VMF_MAX_KAPPA && vmf_kappa_estimate(1.0) == VMF_MAX_KAPPA, "rbar 1 is the cap");
    double near1 = vmf_kappa_from_rbar(1.0 - 1e-9);
    CHECK(near1 == VMF_MAX_KAPPA, "rbar 1 - 1e-9 (kappa 1e9) is capped: %g", near1);
    CHECK(fabs(vmf_kappa_from_rbar(1.0 - 1e-5) - 1e5) < 1.0, "rbar 1 - 1e-5: %g", vmf_kappa_from_rbar(1.0 - 1e-5));
    CHECK(!isnan(vmf_kappa_from_rbar(NAN)) && vmf_kappa_from_rbar(NAN) == 0.0, "NaN rbar gives 0");
}

/* Sampled directions: unit, finite, their mean cosine is rbar(kappa), and the cdf of cos theta at
 * its quartiles matches (binomial bounds, 5 sigma). */
static void test_sampling(void) {
    rng_state rng = rng_make(5, 9);
    vec3 axis = normalize3(v3(0.3f, -0.5f, 0.8f));
    for (int a = 0; a < NK; a++) {
        double k = kappas[a];
        vmf v = {axis, (float)k};
        const int n = 200000;
        double sum = 0.0, sum2 = 0.0;
        int bad = 0, below[3] = {0, 0, 0};
        /* quartiles of 1 - cos: F(t) = (1 - e^{-k t}) / (1 - e^{-2k}) */
        double q[3];
        for (int j = 0; j < 3; j++) {
            double p = 0.25 * (j + 1);
            q[j] = k < 1e-8 ? 2.0 * p : -log1p(p * expm1(-2.0 * k)) / k;
        }
        for (int i = 0; i < n; i++) {
            vec3 s = vmf_sample(v, rng_vec2(&rng));
            if (!is_finite3(s) || fabsf(length3(s) - 1.0f) > 1e-5f) bad++;
            double dx = (double)s.x - axis.x, dy = (double)s.y - axis.y, dz = (double)s.z - axis.z;
            double omc = 0.5 * (dx * dx + dy * dy + dz * dz);
            sum += 1.0 - omc;
            sum2 += (1.0 - omc) * (1.0 - omc);
            for (int j = 0; j < 3; j++) below[j] += omc < q[j];
        }
        CHECK(bad == 0, "kappa %g: %d samples not unit or not finite", k, bad);
        double mean = sum / n, var = sum2 / n - mean * mean, sem = sqrt(var > 0 ? var / n : 0) + 1e-7;
        CHECK(fabs(mean - vmf_rbar_from_kappa(k)) < 5.0 * sem, "kappa %g: mean cosine %.6f, rbar %.6f (sem %.2g)", k,
              mean, vmf_rbar_from_kappa(k), sem);
        if (k <= 1e4) /* float directions resolve angles down to ~1e-4 rad: enough below kappa 1e4 */
            for (int j = 0; j < 3; j++) {
                double p = 0.25 * (j + 1), frac = (double)below[j] / n, sd = sqrt(p * (1 - p) / n);
                CHECK(fabs(frac - p) < 5.0 * sd, "kappa %g: %.4f of samples below the %g quantile", k, frac, p);
            }
    }
}

static void test_product_and_convolution(void) {
    rng_state rng = rng_make(6, 9);
    const double ks[][2] = {{0.0, 5.0}, {1.0, 1.0}, {50.0, 200.0}, {800.0, 900.0}, {1e5, 1e6}};
    for (size_t c = 0; c < sizeof ks / sizeof ks[0]; c++) {
        vmf a = {normalize3(v3(0.2f, 0.1f, 1.0f)), (float)ks[c][0]};
        vmf b = {normalize3(v3(0.21f, 0.1f, 1.0f)), (float)ks[c][1]};
        double scale;
        vmf p = vmf_product(a, b, &scale);
        CHECK(isfinite(scale) && scale >= 0.0, "product %zu: scale %g", c, scale);
        /* Pointwise, at directions near the product's peak (elsewhere both sides underflow). */
        for (int t = 0; t < 20; t++) {
            vec3 s = vmf_sample(p, rng_vec2(&rng));
            double lhs = vmf_eval(a, s) * vmf_eval(b, s), rhs = scale * vmf_eval(p, s);
            CHECK(fabs(lhs - rhs) <= 1e-3 * fabs(lhs) + 1e-300, "product %zu: a b = %.9g, scale * p = %.9g", c, lhs,
                  rhs);
        }
    }
    vmf a = {v3(0, 0, 1), 10.0f}, b = {v3(0, 0, -1), 10.0f};
    double scale;
    vmf p = vmf_product(a, b, &scale);
    CHECK(p.kappa == 0.0f &&
              fabs(scale - vmf_eval(a, v3(1, 0, 0)) * vmf_eval(b, v3(1, 0, 0)) * 4.0 * M_PI) < 1e-9 * scale,
          "antipodal product: kappa %g, scale %g", (double)p.kappa, scale);

    /* Convolution: sampling a, then b about each sample, has mean cosine rbar_a rbar_b. */
    const double kc[][2] = {{5.0, 20.0}, {100.0, 100.0}, {1e4, 300.0}};
    for (size_t c = 0; c < 3; c++) {
        double k = vmf_convolve_kappa(kc[c][0], kc[c][1]);
        vmf va = {v3(0, 0, 1), (float)kc[c][0]};
        double sum = 0.0, sum2 = 0.0;
        const int n = 100000;
        for (int i = 0; i < n; i++) {
            vmf vb = {vmf_sample(va, rng_vec2(&rng)), (float)kc[c][1]};
            double z = vmf_sample(vb, rng_vec2(&rng)).z;
            sum += z;
            sum2 += z * z;
        }
        double mean = sum / n, sem = sqrt((sum2 / n - mean * mean) / n) + 1e-7;
        CHECK(fabs(mean - vmf_rbar_from_kappa(k)) < 5.0 * sem, "convolution %zu: kappa %g has rbar %.6f, sampled %.6f",
              c, k, vmf_rbar_from_kappa(k), mean);
    }
    double big = vmf_convolve_kappa(1e5, 1e5);
    CHECK(fabs(big - 5e4) < 5.0, "convolving two kappa 1e5 lobes: %g, expected ~5e4", big);
}

static int cmp_double(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The fitted vMF of a glossy lobe has the core width of the BSDF's own samples (median angle to
 * the mirror direction within 15%: oblique incidence bends the lobes a little), and its albedo is
 * the lobe's (Monte Carlo, 3%). */
static void test_fit_glossy(void) {
    rng_state rng = rng_make(7, 9);
    const struct {
        const char *name;
        bsdf b;
    } cases[] = {
        {"phong 200", make_bsdf_phong(v3s(0.0f), v3(0.7f, 0.6f, 0.5f), 200.0f)},
        {"phong 5000", make_bsdf_phong(v3s(0.1f), v3s(0.8f), 5000.0f)},
        {"ggx alpha 0.01", make_bsdf_gltf(v3(0.9f, 0.7f, 0.4f), 1.0f, 0.1f, 0.0f)},
        {"ggx alpha 0.04", make_bsdf_gltf(v3s(0.95f), 1.0f, 0.2f, 0.0f)},
        {"ward 0.05", make_bsdf_ward(v3s(0.0f), v3s(0.9f), 0.05f, 0.05f)},
    };
    const double angles[] = {0.0, 30.0, 50.0};
    enum { N = 40000 };
    static double omc[N];
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++)
        for (int a = 0; a < 3; a++) {
            double th = angles[a] * M_PI / 180.0;
            vec3 wo = v3((float)sin(th), 0.0f, (float)cos(th));
            vmf lobe;
            vec3 albedo;
            CHECK(vmf_fit_glossy(&cases[c].b, wo, &lobe, &albedo), "%s: no fit", cases[c].name);
            double alb = 0.0;
            int got = 0;
            for (int i = 0; i < N; i++) {
                bsdf_sample_result s;
                float ul = rng_float(&rng);
                if (!bsdf_sample(&cases[c].b, wo, BSDF_GLOSSY, ul, rng_vec2(&rng), &s)) continue;
                double dx = (double)s.wi.x - lobe.mu.x, dy = (double)s.wi.y - lobe.mu.y,
                       dz = (double)s.wi.z - lobe.mu.z;
                omc[got++] = 0.5 * (dx * dx + dy * dy + dz * dz);
                alb += avg3(s.f) * s.wi.z / s.pdf;
            }
            qsort(omc, (size_t)got, sizeof(double), cmp_double);
            double k = lobe.kappa, median = omc[got / 2], want = -log1p(0.5 * expm1(-2.0 * k)) / k;
            CHECK(fabs(median / want - 1.0) < 0.15, "%s at %g deg: median 1 - cos %.3g, fitted vMF's %.3g",
                  cases[c].name, angles[a], median, want);
            alb /= N;
            CHECK(fabs(avg3(albedo) / alb - 1.0) < 0.03, "%s at %g deg: albedo %.4f, Monte Carlo %.4f", cases[c].name,
                  angles[a], (double)avg3(albedo), alb);
        }
    vmf lobe;
    vec3 albedo;
    bsdf lambert = make_bsdf_lambert(v3s(0.5f));
    CHECK(!vmf_fit_glossy(&lambert, v3(0, 0, 1), &lobe, &albedo), "a lambert bsdf has no glossy lobe to fit");
    CHECK(!vmf_fit_glossy(&cases[0].b, v3(0, 0.6f, -0.8f), &lobe, &albedo), "wo below the surface was fitted");
    /* Rough lobes get broad but finite fits: at roughness 1 the median angle is 90 degrees, the
     * uniform sphere's (kappa 0); a little less rough, a small kappa with that median. */
    bsdf rough = make_bsdf_gltf(v3s(1.0f), 1.0f, 1.0f, 0.0f);
    CHECK(vmf_fit_glossy(&rough, v3(0, 0, 1), &lobe, &albedo) && lobe.kappa >= 0.0f && lobe.kappa < 0.01f,
          "roughness 1: kappa %g", (double)lobe.kappa);
    rough = make_bsdf_gltf(v3s(1.0f), 1.0f, 0.9f, 0.0f);
    CHECK(vmf_fit_glossy(&rough, v3(0, 0, 1), &lobe, &albedo) && lobe.kappa > 0.0f && lobe.kappa < 5.0f,
          "roughness 0.9: kappa %g", (double)lobe.kappa);
    double a2 = 0.81 * 0.81, t = 2.0 * a2 / (1.0 + a2); /* alpha = roughness^2 */
    CHECK_NEAR(-log1p(0.5 * expm1(-2.0 * (double)lobe.kappa)) / (double)lobe.kappa, t, 1e-5,
               "roughness 0.9: the fit's median 1 - cos");
}

/* GGX's lobe as bands: weights summing to 1, the mixture's peak at normal incidence within 6% of
 * the cosine-weighted lobe's (one vMF of the median width: 0.69 of it); Phong keeps its one band;
 * the across squeeze is cos theta_o for microfacet lobes. */
static void test_fit_bands(void) {
    bsdf ggx = make_bsdf_gltf(v3s(1.0f), 1.0f, 0.3f, 0.0f); /* alpha 0.09 */
    vmf_lobe lobe;
    vmf single;
    vec3 albedo, albedo1;
    CHECK(vmf_fit_glossy_bands(&ggx, v3(0, 0, 1), &lobe, &albedo) == VMF_LOBE_BANDS, "GGX: %d bands", lobe.bands);
    vmf_fit_glossy(&ggx, v3(0, 0, 1), &single, &albedo1);
    double wsum = 0.0, peak = 0.0;
    for (int b = 0; b < lobe.bands; b++) {
        wsum += lobe.weight[b];
        peak += lobe.weight[b] * vmf_eval(lobe.band[b], v3(0, 0, 1));
    }
    double want = avg3(bsdf_eval(&ggx, v3(0, 0, 1), v3(0, 0, 1), BSDF_GLOSSY)) / avg3(albedo);
    CHECK_NEAR(wsum, 1.0, 1e-6, "GGX band weights");
    CHECK(fabs(peak / want - 1.0) < 0.06, "GGX bands: peak %.3f of the lobe's %.3f", peak, want);
    CHECK(vmf_eval(single, v3(0, 0, 1)) / want < 0.75, "one vMF's peak %.3f of the lobe's: the bands' reason is gone?",
          vmf_eval(single, v3(0, 0, 1)) / want);
    vec3 wo = v3(0.8f, 0.0f, 0.6f);
    CHECK(vmf_fit_glossy_bands(&ggx, wo, &lobe, &albedo) && fabs(lobe.squeeze - 0.6f) < 1e-6f, "GGX squeeze %g",
          (double)lobe.squeeze);
    bsdf phong = make_bsdf_phong(v3s(0.0f), v3s(0.9f), 300.0f);
    CHECK(vmf_fit_glossy_bands(&phong, wo, &lobe, &albedo) == 1 && lobe.squeeze == 1.0f && lobe.weight[0] == 1.0f,
          "Phong: one round band");
    /* Band shares: sum to 1; the sharp band owns the mirror direction, the broad one the tail. */
    float share[VMF_LOBE_BANDS];
    vec3 mirror = v3(-wo.x, -wo.y, wo.z), tail = normalize3(v3(-0.3f, 0.5f, 0.8f));
    CHECK(vmf_glossy_band_shares(&ggx, wo, mirror, share) == VMF_LOBE_BANDS, "GGX: shares per band");
    CHECK_NEAR(share[0] + share[1], 1.0, 1e-6, "shares at the mirror direction");
    CHECK(share[1] > share[0], "at the mirror direction the sharp band's share %.3f is below the broad one's",
          share[1]);
    vmf_glossy_band_shares(&ggx, wo, tail, share);
    CHECK(share[0] > 0.99f, "far in the tail the broad band's share is only %.3f", share[0]);
}

/* vmf_mass_above against quadrature over the vMF (its quantiles in theta, the exact azimuthal share
 * above the plane for each): within 0.035 everywhere, exact at kappa 0. */
static void test_mass_above(void) {
    const double mass_kappas[] = {0.0, 0.1, 1.0, 5.0, 30.0, 300.0, 1e4};
    const double cosines[] = {-0.5, -0.1, 0.0, 0.1, 0.3, 0.6, 0.95, 1.0};
    double worst = 0.0;
    for (size_t i = 0; i < sizeof mass_kappas / sizeof mass_kappas[0]; i++)
        for (size_t j = 0; j < sizeof cosines / sizeof cosines[0]; j++) {
            double k = mass_kappas[i], c = cosines[j], sc = sqrt(fmax(0.0, 1.0 - c * c)), sum = 0.0;
            enum { M = 20000 };
            for (int q = 0; q < M; q++) {
                double u = (q + 0.5) / M, omc = k < 1e-8 ? 2.0 * u : -log1p(u * expm1(-2.0 * k)) / k;
                double t = 1.0 - omc, st = sqrt(fmax(0.0, omc * (2.0 - omc))), den = sc * st;
                double x = den < 1e-12 ? (c * t > 0.0 ? -2.0 : 2.0) : -c * t / den;
                sum += x <= -1.0 ? 1.0 : x >= 1.0 ? 0.0 : acos(x) / M_PI;
            }
            double exact = sum / M, got = vmf_mass_above(k, c);
            worst = fmax(worst, fabs(got - exact));
            CHECK(fabs(got - exact) < 0.035, "kappa %g, cos %g: mass above %.4f, quadrature %.4f", k, c, got, exact);
            CHECK(got >= 0.0 && got <= 1.0, "kappa %g, cos %g: %g", k, c, got);
        }
    printf("vmf_mass_above: worst difference from quadrature %.4f\n", worst);
    CHECK_NEAR(vmf_mass_above(0.0, 0.7), 0.5, 1e-12, "uniform sphere");
}

static void test_merge(void) {
    vmf same[3] = {{v3(0, 0, 1), 500.0f}, {v3(0, 0, 1), 500.0f}, {v3(0, 0, 1), 500.0f}};
    float w3[3] = {1.0f, 2.0f, 0.5f};
    vmf m = vmf_merge(same, w3, NULL, 3);
    CHECK(m.mu.z > 0.999999f && fabsf(m.kappa - 500.0f) < 5.0f, "identical lobes merged to kappa %g", (double)m.kappa);
    /* Two sharp lobes 20 degrees apart: the merged mean halves the angle, and it is broad. */
    float s = (float)sin(10 * M_PI / 180), c = (float)cos(10 * M_PI / 180);
    vmf two[2] = {{v3(s, 0, c), 1e4f}, {v3(-s, 0, c), 1e4f}};
    m = vmf_merge(two, NULL, NULL, 2);
    CHECK(fabsf(m.mu.x) < 1e-6f && m.mu.z > 0.99999f, "merged mean (%g %g %g)", (double)m.mu.x, (double)m.mu.y,
          (double)m.mu.z);
    CHECK(m.kappa < 200.0f && m.kappa > 20.0f, "merged kappa %g: the spread of the centres must dominate",
          (double)m.kappa);
    /* Weights pull the mean; members select; zero weights are ignored. */
    float w2[2] = {3.0f, 1.0f};
    m = vmf_merge(two, w2, NULL, 2);
    CHECK(m.mu.x > 0.0f, "the heavier lobe did not pull the mean");
    int only_second = 1;
    m = vmf_merge(two, NULL, &only_second, 1);
    CHECK(m.mu.x < 0.0f && fabsf(m.kappa - 1e4f) < 100.0f, "one member merged to (%g, kappa %g)", (double)m.mu.x,
          (double)m.kappa);
    vmf anti[2] = {{v3(0, 0, 1), 100.0f}, {v3(0, 0, -1), 100.0f}};
    m = vmf_merge(anti, NULL, NULL, 2);
    CHECK(m.kappa == 0.0f && is_finite3(m.mu) && fabsf(length3(m.mu) - 1.0f) < 1e-5f, "antipodal lobes: kappa %g",
          (double)m.kappa);
    float zero[2] = {0.0f, 0.0f};
    m = vmf_merge(two, zero, NULL, 2);
    CHECK(m.kappa == 0.0f && is_finite3(m.mu), "weightless members merged to kappa %g", (double)m.kappa);
}

static void test_em(void) {
    rng_state rng = rng_make(8, 9);
    /* A known two-lobe mixture, 90 degrees apart, weights 0.3 / 0.7. */
    enum { N = 3000 };
    static vec3 dirs[N];
    static int assign[N], truth[N];
    vmf comp[2] = {{v3(1, 0, 0), 50.0f}, {v3(0, 0, 1), 200.0f}};
    for (int i = 0; i < N; i++) {
        truth[i] = rng_float(&rng) < 0.3f ? 0 : 1;
        dirs[i] = vmf_sample(comp[truth[i]], rng_vec2(&rng));
    }
    int k = vmf_em(dirs, NULL, N, 2, assign);
    CHECK(k == 2, "two lobes: %d clusters", k);
    int cluster_of[2] = {-1, -1}, agree = 0;
    for (int i = 0; i < N; i++)
        if (cluster_of[truth[i]] < 0) cluster_of[truth[i]] = assign[i];
    for (int i = 0; i < N; i++) agree += assign[i] == cluster_of[truth[i]];
    CHECK(cluster_of[0] != cluster_of[1] && agree > N - 5, "two lobes: %d of %d directions in their lobe's cluster",
          agree, N);
    for (int t = 0; t < 2; t++) {
        int members[N], nm = 0;
        for (int i = 0; i < N; i++)
            if (assign[i] == cluster_of[t]) members[nm++] = i;
        vmf pts[N];
        for (int i = 0; i < nm; i++) pts[i] = (vmf){dirs[members[i]], (float)VMF_MAX_KAPPA};
        vmf fit = vmf_merge(pts, NULL, NULL, nm); /* unit directions: Eq. 3 on their mean */
        CHECK(dot3(fit.mu, comp[t].mu) > cosf(0.02f), "lobe %d: mean off by %g rad", t,
              acos(fmin(1.0, dot3(fit.mu, comp[t].mu))));
        CHECK(fabsf(fit.kappa / comp[t].kappa - 1.0f) < 0.15f, "lobe %d: kappa %g, expected %g", t, (double)fit.kappa,
              (double)comp[t].kappa);
        CHECK(fabs((double)nm / N - (t == 0 ? 0.3 : 0.7)) < 0.03, "lobe %d: share %.3f", t, (double)nm / N);
    }

    /* Identical directions: one cluster however many are asked for. */
    vec3 same[5];
    for (int i = 0; i < 5; i++) same[i] = normalize3(v3(0.3f, 0.4f, 0.5f));
    k = vmf_em(same, NULL, 5, 4, assign);
    CHECK(k == 1 && assign[0] == 0 && assign[4] == 0, "identical directions: %d clusters", k);
    /* Antipodal pairs: one cluster (of no mean direction) or two. */
    vec3 anti[4] = {v3(0, 0, 1), v3(0, 0, -1), v3(0, 0, 1), v3(0, 0, -1)};
    k = vmf_em(anti, NULL, 4, 1, assign);
    CHECK(k == 1, "antipodal, K = 1: %d clusters", k);
    k = vmf_em(anti, NULL, 4, 2, assign);
    CHECK(k == 2 && assign[0] == assign[2] && assign[1] == assign[3] && assign[0] != assign[1],
          "antipodal, K = 2: %d clusters, %d %d %d %d", k, assign[0], assign[1], assign[2], assign[3]);
    /* K larger than the sample count, weights (zero ones included), no directions. */
    vec3 three[3] = {v3(1, 0, 0), v3(0, 1, 0), v3(0, 0, 1)};
    float w[3] = {0.0f, 2.0f, 1.0f};
    k = vmf_em(three, w, 3, 8, assign);
    int ok = k >= 1 && k <= 3;
    for (int i = 0; i < 3; i++) ok &= assign[i] >= 0 && assign[i] < k;
    CHECK(ok, "K > n: %d clusters, assignments %d %d %d", k, assign[0], assign[1], assign[2]);
    float zeros[3] = {0, 0, 0};
    k = vmf_em(three, zeros, 3, 2, assign);
    CHECK(k >= 1 && k <= 2 && assign[0] >= 0 && assign[0] < k, "all weights zero: %d clusters", k);
    CHECK(vmf_em(three, NULL, 0, 2, assign) == 0, "no directions: clusters");
    /* Empty clusters do not survive: five directions in one tight bunch and one far away, K 4. */
    vec3 bunch[6];
    for (int i = 0; i < 5; i++) bunch[i] = normalize3(v3(0.001f * i, 0, 1));
    bunch[5] = v3(1, 0, 0);
    k = vmf_em(bunch, NULL, 6, 4, assign);
    int used[4] = {0, 0, 0, 0};
    for (int i = 0; i < 6; i++)
        if (assign[i] >= 0 && assign[i] < 4) used[assign[i]] = 1;
    int nused = used[0] + used[1] + used[2] + used[3];
    CHECK(k >= 2 && nused == k, "bunch: %d clusters, %d used", k, nused);
}

int main(void) {
    test_density_and_rbar();
    test_kappa_from_rbar();
    test_sampling();
    test_product_and_convolution();
    test_fit_glossy();
    test_fit_bands();
    test_mass_above();
    test_merge();
    test_em();
    return check_exit("test_vmf");
}
