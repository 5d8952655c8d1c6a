/* glint — von Mises-Fisher distributions on the unit sphere, for the highlight estimator
 * (Laurijssen et al. 2010): gamma(s) = c(kappa) exp(kappa mu.s), c(kappa) = kappa / (4 pi sinh kappa).
 *
 * Everything here is safe for kappa from 0 to VMF_MAX_KAPPA: sinh is never formed (it overflows
 * near kappa 710), 1 - cos is never formed by subtraction where it cancels, and kappa -> 0 takes
 * the uniform limit 1 / (4 pi). Scalar maths in double; directions are vec3. */
#ifndef GLINT_VMF_H
#define GLINT_VMF_H

#include "bsdf.h"
#include "gmath.h"

#define VMF_MAX_KAPPA 1e6

typedef struct {
    vec3 mu;     /* unit mean direction */
    float kappa; /* concentration, 0 (uniform) .. VMF_MAX_KAPPA */
} vmf;

/* log c(kappa). */
double vmf_log_norm(double kappa);
/* The density (per steradian) at a direction whose cosine to mu is cos_theta, and at s. */
double vmf_eval_cos(double kappa, double cos_theta);
double vmf_eval(vmf v, vec3 s);
/* A direction distributed as v, from u in [0,1)^2. */
vec3 vmf_sample(vmf v, vec2 u);

/* Mean resultant length A(kappa) = E[mu.s] = coth kappa - 1/kappa. */
double vmf_rbar_from_kappa(double kappa);
/* Banerjee et al.'s estimate (3 r - r^3) / (1 - r^2), the paper's Eq. 3: r <= 0 gives 0, r >= 1
 * (or an estimate past it) VMF_MAX_KAPPA. */
double vmf_kappa_estimate(double rbar);
/* The exact inverse of vmf_rbar_from_kappa (Newton from Banerjee's estimate), same limits. */
double vmf_kappa_from_rbar(double rbar);

/* a(s) b(s) = *scale * result(s): the product of two vMFs is a scaled vMF. */
vmf vmf_product(vmf a, vmf b, double *scale);
/* Concentration of the convolution of two vMFs (one blurring the other): the vMF whose mean
 * resultant length is the product of theirs (Mardia & Jupp 2000). */
double vmf_convolve_kappa(double ka, double kb);

/* The glossy lobe of b for outgoing direction wo (local frame) as a vMF about the mirror
 * direction with the lobe's median angular width (isotropic: anisotropic lobes by the geometric
 * mean of their roughnesses), and the lobe's directional albedo in *albedo, the colour the vMF
 * carries (bsdf_glossy_albedo). Returns 0 when b has no glossy lobe or wo is below the surface. */
int vmf_fit_glossy(const bsdf *b, vec3 wo, vmf *lobe, vec3 *albedo);

/* The same lobe as a mixture of vMF bands about the mirror direction, weights summing to 1: one
 * band for Phong and Ward (the fit above), VMF_LOBE_BANDS for GGX, whose long tails one vMF of its
 * median width misses (its peak 0.69 of the lobe's, its shoulders 1.5 times): GGX's distribution of
 * normals is exactly a mixture of Beckmann ones, D_GGX(alpha) = int_0^inf e^-t D_Beckmann(alpha /
 * sqrt t) dt, and each band is one Beckmann lobe (fitted like Ward's) at a node of the least-squares
 * fit of that mixture. Returns the number of bands (0 as vmf_fit_glossy). */
#define VMF_LOBE_BANDS 2
typedef struct {
    vmf band[VMF_LOBE_BANDS];
    float weight[VMF_LOBE_BANDS];
    int bands;
    /* A microfacet lobe (GGX, Ward) seen off normal incidence is narrower across the plane of
     * incidence than along it: its reflected directions spread by 2 dh along and 2 dh cos theta_o
     * across for a tilt dh of the half vector. Each band's kappa is the geometric mean of the two
     * axes'; the lobe's concentration is kappa cos theta_o along and kappa / cos theta_o across. 1
     * for Phong, which is round about the mirror direction. */
    float squeeze;
} vmf_lobe;
int vmf_fit_glossy_bands(const bsdf *b, vec3 wo, vmf_lobe *lobe, vec3 *albedo);
/* For a direction wi reflected by b's glossy lobe (local frame), each band's share of the lobe
 * there (the bands' densities at wi's half vector, normalised to sum to 1): the band it most
 * likely came from. Returns the number of bands, as vmf_fit_glossy_bands. */
int vmf_glossy_band_shares(const bsdf *b, vec3 wo, vec3 wi, float share[VMF_LOBE_BANDS]);

/* The share of a vMF's mass above a plane through the sphere's centre whose normal makes cosine
 * cos_mu_n with the mean: the normal approximation to the distribution of s.n, from the vMF's
 * exact first two moments (within 0.035 of the exact share over every kappa and angle; exact at
 * kappa 0, far above and far below). */
double vmf_mass_above(double kappa, double cos_mu_n);

/* A set of vMF lobes merged into one (the paper's Eq. 5): the weighted mean of the members'
 * unnormalized mean vectors rbar_i mu_i gives the merged mean direction and, through Eq. 3, its
 * concentration. Members with weight <= 0 are ignored; no member gives kappa 0. */
vmf vmf_merge(const vmf *lobes, const float *weights, const int *members, int num_members);

/* Spherical hard EM (the paper's Alg. 4.1, Banerjee et al. 2005) of n weighted unit directions
 * into at most k clusters. Writes each direction's cluster to assign[i] and returns the number of
 * clusters, which are non-empty and numbered 0..result-1 (fewer than k when there are fewer
 * distinct directions). Deterministic: the first centre is the heaviest direction, each next one
 * the direction farthest from those chosen. n <= 0 returns 0. */
int vmf_em(const vec3 *dirs, const float *weights, int n, int k, int *assign);

#endif
