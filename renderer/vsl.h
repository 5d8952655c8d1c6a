/* glint — what one virtual light sends to one shading point: the VPL baseline (a point light
 * with the 1/d^2 geometry term) and the virtual spherical light (VSL paper Eq. 5). Visibility and
 * clamping are the caller's (vl_shade does both). */
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

/* Phi_j / (pi r_j^2 share) x the integral over the cone Omega_j of Eq. 5, no visibility: uniform
 * cone sampling (cosine-weighted hemisphere when x is inside the sphere), BSDF sampling at x and
 * BSDF sampling at the light, one sample model with the balance heuristic; ceil(100 |Omega|/2pi)
 * samples, at least 1. Unless all_strategies, a pair without a glossy lobe sharper than
 * BSDF_HIGHLIGHT_ALPHA uses cone sampling alone. share is vsl_front_share: where the sphere
 * reaches behind x's surface or the light's, that part would send its light from inside the
 * geometry and the paper's estimator loses it (half of what a light on the floor by a wall sends
 * to the wall, 10-20% along a room's edges); the rest of the sphere carries it instead
 * (docs/design.md). *samples (optional) receives the count used. */
vec3 vsl_contribution(const virtual_light *vl, const shading_point *x, vl_terms terms, int all_strategies,
                      rng_state *rng, int *samples);

/* The share of the sphere's cross-section in front of the receiver's tangent plane and of the
 * light's (1 when the sphere clears both): each plane cuts a disk seen edge-on to it at the
 * centre's distance from it over r; the two shares a and b (a <= b) combine as a sqrt(b), between
 * the smaller alone (measured 4% short where both cut) and their product (8-14% over). Within 4%
 * of the energy the point light sends to a wall at any distance of the light from it (test_vsl). */
double vsl_front_share(const virtual_light *vl, const shading_point *x);

/* The integral of Eq. 5 alone (without Phi / (pi r^2)), for tests. */
vec3 vsl_integral(const virtual_light *vl, const shading_point *x, vl_terms terms, int all_strategies, rng_state *rng,
                  int *samples);

/* The Eq. 5 integrand at direction l (world, from x): f_x cos_x f_j cos_j with the term split,
 * zero outside Omega_j. Exposed for brute-force checks. */
vec3 vsl_integrand(const virtual_light *vl, const shading_point *x, vl_terms terms, vec3 l);

#endif
