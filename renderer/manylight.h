/* glint — the many-light methods' frame: trace a fresh set of virtual lights, give VSLs their
 * radii, optionally cluster the lights by matrix row-column sampling, then shade pixels from
 * them. The session calls manylight_begin_frame once per frame and manylight_shade per pixel. */
#ifndef GLINT_MANYLIGHT_H
#define GLINT_MANYLIGHT_H

#include "camera.h"
#include "lighttree.h"
#include "params.h"
#include "pixel_alloc.h"
#include "plan.h"
#include "sampling.h"
#include "threadpool.h"
#include "vsl.h"

/* One light the pixels shade from: a virtual light (a cluster's representative) and the factor
 * its contribution is scaled by (cluster norm / representative norm; 1 without clustering). */
typedef struct {
    int light;
    float scale;
} ml_entry;

typedef struct {
    vl_kernel kernel;
    vl_terms terms;
    int all_strategies;    /* the three-strategy VSL integral for every pair (the plan's choice) */
    int clamp;             /* on for this method? */
    float clamp_bound;     /* this frame's bound */
    float radius_mult;     /* this frame's multiplier */
    int per_pixel;         /* 0: every entry */
    int candidates;        /* resampling candidates at the camera hit (1: the draws are shaded as they come) */
    int candidates_beyond; /* ... and at a path's later hits */
    float trace_alpha;     /* glossy lobes sharper than this are traced through, not gathered */
    float reg_alpha;       /* this frame's roughness floor at hits lit through two traced lobes or more (0: off) */
    float reg_image;       /* this frame's factor on the sending lobe's roughness at a traced hit (0: off) */
    int glossy_split;      /* directions traced through such a lobe at the camera hit (the mean with adapt) */
    int glass;             /* the scene has transmissive materials: gathered paths are also traced through them */
    vlight_set set;
    ml_entry *entries;
    int num_entries, cap_entries;
    alias_table pick; /* per-pixel choice of entries: by cluster norm, or by light power */
    lighttree tree;   /* ... or by the light tree (use_tree) */
    int use_tree;
    int clustered; /* entries came from matrix row-column sampling this frame */
} manylight;

void manylight_deinit(manylight *m);

/* Prepares frame `frame` (0 = first of the running mean) of method p->method as the plan says
 * (its depth, whether highlights own the glossy-glossy paths, the VSL kernel). Uses the pool for
 * the sampled rows of the reduced matrix. Returns 0, or -1 with err set (out of memory). */
int manylight_begin_frame(manylight *m, const scene *s, const camera *cam, const render_params *p,
                          const effect_plan *plan, long long frame, threadpool *pool, render_stats *st, char *err,
                          size_t errlen);

/* Light at x from this frame's virtual lights (visibility, clamping, scaling included), the paths
 * in `terms` (the frame's m->terms at the camera hit, VL_TERMS_ALL beyond), resampled from
 * `candidates` draws (m->candidates at the camera hit, m->candidates_beyond further on). */
vec3 manylight_shade(const manylight *m, const scene *s, const shading_point *x, vl_terms terms, int candidates,
                     rng_state *rng, render_stats *st);

/* Indirect light at the camera hit x (scattering event 1 of at most max_depth), of the paths in
 * m->terms there; with highlights not NULL (a pixel whose highlights the virtual lights take), of
 * every path, the highlights' own (pt.c's split) added to *highlights. Gathered from the virtual
 * lights, except through a glossy lobe sharper than trace_alpha, where a handful of lights cannot
 * represent the incoming light: that lobe is sampled, and the path picks up the direct light at
 * the next hit and gathers there (the same rule again). At the camera hit the lobe is sampled in
 * `split` directions, the first `split` points of seq (the pixel's run); rec, when not NULL,
 * records each one's light. With glossy (not NULL), the part of the result whose path left x through
 * its traced lobes (a glossy lobe sharper than trace_alpha, a transmission) goes there too: the
 * part that moves over x as the view turns, for a display. So does all the gathered lobes' light
 * where they hold a glossy lobe (rougher than trace_alpha): a rough lobe that reflects a bright
 * patch moves it too, and the gather does not tell the lobes apart (docs/design.md). */
vec3 manylight_indirect(const manylight *m, const scene *s, const shading_point *x, vec3 *highlights, vec3 *glossy,
                        int max_depth, int split, qmc_run seq, pixel_record *rec, rng_state *rng, render_stats *st);

/* The camera hit as a shading point (BSDF looked up, wo toward the viewer). */
shading_point shading_point_at(const scene *s, const surface_hit *h, vec3 ray_dir);

/* The schedules that make the progressive estimates consistent (docs/design.md): the VSL radius
 * multiplier at frame index i >= 1, mult * prod_{k<i} sqrt((k + a) / (k + 1)), and the clamp
 * bound c i^growth. a <= 0 or growth <= 0 leave them constant. */
float vsl_radius_mult_at(float mult, float shrink, long long i);
float vpl_clamp_at(float c, float growth, long long i);

#endif
