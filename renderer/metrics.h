/* glint — image error against a reference, on HDR radiance, its split into noise and bias over
 * independent runs, and the small numerics of error-versus-time curves. Images are n float values
 * (pixels x channels), compared value by value. */
#ifndef GLINT_METRICS_H
#define GLINT_METRICS_H

#include <stddef.h>

/* The papers' relative L2 error ||I - R||_2 / ||R||_2. A zero reference (or n = 0) gives 0 when
 * the image is zero too, else INFINITY: there is no relative scale to measure against. */
double metric_rel_l2(const float *img, const float *ref, size_t n);

/* An error with a reference's own relative noise taken out in quadrature, as the bias of
 * metric_noise_bias takes it: sqrt(max(0, rel_l2^2 - ref_noise^2)); rel_l2 itself for ref_noise 0. */
double metric_without_noise(double rel_l2, double ref_noise);

/* The share of ||I - R||^2 that the ceil(fraction x pixels) pixels of largest squared error hold
 * (each pixel `channels` values): near 1 when a few pixels carry the error (a light's speck in a
 * mirror), near fraction when it is spread evenly. 0 for no error; -1 when out of memory. */
double metric_peak_share(const float *img, const float *ref, size_t pixels, int channels, double fraction);

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

/* The split of the error of N independent runs I_1..I_N (seeds) against a reference R into noise
 * and bias, without keeping the N images: per checkpoint, a running sum image and the sum of
 * ||I_k - R||^2 suffice. metric_accumulate adds img into sum (n doubles) and returns
 * ||img - ref||^2; metric_mean_err2 is ||M - R||^2 for the mean image M = sum / count;
 * metric_norm2 is ||v||^2. */
double metric_accumulate(double *sum, const float *img, const float *ref, size_t n);
double metric_mean_err2(const double *sum, int count, const float *ref, size_t n);
double metric_norm2(const float *v, size_t n);

/* From sum_err2 = sum_k ||I_k - R||^2, mean_err2 = ||M - R||^2 and ref_norm2 = ||R||^2 over count
 * runs, relative to ||R||:
 *   noise^2 = sum_k ||I_k - M||^2 / (count - 1) / ||R||^2  (one run's noise, unbiased),
 *   bias^2  = max(0, ||M - R||^2 / ||R||^2 - noise^2 / count - ref_noise^2),
 * where ref_noise is the reference's own relative noise (0 when unknown). sum_k ||I_k - M||^2 is
 * taken as sum_err2 - count mean_err2: a difference of error-sized terms, where the image's
 * ||I_k||^2 would cancel far larger ones. Then the RMS over the runs of their rel_l2 satisfies rms^2 = noise^2 + bias^2 +
 * ref_noise^2 exactly unless bias^2 was clamped. count < 2: both NAN (one run cannot tell noise
 * from bias). A zero reference follows metric_rel_l2: 0 for a zero numerator, else INFINITY. */
void metric_noise_bias(double sum_err2, double mean_err2, double ref_norm2, int count, double ref_noise, double *noise,
                       double *bias);

/* Least-squares slope of log y against log x over the points with x > 0 and finite y > 0 (the
 * convergence rate of an error curve: -0.5 for unbiased Monte Carlo). NAN with fewer than two
 * such points or no spread in x. */
double metric_loglog_slope(const double *x, const double *y, int n);

/* Where the last doubling of increasing x begins: the smallest k with x[k] >= x[n-1] / 2, but at
 * most n - 2, so a fit from k on has two points even when the last step is more than a doubling
 * (0 when n < 2). The slope from there on tells whether a curve still falls at its end. */
int metric_last_doubling(const double *x, int n);

/* Interpolation on a curve of increasing x, linear in log-log: y at x0 (NAN outside [x[0],
 * x[n-1]]), and the smallest x at which the curve comes down to y0 (NAN when it never does). */
double metric_loglog_at(const double *x, const double *y, int n, double x0);
double metric_loglog_reach(const double *x, const double *y, int n, double y0);

#endif
