/* glint — a geometry buffer: the first hit of each pixel's centre ray (position, normal, depth,
 * material, albedo, how glossy it is). The display pipeline (display.h) reprojects history and
 * guides its filter with it; the estimators never read it, so it changes no estimate. */
#ifndef GLINT_GBUFFER_H
#define GLINT_GBUFFER_H

#include <math.h>
#include <stdint.h>

#include "scene.h"
#include "threadpool.h"

/* Structure of arrays, one entry per pixel, row-major, top row first. */
typedef struct {
    int width, height;
    camera cam;        /* the camera it was traced from */
    float *pos;        /* 3 a pixel: the hit's world position */
    float *normal;     /* 3: the shading normal, turned to face the camera */
    float *depth;      /* distance from the camera along the ray; 0 where the ray escapes */
    float *albedo;     /* 3: the light a pixel reflects per unit light arriving (diffuse + glossy +
                        * transmitted directional albedo at this view), floored at GBUFFER_MIN_ALBEDO:
                        * the display divides the light by it to filter (display.h) */
    float *gloss;      /* the glossy lobe's share of that albedo at this view, 0..1 */
    float *alpha;      /* the glossy lobe's width (microfacet alpha); 1 without a glossy lobe */
    int32_t *material; /* the material's index; -1 where the ray escapes */
} gbuffer;

/* The share of a point's light that its glossy lobe (albedo share gloss, width alpha) may bring, at
 * worst: a lobe alpha wide peaks about 1 / alpha^2 above a diffuse lobe of the same albedo, so where
 * it reflects a light the highlight outshines the rest though its share of the albedo is small
 * (docs/design.md). What the display's history keeps of a turned view, and how sharply its filter
 * tells normals apart, go by it. */
static inline float gbuffer_glossy_share(float gloss, float alpha) {
    float peak = gloss / fmaxf(alpha * alpha, 1e-6f);
    return peak > 0.0f ? peak / (peak + 1.0f - gloss) : 0.0f;
}

/* Below this albedo a channel is not divided any further: a black surface keeps its light. */
#define GBUFFER_MIN_ALBEDO 0.02f

/* Caller's memory: 0, or -1 out of memory (g left empty). */
int gbuffer_init(gbuffer *g, int width, int height);
void gbuffer_deinit(gbuffer *g);
/* Traces every pixel's centre ray of cam (pixel (x, y) at x + 0.5, y + 0.5, as the film's pixels
 * are) on pool's threads (NULL: the calling thread). */
void gbuffer_trace(gbuffer *g, const scene *s, const camera *cam, threadpool *pool);

/* Where world points land in g's camera, set up once (gbuffer_projector) so that each point is a few
 * multiplies: image coordinates (pixel (x, y) spans [x, x + 1)); 0 when p is behind the camera. */
typedef struct {
    vec3 position, right, up, forward;
    float sx, sy;         /* pixels per unit of tangent across and up */
    float half_w, half_h; /* the image's centre */
} gbuffer_projector;
gbuffer_projector gbuffer_projector_of(const gbuffer *g);
/* The arithmetic alone, without a test (a loop over many points stays vector code): (x, y), and
 * the depth along the view as the result; (x, y) mean nothing where it is not above 0. */
static inline float gbuffer_project_raw(const gbuffer_projector *pr, vec3 p, float *x, float *y) {
    vec3 d = sub3(p, pr->position);
    float z = dot3(d, pr->forward), iz = 1.0f / (z > 0.0f ? z : 1.0f);
    *x = pr->half_w + dot3(d, pr->right) * iz * pr->sx;
    *y = pr->half_h - dot3(d, pr->up) * iz * pr->sy;
    return z;
}
static inline int gbuffer_project_with(const gbuffer_projector *pr, vec3 p, float *x, float *y) {
    float ox, oy;
    if (!(gbuffer_project_raw(pr, p, &ox, &oy) > 0.0f)) return 0;
    *x = ox, *y = oy;
    return isfinite(*x) && isfinite(*y);
}
int gbuffer_project(const gbuffer *g, vec3 p, float *x, float *y);

#endif
