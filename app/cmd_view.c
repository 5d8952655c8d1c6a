/* glint view: the interactive, progressive viewer.
 *
 * Two threads. The render thread owns the scene and the render sessions: it renders frame after
 * frame, applies requested changes between frames, and publishes each resolved image by swapping
 * buffers under a lock held only for the swap. The UI thread owns the window: it handles input
 * and scripts, tone-maps and draws the newest image, and never waits for a frame.
 *
 * While the camera moves, frames come from a preview session at a fraction of the resolution
 * (coarser while its frames are slow) so the image follows the input; once things rest, the
 * full-resolution session accumulates.
 *
 * Lights are edited the same way: the UI keeps the wanted offset and intensity of every light and
 * sends them with each change; the render thread applies the difference to the scene between
 * frames, when nothing reads it. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <GLFW/glfw3.h>

#include "camera.h"
#include "cli.h"
#include "commands.h"
#include "metrics.h"
#include "session.h"
#include "ui.h"
#include "view_script.h"

#define PREVIEW_DIVISOR 3      /* preview resolution = full / 3 on each axis, or coarser... */
#define PREVIEW_MAX_DIVISOR 8
#define PREVIEW_TARGET_MS 70.0 /* ...so that a preview frame takes about this long */
#define PREVIEW_HOLD_SECONDS 0.3
#define MAX_VIEW_CAMERAS 32
#define MAX_LIGHT_GROUPS 64    /* lights the viewer lists and edits; more are rendered, not listed */
#define MAX_CURVES 6           /* error curves kept for comparison */
#define MAX_CURVE_POINTS 512   /* per curve; halved (every other point) when full */

/* ---- shared state --------------------------------------------------------------------------- */

typedef struct {
    float *rgb;
    int width, height;
    int preview;
} image_buf;

typedef struct {
    char name[1024];
    int num_cameras;
    camera cameras[MAX_VIEW_CAMERAS];
    bounds3 bounds;
    float diag;
    int num_lights;
    light_group lights[MAX_LIGHT_GROUPS]; /* as loaded */
} scene_info;

/* Light edits: the offset and intensity multiplier of every light, against the scene as loaded. */
typedef struct {
    vec3 offset[MAX_LIGHT_GROUPS];
    float gain[MAX_LIGHT_GROUPS];
} light_edits;

/* What the render thread reports about its frames. It writes them under the lock; the UI thread
 * copies them as a whole with each image it takes. */
typedef struct {
    uint64_t frames_generation; /* the request generation those frames show */
    long long frames;        /* full-resolution frames since the last reset */
    uint64_t frames_total;   /* full-resolution frames ever */
    uint64_t resets;
    double reset_at, frame_ms, rays_per_second;
    unsigned long long rejected;
    unsigned long long virtual_lights;
    char plan[1200];         /* the full-resolution session's effect plan, one pass a line */
    int plan_highlights;
    unsigned long long hl_points, hl_lobes; /* the last full-resolution frame's (vsl+hl) */
    double hl_merge_share;   /* its thread time spent merging, as a fraction */
    double rel_error;        /* the last full-resolution frame's against the reference */
    double rel_error_at;     /* ... and its seconds since the reset */
    uint64_t rel_error_serial, rel_error_resets;
    uint64_t preview_frames; /* reduced-resolution frames published, ever */
} view_stats;

typedef struct {
    pthread_mutex_t lock;
    /* requests: UI -> render thread */
    camera cam;
    render_params params;
    uint64_t generation;     /* bumped by every change that resets the accumulation */
    double changed_at;       /* when the last such change happened (cli_now) */
    unsigned show_mask;
    int render_w, render_h;  /* requested full resolution */
    char export_path[1024];
    int export_pending;
    char load_path[1024];
    int load_kind;           /* 0 none, 1 scene, 2 environment map */
    int quit;
    uint64_t lights_scene;   /* the scene (info_serial) the light requests below refer to */
    light_edits lights;      /* wanted */
    image_rgb reference_new; /* a new reference for the error, handed over (the render thread frees it) */
    int reference_pending;
    /* results: render thread -> UI */
    image_buf image;
    uint64_t image_serial;
    view_stats stats;
    char message[1200];
    uint64_t message_serial;
    scene_info info;
    uint64_t info_serial;
} shared_state;

typedef struct {
    shared_state sh;
    scene *scene;                       /* render thread */
    render_session *full, *preview;     /* render thread */
    image_buf back;                     /* render thread */
    light_edits lights_applied;         /* render thread: the edits the scene has */
    image_rgb reference;                /* render thread: for the error of each frame */
    float *combined;                    /* render thread: the whole image when another part is shown */
    size_t combined_len;
    int preview_divisor;                /* render thread */
    /* Set by the UI thread with every change that resets the accumulation, cleared by the render
     * thread when it takes the change: a full-resolution frame in flight stops at its next tile,
     * so a slow frame never holds up the first preview of a new view. */
    atomic_int abort_frame;
    int scene_edited;                   /* render thread: lights changed since the plan was made */
    int full_film_partial;              /* render thread: a stopped frame left samples in the full
                                         * film; cleared by the next full frame that completes */
} viewer;

static double seconds_since(double t) { return cli_now() - t; }

/* ---- render thread -------------------------------------------------------------------------- */

static void fill_info(scene_info *info, const scene *s) {
    snprintf(info->name, sizeof info->name, "%s", s->path);
    info->num_cameras = s->num_cameras < MAX_VIEW_CAMERAS ? s->num_cameras : MAX_VIEW_CAMERAS;
    for (int i = 0; i < info->num_cameras; i++) info->cameras[i] = s->cameras[i];
    info->bounds = s->bounds;
    info->diag = s->diag;
    int n = scene_light_groups(s, info->lights, MAX_LIGHT_GROUPS); /* -1 (out of memory): none listed */
    info->num_lights = n < 0 ? 0 : n < MAX_LIGHT_GROUPS ? n : MAX_LIGHT_GROUPS;
}

/* The scene as loaded: no light edits. */
static void clear_light_edits(light_edits *e) {
    for (int g = 0; g < MAX_LIGHT_GROUPS; g++) {
        e->offset[g] = v3(0, 0, 0);
        e->gain[g] = 1.0f;
    }
}

static void set_message(viewer *v, const char *fmt, const char *a, const char *b) {
    pthread_mutex_lock(&v->sh.lock);
    snprintf(v->sh.message, sizeof v->sh.message, fmt, a, b);
    v->sh.message_serial++;
    pthread_mutex_unlock(&v->sh.lock);
}

/* A preview session at the full session's size / divisor. NULL with err set on failure. */
static render_session *create_preview(viewer *v, int divisor, const camera *cam, const render_params *params, char *err,
                                      size_t errlen) {
    const render_params *fp = session_params(v->full);
    render_params p = *params;
    p.width = fp->width / divisor > 0 ? fp->width / divisor : 1;
    p.height = fp->height / divisor > 0 ? fp->height / divisor : 1;
    /* No abort flag: while things move every preview frame must finish, or none would be shown. */
    return session_create(v->scene, cam, &p, err, errlen);
}

/* (Re)creates both sessions for the current scene at w x h. Returns 0 or -1 (message set). */
static int make_sessions(viewer *v, int w, int h, const camera *cam, const render_params *params) {
    session_destroy(v->full);
    session_destroy(v->preview);
    v->full = v->preview = NULL;
    render_params p = *params;
    char err[512];
    p.width = w;
    p.height = h;
    v->full = session_create(v->scene, cam, &p, err, sizeof err);
    if (v->full) session_set_abort_flag(v->full, &v->abort_frame);
    v->full_film_partial = 0; /* a new film */
    if (v->preview_divisor < PREVIEW_DIVISOR) v->preview_divisor = PREVIEW_DIVISOR;
    if (v->full) v->preview = create_preview(v, v->preview_divisor, cam, params, err, sizeof err);
    if (!v->full || !v->preview) {
        set_message(v, "%s%s", err, "");
        return -1;
    }
    return 0;
}

/* Coarser previews when their frames are slow (a large window, a costly method, a busy
 * machine), finer again when they are quick, so the image follows motion at about 10 frames a
 * second or more. The thresholds leave room: one step changes the time by a factor of 0.56 to
 * 0.77, less than their ratio. */
static void adapt_preview(viewer *v, double frame_ms, const camera *cam, const render_params *params) {
    int d = v->preview_divisor;
    if (frame_ms > 1.3 * PREVIEW_TARGET_MS && d < PREVIEW_MAX_DIVISOR) d++;
    else if (frame_ms < 0.45 * PREVIEW_TARGET_MS && d > PREVIEW_DIVISOR) d--;
    if (d == v->preview_divisor) return;
    char err[512];
    render_session *p = create_preview(v, d, cam, params, err, sizeof err);
    if (!p) return; /* keep the one there is */
    session_destroy(v->preview);
    v->preview = p;
    v->preview_divisor = d;
}

static void handle_load(viewer *v, int kind, const char *path, const camera *cam, const render_params *params) {
    char err[1024];
    if (kind == 1) {
        scene *s = scene_load(path, cli_print_warning, NULL, err, sizeof err);
        if (!s) {
            cli_error("%s", err);
            set_message(v, "%s%s", err, "");
            return;
        }
        /* The sessions read the old scene: replace them with it. */
        int w = session_params(v->full)->width, h = session_params(v->full)->height;
        session_destroy(v->full);
        session_destroy(v->preview);
        v->full = v->preview = NULL;
        scene_destroy(v->scene);
        v->scene = s;
        clear_light_edits(&v->lights_applied);
        camera c = scene_camera(s, -1, (float)w / (float)h);
        make_sessions(v, w, h, &c, params);
        pthread_mutex_lock(&v->sh.lock);
        fill_info(&v->sh.info, s);
        v->sh.info_serial++;
        pthread_mutex_unlock(&v->sh.lock);
        set_message(v, "loaded %s%s", path, "");
    } else {
        if (scene_set_env(v->scene, path, 0.0f, err, sizeof err) != 0) {
            cli_error("%s", err);
            set_message(v, "%s%s", err, "");
            return;
        }
        session_set_camera(v->full, cam);
        session_set_camera(v->preview, cam);
        set_message(v, "environment %s%s", path, "");
    }
}

/* Brings the scene's lights to the wanted offsets and gains (render thread, between frames). */
static void apply_light_edits(viewer *v, const light_edits *wanted) {
    char err[512];
    light_edits *done = &v->lights_applied;
    for (int g = 0; g < MAX_LIGHT_GROUPS; g++) {
        vec3 d = sub3(wanted->offset[g], done->offset[g]);
        float gain = wanted->gain[g];
        int failed = !is_black3(d) && scene_move_light(v->scene, g, d, err, sizeof err) != 0;
        failed = failed || (gain != done->gain[g] && scene_set_light_gain(v->scene, g, gain, err, sizeof err) != 0);
        if (failed) {
            cli_error("%s", err);
            set_message(v, "%s%s", err, "");
        }
        /* Taken as applied either way: a failed edit is reported once, not every frame. */
        v->scene_edited |= !is_black3(d) || gain != done->gain[g];
        done->offset[g] = wanted->offset[g];
        done->gain[g] = gain;
    }
}

/* The relative L2 error of the whole image (every component, whatever is shown) against the
 * reference; -1 without a reference of this size. shown is the image resolved with mask. */
static double frame_error(viewer *v, const film *f, unsigned mask, const float *shown) {
    const image_rgb *ref = &v->reference;
    if (!ref->rgb || ref->width != f->width || ref->height != f->height) return -1.0;
    size_t n = 3 * (size_t)f->width * (size_t)f->height;
    const float *img = shown;
    if (mask != COMP_MASK_ALL) {
        if (v->combined_len != n) {
            free(v->combined);
            v->combined = malloc(sizeof(float) * n);
            v->combined_len = v->combined ? n : 0;
            if (!v->combined) return -1.0;
        }
        film_resolve(f, COMP_MASK_ALL, v->combined);
        img = v->combined;
    }
    return metric_rel_l2(img, ref->rgb, n);
}

/* before: the session's statistics before the frame, so the frame's own work is the difference.
 * The film is resolved with the components shown now, not when the frame started: a frame after a
 * display change shows that change. */
static void publish(viewer *v, render_session *rs, int preview, double frame_ms, const render_stats *before,
                    uint64_t resets_seen, uint64_t gen) {
    const film *f = session_film(rs);
    if (v->back.width != f->width || v->back.height != f->height) {
        free(v->back.rgb);
        v->back.rgb = malloc(sizeof(float) * 3 * (size_t)f->width * (size_t)f->height);
        v->back.width = v->back.rgb ? f->width : 0;
        v->back.height = v->back.rgb ? f->height : 0;
        if (!v->back.rgb) return;
    }
    pthread_mutex_lock(&v->sh.lock);
    unsigned mask = v->sh.show_mask;
    pthread_mutex_unlock(&v->sh.lock);
    film_resolve(f, mask, v->back.rgb);
    v->back.preview = preview;
    double rel_error = preview ? -1.0 : frame_error(v, f, mask, v->back.rgb);
    render_stats st = session_stats(rs);
    uint64_t rays = 0;
    for (int k = 0; k < RAY_KIND_COUNT; k++) rays += st.rays[k];
    double thread_ns = 1e6 * frame_ms * (double)session_params(rs)->threads;
    double merge_share = thread_ns > 0.0 ? (double)(st.hl_merge_ns - before->hl_merge_ns) / thread_ns : 0.0;
    pthread_mutex_lock(&v->sh.lock);
    if (v->sh.stats.resets == resets_seen) { /* drop a frame of a state already replaced */
        image_buf t = v->sh.image;
        v->sh.image = v->back;
        v->back = t;
        v->sh.image_serial++;
        if (!preview) {
            v->sh.stats.frames_generation = gen;
            v->sh.stats.frames = session_frames(rs);
            v->sh.stats.frames_total++;
        }
        v->sh.stats.frame_ms = frame_ms;
        double secs = seconds_since(v->sh.stats.reset_at);
        v->sh.stats.rays_per_second = secs > 0.0 && !preview ? (double)rays / secs : 0.0;
        v->sh.stats.rejected = st.rejected_samples;
        if (preview) v->sh.stats.preview_frames++;
        if (!preview && rel_error >= 0.0) {
            v->sh.stats.rel_error = rel_error;
            v->sh.stats.rel_error_at = secs;
            v->sh.stats.rel_error_resets = v->sh.stats.resets;
            v->sh.stats.rel_error_serial++;
        }
        if (!preview) {
            plan_summary(session_plan(rs), v->sh.stats.plan, sizeof v->sh.stats.plan);
            v->sh.stats.plan_highlights = session_plan(rs)->highlights;
            v->sh.stats.virtual_lights = st.virtual_lights;
            v->sh.stats.hl_points = st.hl_points - before->hl_points;
            v->sh.stats.hl_lobes = st.hl_lobes - before->hl_lobes;
            v->sh.stats.hl_merge_share = merge_share;
        }
    }
    pthread_mutex_unlock(&v->sh.lock);
}

static void *render_main(void *arg) {
    viewer *v = arg;
    uint64_t applied = 0;
    pthread_mutex_lock(&v->sh.lock);
    for (;;) {
        /* Exports and loads first: a quit right after an export request still writes it. Not
         * while a stopped frame's samples are in the film: after the next full frame. */
        if (v->sh.export_pending && !v->full_film_partial) {
            char path[1024], err[1200];
            snprintf(path, sizeof path, "%s", v->sh.export_path);
            v->sh.export_pending = 0;
            pthread_mutex_unlock(&v->sh.lock);
            /* Highlights are a layer of their own when the film has them split off (as glint render). */
            const render_params *fp = session_params(v->full);
            int split = fp->pt_highlights || fp->method == METHOD_VSL_HL;
            const unsigned layers = (1u << COMP_DIRECT) | (1u << COMP_INDIRECT) | (split ? 1u << COMP_HIGHLIGHTS : 0u);
            if (film_save_exr(session_film(v->full), layers, path, WRITE_NO_REPLACE, err, sizeof err) != 0) {
                cli_error("%s", err);
                set_message(v, "%s%s", err, "");
            } else {
                printf("glint: wrote %s\n", path);
                fflush(stdout);
                set_message(v, "wrote %s%s", path, "");
            }
            pthread_mutex_lock(&v->sh.lock);
            continue;
        }
        if (v->sh.quit && !(v->sh.export_pending && v->full_film_partial)) break;
        if (v->sh.load_kind) {
            int kind = v->sh.load_kind;
            char path[1024];
            snprintf(path, sizeof path, "%s", v->sh.load_path);
            v->sh.load_kind = 0;
            camera cam = v->sh.cam;
            render_params params = v->sh.params;
            pthread_mutex_unlock(&v->sh.lock);
            handle_load(v, kind, path, &cam, &params);
            pthread_mutex_lock(&v->sh.lock);
            applied = 0; /* re-apply the camera and parameters to the new sessions */
            continue;
        }
        const film *ff = session_film(v->full);
        int resize = ff->width != v->sh.render_w || ff->height != v->sh.render_h;
        uint64_t gen = v->sh.generation;
        atomic_store(&v->abort_frame, 0); /* this change is taken: frames of it run to the end */
        camera cam = v->sh.cam;
        render_params params = v->sh.params;
        int preview = seconds_since(v->sh.changed_at) < PREVIEW_HOLD_SECONDS;
        int rw = v->sh.render_w, rh = v->sh.render_h;
        /* Light requests made for a scene since replaced are stale: the new one starts as loaded. */
        int edit_lights = gen != applied && v->sh.lights_scene == v->sh.info_serial;
        light_edits lights;
        if (edit_lights) lights = v->sh.lights;
        if (v->sh.reference_pending) {
            image_rgb_free(&v->reference);
            v->reference = v->sh.reference_new;
            v->sh.reference_new = (image_rgb){0};
            v->sh.reference_pending = 0;
        }
        if (gen != applied || resize) {
            v->sh.stats.resets++;
            v->sh.stats.reset_at = cli_now();
            v->sh.stats.frames = 0;
        }
        uint64_t resets_seen = v->sh.stats.resets;
        pthread_mutex_unlock(&v->sh.lock);

        if (edit_lights) apply_light_edits(v, &lights);
        /* The scene's analysis follows light edits once they settle, not at every step of a drag. */
        if (v->scene_edited && !preview) {
            if (session_scene_changed(v->full) != 0 || session_scene_changed(v->preview) != 0)
                set_message(v, "%s%s", session_error(v->full), "");
            v->scene_edited = 0;
        }
        if (resize) {
            if (make_sessions(v, rw, rh, &cam, &params) != 0) break;
            applied = gen;
        } else if (gen != applied) {
            session_set_params(v->full, &params);
            session_set_params(v->preview, &params);
            session_set_camera(v->full, &cam);
            session_set_camera(v->preview, &cam);
            applied = gen;
        }
        render_session *rs = preview ? v->preview : v->full;
        render_stats before = session_stats(rs);
        double t0 = cli_now();
        if (session_render_frame(rs) == 1) { /* stopped for a newer change: nothing to show */
            if (rs == v->full) v->full_film_partial = 1;
            pthread_mutex_lock(&v->sh.lock);
            continue;
        }
        if (rs == v->full) v->full_film_partial = 0;
        double ms = 1e3 * seconds_since(t0);
        publish(v, rs, preview, ms, &before, resets_seen, gen);
        if (preview) adapt_preview(v, ms, &cam, &params);
        pthread_mutex_lock(&v->sh.lock);
    }
    pthread_mutex_unlock(&v->sh.lock);
    return NULL;
}

/* ---- camera control (UI thread) --------------------------------------------------------------- */

typedef struct {
    vec3 pos;
    float yaw, pitch; /* radians; yaw 0 looks along -z, pitch up positive */
    float dist;       /* to the orbit centre */
    float yfov;
} cam_ctl;

static vec3 ctl_forward(const cam_ctl *c) {
    return v3(cosf(c->pitch) * sinf(c->yaw), sinf(c->pitch), -cosf(c->pitch) * cosf(c->yaw));
}

static camera ctl_camera(const cam_ctl *c) {
    return camera_look_at(c->pos, add3(c->pos, ctl_forward(c)), v3(0, 1, 0), c->yfov);
}

static cam_ctl ctl_from_camera(const camera *cam, const scene_info *info) {
    cam_ctl c;
    c.pos = cam->position;
    c.yaw = atan2f(cam->forward.x, -cam->forward.z);
    c.pitch = asinf(clampf(cam->forward.y, -0.999f, 0.999f));
    c.yfov = cam->yfov;
    float d = dot3(sub3(bounds_center(info->bounds), cam->position), cam->forward);
    c.dist = fmaxf(d, 0.05f * info->diag);
    return c;
}

static void ctl_orbit(cam_ctl *c, float dyaw, float dpitch) {
    vec3 target = madd3(c->pos, ctl_forward(c), c->dist);
    c->yaw += dyaw;
    c->pitch = clampf(c->pitch + dpitch, -1.55f, 1.55f);
    c->pos = madd3(target, ctl_forward(c), -c->dist);
}

static void ctl_pan(cam_ctl *c, float dx, float dy) {
    camera cam = ctl_camera(c);
    c->pos = add3(c->pos, add3(scale3(cam.right, dx * c->dist), scale3(cam.up, dy * c->dist)));
}

static void ctl_zoom(cam_ctl *c, float factor) {
    vec3 target = madd3(c->pos, ctl_forward(c), c->dist);
    c->dist *= factor;
    c->pos = madd3(target, ctl_forward(c), -c->dist);
}

/* ---- the UI thread ---------------------------------------------------------------------------- */

typedef struct {
    const char *scene_path, *env_path, *script_path;
    int width, height;
    render_params params;
    int camera;
    double exposure;
    int tonemap;
    const char *reference_path;
} view_options;

/* Relative error against seconds since a reset, for one method and setting. */
typedef struct {
    char label[96];
    int n;
    float seconds[MAX_CURVE_POINTS], error[MAX_CURVE_POINTS];
} error_curve;

typedef struct {
    viewer *v;
    GLFWwindow *win;
    ui_controls ctl, applied_ctl;
    cam_ctl cam;
    scene_info info;
    uint64_t info_serial, image_serial, message_serial;
    image_buf front;
    unsigned char *pixels;
    int pixels_cap;
    unsigned texture;
    int tex_w, tex_h;
    int need_tonemap;
    char message[1200];
    view_stats stats; /* copied from the render thread */
    uint64_t sent_generation;
    int preview_w, preview_h; /* the last preview frame's size */
    double started_at;
    light_edits lights; /* the wanted offset and intensity of each, sent with every change */
    char light_labels[MAX_LIGHT_GROUPS][96];
    const char *light_label_ptrs[MAX_LIGHT_GROUPS];
    float light_xy[2 * MAX_LIGHT_GROUPS]; /* window positions, NaN off screen */
    int left_was_down, dragging_light;
    /* camera bookmarks 1-9 of this scene, and their file */
    cam_ctl bookmarks[10];
    int bookmark_set[10];
    char bookmarks_path[1100];
    char bookmarks_text[1200];
    /* the reference image and the error against it */
    image_rgb reference;
    char reference_path[1024];
    double rel_error;
    uint64_t curve_resets;
    error_curve curves[MAX_CURVES];
    int num_curves, current_curve;
    ui_curve ui_curves[MAX_CURVES];
    /* a scripted continuous orbit */
    double spin_rate, spin_until; /* degrees per second, until when */
    /* input */
    double mouse_x, mouse_y;
    double scroll;
    int keys_pressed[GLFW_KEY_LAST + 1];
    double last_time;
    /* script */
    view_script script;
    const char *script_path_for_errors;
    char window_shot[1024]; /* a pending capture of the window, taken after the next draw */
    int script_pos, script_waiting, script_errors;
    long long script_wait_target;
    uint64_t script_wait_generation;
    int quit;
} ui_thread;

static unsigned show_mask_of(int show) {
    switch (show) {
    case UI_SHOW_DIRECT: return 1u << COMP_DIRECT;
    case UI_SHOW_INDIRECT: return 1u << COMP_INDIRECT;
    case UI_SHOW_HIGHLIGHTS: return 1u << COMP_HIGHLIGHTS;
    default: return COMP_MASK_ALL;
    }
}

static void reset_view(ui_thread *u) {
    int w, h;
    glfwGetFramebufferSize(u->win, &w, &h);
    float aspect = h > 0 ? (float)w / (float)h : 16.0f / 9.0f;
    camera c = u->ctl.camera >= 0 && u->ctl.camera < u->info.num_cameras
                   ? u->info.cameras[u->ctl.camera]
                   : (u->info.num_cameras > 0 ? u->info.cameras[0] : camera_frame_bounds(u->info.bounds, 0.8f, aspect));
    u->cam = ctl_from_camera(&c, &u->info);
}

/* The many-light settings the panel edits, onto the parameters (fields it lacks are kept). */
static vl_params vl_from_controls(const ui_controls *c, vl_params vl) {
    vl.clamp = c->clamp;
    vl.clamp_value = c->clamp_value;
    vl.radius_mult = c->radius_mult;
    vl.radius_shrink = c->radius_shrink > 0.0f ? c->radius_shrink : -1.0f;
    vl.count = c->vl_count;
    vl.columns = c->columns;
    vl.per_pixel = c->per_pixel;
    vl.select = c->light_select == 1 ? VL_SELECT_TREE : VL_SELECT_POWER;
    vl.candidates = c->candidates;
    vl.trace_glossy = c->trace_glossy > 0.0f ? c->trace_glossy : -1.0f;
    vl.glossy_rays = c->glossy_rays;
    vl.secondary_rays = c->secondary_rays;
    vl.clusters = c->clusters;
    vl.merge = c->merge == 1 ? HL_MERGE_OFF : c->merge == 2 ? HL_MERGE_TRACE : HL_MERGE_ON;
    return vl;
}

static void controls_from_vl(ui_controls *c, const vl_params *vl) {
    c->clamp = vl->clamp;
    c->clamp_value = vl->clamp_value > 0.0f ? vl->clamp_value : VL_DEFAULT_CLAMP;
    c->radius_mult = vl->radius_mult > 0.0f ? vl->radius_mult : VL_DEFAULT_RADIUS_MULT;
    c->radius_shrink = vl->radius_shrink > 0.0f ? vl->radius_shrink : vl->radius_shrink < 0.0f ? 0.0f : VL_DEFAULT_RADIUS_SHRINK;
    c->vl_count = vl->count > 0 ? vl->count : VL_DEFAULT_COUNT;
    c->columns = vl->columns;
    c->per_pixel = vl->per_pixel != 0 ? vl->per_pixel : (vl->columns > 0 ? -1 : VL_DEFAULT_PER_PIXEL);
    c->light_select = vl->select == VL_SELECT_TREE;
    c->candidates = vl->candidates > 0 ? vl->candidates : VL_DEFAULT_CANDIDATES;
    c->trace_glossy = vl->trace_glossy > 0.0f ? vl->trace_glossy : vl->trace_glossy < 0.0f ? 0.0f : VL_DEFAULT_TRACE_GLOSSY;
    c->glossy_rays = vl->glossy_rays > 0 ? vl->glossy_rays : VL_DEFAULT_GLOSSY_RAYS;
    c->secondary_rays = vl->secondary_rays > 0 ? vl->secondary_rays : HL_DEFAULT_SECONDARY_RAYS;
    c->clusters = vl->clusters > 0 ? vl->clusters : HL_DEFAULT_CLUSTERS;
    c->merge = vl->merge == HL_MERGE_OFF ? 1 : vl->merge == HL_MERGE_TRACE ? 2 : 0;
}

static int vl_controls_differ(const ui_controls *a, const ui_controls *b) {
    return a->clamp != b->clamp || a->clamp_value != b->clamp_value || a->radius_mult != b->radius_mult ||
           a->radius_shrink != b->radius_shrink || a->vl_count != b->vl_count || a->columns != b->columns ||
           a->per_pixel != b->per_pixel || a->light_select != b->light_select || a->candidates != b->candidates ||
           a->trace_glossy != b->trace_glossy || a->glossy_rays != b->glossy_rays ||
           a->secondary_rays != b->secondary_rays || a->clusters != b->clusters || a->merge != b->merge;
}

/* Sends the camera and estimator settings to the render thread; each call is a change that
 * resets the accumulation. */
static void send_change(ui_thread *u) {
    shared_state *sh = &u->v->sh;
    pthread_mutex_lock(&sh->lock);
    sh->cam = ctl_camera(&u->cam);
    sh->params.max_depth = u->ctl.max_depth;
    sh->params.method = (render_method)u->ctl.method;
    sh->params.vl = vl_from_controls(&u->ctl, sh->params.vl);
    sh->lights = u->lights;
    sh->lights_scene = u->info_serial;
    u->sent_generation = ++sh->generation;
    sh->changed_at = cli_now();
    if (!sh->export_pending) atomic_store(&u->v->abort_frame, 1); /* an export takes the frame as asked */
    pthread_mutex_unlock(&sh->lock);
}

/* Full-resolution frames rendered in the state the UI last asked for. */
static long long frames_of_current_state(const ui_thread *u) {
    return u->stats.frames_generation == u->sent_generation ? u->stats.frames : 0;
}

/* Sends what changed in the controls since the last call: estimator settings reset the
 * accumulation; display settings only change how the image is shown. */
static void apply_controls(ui_thread *u, int camera_changed) {
    if (u->ctl.method != u->applied_ctl.method || u->ctl.max_depth != u->applied_ctl.max_depth ||
        vl_controls_differ(&u->ctl, &u->applied_ctl))
        camera_changed = 1;
    /* Picking another light shows its intensity; changing the intensity changes the light. */
    if (u->ctl.light < 0 || u->ctl.light >= u->info.num_lights) u->ctl.light = -1;
    if (u->ctl.light != u->applied_ctl.light) {
        u->ctl.light_gain = u->ctl.light >= 0 ? u->lights.gain[u->ctl.light] : 1.0f;
    } else if (u->ctl.light >= 0 && u->ctl.light_gain != u->applied_ctl.light_gain) {
        u->lights.gain[u->ctl.light] = u->ctl.light_gain;
        camera_changed = 1;
    }
    if (camera_changed) send_change(u);
    if (u->ctl.exposure != u->applied_ctl.exposure || u->ctl.tonemap != u->applied_ctl.tonemap) u->need_tonemap = 1;
    if (u->ctl.show != u->applied_ctl.show) {
        pthread_mutex_lock(&u->v->sh.lock);
        u->v->sh.show_mask = show_mask_of(u->ctl.show);
        pthread_mutex_unlock(&u->v->sh.lock);
        u->need_tonemap = 1;
    }
    u->applied_ctl = u->ctl;
}

/* ---- lights (UI thread) ------------------------------------------------------------------------ */

static vec3 light_position(const ui_thread *u, int g) {
    return add3(u->info.lights[g].center, u->lights.offset[g]);
}

static int light_movable(const ui_thread *u, int g) {
    return g >= 0 && g < u->info.num_lights && u->info.lights[g].type != LIGHT_DIRECTIONAL;
}

/* World units per window pixel at distance z in front of the camera. */
static float pixel_footprint(const ui_thread *u, float z) {
    int wh;
    glfwGetWindowSize(u->win, NULL, &wh);
    return 2.0f * z * tanf(0.5f * u->cam.yfov) / (float)(wh > 0 ? wh : 1);
}

/* Where each light appears in the window (for markers and picking). */
static void update_light_screen(ui_thread *u) {
    int ww, wh;
    glfwGetWindowSize(u->win, &ww, &wh);
    camera c = ctl_camera(&u->cam);
    float t = tanf(0.5f * c.yfov), aspect = wh > 0 ? (float)ww / (float)wh : 1.0f;
    for (int g = 0; g < u->info.num_lights; g++) {
        vec3 d = sub3(light_position(u, g), c.position);
        float z = dot3(d, c.forward);
        u->light_xy[2 * g] = u->light_xy[2 * g + 1] = NAN;
        if (!light_movable(u, g) || !(z > 1e-6f)) continue;
        float x = dot3(d, c.right) / (z * t * aspect), y = dot3(d, c.up) / (z * t);
        u->light_xy[2 * g] = 0.5f * (x + 1.0f) * (float)ww;
        u->light_xy[2 * g + 1] = 0.5f * (1.0f - y) * (float)wh;
    }
}

/* The light drawn nearest to window position (x, y), within a few pixels; -1 for none. */
static int pick_light(ui_thread *u, double x, double y) {
    update_light_screen(u);
    int best = -1;
    double best_d2 = 24.0 * 24.0;
    for (int g = 0; g < u->info.num_lights; g++) {
        double dx = (double)u->light_xy[2 * g] - x, dy = (double)u->light_xy[2 * g + 1] - y;
        double d2 = dx * dx + dy * dy;
        if (d2 < best_d2) best_d2 = d2, best = g;
    }
    return best;
}

/* Moves light g by delta (world units); the caller sends the change. Returns 0, or -1 with a
 * message when g has no position. */
static int move_light(ui_thread *u, int g, vec3 delta, char *err, size_t errlen) {
    if (g < 0 || g >= u->info.num_lights)
        return snprintf(err, errlen, "no light %d (the scene has %d)", g, u->info.num_lights), -1;
    if (!light_movable(u, g))
        return snprintf(err, errlen, "light %d (%s) is directional: it has no position", g, u->info.lights[g].name), -1;
    if (!is_finite3(delta) || length3(delta) > 1e3f * u->info.diag)
        return snprintf(err, errlen, "light %d: move too large", g), -1;
    u->lights.offset[g] = add3(u->lights.offset[g], delta);
    return 0;
}

/* A new scene: its lights as loaded, the first one selected. */
static void reset_lights(ui_thread *u) {
    clear_light_edits(&u->lights);
    static const char *const kinds[] = {"point", "spot", "directional", "area", "environment"};
    for (int g = 0; g < u->info.num_lights; g++) {
        const light_group *lg = &u->info.lights[g];
        snprintf(u->light_labels[g], sizeof u->light_labels[g], "%d: %.60s (%s)", g, lg->name,
                 (unsigned)lg->type < 5 ? kinds[lg->type] : "?");
        u->light_label_ptrs[g] = u->light_labels[g];
    }
    u->ctl.light = u->applied_ctl.light = u->info.num_lights > 0 ? 0 : -1;
    u->ctl.light_gain = u->applied_ctl.light_gain = 1.0f;
}

/* ---- camera bookmarks (UI thread) -------------------------------------------------------------- */

/* Beside the scene file; a built-in scene has none, so NAME.glint-bookmarks in the current
 * directory. */
static void bookmarks_load(ui_thread *u) {
    memset(u->bookmark_set, 0, sizeof u->bookmark_set);
    const char *builtin = scene_builtin_name(u->info.name);
    if (builtin) snprintf(u->bookmarks_path, sizeof u->bookmarks_path, "%s.glint-bookmarks", builtin);
    else snprintf(u->bookmarks_path, sizeof u->bookmarks_path, "%s.bookmarks", u->info.name);
    FILE *f = fopen(u->bookmarks_path, "r");
    if (!f) {
        if (errno != ENOENT) {
            snprintf(u->message, sizeof u->message, "%s: %s; no bookmarks", u->bookmarks_path, strerror(errno));
            cli_warning("%s", u->message);
        }
        return;
    }
    cam_ctl marks[10];
    int set[10] = {0}, bad = 0, lineno = 0;
    char line[512];
    while (!bad && fgets(line, sizeof line, f)) {
        lineno++;
        size_t len = strlen(line);
        if (len == sizeof line - 1 && line[len - 1] != '\n') bad = lineno; /* too long to be ours */
        const char *p = line + strspn(line, " \t");
        if (bad || *p == '#' || *p == '\n' || *p == '\r' || *p == 0) continue;
        int slot, used = 0;
        float x, y, z, yaw, pitch, dist, yfov;
        if (sscanf(p, "%d %f %f %f %f %f %f %f %n", &slot, &x, &y, &z, &yaw, &pitch, &dist, &yfov, &used) != 8 ||
            p[used] != 0 || slot < 1 || slot > 9 || !is_finite3(v3(x, y, z)) || !isfinite(yaw) || !isfinite(pitch) ||
            !(dist > 0.0f && dist < 1e30f) || !(yfov > 0.0f && yfov < 3.1f)) {
            bad = lineno;
            continue;
        }
        marks[slot] = (cam_ctl){v3(x, y, z), yaw, clampf(pitch, -1.55f, 1.55f), dist, yfov};
        set[slot] = 1;
    }
    fclose(f);
    if (bad) {
        snprintf(u->message, sizeof u->message, "%s:%d: not a bookmark line (N x y z yaw pitch distance fov); file ignored",
                 u->bookmarks_path, bad);
        cli_warning("%s", u->message);
        return;
    }
    for (int i = 1; i <= 9; i++)
        if (set[i]) u->bookmarks[i] = marks[i], u->bookmark_set[i] = 1;
}

/* Saves the current view as bookmark slot (1-9), rewriting the file atomically. Returns 0 or -1. */
static int bookmark_save(ui_thread *u, int slot) {
    u->bookmarks[slot] = u->cam;
    u->bookmark_set[slot] = 1;
    char buf[2048], err[1200];
    int len = snprintf(buf, sizeof buf,
                       "# glint camera bookmarks: N, position x y z, yaw and pitch (radians), orbit distance, "
                       "vertical fov (radians)\n");
    for (int i = 1; i <= 9; i++) {
        const cam_ctl *c = &u->bookmarks[i];
        if (u->bookmark_set[i] && len < (int)sizeof buf)
            len += snprintf(buf + len, sizeof buf - (size_t)len, "%d %.9g %.9g %.9g %.9g %.9g %.9g %.9g\n", i, (double)c->pos.x,
                            (double)c->pos.y, (double)c->pos.z, (double)c->yaw, (double)c->pitch, (double)c->dist, (double)c->yfov);
    }
    if (len >= (int)sizeof buf || write_file_atomic(u->bookmarks_path, buf, (size_t)len, WRITE_REPLACE, err, sizeof err) != 0) {
        if (len >= (int)sizeof buf) snprintf(err, sizeof err, "%s: bookmarks too long", u->bookmarks_path);
        snprintf(u->message, sizeof u->message, "%s", err);
        cli_error("%s", err);
        return -1;
    }
    snprintf(u->message, sizeof u->message, "bookmark %d saved to %s", slot, u->bookmarks_path);
    return 0;
}

/* Returns 0, or -1 (message set) when the slot is empty. */
static int bookmark_restore(ui_thread *u, int slot) {
    if (!u->bookmark_set[slot]) {
        snprintf(u->message, sizeof u->message, "no bookmark %d (%s)", slot, u->bookmarks_path);
        return -1;
    }
    u->cam = u->bookmarks[slot];
    u->ctl.camera = u->applied_ctl.camera = -1; /* a free camera, not the scene's */
    send_change(u);
    snprintf(u->message, sizeof u->message, "bookmark %d", slot);
    return 0;
}

static void describe_bookmarks(ui_thread *u) {
    int len = 0;
    for (int i = 1; i <= 9; i++)
        if (u->bookmark_set[i]) len += snprintf(u->bookmarks_text + len, sizeof u->bookmarks_text - (size_t)len, "%d ", i);
    snprintf(u->bookmarks_text + len, sizeof u->bookmarks_text - (size_t)len, "%s(%s)", len ? "" : "none ", u->bookmarks_path);
}

/* ---- the reference image and the error plot (UI thread) ---------------------------------------- */

/* Loads a reference for the error view and plot: it must match the render size. Returns 0, or -1
 * with the message shown (the previous reference stays). */
static int load_reference(ui_thread *u, const char *path) {
    image_rgb img;
    char err[1200];
    if (image_rgb_load(path, &img, err, sizeof err) != 0) {
        snprintf(u->message, sizeof u->message, "%s", err);
        cli_error("%s", err);
        return -1;
    }
    shared_state *sh = &u->v->sh;
    pthread_mutex_lock(&sh->lock);
    int w = sh->render_w, h = sh->render_h;
    pthread_mutex_unlock(&sh->lock);
    image_rgb copy = {img.width, img.height, NULL};
    size_t bytes = sizeof(float) * 3 * (size_t)img.width * (size_t)img.height;
    if (img.width != w || img.height != h) {
        snprintf(u->message, sizeof u->message, "%s: the reference is %dx%d but the render is %dx%d; not used", path,
                 img.width, img.height, w, h);
    } else if (!(copy.rgb = malloc(bytes))) {
        snprintf(u->message, sizeof u->message, "%s: out of memory", path);
    }
    if (!copy.rgb) {
        cli_error("%s", u->message);
        image_rgb_free(&img);
        return -1;
    }
    memcpy(copy.rgb, img.rgb, bytes);
    pthread_mutex_lock(&sh->lock);
    image_rgb_free(&sh->reference_new);
    sh->reference_new = copy; /* the render thread's own copy, for the error of each frame */
    sh->reference_pending = 1;
    pthread_mutex_unlock(&sh->lock);
    image_rgb_free(&u->reference);
    u->reference = img;
    snprintf(u->reference_path, sizeof u->reference_path, "%s", path);
    u->rel_error = -1.0;
    u->num_curves = 0; /* errors against another image do not compare */
    u->current_curve = -1;
    u->need_tonemap = 1;
    snprintf(u->message, sizeof u->message, "reference %s", path);
    return 0;
}

/* The plot's name for the current method and settings. */
static void curve_label(const ui_thread *u, char *out, size_t n) {
    const ui_controls *c = &u->ctl;
    int len = snprintf(out, n, "%s, depth %d", method_name((render_method)c->method), c->max_depth);
    if (c->method != METHOD_PT && len < (int)n)
        len += snprintf(out + len, n - (size_t)len, ", %d lights, radius x%g", c->vl_count, (double)c->radius_mult);
    if (c->method == METHOD_VSL_HL && len < (int)n)
        snprintf(out + len, n - (size_t)len, ", N %d, K %d", c->secondary_rays, c->clusters);
}

/* A new error measurement. A new accumulation starts its curve afresh, replacing an earlier one of
 * the same settings, so switching between methods leaves one curve for each side by side. */
static void add_error_point(ui_thread *u, double seconds, double error, uint64_t resets) {
    if (u->current_curve < 0 || resets != u->curve_resets) {
        char label[96];
        curve_label(u, label, sizeof label);
        int c = -1;
        for (int i = 0; i < u->num_curves; i++)
            if (strcmp(u->curves[i].label, label) == 0) c = i;
        if (c < 0 && u->num_curves == MAX_CURVES) { /* forget the oldest */
            memmove(&u->curves[0], &u->curves[1], sizeof(error_curve) * (MAX_CURVES - 1));
            c = MAX_CURVES - 1;
        } else if (c < 0) {
            c = u->num_curves++;
        }
        snprintf(u->curves[c].label, sizeof u->curves[c].label, "%s", label);
        u->curves[c].n = 0;
        u->current_curve = c;
        u->curve_resets = resets;
    }
    error_curve *k = &u->curves[u->current_curve];
    if (k->n == MAX_CURVE_POINTS) { /* keep the whole time span at half the density */
        for (int i = 0; i < MAX_CURVE_POINTS / 2; i++) {
            k->seconds[i] = k->seconds[2 * i + 1];
            k->error[i] = k->error[2 * i + 1];
        }
        k->n = MAX_CURVE_POINTS / 2;
    }
    k->seconds[k->n] = (float)seconds;
    k->error[k->n] = (float)error;
    k->n++;
    u->rel_error = error;
}

/* Per-pixel relative error |I - R| / (|R| + eps) as colours on a log scale: blue 1%, green 10%,
 * red 100% and more. eps, a hundredth of the mean reference, keeps black pixels from glaring. */
static void false_colour_error(const float *img, const float *ref, int num_pixels, unsigned char *out) {
    size_t n = 3 * (size_t)num_pixels;
    double mean = 0.0;
    for (size_t i = 0; i < n; i++) mean += (double)ref[i];
    float eps = (float)(0.01 * mean / (double)(n ? n : 1)) + 1e-20f;
    for (int i = 0; i < num_pixels; i++) {
        const float *a = img + 3 * (size_t)i, *r = ref + 3 * (size_t)i;
        float d2 = 0.0f, r2 = 0.0f;
        for (int k = 0; k < 3; k++) {
            d2 += (a[k] - r[k]) * (a[k] - r[k]);
            r2 += r[k] * r[k];
        }
        float e = sqrtf(d2) / (sqrtf(r2) + eps);
        float t = isfinite(e) ? clampf(0.5f * (log10f(fmaxf(e, 1e-6f)) + 2.0f), 0.0f, 1.0f) : 1.0f;
        float rgb[3] = {clampf(2.0f * t - 1.0f, 0.0f, 1.0f), 1.0f - fabsf(2.0f * t - 1.0f), clampf(1.0f - 2.0f * t, 0.0f, 1.0f)};
        for (int k = 0; k < 3; k++) out[3 * (size_t)i + (size_t)k] = (unsigned char)(255.0f * rgb[k] + 0.5f);
    }
}

static void request_export(ui_thread *u, const char *name) {
    char path[1024];
    if (unique_path(name, path, sizeof path) != 0) {
        snprintf(u->message, sizeof u->message, "%s: no free file name", name);
        return;
    }
    shared_state *sh = &u->v->sh;
    pthread_mutex_lock(&sh->lock);
    snprintf(sh->export_path, sizeof sh->export_path, "%s", path);
    sh->export_pending = 1;
    pthread_mutex_unlock(&sh->lock);
}

static void tonemap_and_upload(ui_thread *u);

static void take_screenshot(ui_thread *u, const char *name) {
    char path[1024], err[1200];
    if (u->need_tonemap) { /* a newer image or exposure than the one drawn last: save what is current */
        tonemap_and_upload(u);
        u->need_tonemap = 0;
    }
    if (!u->front.rgb || !u->pixels) {
        snprintf(u->message, sizeof u->message, "%s: nothing rendered yet", name);
        cli_error("%s", u->message);
        return;
    }
    if (unique_path(name, path, sizeof path) != 0) {
        snprintf(u->message, sizeof u->message, "%s: no free file name", name);
        cli_error("%s", u->message);
        return;
    }
    if (png_save_rgb8(path, u->front.width, u->front.height, u->pixels, WRITE_NO_REPLACE, err, sizeof err) != 0) {
        snprintf(u->message, sizeof u->message, "%s", err);
        cli_error("%s", err);
        return;
    }
    snprintf(u->message, sizeof u->message, "wrote %s", path);
    printf("glint: wrote %s\n", path);
    fflush(stdout);
}

static void request_load(ui_thread *u, int kind, const char *path) {
    shared_state *sh = &u->v->sh;
    pthread_mutex_lock(&sh->lock);
    snprintf(sh->load_path, sizeof sh->load_path, "%s", path);
    sh->load_kind = kind;
    /* A new generation: frames counted after this show the result of the load. */
    u->sent_generation = ++sh->generation;
    if (!sh->export_pending) atomic_store(&u->v->abort_frame, 1);
    pthread_mutex_unlock(&sh->lock);
}

static void print_stats(ui_thread *u) {
    /* the mean luminance of the image shown: light edits must move it */
    double mean = 0.0;
    int np = u->front.rgb ? u->front.width * u->front.height : 0;
    for (int i = 0; i < np; i++) {
        const float *c = u->front.rgb + 3 * (size_t)i;
        mean += (double)luminance3(v3(c[0], c[1], c[2]));
    }
    mean = np > 0 ? mean / np : 0.0;
    vec3 lp = u->ctl.light >= 0 ? light_position(u, u->ctl.light) : v3(0, 0, 0);
    update_light_screen(u);
    float lx = u->ctl.light >= 0 ? u->light_xy[2 * u->ctl.light] : NAN;
    float ly = u->ctl.light >= 0 ? u->light_xy[2 * u->ctl.light + 1] : NAN;
    int nb = 0;
    char marks[16];
    for (int i = 1; i <= 9; i++)
        if (u->bookmark_set[i]) marks[nb++] = (char)('0' + i);
    marks[nb] = 0;
    printf("stats lights=%d light=%d light_intensity=%g light_pos=%.5f,%.5f,%.5f light_xy=%.1f,%.1f tonemap=%s mean=%.6g "
           "rel_error=%.6g preview_frames=%llu preview_size=%dx%d time=%.3f cam=%.5f,%.5f,%.5f bookmarks=%s ",
           u->info.num_lights, u->ctl.light, (double)u->ctl.light_gain, (double)lp.x, (double)lp.y, (double)lp.z, (double)lx, (double)ly,
           tonemap_names[u->ctl.tonemap], mean, u->rel_error, (unsigned long long)u->stats.preview_frames, u->preview_w, u->preview_h,
           seconds_since(u->started_at), (double)u->cam.pos.x, (double)u->cam.pos.y, (double)u->cam.pos.z,
           nb ? marks : "-");
    printf("scene=%s frames=%lld frames_total=%llu resets=%llu width=%d height=%d preview=%d exposure=%g show=%d "
           "max_depth=%d method=%s rejected=%llu radius_mult=%g clamp=%d vsl_count=%d columns=%d per_pixel=%d "
           "light_select=%d candidates=%d trace_glossy=%g glossy_rays=%d virtual_lights=%llu secondary_rays=%d clusters=%d "
           "merge=%s hl_lobes=%llu "
           "plan_highlights=%d\n",
           u->info.name, frames_of_current_state(u), (unsigned long long)u->stats.frames_total, (unsigned long long)u->stats.resets, u->front.width,
           u->front.height, u->front.preview, (double)u->ctl.exposure, u->ctl.show, u->ctl.max_depth,
           method_name((render_method)u->ctl.method), u->stats.rejected, (double)u->ctl.radius_mult, u->ctl.clamp,
           u->ctl.vl_count, u->ctl.columns, u->ctl.per_pixel, u->ctl.light_select, u->ctl.candidates,
           (double)u->ctl.trace_glossy, u->ctl.glossy_rays, u->stats.virtual_lights, u->ctl.secondary_rays, u->ctl.clusters,
           u->ctl.merge == 1 ? "off" : u->ctl.merge == 2 ? "trace" : "on", u->stats.hl_lobes, u->stats.plan_highlights);
    fflush(stdout);
}

/* A live parameter by its command-line name. Returns 0, or -1 with a message. */
static int set_parameter(ui_thread *u, const char *name, const char *value, char *err, size_t errlen) {
    char opt[80];
    snprintf(opt, sizeof opt, "--%s", name);
    long long n;
    double x;
    if (strcmp(name, "vpl-glossy") != 0) { /* the many-light settings, as glint render's options */
        vl_params vl = vl_from_controls(&u->ctl, (vl_params){0});
        int applied = cli_set_vl_param(name, value, &vl);
        if (applied < 0) return snprintf(err, errlen, "bad value '%s'", value), -1;
        if (applied > 0) {
            controls_from_vl(&u->ctl, &vl);
            return 0;
        }
    }
    if (strcmp(name, "method") == 0) {
        int m = method_from_name(value);
        if (m < 0) return snprintf(err, errlen, "unknown method '%s'", value), -1;
        u->ctl.method = m;
    } else if (strcmp(name, "max-depth") == 0) {
        if (cli_parse_int(opt, value, 1, 1000, &n) != 0) return snprintf(err, errlen, "bad value '%s'", value), -1;
        u->ctl.max_depth = (int)n;
    } else if (strcmp(name, "exposure") == 0) {
        if (cli_parse_float(opt, value, -30, 30, &x) != 0) return snprintf(err, errlen, "bad value '%s'", value), -1;
        u->ctl.exposure = (float)x;
    } else if (strcmp(name, "show") == 0) {
        static const char *names[UI_SHOW_COUNT] = {"all", "direct", "indirect", "highlights", "error"};
        int found = -1;
        for (int i = 0; i < UI_SHOW_COUNT; i++)
            if (strcmp(value, names[i]) == 0) found = i;
        if (found < 0) return snprintf(err, errlen, "show: one of all, direct, indirect, highlights, error"), -1;
        if (found == UI_SHOW_ERROR && !u->reference.rgb) return snprintf(err, errlen, "show error: no reference loaded"), -1;
        u->ctl.show = found;
    } else if (strcmp(name, "tonemap") == 0) {
        int t = tonemap_from_name(value);
        if (t < 0) return snprintf(err, errlen, "tonemap: one of reinhard, clamp, exponential"), -1;
        u->ctl.tonemap = t;
    } else if (strcmp(name, "light") == 0) {
        if (cli_parse_int(opt, value, 0, u->info.num_lights - 1, &n) != 0) return snprintf(err, errlen, "no light %s", value), -1;
        u->ctl.light = (int)n;
    } else if (strcmp(name, "light-intensity") == 0) {
        if (u->ctl.light < 0) return snprintf(err, errlen, "light-intensity: no light selected"), -1;
        if (cli_parse_float(opt, value, 1e-3, 1e3, &x) != 0) return snprintf(err, errlen, "bad value '%s'", value), -1;
        u->ctl.light_gain = (float)x;
    } else if (strcmp(name, "camera") == 0) {
        if (cli_parse_int(opt, value, -1, u->info.num_cameras - 1, &n) != 0)
            return snprintf(err, errlen, "no camera %s", value), -1;
        u->ctl.camera = (int)n;
    } else if (strcmp(name, "panel") == 0) {
        if (cli_parse_int(opt, value, 0, 1, &n) != 0) return snprintf(err, errlen, "panel: 0 or 1"), -1;
        u->ctl.show_panel = (int)n;
    } else {
        return snprintf(err, errlen, "unknown parameter '%s'", name), -1;
    }
    return 0;
}

/* keys_pressed holds 1 + the modifier bits of each press since the last frame. */
static void press_key(ui_thread *u, int key, int mods) {
    if (key >= 0 && key <= GLFW_KEY_LAST) u->keys_pressed[key] = 1 + mods;
}

/* A key by name, with "ctrl+" or "shift+" in front for the modifier (into *mods). */
static int key_from_name(const char *name, int *mods) {
    *mods = 0;
    if (strncmp(name, "ctrl+", 5) == 0) *mods = GLFW_MOD_CONTROL, name += 5;
    else if (strncmp(name, "shift+", 6) == 0) *mods = GLFW_MOD_SHIFT, name += 6;
    if (strcmp(name, "r") == 0) return GLFW_KEY_R;
    if (strcmp(name, "f11") == 0) return GLFW_KEY_F11;
    if (strcmp(name, "f12") == 0) return GLFW_KEY_F12;
    if (strcmp(name, "tab") == 0) return GLFW_KEY_TAB;
    if (strcmp(name, "escape") == 0) return GLFW_KEY_ESCAPE;
    if (strlen(name) == 1 && name[0] >= '0' && name[0] <= '9') return GLFW_KEY_0 + (name[0] - '0');
    return -1;
}

/* Runs script actions until one has to wait. */
static void run_script(ui_thread *u) {
    while (u->script_pos < u->script.count && !u->quit) {
        const script_action *a = &u->script.actions[u->script_pos];
        char err[1200];
        switch (a->kind) {
        case ACT_WAIT:
            /* N frames of the current state: frames of a state already replaced do not count. */
            if (!u->script_waiting || u->script_wait_generation != u->sent_generation) {
                u->script_waiting = 1;
                u->script_wait_generation = u->sent_generation;
                u->script_wait_target = frames_of_current_state(u) + (long long)a->a;
            }
            if (frames_of_current_state(u) < u->script_wait_target) return;
            u->script_waiting = 0;
            break;
        case ACT_SET:
            if (set_parameter(u, a->name, a->text, err, sizeof err) != 0) {
                cli_error("%s:%d: %s", u->script_path_for_errors, a->line, err);
                u->script_errors++;
            }
            if (u->ctl.camera != u->applied_ctl.camera) {
                reset_view(u);
                apply_controls(u, 1);
            } else {
                apply_controls(u, 0);
            }
            break;
        case ACT_ORBIT:
            ctl_orbit(&u->cam, (float)(a->a * 3.14159265358979 / 180.0), (float)(a->b * 3.14159265358979 / 180.0));
            send_change(u);
            break;
        case ACT_PAN:
            ctl_pan(&u->cam, (float)a->a, (float)a->b);
            send_change(u);
            break;
        case ACT_ZOOM:
            ctl_zoom(&u->cam, (float)a->a);
            send_change(u);
            break;
        case ACT_KEY: {
            int mods, k = key_from_name(a->name, &mods);
            if (k < 0) {
                cli_error("%s:%d: unknown key '%s'", u->script_path_for_errors, a->line, a->name);
                u->script_errors++;
            } else {
                press_key(u, k, mods);
            }
            break;
        }
        case ACT_MOVE_LIGHT:
            if (move_light(u, (int)a->a, v3((float)a->b, (float)a->c, (float)a->d), err, sizeof err) != 0) {
                cli_error("%s:%d: %s", u->script_path_for_errors, a->line, err);
                u->script_errors++;
            } else {
                u->ctl.light = (int)a->a;
                apply_controls(u, 1);
            }
            break;
        case ACT_SAVE_BOOKMARK:
            if (bookmark_save(u, (int)a->a) != 0) u->script_errors++;
            break;
        case ACT_RESTORE_BOOKMARK:
            if (bookmark_restore(u, (int)a->a) != 0) {
                cli_error("%s:%d: %s", u->script_path_for_errors, a->line, u->message);
                u->script_errors++;
            }
            break;
        case ACT_REFERENCE: load_reference(u, a->text); break;
        case ACT_SPIN:
            if (!u->script_waiting) {
                u->script_waiting = 1;
                u->spin_rate = a->a;
                u->spin_until = cli_now() + a->b;
            }
            if (cli_now() < u->spin_until) return;
            u->script_waiting = 0;
            break;
        case ACT_SCREENSHOT: take_screenshot(u, a->text); break;
        case ACT_EXPORT: request_export(u, a->text); break;
        case ACT_LOAD: request_load(u, 1, a->text); break;
        case ACT_ENV: request_load(u, 2, a->text); break;
        case ACT_WINDOW_SHOT: /* taken after this frame's draw: later actions wait for it */
            snprintf(u->window_shot, sizeof u->window_shot, "%s", a->text);
            u->script_pos++;
            return;
        case ACT_STATS: print_stats(u); break;
        case ACT_QUIT: u->quit = 1; break;
        }
        u->script_pos++;
    }
}

/* ---- input ---------------------------------------------------------------------------------- */

static void on_key(GLFWwindow *win, int key, int scancode, int action, int mods) {
    (void)scancode;
    ui_thread *u = glfwGetWindowUserPointer(win);
    if (action == GLFW_PRESS && !ui_wants_keyboard()) press_key(u, key, mods);
}

static void on_scroll(GLFWwindow *win, double dx, double dy) {
    (void)dx;
    ui_thread *u = glfwGetWindowUserPointer(win);
    if (!ui_wants_mouse()) u->scroll += dy;
}

static void on_drop(GLFWwindow *win, int count, const char **paths) {
    ui_thread *u = glfwGetWindowUserPointer(win);
    if (count < 1) return;
    /* An image is an environment map; anything else is taken for a scene. */
    const char *dot = strrchr(paths[0], '.');
    int env = dot && (strcmp(dot, ".exr") == 0 || strcmp(dot, ".hdr") == 0);
    request_load(u, env ? 2 : 1, paths[0]);
}

/* Keys, mouse and the panel's actions. Returns 1 when the camera changed. */
static int handle_input(ui_thread *u, double dt) {
    int changed = 0;
    float speed = 0.25f * u->info.diag; /* scene sizes per second */
    if (!ui_wants_keyboard()) {
        camera c = ctl_camera(&u->cam);
        vec3 move = v3s(0.0f);
        if (glfwGetKey(u->win, GLFW_KEY_W) == GLFW_PRESS) move = add3(move, c.forward);
        if (glfwGetKey(u->win, GLFW_KEY_S) == GLFW_PRESS) move = sub3(move, c.forward);
        if (glfwGetKey(u->win, GLFW_KEY_D) == GLFW_PRESS) move = add3(move, c.right);
        if (glfwGetKey(u->win, GLFW_KEY_A) == GLFW_PRESS) move = sub3(move, c.right);
        if (glfwGetKey(u->win, GLFW_KEY_E) == GLFW_PRESS) move = add3(move, v3(0, 1, 0));
        if (glfwGetKey(u->win, GLFW_KEY_Q) == GLFW_PRESS) move = sub3(move, v3(0, 1, 0));
        if (!is_black3(move)) {
            u->cam.pos = madd3(u->cam.pos, normalize3(move), speed * (float)dt);
            changed = 1;
        }
        /* The selected light: arrows along the view plane, PageUp/PageDown along the view. */
        vec3 lmove = v3s(0.0f);
        if (glfwGetKey(u->win, GLFW_KEY_RIGHT) == GLFW_PRESS) lmove = add3(lmove, c.right);
        if (glfwGetKey(u->win, GLFW_KEY_LEFT) == GLFW_PRESS) lmove = sub3(lmove, c.right);
        if (glfwGetKey(u->win, GLFW_KEY_UP) == GLFW_PRESS) lmove = add3(lmove, c.up);
        if (glfwGetKey(u->win, GLFW_KEY_DOWN) == GLFW_PRESS) lmove = sub3(lmove, c.up);
        if (glfwGetKey(u->win, GLFW_KEY_PAGE_UP) == GLFW_PRESS) lmove = add3(lmove, c.forward);
        if (glfwGetKey(u->win, GLFW_KEY_PAGE_DOWN) == GLFW_PRESS) lmove = sub3(lmove, c.forward);
        char err[256];
        if (!is_black3(lmove) && light_movable(u, u->ctl.light) &&
            move_light(u, u->ctl.light, scale3(normalize3(lmove), speed * (float)dt), err, sizeof err) == 0)
            changed = 1;
    }
    if (cli_now() < u->spin_until) { /* a scripted drag */
        ctl_orbit(&u->cam, (float)(u->spin_rate * dt * 3.14159265358979 / 180.0), 0.0f);
        changed = 1;
    }
    double x, y;
    glfwGetCursorPos(u->win, &x, &y);
    double dx = x - u->mouse_x, dy = y - u->mouse_y;
    u->mouse_x = x;
    u->mouse_y = y;
    /* Ctrl + left button: a click picks the light drawn nearest, a drag moves the selected one
     * with the cursor (at the light's depth, so it stays under the cursor). */
    int left = glfwGetMouseButton(u->win, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
    int ctrl = glfwGetKey(u->win, GLFW_KEY_LEFT_CONTROL) == GLFW_PRESS ||
               glfwGetKey(u->win, GLFW_KEY_RIGHT_CONTROL) == GLFW_PRESS;
    if (left && !u->left_was_down && ctrl && !ui_wants_mouse()) {
        int g = pick_light(u, x, y);
        if (g >= 0) u->ctl.light = g;
        u->dragging_light = 1;
    }
    if (!left) u->dragging_light = 0;
    u->left_was_down = left;
    if (u->dragging_light) {
        int g = u->ctl.light;
        if ((dx != 0.0 || dy != 0.0) && light_movable(u, g)) {
            camera c = ctl_camera(&u->cam);
            float z = dot3(sub3(light_position(u, g), c.position), c.forward);
            float px = pixel_footprint(u, fmaxf(z, 0.01f * u->info.diag));
            vec3 d = add3(scale3(c.right, (float)dx * px), scale3(c.up, (float)-dy * px));
            char err[256];
            if (move_light(u, g, d, err, sizeof err) == 0) changed = 1;
        }
    } else if (!ui_wants_mouse() && (dx != 0.0 || dy != 0.0)) {
        int wh;
        glfwGetWindowSize(u->win, NULL, &wh);
        float scale = 1.0f / (float)(wh > 0 ? wh : 1);
        if (left) {
            ctl_orbit(&u->cam, (float)dx * 3.0f * scale, (float)-dy * 3.0f * scale);
            changed = 1;
        } else if (glfwGetMouseButton(u->win, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS ||
                   glfwGetMouseButton(u->win, GLFW_MOUSE_BUTTON_MIDDLE) == GLFW_PRESS) {
            ctl_pan(&u->cam, (float)-dx * scale, (float)dy * scale);
            changed = 1;
        }
    }
    if (u->scroll != 0.0) {
        ctl_zoom(&u->cam, powf(0.85f, (float)u->scroll));
        u->scroll = 0.0;
        changed = 1;
    }
    if (u->keys_pressed[GLFW_KEY_R]) u->ctl.reset_view = 1;
    if (u->keys_pressed[GLFW_KEY_F12]) u->ctl.screenshot = 1;
    if (u->keys_pressed[GLFW_KEY_F11]) u->ctl.export_exr = 1;
    if (u->keys_pressed[GLFW_KEY_TAB]) u->ctl.show_panel = !u->ctl.show_panel;
    if (u->keys_pressed[GLFW_KEY_ESCAPE]) u->quit = 1;
    /* 1-9 the scene's cameras; with ctrl, save bookmark N; with shift, restore it. */
    for (int k = 1; k <= 9; k++) {
        int pressed = u->keys_pressed[GLFW_KEY_0 + k];
        int mods = pressed - 1;
        if (!pressed) continue;
        if (mods & GLFW_MOD_CONTROL) bookmark_save(u, k);
        else if (mods & GLFW_MOD_SHIFT) bookmark_restore(u, k);
        else if (k - 1 < u->info.num_cameras) u->ctl.camera = k - 1;
    }
    memset(u->keys_pressed, 0, sizeof u->keys_pressed);

    if (u->ctl.camera != u->applied_ctl.camera) u->ctl.reset_view = 1;
    if (u->ctl.reset_view) {
        reset_view(u);
        u->ctl.reset_view = 0;
        changed = 1;
    }
    if (u->ctl.screenshot) take_screenshot(u, "glint-screenshot.png");
    if (u->ctl.export_exr) request_export(u, "glint-export.exr");
    if (u->ctl.load_scene) request_load(u, 1, u->ctl.path);
    if (u->ctl.load_env) request_load(u, 2, u->ctl.path);
    if (u->ctl.load_reference) load_reference(u, u->ctl.path);
    u->ctl.screenshot = u->ctl.export_exr = u->ctl.load_scene = u->ctl.load_env = u->ctl.load_reference = 0;
    return changed;
}

/* ---- display -------------------------------------------------------------------------------- */

/* Takes the newest published image and statistics. Returns 1 when the image is new. */
static int fetch(ui_thread *u) {
    shared_state *sh = &u->v->sh;
    int fresh = 0, new_info = 0;
    pthread_mutex_lock(&sh->lock);
    if (sh->image_serial != u->image_serial) {
        image_buf t = u->front;
        u->front = sh->image;
        sh->image = t;
        u->image_serial = sh->image_serial;
        fresh = 1;
        if (u->front.preview) u->preview_w = u->front.width, u->preview_h = u->front.height;
    }
    int new_error = sh->stats.rel_error_serial != u->stats.rel_error_serial;
    u->stats = sh->stats;
    if (sh->message_serial != u->message_serial) {
        snprintf(u->message, sizeof u->message, "%s", sh->message);
        u->message_serial = sh->message_serial;
    }
    if (sh->info_serial != u->info_serial) {
        u->info = sh->info;
        u->info_serial = sh->info_serial;
        new_info = 1;
    }
    pthread_mutex_unlock(&sh->lock);
    if (new_error && u->reference.rgb) add_error_point(u, u->stats.rel_error_at, u->stats.rel_error, u->stats.rel_error_resets);
    if (new_info) { /* a new scene: its own view, lights and bookmarks */
        u->ctl.camera = -1;
        u->applied_ctl.camera = -1;
        u->ctl.reset_view = 1;
        reset_lights(u);
        bookmarks_load(u);
    }
    return fresh;
}

static void tonemap_and_upload(ui_thread *u) {
    int w = u->front.width, h = u->front.height;
    if (!u->front.rgb || w <= 0 || h <= 0) return;
    if (w * h > u->pixels_cap) {
        free(u->pixels);
        u->pixels = malloc(3 * (size_t)w * (size_t)h);
        u->pixels_cap = u->pixels ? w * h : 0;
        if (!u->pixels) return;
    }
    const image_rgb *ref = &u->reference;
    if (u->ctl.show == UI_SHOW_ERROR && ref->rgb && ref->width == w && ref->height == h) {
        false_colour_error(u->front.rgb, ref->rgb, w * h, u->pixels);
    } else { /* also the preview while moving in the error view: it has another size */
        tonemap_params tp = {u->ctl.exposure, 0.0f, 0.0f, (tonemap_op)u->ctl.tonemap};
        tonemap_apply(u->front.rgb, w * h, &tp, u->pixels);
    }
    if (!u->texture) {
        GLuint t;
        glGenTextures(1, &t);
        u->texture = t;
        glBindTexture(GL_TEXTURE_2D, t);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    }
    glBindTexture(GL_TEXTURE_2D, u->texture);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    if (w != u->tex_w || h != u->tex_h) {
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB8, w, h, 0, GL_RGB, GL_UNSIGNED_BYTE, u->pixels);
        u->tex_w = w;
        u->tex_h = h;
    } else {
        glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, w, h, GL_RGB, GL_UNSIGNED_BYTE, u->pixels);
    }
}

/* Saves the window's back buffer as drawn (panel included). */
static void capture_window(ui_thread *u, int w, int h) {
    char path[1024], err[1200];
    unsigned char *px = malloc(3 * (size_t)w * (size_t)h), *row = malloc(3 * (size_t)w);
    if (!px || !row || unique_path(u->window_shot, path, sizeof path) != 0) {
        cli_error("%s: cannot capture the window", u->window_shot);
    } else {
        glPixelStorei(GL_PACK_ALIGNMENT, 1);
        glReadPixels(0, 0, w, h, GL_RGB, GL_UNSIGNED_BYTE, px);
        for (int y = 0; y < h / 2; y++) { /* OpenGL's rows run bottom-up */
            memcpy(row, px + 3 * (size_t)w * (size_t)y, 3 * (size_t)w);
            memcpy(px + 3 * (size_t)w * (size_t)y, px + 3 * (size_t)w * (size_t)(h - 1 - y), 3 * (size_t)w);
            memcpy(px + 3 * (size_t)w * (size_t)(h - 1 - y), row, 3 * (size_t)w);
        }
        if (png_save_rgb8(path, w, h, px, WRITE_NO_REPLACE, err, sizeof err) != 0) cli_error("%s", err);
        else printf("glint: wrote %s\n", path);
    }
    free(px);
    free(row);
    u->window_shot[0] = 0;
}

/* ---- options and the main loop ---------------------------------------------------------------- */

static void print_view_help(void) {
    printf("usage: glint [view] [SCENE] [options]\n"
           "\n"
           "Opens the interactive viewer on SCENE (a .gltf/.glb or builtin:NAME, see glint --help;\n"
           "default: the default built-in scene).\n"
           "\n"
           "options:\n"
           "  --size WxH           window and render size [960x540]\n"
           "  --method NAME        estimator: pt, vpl, vsl, vsl+hl [pt]\n"
           "  --max-depth D        scattering events per path [%d]\n"
           "  --plan auto|full     auto: only the passes the scene calls for; full: every pass [auto]\n"
           "  --env FILE           environment map (.exr or .hdr)\n"
           "  --camera INDEX       start from the scene's camera INDEX\n"
           "  --seed S             random seed [0]\n"
           "  --exposure STOPS     display exposure [0]\n"
           "  --tonemap NAME       display tone mapper: reinhard, clamp, exponential [reinhard]\n"
           "  --reference FILE.exr an image of the render's size: error view and plot\n"
           "  --script FILE        replay a script of viewer actions (see README)\n"
           "\n"
           "%s"
           "\n"
           "controls: left drag orbit, right/middle drag pan, wheel zoom, WASD/QE fly, R reset view,\n"
           "1-9 scene cameras, ctrl+1-9 save and shift+1-9 restore a camera bookmark, arrows and\n"
           "PageUp/PageDown move the selected light, ctrl+click picks a light, ctrl+drag moves it,\n"
           "F12 screenshot (PNG), F11 export (EXR), Tab panel, Esc quit.\n"
           "Drop a .gltf/.glb on the window to open it, an .exr/.hdr to light the scene with it.\n",
           DEFAULT_MAX_DEPTH, cli_vl_help());
}

static int parse_view_options(int argc, char **argv, view_options *o) {
    memset(o, 0, sizeof *o);
    o->width = 960;
    o->height = 540;
    o->camera = -1;
    o->params.max_depth = DEFAULT_MAX_DEPTH;
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i], *v;
        long long n;
        int vl;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            print_view_help();
            return 1;
        } else if (strcmp(a, "--size") == 0) {
            if (!(v = cli_value(argc, argv, &i)) || cli_parse_size(a, v, &o->width, &o->height)) return -1;
        } else if (strcmp(a, "--method") == 0) {
            if (!(v = cli_value(argc, argv, &i))) return -1;
            int m = method_from_name(v);
            if (m < 0) return cli_error("--method: unknown method '%s' (available: pt, vpl, vsl, vsl+hl)", v), -1;
            o->params.method = (render_method)m;
        } else if ((vl = cli_vl_option(argc, argv, &i, &o->params.vl)) != 0) {
            if (vl < 0) return -1;
        } else if (strcmp(a, "--max-depth") == 0) {
            if (!(v = cli_value(argc, argv, &i)) || cli_parse_int(a, v, 1, 1000, &n)) return -1;
            o->params.max_depth = (int)n;
        } else if (strcmp(a, "--plan") == 0) {
            if (!(v = cli_value(argc, argv, &i)) || cli_parse_plan(a, v, &o->params.plan)) return -1;
        } else if (strcmp(a, "--env") == 0) {
            if (!(o->env_path = cli_value(argc, argv, &i))) return -1;
        } else if (strcmp(a, "--camera") == 0) {
            if (!(v = cli_value(argc, argv, &i)) || cli_parse_int(a, v, 0, 1 << 20, &n)) return -1;
            o->camera = (int)n;
        } else if (strcmp(a, "--seed") == 0) {
            if (!(v = cli_value(argc, argv, &i)) || cli_parse_u64(a, v, &o->params.seed)) return -1;
        } else if (strcmp(a, "--exposure") == 0) {
            if (!(v = cli_value(argc, argv, &i)) || cli_parse_float(a, v, -30, 30, &o->exposure)) return -1;
        } else if (strcmp(a, "--tonemap") == 0) {
            if (!(v = cli_value(argc, argv, &i))) return -1;
            if ((o->tonemap = tonemap_from_name(v)) < 0)
                return cli_error("--tonemap: unknown tone mapper '%s' (available: reinhard, clamp, exponential)", v), -1;
        } else if (strcmp(a, "--reference") == 0) {
            if (!(o->reference_path = cli_value(argc, argv, &i))) return -1;
        } else if (strcmp(a, "--script") == 0) {
            if (!(o->script_path = cli_value(argc, argv, &i))) return -1;
        } else if (cli_scene_argument("view", a, &o->scene_path) != 0) {
            return -1;
        }
    }
    return 0;
}

static void on_glfw_error(int code, const char *description) {
    (void)code;
    cli_warning("window system: %s", description);
}

int cmd_view(int argc, char **argv) {
    view_options o;
    int r = parse_view_options(argc, argv, &o);
    if (r) return r > 0 ? EXIT_OK : EXIT_USAGE;

    static ui_thread u; /* large (key table, buffers): not on the stack */
    memset(&u, 0, sizeof u);
    char err[1200];
    if (o.script_path) {
        if (view_script_load(o.script_path, &u.script, err, sizeof err) != 0) {
            cli_error("%s", err);
            return EXIT_USAGE;
        }
        u.script_path_for_errors = o.script_path;
    }

    scene *s = load_scene_or_default(o.scene_path, o.env_path, 0.0f);
    if (!s) {
        view_script_free(&u.script);
        return EXIT_FAILURE_;
    }
    if (o.camera >= 0 && o.camera >= s->num_cameras) {
        cli_error("--camera: the scene has %d camera%s", s->num_cameras, s->num_cameras == 1 ? "" : "s");
        scene_destroy(s);
        view_script_free(&u.script);
        return EXIT_USAGE;
    }

    glfwSetErrorCallback(on_glfw_error);
    if (!glfwInit()) {
        cli_error("cannot open a window (no display?); glint render renders without one");
        scene_destroy(s);
        view_script_free(&u.script);
        return EXIT_FAILURE_;
    }
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    char title[1200];
    snprintf(title, sizeof title, "glint — %s", s->path);
    GLFWwindow *win = glfwCreateWindow(o.width, o.height, title, NULL, NULL);
    if (!win) {
        cli_error("cannot create an OpenGL 3.3 window");
        glfwTerminate();
        scene_destroy(s);
        view_script_free(&u.script);
        return EXIT_FAILURE_;
    }
    glfwMakeContextCurrent(win);
    glfwSwapInterval(1);
    glfwSetWindowUserPointer(win, &u);
    /* Our callbacks first: Dear ImGui's backend chains to them. */
    glfwSetKeyCallback(win, on_key);
    glfwSetScrollCallback(win, on_scroll);
    glfwSetDropCallback(win, on_drop);
    if (ui_init(win) != 0) {
        cli_error("cannot initialise the panel");
        glfwDestroyWindow(win);
        glfwTerminate();
        scene_destroy(s);
        view_script_free(&u.script);
        return EXIT_FAILURE_;
    }

    static viewer v;
    memset(&v, 0, sizeof v);
    pthread_mutex_init(&v.sh.lock, NULL);
    v.scene = s;
    u.v = &v;
    u.win = win;
    fill_info(&u.info, s);
    v.sh.info = u.info;
    u.ctl = (ui_controls){.method = o.params.method,
                          .max_depth = o.params.max_depth,
                          .camera = o.camera,
                          .exposure = (float)o.exposure,
                          .tonemap = o.tonemap,
                          .show = UI_SHOW_ALL,
                          .show_panel = 1};
    controls_from_vl(&u.ctl, &o.params.vl);
    u.applied_ctl = u.ctl;
    reset_lights(&u);
    clear_light_edits(&v.sh.lights);
    clear_light_edits(&v.lights_applied);
    bookmarks_load(&u);
    u.rel_error = -1.0;
    u.current_curve = -1;
    u.started_at = cli_now();
    int fw, fh;
    glfwGetFramebufferSize(win, &fw, &fh);
    reset_view(&u);
    v.sh.cam = ctl_camera(&u.cam);
    v.sh.params = o.params;
    v.sh.render_w = fw > 0 ? fw : o.width;
    v.sh.render_h = fh > 0 ? fh : o.height;
    v.sh.show_mask = COMP_MASK_ALL;
    v.sh.changed_at = -1e9;
    v.sh.stats.reset_at = cli_now(); /* the first accumulation starts now, not at the clock's origin */
    if (make_sessions(&v, v.sh.render_w, v.sh.render_h, &v.sh.cam, &o.params) != 0) {
        cli_error("%s", v.sh.message);
        ui_shutdown();
        glfwDestroyWindow(win);
        glfwTerminate();
        scene_destroy(s);
        view_script_free(&u.script);
        return EXIT_FAILURE_;
    }
    pthread_t render_thread;
    pthread_create(&render_thread, NULL, render_main, &v);
    if (o.reference_path) load_reference(&u, o.reference_path); /* a bad one is shown; the viewer runs on */

    glfwGetCursorPos(win, &u.mouse_x, &u.mouse_y);
    u.last_time = cli_now();
    double resized_at = 0.0;
    int pending_w = 0, pending_h = 0;
    while (!u.quit && !glfwWindowShouldClose(win)) {
        glfwWaitEventsTimeout(1.0 / 60.0);
        double now = cli_now(), dt = now - u.last_time;
        u.last_time = now;
        if (fetch(&u)) u.need_tonemap = 1;
        run_script(&u);

        ui_begin_frame();
        ui_draw_image(u.texture);
        if (u.ctl.show_panel) {
            update_light_screen(&u);
            ui_draw_lights(u.light_xy, u.info.num_lights, u.ctl.light);
        }
        for (int c = 0; c < u.num_curves; c++)
            u.ui_curves[c] = (ui_curve){u.curves[c].label, u.curves[c].seconds, u.curves[c].error, u.curves[c].n};
        describe_bookmarks(&u);
        ui_stats st = {.scene_name = u.info.name,
                       .frames = u.stats.frames,
                       .spp = (double)u.stats.frames,
                       .seconds = seconds_since(u.stats.reset_at),
                       .frame_ms = u.stats.frame_ms,
                       .rays_per_second = u.stats.rays_per_second,
                       .rejected_samples = u.stats.rejected,
                       .many_light = u.ctl.method != METHOD_PT,
                       .virtual_lights = u.stats.virtual_lights,
                       .highlights = u.ctl.method == METHOD_VSL_HL,
                       .max_secondary_rays = HL_MAX_SECONDARY_RAYS,
                       .max_clusters = HL_MAX_CLUSTERS,
                       .hl_points = u.stats.hl_points,
                       .hl_lobes = u.stats.hl_lobes,
                       .hl_merge_share = u.stats.hl_merge_share,
                       .plan = u.stats.plan,
                       .width = u.front.width,
                       .height = u.front.height,
                       .previewing = u.front.preview,
                       .num_cameras = u.info.num_cameras,
                       .tonemap_names = tonemap_names,
                       .num_tonemaps = TONEMAP_COUNT,
                       .light_names = u.light_label_ptrs,
                       .num_lights = u.info.num_lights,
                       .light_movable = light_movable(&u, u.ctl.light),
                       .reference = u.reference.rgb ? u.reference_path : NULL,
                       .rel_error = u.rel_error,
                       .curves = u.ui_curves,
                       .num_curves = u.num_curves,
                       .bookmarks = u.bookmarks_text,
                       .message = u.message};
        const char *methods[METHOD_COUNT];
        for (int m = 0; m < METHOD_COUNT; m++) methods[m] = method_name((render_method)m);
        st.method_names = methods;
        st.num_methods = METHOD_COUNT;
        ui_panel(&u.ctl, &st);

        apply_controls(&u, handle_input(&u, dt));

        /* A new window size becomes the render size once it has stopped changing. */
        glfwGetFramebufferSize(win, &fw, &fh);
        if (fw > 0 && fh > 0 && (fw != v.sh.render_w || fh != v.sh.render_h)) {
            if (fw != pending_w || fh != pending_h) {
                pending_w = fw;
                pending_h = fh;
                resized_at = now;
            } else if (now - resized_at > 0.2) {
                pthread_mutex_lock(&v.sh.lock);
                v.sh.render_w = fw;
                v.sh.render_h = fh;
                pthread_mutex_unlock(&v.sh.lock);
                /* the aspect ratio changed: recompute the camera */
                send_change(&u);
            }
        }

        if (u.need_tonemap) {
            tonemap_and_upload(&u);
            u.need_tonemap = 0;
        }
        glViewport(0, 0, fw, fh);
        glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
        glClear(GL_COLOR_BUFFER_BIT);
        ui_end_frame();
        if (u.window_shot[0]) capture_window(&u, fw, fh);
        glfwSwapBuffers(win);
    }

    pthread_mutex_lock(&v.sh.lock);
    v.sh.quit = 1;
    pthread_mutex_unlock(&v.sh.lock);
    pthread_join(render_thread, NULL);
    if (u.texture) {
        GLuint t = u.texture;
        glDeleteTextures(1, &t);
    }
    ui_shutdown();
    glfwDestroyWindow(win);
    glfwTerminate();
    session_destroy(v.full);
    session_destroy(v.preview);
    scene_destroy(v.scene);
    free(v.back.rgb);
    free(v.combined);
    image_rgb_free(&v.reference);
    image_rgb_free(&v.sh.reference_new);
    image_rgb_free(&u.reference);
    free(v.sh.image.rgb);
    free(u.front.rgb);
    free(u.pixels);
    pthread_mutex_destroy(&v.sh.lock);
    int errors = u.script_errors;
    view_script_free(&u.script);
    return errors ? EXIT_FAILURE_ : EXIT_OK;
}
