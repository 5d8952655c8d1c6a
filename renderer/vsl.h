/* glint — what one virtual light sends to one shading point: the VPL baseline (a point light
 * with the 1/d^2 geometry term) and the virtual spherical light (VSL paper Eq. 5, over the
 * sphere's great disk in the light's plane). Visibility and clamping are the caller's
 * (shade_one in manylight.c does both). */
#ifndef GLINT_VSL_H
#define GLINT_VSL_H

#include "rng.h"
#include "vlights.h"

typedef enum {
    VL_KERNEL_VPL = 0,    /* diffuse-only VPL: the light's diffuse lobe only (instant radiosity) */
    VL_KERNEL_VPL_GLOSSY, /* VPL with the full BSDF at the light (VSL paper Fig. 2b) */
    VL_KERNEL_VSL,        /* virtual spherical light */
} vl_kernel;

/* Which part of path space: with the highlight estimator on, the paths glossy(x) -> glossy(p_j)
 * with p_j a first bounce from a light belong to it (both lobes sharper than
 * BSDF_HIGHLIGHT_ALPHA), and the many-light estimators skip them at the camera hit x. */
typedef enum {
    VL_TERMS_ALL = 0,
    VL_TERMS_NO_HIGHLIGHTS, /* drop glossy(x) x glossy(p_j) for depth-1 lights */
    VL_TERMS_HIGHLIGHTS,    /* only that product (for tests: the two add up to ALL) */
} vl_terms;

/* The receiving point: position, geometric normal (on the viewer's side), shading frame, BSDF
 * and the direction toward the viewer in that frame. */
typedef struct {
    vec3 p, ng;
    frame3 frame;
    bsdf b;
    vec3 wo;
    int material, backface; /* the hit's, for the medium beyond a transmission */
} shading_point;

/* Phi_j f_x(v, l) cos_x f_j(i_j, -l) cos_j / d^2, no visibility, unclamped. */
vec3 vpl_contribution(const virtual_light *vl, const shading_point *x, int glossy_at_light, vl_terms terms);

/* Largest number of integration samples for one VSL (when x is inside its sphere, |Omega| = 2pi). */
#define VSL_MAX_SAMPLES 100

/* Phi_j / (pi r_j^2 share) x the integral of f_x cos_x f_j over the solid angle of the light's
 * disk (radius r_j about p_j in its tangent plane; the disk's solid angle carries cos_j), no
 * visibility: points spread evenly over the disk, BSDF sampling at x and BSDF sampling at the
 * light, one-sample model with the balance heuristic; ceil(100 |Omega|/2pi) samples with Omega
 * the sphere's cone, at least one a strategy. Unless all_strategies, a pair without a glossy lobe
 * sharper than BSDF_HIGHLIGHT_ALPHA takes points on the disk alone (and x's BSDF where x is inside
 * the sphere). The result is the mean of point lights spread over the disk: a facing plane
 * receives all the light's power, a wall beside it half, at any distance (docs/design.md,
 * "Virtual spherical lights"). share is vsl_front_share. *samples (optional) receives the count
 * used. */
vec3 vsl_contribution(const virtual_light *vl, const shading_point *x, vl_terms terms, int all_strategies,
                      rng_state *rng, int *samples);

/* The share of the light's disk in front of the receiver's tangent plane (1 when the disk clears
 * it): the part beyond would send its light from inside the receiver's surface, and the rest of
 * the disk carries it instead. */
double vsl_front_share(const virtual_light *vl, const shading_point *x);

/* The integral alone (without Phi / (pi r^2 share)), for tests. */
vec3 vsl_integral(const virtual_light *vl, const shading_point *x, vl_terms terms, int all_strategies, rng_state *rng,
                  int *samples);

/* The integrand at direction l (world, from x): f_x cos_x f_j with the term split, zero where
 * l misses the disk. Exposed for brute-force checks. */
vec3 vsl_integrand(const virtual_light *vl, const shading_point *x, vl_terms terms, vec3 l);

#endif
