/* glint view: the plain data the UI and the render side hand each other (view_controller.h): light
 * edits, an image shown and what it shows, a scene's description, and what a load reads. */
#ifndef GLINT_VIEW_STATE_H
#define GLINT_VIEW_STATE_H

#include <stddef.h>
#include <stdint.h>

#include "scene.h"

#define MAX_VIEW_CAMERAS 32
#define MAX_LIGHT_GROUPS 64  /* lights the viewer lists and edits; more are rendered, not listed */
#define MAX_VIEW_VARIANTS 64 /* material variants the panel lists */

/* Light edits: the offset and intensity multiplier of every light, against the scene as loaded. */
typedef struct {
    vec3 offset[MAX_LIGHT_GROUPS];
    float gain[MAX_LIGHT_GROUPS];
} light_edits;

/* The scene as loaded: no light edits. */
void clear_light_edits(light_edits *e);
/* The edits as a description gives them (reference_lights_text); "" when none. */
void light_edits_text(const light_edits *e, char *out, size_t n);

/* An image shown and what it shows: the camera and lights it was rendered with travel with it, as
 * the UI's may have moved on since. */
typedef struct {
    float *rgb;
    int width, height;
    int full_w, full_h;  /* the render size it belongs to */
    uint64_t generation; /* the change it shows */
    camera cam;
    light_edits lights;
    long long frames;    /* frames of the film behind it (the display adds what came before) */
    uint64_t seed;       /* the film's random seed (each accumulation its own) */
    int denoise;         /* resolved with the display's filter on */
    unsigned mask;       /* what it shows: the film components, SHOW_ESTIMATOR_SHARE or SHOW_WORK_MAP */
    double published_at; /* cli_now() */
} image_buf;

/* What the UI knows of a scene: its name, cameras, bounds and lights as loaded. */
typedef struct {
    char name[1024];
    int num_cameras;
    camera cameras[MAX_VIEW_CAMERAS];
    bounds3 bounds;
    float diag;
    int num_lights;
    light_group lights[MAX_LIGHT_GROUPS]; /* as loaded */
    int unlit;                            /* no light of its own (punctual or emissive): black without an environment */
    /* material variants (KHR_materials_variants): names, the one shown (-1: the defaults) */
    int num_variants, variant;
    char variant_names[MAX_VIEW_VARIANTS][64];
    int kept_view; /* it replaced the last scene to show another variant: the view stays */
} scene_info;

void fill_scene_info(scene_info *info, const scene *s);

#define ENV_SKY "sky" /* the uniform sky's name in requests and controller_env */
/* What a load reads. */
enum { LOAD_NONE = 0, LOAD_SCENE, LOAD_ENV, LOAD_SKY, LOAD_NO_ENV };

#endif
