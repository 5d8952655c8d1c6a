#include "metrics.h"

#include <math.h>
#include <stdlib.h>

double metric_rel_l2(const float *img, const float *ref, size_t n) {
    double err = 0.0, norm = 0.0;
    for (size_t i = 0; i < n; i++) {
        double d = (double)img[i] - (double)ref[i];
        err += d * d;
        norm += (double)ref[i] * (double)ref[i];
    }
    if (norm > 0.0) return sqrt(err / norm);
    return err > 0.0 ? (double)INFINITY : 0.0;
}

static int descending(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x < y) - (x > y);
}

double metric_peak_share(const float *img, const float *ref, size_t pixels, int channels, double fraction) {
    if (pixels == 0 || channels <= 0) return 0.0;
    double *e = malloc(sizeof(double) * pixels), all = 0.0, top = 0.0;
    if (!e) return -1.0;
    for (size_t i = 0; i < pixels; i++) {
        double s = 0.0;
        for (int c = 0; c < channels; c++) {
            double d = (double)img[i * (size_t)channels + (size_t)c] - (double)ref[i * (size_t)channels + (size_t)c];
            s += d * d;
        }
        e[i] = s;
        all += s;
    }
    double want = ceil(fmin(fmax(fraction, 0.0), 1.0) * (double)pixels);
    size_t k = (size_t)want;
    qsort(e, pixels, sizeof *e, descending);
    for (size_t i = 0; i < k; i++) top += e[i];
    free(e);
    return all > 0.0 ? fmin(top / all, 1.0) : 0.0;
}

double metric_relmse(const float *img, const float *ref, size_t n) {
    if (n == 0) return 0.0;
    double sum = 0.0;
    for (size_t i = 0; i < n; i++) {
        double d = (double)img[i] - (double)ref[i];
        sum += d * d / ((double)ref[i] * (double)ref[i] + METRIC_RELMSE_EPS);
    }
    return sum / (double)n;
}

double metric_mean_variance_halves(const float *first, const float *all, size_t n, long long m, long long total,
                                   double *rel_noise) {
    if (rel_noise) *rel_noise = 0.0;
    if (n == 0 || m <= 0 || m >= total) return 0.0;
    double dm = (double)m, dt = (double)total, rest = dt - dm;
    /* E[(first - second)^2] = sigma^2 (1/m + 1/rest); the final mean's variance is sigma^2 / total. */
    double scale = 1.0 / ((1.0 / dm + 1.0 / rest) * dt);
    double var = 0.0, norm = 0.0;
    for (size_t i = 0; i < n; i++) {
        double a = (double)first[i], mean = (double)all[i];
        double second = (dt * mean - dm * a) / rest;
        double d = a - second;
        var += d * d * scale;
        norm += mean * mean;
    }
    if (rel_noise) *rel_noise = norm > 0.0 ? sqrt(var / norm) : 0.0;
    return var / (double)n;
}

double metric_accumulate(double *sum, const float *img, const float *ref, size_t n) {
    double err = 0.0;
    for (size_t i = 0; i < n; i++) {
        double d = (double)img[i] - (double)ref[i];
        err += d * d;
        sum[i] += (double)img[i];
    }
    return err;
}

double metric_mean_err2(const double *sum, int count, const float *ref, size_t n) {
    if (count <= 0) return 0.0;
    double err = 0.0, inv = 1.0 / (double)count;
    for (size_t i = 0; i < n; i++) {
        double d = sum[i] * inv - (double)ref[i];
        err += d * d;
    }
    return err;
}

double metric_norm2(const float *v, size_t n) {
    double s = 0.0;
    for (size_t i = 0; i < n; i++) s += (double)v[i] * (double)v[i];
    return s;
}

/* x / norm, with metric_rel_l2's convention for a zero reference. */
static double relative(double x, double norm) {
    if (norm > 0.0) return x / norm;
    return x > 0.0 ? (double)INFINITY : 0.0;
}

void metric_noise_bias(double sum_err2, double mean_err2, double ref_norm2, int count, double ref_noise, double *noise,
                       double *bias) {
    *noise = *bias = (double)NAN;
    if (count < 2) return;
    double n = (double)count;
    /* sum_k ||I_k - R||^2 = sum_k ||I_k - M||^2 + count ||M - R||^2: the cross term sums to zero. */
    double spread = fmax(sum_err2 - n * mean_err2, 0.0);
    double noise2 = spread / (n - 1.0); /* absolute, one run */
    /* E||M - R||^2 = bias^2 + noise^2 / count + the reference's own noise^2 (independent). */
    double bias2 = fmax(mean_err2 - noise2 / n - ref_noise * ref_noise * ref_norm2, 0.0);
    *noise = sqrt(relative(noise2, ref_norm2));
    *bias = sqrt(relative(bias2, ref_norm2));
}

static int usable(double x, double y) { return x > 0.0 && isfinite(x) && y > 0.0 && isfinite(y); }

double metric_loglog_slope(const double *x, const double *y, int n) {
    double sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0;
    int k = 0;
    for (int i = 0; i < n; i++) {
        if (!usable(x[i], y[i])) continue;
        double lx = log(x[i]), ly = log(y[i]);
        sx += lx, sy += ly, sxx += lx * lx, sxy += lx * ly;
        k++;
    }
    if (k < 2) return (double)NAN;
    double den = (double)k * sxx - sx * sx;
    if (!(fabs(den) > 1e-12 * (double)k * sxx)) return (double)NAN;
    return ((double)k * sxy - sx * sy) / den;
}

int metric_last_doubling(const double *x, int n) {
    if (n < 2) return 0;
    int k = 0;
    while (k < n - 2 && x[k] < 0.5 * x[n - 1]) k++;
    return k;
}

double metric_loglog_at(const double *x, const double *y, int n, double x0) {
    for (int i = 0; i + 1 < n; i++) {
        if (!usable(x[i], y[i]) || !usable(x[i + 1], y[i + 1])) continue;
        if (x0 < x[i] || x0 > x[i + 1]) continue;
        if (x[i + 1] == x[i]) return y[i];
        double t = log(x0 / x[i]) / log(x[i + 1] / x[i]);
        return exp(log(y[i]) + t * log(y[i + 1] / y[i]));
    }
    if (n >= 1 && usable(x[n - 1], y[n - 1]) && x0 == x[n - 1]) return y[n - 1];
    return (double)NAN;
}

double metric_loglog_reach(const double *x, const double *y, int n, double y0) {
    if (!(y0 > 0.0)) return (double)NAN;
    if (n >= 1 && usable(x[0], y[0]) && y[0] <= y0) return x[0];
    for (int i = 0; i + 1 < n; i++) {
        if (!usable(x[i], y[i]) || !usable(x[i + 1], y[i + 1])) continue;
        if (!(y[i] > y0 && y[i + 1] <= y0)) continue;
        double t = log(y0 / y[i]) / log(y[i + 1] / y[i]);
        return exp(log(x[i]) + t * log(x[i + 1] / x[i]));
    }
    return (double)NAN;
}

double metric_without_noise(double rel_l2, double ref_noise) {
    return ref_noise > 0.0 ? sqrt(fmax(rel_l2 * rel_l2 - ref_noise * ref_noise, 0.0)) : rel_l2;
}
