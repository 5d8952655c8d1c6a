/* glint — a render session: the scene (read-only), a camera, the parameters, the film and the
 * statistics. Each frame is one pass of fresh samples over the image (one camera sample per
 * pixel); the image is the running mean. */
#ifndef GLINT_SESSION_H
#define GLINT_SESSION_H

#include <stdatomic.h>
#include <stddef.h>

#include "film.h"
#include "params.h"
#include "plan.h"
#include "scene.h"

typedef struct render_session render_session;

/* Creates a session rendering s from cam. The scene must outlive the session. Returns NULL with
 * err set on failure. */
render_session *session_create(const scene *s, const camera *cam, const render_params *params, char *err,
                               size_t errlen);
void session_destroy(render_session *rs);

/* Renders one frame (all threads; returns when done). Returns 0, or -1 with the reason in
 * session_error() when a frame could not be prepared (out of memory; the film is unchanged), or 1
 * when the abort flag stopped it: the frame is not counted, but the tiles rendered before the
 * stop are in the film, so the caller must reset the accumulation. */
int session_render_frame(render_session *rs);
/* A flag the session polls before each tile: while it is non-zero, frames stop early (above).
 * For interactive use, where the change that sets it resets the accumulation anyway. NULL: none. */
void session_set_abort_flag(render_session *rs, const atomic_int *flag);
const char *session_error(const render_session *rs);
/* Clears the accumulation (the next frame starts a new mean) and the statistics with it. */
void session_reset(render_session *rs);
void session_set_camera(render_session *rs, const camera *cam);
/* The camera its frames are rendered from. */
const camera *session_camera(const render_session *rs);
/* The scene changed (a light moved or dimmed, another environment map): analyses it again,
 * re-makes the plan, drops what was derived from the old map and resets.
 * Returns 0, or -1 with session_error() set (out of memory; the old analysis stays). */
int session_scene_changed(render_session *rs);
/* Takes new estimator parameters (method, max_depth, seed; the size and thread count stay) and
 * resets the accumulation. */
void session_set_params(render_session *rs, const render_params *params);

long long session_frames(const render_session *rs);
const film *session_film(const render_session *rs);
const render_params *session_params(const render_session *rs);
render_stats session_stats(const render_session *rs);
/* What the scene calls for (analysed when the session is created) and the passes it runs. */
const scene_analysis *session_analysis(const render_session *rs);
const effect_plan *session_plan(const render_session *rs);

#endif
