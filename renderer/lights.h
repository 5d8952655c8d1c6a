/* glint — lights: next-event estimation's candidates and the light it keeps, sampling a light from
 * a shading point, the matching pdfs for multiple importance sampling, selection by power for
 * emission, and the environment map. */
#ifndef GLINT_LIGHTS_H
#define GLINT_LIGHTS_H

#include "rng.h"
#include "scene.h"

typedef struct {
    int light;     /* index into scene.lights */
    vec3 wi;       /* unit direction from the shading point toward the light */
    float dist;    /* distance to the sampled point; INFINITY for directional and environment */
    vec3 p_light;  /* the sampled point (area lights, point and spot lights) */
    vec3 n_light;  /* its geometric normal, facing the shading point (area lights) */
    vec3 radiance; /* area/environment: radiance arriving along -wi; delta lights: the
                     * irradiance-like value intensity/d^2 (or lux) */
    float pdf;     /* solid-angle pdf times the selection probability; for delta lights just
                     * the selection probability */
    int delta;     /* a point, spot or directional light: no MIS possible */
} light_sample;

/* Picks a light by power (u_select) among those next-event estimation draws rather than takes each,
 * and a point or direction on it (u) as seen from p. Returns 0 when the sample carries nothing (no
 * such lights, back of a single-sided emitter, outside a spot cone, zero pdf). */
int light_sample_direct(const scene *s, vec3 p, float u_select, vec2 u, light_sample *out);

/* The same for one given light (index into scene.lights), as if it were always chosen: the pdf
 * has no selection probability in it. */
int light_sample_one(const scene *s, int light, vec3 p, vec2 u, light_sample *out);

/* The same for a punctual light given as it is (its light index -1): the display asks what a light
 * brought before an edit. 0 for another kind of light, or where nothing arrives (outside a spot's
 * cone). */
int light_sample_punctual(const light *l, vec3 p, light_sample *out);

/* What of the sampled light reaches p (geometric normal ng), p in a medium of absorption sigma:
 * one shadow ray, offset off p's surface toward the light, ending short of the sampled point (off
 * the emitter) or unbounded for directional and environment light; it passes smooth unbent glass
 * (scene_transmittance). Black when blocked. Counts the ray into *shadow_rays. */
vec3 light_sample_visible(const scene *s, vec3 p, vec3 ng, const light_sample *ls, vec3 sigma, uint64_t *shadow_rays);

/* A ray leaving a light, for light tracing (virtual lights). */
typedef struct {
    vec3 o, d;      /* origin and unit direction */
    vec3 power;     /* flux carried by this one sample: emitted radiance x cos / (pdf of origin,
                     * direction and light selection); the mean over samples is the total power */
    vec3 n;         /* area lights: the emitting side's normal (the origin needs an offset) */
    int on_surface; /* the origin lies on an emissive triangle */
} light_emission;

/* Picks a light by power (u_select) and samples an emitted ray from it: a point (u_pos) and a
 * direction (u_dir). Directional and environment light enter through a disk of the scene's
 * bounding-sphere radius. Returns 0 when the sample carries nothing. */
int light_sample_emission(const scene *s, float u_select, vec2 u_pos, vec2 u_dir, light_emission *out);

/* The pdf light_sample_direct would have given for reaching emissive triangle light `light` at
 * hit h from p: selection probability times area-to-solid-angle density. */
float light_pdf_triangle(const scene *s, int light, vec3 p, const surface_hit *h);
/* The pdf light_sample_direct would have given for the environment along direction d. */
float light_pdf_env(const scene *s, vec3 d);

/* Next-event estimation's two multiple-importance weights (the power heuristic, one sample each),
 * the one rule the path tracer and the highlight estimator share. For a light sample: against the
 * lobe that could have found the same direction (lobe_pdf, solid angle); a delta light cannot be
 * found, so 1. For emission found by sampling the lobe from p, directly or beyond glass that
 * shadow rays pass (docs/design.md, "Transmission and volume"): against light_sample_direct's pdf
 * for the same point (h: an emissive triangle's hit; NULL: the environment along d). */
static inline float nee_light_weight(const light_sample *ls, float lobe_pdf) {
    return ls->delta ? 1.0f : mis_power(ls->pdf, lobe_pdf);
}
float nee_emission_weight(const scene *s, vec3 p, const surface_hit *h, vec3 d, float lobe_pdf);

/* A lobe as next-event estimation sees it: its value toward the light sample (f times the cosine,
 * or a merged lobe's value) and, unless the light is delta, the pdf with which the lobe's own
 * sampling finds that direction. Black means no shadow ray. */
typedef vec3 (*nee_lobe_fn)(const void *lobe, const light_sample *ls, float *lobe_pdf);

/* Next-event estimation, the one routine. Its candidates: each punctual light (up to NEE_EACH_MAX
 * of them; more are drawn with the rest) and one light drawn by power from the rest (u_select, a
 * point on it by u), each kept only above the geometric surface (ng) and valued by the lobe (*f
 * for the one kept). Of several it keeps one in proportion to what each would bring before its
 * shadow ray (resampled importance sampling over candidates of disjoint kinds, the pick from rng):
 * a spot of little power in the sharp lobe that faces it, which a draw by power mostly missed, is
 * nearly always the one (docs/design.md, "Which light a sample takes"). The MIS weights keep the
 * draw's density. One shadow ray (through smooth unbent glass, from a medium of absorption sigma:
 * light_sample_visible). Returns the kept light's weighted arrival (black when nothing arrives);
 * the contribution is *f times it. *ls (optional) receives its sample. */
#define NEE_EACH_MAX 8
/* How many of a scene's punctual lights next-event estimation takes each: all, up to NEE_EACH_MAX;
 * past that none (they are drawn with the rest). It draws as well when other lights remain. */
static inline int nee_each_count(int punctual) { return punctual <= NEE_EACH_MAX ? punctual : 0; }
vec3 nee_direct(const scene *s, vec3 p, vec3 ng, vec3 sigma, float u_select, vec2 u, rng_state *rng, nee_lobe_fn lobe,
                const void *ctx, uint64_t *shadow_rays, vec3 *f, light_sample *ls);

/* Rebuilds the light list after geometry, materials or the environment changed: keeps the
 * punctual lights, re-derives emissive triangles and the environment light, powers and the
 * selection distribution. Returns 0 or -1 with err set. */
int scene_build_lights(scene *s, char *err, size_t errlen);

#endif
