/* glint — indirect highlights by vMF merging (Laurijssen et al. 2010, docs/design.md): the paths
 * camera - glossy(x) - glossy(q) - light, both lobes sharper than BSDF_HIGHLIGHT_ALPHA. At a
 * camera hit x, N secondary rays sample x's glossy lobe; each hit q_i with such a lobe contributes
 * that lobe, fitted as a vMF about the mirror of the direction back to x and weighted by its
 * albedo (bsdf_glossy_albedo's tables) and x's sample weight; an anisotropic lobe, which no
 * isotropic vMF follows, is lit through its own BSDF instead. The lobes are merged
 * into at most K vMFs (spherical hard EM on their directions, Eq. 5 per cluster, the clusters'
 * energies summing to the members', Eq. 10), and each merged lobe is lit once from its members'
 * mean position: every punctual light by a shadow ray, area lights by one light sample and one
 * lobe sample (multiple importance sampling), the environment through its vMF-prefiltered map and
 * one ray along the lobe's mean. */
#ifndef GLINT_HIGHLIGHTS_H
#define GLINT_HIGHLIGHTS_H

#include "params.h"
#include "rng.h"
#include "sampling.h"
#include "vsl.h"

struct env_vmf_filter;

typedef enum {
    HL_MERGED = 0, /* the paper's estimator */
    HL_UNMERGED,   /* every secondary hit's own vMF lobe lit from that hit (the paper's Fig. 4 top) */
    HL_TRACED,     /* every secondary hit lit through its true glossy BSDF lobe, light sampling and
                    * lobe sampling with MIS: the path tracer's estimate of the same paths, for
                    * tests and benchmarks (no vMF approximation, no shared position) */
} hl_mode;

typedef struct {
    hl_mode mode;
    int secondary_rays;                      /* N, 1..HL_MAX_SECONDARY_RAYS */
    int clusters;                            /* K, 1..HL_MAX_CLUSTERS */
    const struct env_vmf_filter *env_filter; /* the scene's environment, prefiltered; NULL: none */
    int num_punctual;                        /* the scene's point, spot and directional lights (first in its list) */
    int area_lights;                         /* whether it has emissive triangles */
    int share;                               /* neighbouring pixels share their secondary hits */
    float dim_share;   /* with --adapt: pixels whose highlights were below this share leave them; < 0: never */
    float check_share; /* merged: the share of frames checked against the trace (hl_estimate); <= 0: none */
    int choose;        /* merged: pixels may turn to the trace (--merge auto, hl_judge_trace) */
} hl_setup;

/* The highlight settings for scene s from the parameters (defaults filled in, ranges clamped). */
hl_setup hl_setup_from(const scene *s, const vl_params *vp, const struct env_vmf_filter *env_filter);

/* How many of n secondary rays start from point j of `points`: ray k from point k mod points. */
static inline int hl_rays_of_point(int n, int points, int j) { return n / points + (j < n % points); }

/* The highlights of a pixel from its camera hits xs[0..points): light along camera - glossy(x) -
 * glossy(q) - light, reflected toward the camera, the mean over the points, from the setup's N
 * secondary rays shared among them (ray k from point k mod points, its direction point k / points
 * of runs[k mod points], the point's run over frames); each point merges its own lobes. A point
 * without a glossy lobe adds zero. *sharp is set when some point's lobe is sharp (hl_point_sharp):
 * a pixel worth spreading over. Merged, with traced non-NULL: the same hits are also lit through
 * their own lobes, and *traced is the trace's estimate. Counts work into st. */
vec3 hl_estimate(const hl_setup *h, const scene *s, const shading_point *xs, int points, const qmc_run *runs,
                 rng_state *rng, render_stats *st, int *sharp, vec3 *traced);

/* Whether x has a highlight lobe sharp enough that its members take its image (every band of its
 * vMF fit narrow; docs/design.md, "Merging without the sample's spread"). */
int hl_point_sharp(const hl_setup *h, const shading_point *x);

/* The highlights of up to HL_SHARE_POINTS neighbouring pixels' camera hits xs (one each, a 2x2
 * block), which share their secondary hits: each point traces the setup's N rays (N at most
 * HL_SHARE_MAX_RAYS), the one in slot j taking points j N .. j N + N - 1 of the block's run, and
 * every point merges every hit it sees into 2K lobes, weighted by the balance heuristic over the
 * points' sampling densities (docs/design.md, "Hits shared by neighbours"). out[j]: point j's
 * highlights (zero without a glossy lobe). Points whose lobe is sharp (hl_point_sharp) take no
 * part and are left to their own estimator: returns the mask of the others. */
#define HL_SHARE_POINTS 4
unsigned hl_estimate_shared(const hl_setup *h, const scene *s, const shading_point *xs, int m, qmc_run run,
                            const int *slot, rng_state *rngs, render_stats *st, vec3 *out);
#endif
