/* glint — image error against a reference, on HDR radiance (DESIGN.md, "Accuracy and its cost in
 * time"), and the small numerics of error-versus-time curves. Images are n float values (pixels x
 * channels), compared value by value. */
#ifndef GLINT_METRICS_H
#define GLINT_METRICS_H

#include <stddef.h>

/* The papers' relative L2 error ||I - R||_2 / ||R||_2. A zero reference (or n = 0) gives 0 when
 * the image is zero too, else INFINITY: there is no relative scale to measure against. */
double metric_rel_l2(const float *img, const float *ref, size_t n);

/* Relative mean squared error: mean of (I - R)^2 / (R^2 + METRIC_RELMSE_EPS). The epsilon keeps
 * black reference pixels from dominating. n = 0 gives 0. */
#define METRIC_RELMSE_EPS 1e-2
double metric_relmse(const float *img, const float *ref, size_t n);

/* The variance of a progressive mean, estimated from two halves of its samples: first is the mean
 * after the first m passes, all the mean after all total passes (0 < m < total). Each value's
 * second half is (total all - m first) / (total - m); the difference of the halves has variance
 * sigma^2 (1/m + 1/(total - m)), so each value gives an estimate of the variance of the final
 * mean, sigma^2 / total. Returns the mean over the n values (0 when m is out of range); when
 * rel_noise is not NULL it gets the expected relative L2 error of the image itself,
 * sqrt(sum of variances / sum of squares) (0 for a zero image). */
double metric_mean_variance_halves(const float *first, const float *all, size_t n, long long m, long long total,
                                   double *rel_noise);

/* Least-squares slope of log y against log x over the points with x > 0 and finite y > 0 (the
 * convergence rate of an error curve: -0.5 for unbiased Monte Carlo). NAN with fewer than two
 * such points or no spread in x. */
double metric_loglog_slope(const double *x, const double *y, int n);

/* Interpolation on a curve of increasing x, linear in log-log: y at x0 (NAN outside [x[0],
 * x[n-1]]), and the smallest x at which the curve comes down to y0 (NAN when it never does). */
double metric_loglog_at(const double *x, const double *y, int n, double x0);
double metric_loglog_reach(const double *x, const double *y, int n, double y0);

#endif
