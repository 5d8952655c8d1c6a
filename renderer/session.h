/* glint — a render session: the scene (read-only), a camera, the parameters, the film and the
 * statistics. Each frame is one pass of fresh samples over the image (one camera sample per
 * pixel); the image is the running mean. */
#ifndef GLINT_SESSION_H
#define GLINT_SESSION_H

#include <stddef.h>
#include <stdint.h>

#include "film.h"
#include "scene.h"

typedef enum {
    METHOD_PT = 0, /* unbiased path tracing: the reference */
    METHOD_COUNT
} render_method;

/* "pt", ...; method_from_name returns -1 for an unknown name. */
const char *method_name(render_method m);
int method_from_name(const char *name);

#define DEFAULT_MAX_DEPTH 16

/* Zero means default for every field. */
typedef struct {
    int width, height;    /* 0: 960 x 540 */
    render_method method;
    int max_depth;        /* scattering events per path; 0: DEFAULT_MAX_DEPTH; 1 is direct light only */
    uint64_t seed;
    int threads;          /* 0: one per core */
} render_params;

/* Work done, by kind of ray; summed over the session's frames. */
typedef enum { RAY_CAMERA = 0, RAY_SHADOW, RAY_BOUNCE, RAY_KIND_COUNT } ray_kind;
extern const char *const ray_kind_names[RAY_KIND_COUNT];

typedef struct {
    uint64_t rays[RAY_KIND_COUNT];
    uint64_t rejected_samples; /* samples dropped because they were NaN or Inf */
} render_stats;

typedef struct render_session render_session;

/* Creates a session rendering s from cam. The scene must outlive the session. Returns NULL with
 * err set on failure. */
render_session *session_create(const scene *s, const camera *cam, const render_params *params, char *err,
                               size_t errlen);
void session_destroy(render_session *rs);

/* Renders one frame (all threads; returns when done). */
void session_render_frame(render_session *rs);
/* Clears the accumulation (the next frame starts a new mean). */
void session_reset(render_session *rs);
void session_set_camera(render_session *rs, const camera *cam);
/* Takes new estimator parameters (method, max_depth, seed; the size and thread count stay) and
 * resets the accumulation. */
void session_set_params(render_session *rs, const render_params *params);

long long session_frames(const render_session *rs);
const film *session_film(const render_session *rs);
const render_params *session_params(const render_session *rs);
render_stats session_stats(const render_session *rs);

#endif
