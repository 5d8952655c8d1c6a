/* glint — virtual lights: light tracing deposits one at every surface hit of a light path, and
 * the many-light estimators (clamped VPLs, virtual spherical lights) gather from them. Virtual
 * lights carry indirect light only: the shared direct estimator owns the first bounce. */
#ifndef GLINT_VLIGHTS_H
#define GLINT_VLIGHTS_H

#include <stddef.h>
#include <stdint.h>

#include "rng.h"
#include "scene.h"

typedef struct {
    vec3 p;       /* position */
    vec3 ng;      /* geometric normal on the side the light arrived from */
    frame3 frame; /* shading frame there (n on the same side) */
    vec3 wi;      /* i_j: unit direction back toward where the light came from, local frame */
    bsdf b;       /* the material there */
    vec3 power;   /* Phi_j: flux, already divided by the number of light paths */
    float radius; /* r_j of the spherical light (0 until set) */
    int depth;    /* bounce: 1 = the first surface a light path hit, glass that shadow rays pass not counted */
} virtual_light;

typedef struct {
    virtual_light *v;
    int count, cap;
    long long paths; /* light paths traced for this set (the powers are divided by it) */
} vlight_set;

void vlight_set_free(vlight_set *set);

/* Traces light paths from the scene's lights (chosen by power) until at least `target` virtual
 * lights are deposited: BSDF sampling at every bounce, Russian roulette, at most max_depth - 1
 * bounces (a virtual light at bounce d lights paths of d + 1 scattering events, and max_depth
 * counts those). Replaces the set's contents. Returns 0, or -1 when out of memory. */
int vlights_trace(const scene *s, int target, int max_depth, uint64_t seed, uint64_t frame, vlight_set *set,
                  uint64_t *bounce_rays);

/* Sets every light's radius to mult x the distance to its 10th nearest neighbour in the set
 * (the VSL paper's rule). A zero distance (duplicates) falls back to a tiny fraction of the
 * scene. Returns 0, or -1 when out of memory. */
#define VSL_NEIGHBOURS 10
int vlights_set_radii(vlight_set *set, float mult, float scene_diag);

#endif
