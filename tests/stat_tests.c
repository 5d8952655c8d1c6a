/* glint — chi-square tests for samplers (see stat_tests.h). */
#include "stat_tests.h"

#include <math.h>
#include <stdlib.h>

#include "rng.h"

#define PI_D 3.14159265358979323846

/* Regularised upper incomplete gamma Q(a, x): the power series of P for x < a + 1, the continued
 * fraction of Q (modified Lentz) otherwise; both converge fast on their side. */
static double gamma_q(double a, double x) {
    if (x <= 0.0) return 1.0;
    double log_prefix = -x + a * log(x) - lgamma(a);
    if (x < a + 1.0) {
        double term = 1.0 / a, sum = term;
        for (int n = 1; n < 10000; n++) {
            term *= x / (a + n);
            sum += term;
            if (fabs(term) < fabs(sum) * 1e-15) break;
        }
        return fmax(0.0, 1.0 - sum * exp(log_prefix));
    }
    const double tiny = 1e-300;
    double b = x + 1.0 - a, c = 1.0 / tiny, d = 1.0 / b, h = d;
    for (int i = 1; i < 10000; i++) {
        double an = -i * (i - a);
        b += 2.0;
        d = an * d + b;
        if (fabs(d) < tiny) d = tiny;
        c = b + an / c;
        if (fabs(c) < tiny) c = tiny;
        d = 1.0 / d;
        double delta = d * c;
        h *= delta;
        if (fabs(delta - 1.0) < 1e-15) break;
    }
    return exp(log_prefix) * h;
}

double chi2_upper_tail(double x, int dof) {
    if (dof <= 0) return 1.0;
    if (!(x == x)) return 0.0; /* NaN statistic: fail */
    return gamma_q(0.5 * dof, 0.5 * x);
}

double chi2_significance(double alpha, int tests) { return 1.0 - pow(1.0 - alpha, 1.0 / tests); }

typedef struct {
    double o, e;
} cell;

static int cell_cmp(const void *a, const void *b) {
    double x = ((const cell *)a)->e, y = ((const cell *)b)->e;
    return x < y ? -1 : (x > y ? 1 : 0);
}

chi2_result chi2_counts(const double *observed, const double *expected, int n) {
    chi2_result r = {0};
    cell *c = malloc(sizeof(cell) * (size_t)n);
    int m = 0;
    for (int i = 0; i < n; i++) {
        c[m++] = (cell){observed[i], expected[i]}; /* cells expecting nothing join the pool */
    }
    qsort(c, (size_t)m, sizeof(cell), cell_cmp);
    /* Pool the smallest cells together until the pool expects at least 5. */
    double po = 0.0, pe = 0.0;
    int first = 0;
    while (first < m && (c[first].e < 5.0 || pe < 5.0)) {
        po += c[first].o;
        pe += c[first].e;
        first++;
    }
    double chi2 = 0.0;
    int cells = 0;
    if (first > 0) {
        chi2 += pe > 0.0 ? (po - pe) * (po - pe) / pe : (po > 0.0 ? INFINITY : 0.0);
        cells++;
    }
    for (int i = first; i < m; i++) {
        chi2 += (c[i].o - c[i].e) * (c[i].o - c[i].e) / c[i].e;
        cells++;
    }
    free(c);
    r.chi2 = chi2;
    r.dof = cells - 1;
    r.p_value = chi2_upper_tail(chi2, r.dof);
    return r;
}

chi2_result chi2_directions(direction_sampler sample, direction_pdf pdf, void *ctx, vec3 axis, int theta_bins,
                            int phi_bins, long samples, uint64_t seed) {
    int n = theta_bins * phi_bins;
    double *observed = calloc((size_t)n + 1, sizeof(double));
    double *expected = calloc((size_t)n + 1, sizeof(double));
    frame3 f = frame_from_normal(normalize3(axis));

    /* Bins are equal in t = sqrt((1 - cos theta) / 2), which crowds them toward the axis where
     * lobes peak: z = 1 - 2 t^2, so the solid-angle element is 4 t dt dphi. Expected counts come
     * from the pdf over each cell by a midpoint sub-grid. */
    const int sub = 12;
    double dt = 1.0 / theta_bins, dphi = 2.0 * PI_D / phi_bins, integral = 0.0;
    for (int i = 0; i < theta_bins; i++)
        for (int j = 0; j < phi_bins; j++) {
            double sum = 0.0;
            for (int a = 0; a < sub; a++) {
                double t = dt * (i + (a + 0.5) / sub);
                double z = 1.0 - 2.0 * t * t, s = 2.0 * t * sqrt(fmax(0.0, 1.0 - t * t));
                for (int b = 0; b < sub; b++) {
                    double phi = dphi * (j + (b + 0.5) / sub);
                    vec3 w = to_world(f, v3((float)(s * cos(phi)), (float)(s * sin(phi)), (float)z));
                    sum += pdf(ctx, w) * 4.0 * t;
                }
            }
            double mass = sum * dt * dphi / (sub * sub);
            expected[i * phi_bins + j] = mass * (double)samples;
            integral += mass;
        }

    rng_state rng = rng_make(seed, 7);
    long produced = 0;
    int non_finite = 0, outside = 0;
    for (long k = 0; k < samples; k++) {
        float u_lobe = rng_float(&rng);
        vec2 u = v2(rng_float(&rng), rng_float(&rng));
        vec3 w;
        if (!sample(ctx, u_lobe, u, &w)) {
            observed[n] += 1.0;
            continue;
        }
        if (!is_finite3(w) || fabsf(length3(w) - 1.0f) > 1e-3f) {
            non_finite++;
            continue;
        }
        produced++;
        /* A direction the pdf says cannot occur is wrong however few there are. */
        if (!(pdf(ctx, w) > 0.0)) outside++;
        vec3 l = to_local(f, w);
        /* 1 - cos from the chord to the axis, precise near the axis: |l - axis|^2 = 2 (1 - cos). */
        double chord2 = (double)l.x * l.x + (double)l.y * l.y + ((double)l.z - 1.0) * ((double)l.z - 1.0);
        double t = sqrt(fmin(1.0, 0.25 * chord2));
        double phi = atan2((double)l.y, (double)l.x);
        if (phi < 0.0) phi += 2.0 * PI_D;
        int i = (int)(t / dt), j = (int)(phi / dphi);
        i = i < 0 ? 0 : (i >= theta_bins ? theta_bins - 1 : i);
        j = j < 0 ? 0 : (j >= phi_bins ? phi_bins - 1 : j);
        observed[i * phi_bins + j] += 1.0;
    }
    /* The draws that produced nothing are one more cell, predicted by the pdf's missing mass. A
     * missing mass within the quadrature's error is no prediction: then the cell is left out and
     * the caller compares pdf_integral with produced. */
    int lost_cell = integral < 1.0 - 2e-3;
    expected[n] = fmax(0.0, 1.0 - integral) * (double)samples;
    chi2_result r = chi2_counts(observed, expected, lost_cell ? n + 1 : n);
    r.pdf_integral = integral;
    r.produced = (double)produced / (double)samples;
    r.non_finite = non_finite;
    r.outside_support = outside;
    free(observed);
    free(expected);
    return r;
}
