/* glint — statistical tests for samplers: does a routine produce directions (or points) with the
 * density its pdf claims? Pearson's chi-square over bins whose expected counts come from
 * integrating the claimed pdf, never from the sampler itself. */
#ifndef GLINT_STAT_TESTS_H
#define GLINT_STAT_TESTS_H

#include <stdint.h>

#include "gmath.h"

/* Draws one direction from (u_lobe, u); returns 0 when no sample was produced (that mass is lost
 * and must show as pdf mass missing, not as a bias). */
typedef int (*direction_sampler)(void *ctx, float u_lobe, vec2 u, vec3 *w);
/* The density the sampler claims, per unit solid angle. */
typedef double (*direction_pdf)(void *ctx, vec3 w);

typedef struct {
    double chi2;         /* Pearson statistic over the merged bins */
    int dof;             /* merged bins - 1 */
    double p_value;      /* P(X >= chi2) for X ~ chi-square(dof) */
    double pdf_integral; /* the claimed pdf integrated over the sphere */
    double produced;     /* fraction of draws that produced a sample */
    int non_finite;      /* draws that returned a NaN/Inf or non-unit direction */
    int outside_support; /* directions drawn where the pdf is 0 */
} chi2_result;

/* Bins the sphere into theta_bins x phi_bins cells around axis, crowded toward the axis (equal in
 * sin(theta / 2)) and equal in phi, integrates the pdf over each cell with a sub-grid, draws
 * `samples` directions and runs the test. Cells with expected count < 5 are pooled. */
chi2_result chi2_directions(direction_sampler sample, direction_pdf pdf, void *ctx, vec3 axis, int theta_bins,
                            int phi_bins, long samples, uint64_t seed);

/* Pearson's test on observed counts against expected counts (same total), pooling small cells. */
chi2_result chi2_counts(const double *observed, const double *expected, int n);

/* Upper tail of the chi-square distribution with dof degrees of freedom: Q(dof/2, x/2). */
double chi2_upper_tail(double x, int dof);

/* Significance for each of `tests` tests such that the whole suite falsely fails with probability
 * alpha (Sidak correction). */
double chi2_significance(double alpha, int tests);

#endif
