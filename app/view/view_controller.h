/* glint view: the viewer's render side behind one narrow interface. The UI thread asks (a change of
 * camera, estimator parameters or lights; how the image is shown; the render size; a load, an
 * export, a reference; pause and limits) and takes what came of it (the newest image shown, the one
 * statistics record of ui/view_stats.h, messages, the scene's description), never waiting for a
 * frame. Behind it a render thread renders parts of frames into the display pipeline
 * (renderer/display.h) and a loading thread reads files; no window, no GL. */
#ifndef GLINT_VIEW_CONTROLLER_H
#define GLINT_VIEW_CONTROLLER_H

#include <stddef.h>
#include <stdint.h>

#include "session.h"
#include "view_state.h"
#include "view_stats.h"

typedef struct view_controller view_controller;

/* The first state: what to render, from where, at what size, and how it is shown. */
typedef struct {
    camera cam;
    render_params params;
    int width, height;
    const char *env; /* the environment the scene came with: a map's path, or NULL */
    int denoise;
    void (*wake)(void); /* called (on the render thread) whenever a new image is there; NULL: none */
} view_start;

/* Starts the threads, which then own s. Returns NULL with err set (s is then still the caller's). */
view_controller *controller_start(scene *s, const view_start *start, char *err, size_t errlen);
/* Quits (a pending export is still written), waits for the threads and frees what they own, the
 * scene included; the statistics as they stood at the end into *last (NULL: not wanted). */
void controller_stop(view_controller *c, view_stats *last);

/* ---- requests: each returns at once --------------------------------------------------------- */

/* A change that restarts the estimate: the camera, the estimator's parameters (method, max depth,
 * many-light and highlight options), the lights as edited for the scene of info serial
 * lights_scene (edits meant for a scene since replaced are dropped). Returns its generation. */
uint64_t controller_change(view_controller *c, const camera *cam, const render_params *p, const light_edits *lights,
                           uint64_t lights_scene);
/* How the image is shown (the film components in mask, the display's filter): never a restart.
 * In place of light, SHOW_ESTIMATOR_SHARE as the mask shows the share of each pixel's film
 * samples the virtual lights gave (session_vl_share: 0 path tracing, 1 the virtual lights),
 * SHOW_WORK_MAP the rays they took against the image's most (session_work_map, 0 to 1). */
#define SHOW_ESTIMATOR_SHARE (1u << 31)
#define SHOW_WORK_MAP (1u << 30)
void controller_set_look(view_controller *c, unsigned show_mask, int denoise);
/* The render size (the next change restarts at it) and the one asked for last. */
void controller_set_size(view_controller *c, int width, int height);
void controller_size(view_controller *c, int *width, int *height);
/* Writes the film (the estimate) to path after the frame under way, before any later change. */
void controller_export(view_controller *c, const char *path);
/* Reads a scene (kind LOAD_SCENE; variant "" for the defaults, keep_view to stay at the view), a
 * map (LOAD_ENV), the uniform sky or no environment on the loading thread while frames go on; a
 * load that fails changes nothing. Returns its serial, for controller_load_settled. */
uint64_t controller_load(view_controller *c, int kind, const char *path, const char *variant, int keep_view);
/* Whether load `serial` has been tried and its outcome (a new scene: info serial info_serial) taken. */
int controller_load_settled(view_controller *c, uint64_t serial, uint64_t info_serial);
/* A reference for the errors (taken over; an empty image: none), measured only from cam with lights
 * (reference_lights_text) when cam is not NULL. */
void controller_set_reference(view_controller *c, image_rgb *ref, const camera *cam, const char *lights);
/* Refinement stops between frames while paused, at spp whole frames or after seconds (0: never). */
void controller_set_refinement(view_controller *c, int paused, long long spp, double seconds);

/* ---- what came of them -------------------------------------------------------------------- */

/* The newest image shown, when its serial is past *serial, swapped into *front (its old buffer goes
 * back for reuse): 1 then. */
int controller_take_image(view_controller *c, uint64_t *serial, image_buf *front);
/* The statistics record as it stands. */
void controller_stats(view_controller *c, view_stats *out);
/* The last message (an export written, a load failed...), when its serial is past *serial: 1 then. */
int controller_take_message(view_controller *c, uint64_t *serial, char *out, size_t n);
/* The scene's description, when its serial is past *serial (a new scene): 1 then. */
int controller_take_info(view_controller *c, uint64_t *serial, scene_info *out);
/* The environment: a map's path, ENV_SKY, or "". */
void controller_env(view_controller *c, char *out, size_t n);
/* The distance to the first surface along o + t d in the scene rendered, INFINITY when none or
 * while the render thread is changing the scene (it never waits). */
float controller_scene_distance(view_controller *c, vec3 o, vec3 d);

/* The stats line's part of the record: " name=value" for each field VIEW_STATS names. */
void view_stats_print(const view_stats *s);

#endif
