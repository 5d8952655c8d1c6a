/* glint view: the render side's own parts (view_controller.c, view_render.c), behind
 * view_controller.h: the state the UI's requests and the render thread's results meet in, under one
 * lock, and the render and loading threads. The UI sees none of it. */
#ifndef GLINT_VIEW_RENDER_H
#define GLINT_VIEW_RENDER_H

#include <pthread.h>
#include <stdatomic.h>

#include "view_controller.h"

/* Everything the UI thread and the render side hand each other; every field under lock except
 * abort_frame. */
typedef struct {
    pthread_mutex_t lock;
    /* requests: UI -> render thread */
    camera cam;
    render_params params;
    uint64_t generation; /* bumped by every change that resets the accumulation */
    uint64_t requests;   /* bumped by every change, load read and quit: what the render thread owes */
    double changed_at;   /* when the last such change happened (cli_now) */
    /* how the image is shown: never a reset */
    unsigned show_mask;
    int denoise;            /* the display's filter (denoise.h) on */
    int render_w, render_h; /* requested full resolution */
    char export_path[1024];
    int export_pending;
    char load_path[1024];
    int load_kind;         /* LOAD_* */
    char load_variant[64]; /* a scene load: the material variant to show ("": the defaults)... */
    int load_keep_view;    /* ...from where the view is (a variant switch) */
    int quit;
    uint64_t lights_scene;   /* the scene (info_serial) the light requests below refer to */
    light_edits lights;      /* wanted */
    image_rgb reference_new; /* a new reference for the error, handed over (the render thread frees it) */
    int reference_pending;
    /* Set when the viewer quits, and by a change while a rest update's part is in flight
     * (preemptible): the part stops at its next chunk of pixels, its finished pixels' samples still
     * the display's. A part at rest may be long (the first frame's, its cost not yet known, is a
     * 64th of a frame: a tenth of a second and more at 960x540), and a drag's first step waited for
     * it; while things move a part is short, and a drag's many steps would stop every one. */
    atomic_int abort_frame;
    int preemptible;
    /* The reference's camera (when its description gives one): frames from elsewhere are not
     * measured against it, so the error plot pauses while the view is away. */
    int reference_cam_valid;
    camera reference_cam;
    char reference_lights[4096]; /* its light edits (reference_lights_text), when it has a camera */
    /* Loads (load_kind, load_path) are read by a thread of their own while frames go on and
     * applied between frames; a failed one changes nothing. */
    uint64_t load_requests, loads_done;
    pthread_cond_t load_cond; /* signalled with each request, each result taken, and quit */
    /* The scene the render thread has, for the UI's ray queries (zoom, fly): the UI reads it under
     * scene_lock (never waiting: try-lock), which the render thread holds for writing whenever it
     * changes or replaces the scene. */
    pthread_rwlock_t scene_lock;
    const scene *scene_now;
    /* results: render thread -> UI */
    void (*wake)(void); /* called after each image published (the UI may be waiting for events) */
    image_buf image;
    uint64_t image_serial;
    view_stats stats;
    char message[1200];
    uint64_t message_serial;
    scene_info info;
    uint64_t info_serial;
    /* The environment, kept across scene loads until cleared: a map's path, ENV_SKY or "". */
    char env_now[1024];
    /* refinement stops between frames while paused or at a limit */
    int paused;
    long long spp_limit; /* 0: none */
    double time_limit;   /* seconds since the reset; 0: none */
} shared_state;

/* The render thread's own state (view_render.c). */
typedef struct render_thread render_thread;

/* Creates the session and display for s at sh's requested size, camera and parameters and starts
 * the threads, which then own s. Returns the thread, or NULL with the error in sh->message (s is
 * then still the caller's). */
render_thread *render_thread_start(shared_state *sh, scene *s);
/* Asks the threads to quit (a pending export is still written), waits for them and frees what they
 * own, the scene included. */
void render_thread_stop(render_thread *rt);

#endif
