/* glint — the unbiased path tracer: next-event estimation with multiple importance sampling
 * (power heuristic) for area and environment lights, Russian roulette, a maximum depth. It is
 * the reference every other estimator is judged against. */
#ifndef GLINT_PT_H
#define GLINT_PT_H

#include "film.h"
#include "params.h"
#include "rng.h"
#include "sampling.h"
#include "scene.h"

/* Radiance along the camera ray (o, d) whose closest hit the caller has traced (first; NULL when
 * the ray escaped), split by path-space component: out[COMP_DIRECT] gets emission
 * seen directly and light arriving at the first hit directly from an emitter, out[COMP_INDIRECT]
 * the rest; with split_highlights, the paths camera - glossy lobe - glossy lobe - light go to
 * out[COMP_HIGHLIGHTS] instead (the highlight estimator's subset, docs/design.md). The direction
 * leaving the first hit is the first point of run (the pixel's run over frames). With glossy (not
 * NULL, COMP_COUNT of them) the part of each component's light that the first hit reflected or
 * transmitted through its view-dependent lobes (BSDF_VIEW_DEPENDENT) goes there too: per sample,
 * f_glossy / f of it, so that it adds up over samples to that lobe's light (a display's; the
 * samples and the random numbers are the same either way). Counts rays into rays[]. */
void pt_radiance(const scene *s, int max_depth, int split_highlights, vec3 o, vec3 d, const surface_hit *first,
                 qmc_run run, rng_state *rng, vec3 out[COMP_COUNT], vec3 *glossy, uint64_t rays[RAY_KIND_COUNT]);

/* Vertices a path may add beyond its depth by transmission alone (panes, a glass's two faces). */
#define PT_MAX_TRANSMISSIONS 32

/* Emission seen directly plus direct light at the camera ray's first hit (the path tracer with
 * max depth 1, so every method shares one direct estimator): one estimate, whose next-event
 * estimation selects its light by u_select in [0, 1) (< 0: drawn), so that a caller taking several
 * can stratify the choice; first and glossy (its one value) as for pt_radiance. Counts one camera
 * ray. */
vec3 pt_direct(const scene *s, vec3 o, vec3 d, const surface_hit *first, float u_select, rng_state *rng, vec3 *glossy,
               uint64_t rays[RAY_KIND_COUNT]);

/* What each of n punctual lights (as given: the display asks what a light brought before an edit)
 * brings to a camera ray's first hit *first along d: the first vertex's next-event estimate of that
 * light in expectation (the lobes' value toward it, its arrival, one shadow ray), into out[k]. The
 * same for every method: they share pt_direct. 0 where the vertex also takes light through rough
 * transmission, which this does not reckon; 1 with out (black where nothing arrives) otherwise.
 * Counts the rays; the hit's material is evaluated once for all of them. */
int pt_punctual_direct(const scene *s, const light *lights, int n, vec3 d, const surface_hit *first, vec3 *out,
                       uint64_t *shadow_rays);

/* How a many-light estimator's traced path widens the glossy lobes of the hit whose direct light it
 * takes (bsdf_regularize; docs/design.md, "Regularised chains" and "Regularised images"): to
 * min_alpha for every light, and to image_alpha (1 + t / d) for a point or spot light at distance d
 * when the ray came t to the hit (image_alpha: its factor times the roughness of the lobe that sent
 * it). Zero: the lobes as they are. */
typedef struct {
    float min_alpha, image_alpha;
} pt_regularize;

/* The same without the emission at the hit (nor the environment when the ray escapes): only
 * light that reaches the hit directly from an emitter and is reflected back along the ray by the
 * hit's BSDF lobes in the mask (BSDF_ALL, or BSDF_NOT_HIGHLIGHT where the highlight lobe's share
 * belongs to the highlight estimator). For estimators that continue a path and must not count the emission
 * their direct light has. The ray travels in a medium of absorption sigma (0: air). With highlights
 * not NULL the ray left the camera hit through its highlight lobe: the part of the light through
 * the hit's highlight lobe goes there, the rest to *direct. reg widens the hit's glossy lobes for
 * its direct light (pt_regularize). */
int pt_reflected_direct(const scene *s, vec3 o, vec3 d, vec3 sigma, int lobes, pt_regularize reg, rng_state *rng,
                        vec3 *direct, vec3 *highlights, surface_hit *first, uint64_t rays[RAY_KIND_COUNT]);

#endif
