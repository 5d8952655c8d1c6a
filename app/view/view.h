/* glint view: the interactive viewer's UI side, shared by its files (not a public interface).
 *
 * The UI thread owns the window: it handles input (view_input.c, view_nav.c, view_camera.c) and
 * scripts (view_script_run.c), tone-maps and draws the newest image with the panel
 * (view_image.c, view_display.c, view_panel.c), and never waits for a frame; view_window.c holds
 * the image's place in the window and sends what the UI asks. Everything it asks of the renderer,
 * and everything it shows of it, goes through the narrow interface of view_controller.h; the one
 * statistics record it shows and prints is ui/view_stats.h's.
 *
 * Lights are edited as the UI keeps them: the wanted offset and intensity of every light, sent with
 * each change; the render side applies the difference to the scene between updates. */
#ifndef GLINT_VIEW_H
#define GLINT_VIEW_H

#include <pthread.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include <GLFW/glfw3.h>

#include "camera.h"
#include "cli.h"
#include "reference.h"
#include "session.h"
#include "ui.h"
#include "view_controller.h"
#include "view_script.h"

#define MAX_CURVES 6         /* error curves kept for comparison */
#define MAX_CURVE_POINTS 512 /* per curve; halved (every other point) when full */
#define MAX_CAPTURES 8       /* captures written at once */

static inline double seconds_since(double t) { return cli_now() - t; }

/* ---- the UI thread --------------------------------------------------------------------------- */

/* The free camera, orbiting a centre in front of it. */
typedef struct {
    vec3 pos;
    float yaw, pitch; /* radians; yaw 0 looks along -z, pitch up positive */
    float dist;       /* to the orbit centre */
    float yfov;
} cam_ctl;

/* Relative error against seconds since a reset, for one method and setting. */
typedef struct {
    char label[96];
    int n;
    float seconds[MAX_CURVE_POINTS], error[MAX_CURVE_POINTS]; /* the estimate's */
    int shown_n;
    float shown_seconds[MAX_CURVE_POINTS], shown_error[MAX_CURVE_POINTS]; /* the image shown's */
} error_curve;

typedef struct {
    view_controller *vc; /* the render side */
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
    double sent_at; /* when it was sent */
    /* The cost of the estimator settings: a full frame's time before their last change (0:
     * unknown), and the generation of that change (full frames from it on measure the new ones). */
    double cost_before_ms;
    uint64_t cost_generation;
    double step_ms; /* from the last change sent to its first image taken here; < 0: none yet */
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
    double rel_error, shown_error; /* the last measured, of the estimate and of the image shown */
    uint64_t curve_resets;
    error_curve curves[MAX_CURVES];
    int num_curves, current_curve;
    ui_curve ui_curves[MAX_CURVES];
    /* the reference's camera, from its description (view_nav.c) */
    int reference_cam_valid;
    camera reference_cam;
    char reference_lights[4096];            /* its light edits */
    int error_paused_shown;                 /* the note about the paused error plot is up */
    pthread_t captures[MAX_CAPTURES];       /* the script's captures being written... */
    char capture_names[MAX_CAPTURES][1024]; /* ...as the script named them */
    int num_captures;
    /* images taken from the render thread: all, those at full resolution, and their pixels */
    unsigned long long images_shown, images_full, image_pixels;
    char status[600];     /* what the panel should say about the view: pauses, an unlit scene */
    uint64_t unlit_noted; /* 1 + the info_serial of the last unlit scene reported */
    uint64_t script_load_target;
    /* a scripted continuous orbit */
    double spin_rate, spin_until; /* degrees per second, until when */
    /* input */
    double mouse_x, mouse_y;
    double scroll;
    int keys_pressed[GLFW_KEY_LAST + 1];
    double last_time;
    /* Drawing: llvmpipe draws the window on the CPU the renderer needs, so a frame is drawn only
     * when something changed (an image, input, the script) and otherwise twice a second; input
     * that drags the camera or a light, and script actions that move them, wait for the image
     * they bring (a drag's 60 events a second drew 60 frames: a fifth of the 2 cores). */
    unsigned long long input_events; /* GLFW input callbacks so far */
    unsigned long long drawn_events; /* ...as of the last frame drawn */
    double drawn_at, redraw_until;   /* the last frame drawn; frames drawn until then after input */
    int settle;                      /* the next frame is drawn: the last one changed the panel */
    int dragging_view;               /* a held button has moved the camera or a light (view_dragging) */
    unsigned long long frames_drawn; /* for the stats line */
    /* script */
    view_script script;
    const char *script_path_for_errors;
    char window_shot[1024]; /* a pending capture of the window, taken after the next draw */
    int script_pos, script_waiting, script_errors;
    unsigned long long script_shown; /* script actions done that the window shows (not moves) */
    long long script_wait_target;
    uint64_t script_wait_generation;
    int quit;
    double reference_noise;   /* the reference's own relative L2 noise, from its description; < 0 unknown */
    double sleep_until;       /* a script's sleep */
    int was_held;             /* refinement stood still at the last frame drawn... */
    double held_seconds;      /* ...since this time */
    int pending_w, pending_h; /* a new size of the place beside the panel, not yet rendered at... */
    double pending_since;     /* ...since this time */
    int panel_dragging;       /* the panel's edge was being dragged at the last frame */
    const char *variant_labels[MAX_VIEW_VARIANTS + 1]; /* the panel's: the defaults, then info's names */
    uint64_t variant_target;                           /* the load of a variant switch under way, or 0 */
} ui_thread;

/* The viewer's UI files, each calling only those above it here (view_display.c, the top, calls
 * them all; view_script_run.c drives them for scripts). */

/* view_camera.c: the free camera */
camera ctl_camera(const cam_ctl *c);
/* The free camera at cam, orbiting a centre in front of it. */
cam_ctl ctl_from_camera(const camera *cam, const scene_info *info);
void ctl_orbit(cam_ctl *c, float dyaw, float dpitch);
void ctl_pan(cam_ctl *c, float dx, float dy);
void ctl_zoom(cam_ctl *c, float factor);

/* view_window.c: the image's place beside the panel, the requests made of the render side */
/* The image's size beside the panel: in framebuffer pixels (the render size), in window units. */
void view_image_size(ui_thread *u, int *w, int *h);
void view_image_window_size(ui_thread *u, int *w, int *h);
/* Where the image is drawn (x0, y0, x1, y1, window units): the place beside the panel, or, while
 * the image shown was rendered for another size, the largest part of it of the image's shape. */
void view_image_rect(ui_thread *u, float rect[4]);
/* Sends the camera, estimator settings and lights: a change that resets the accumulation. */
void send_change(ui_thread *u);
long long frames_of_current_state(const ui_thread *u);
void request_export(ui_thread *u, const char *name);
/* kind: LOAD_SCENE, LOAD_ENV (path), LOAD_SKY, LOAD_NO_ENV. */
void request_load(ui_thread *u, int kind, const char *path);
/* The scene again with material variant v (-1: the defaults), the view kept. */
void request_variant(ui_thread *u, int v);
/* A full frame's time with the current estimator settings; 0 before one is measured. */
double view_cost_ms(const ui_thread *u);

/* view_image.c: the image shown, tone-mapped into the window's texture, and saved */
void make_texture(ui_thread *u);
void tonemap_and_upload(ui_thread *u);
void take_screenshot(ui_thread *u, const char *name);

/* view_nav.c: navigation that cannot get lost, resets and bookmarks, the reference, status */
/* The camera chosen in the controls (or the scene's first, or one framing the scene). */
void reset_view(ui_thread *u);
void bookmarks_load(ui_thread *u);
int bookmark_save(ui_thread *u, int slot);
int bookmark_restore(ui_thread *u, int slot);
/* Which bookmarks are set, and where they live, for the panel. */
void describe_bookmarks(ui_thread *u);
/* A reference image for the error view and plot, measured from cam with lights (its description's;
 * NULL: from any view); 0, or -1 with the message shown. */
int load_reference(ui_thread *u, const char *path, const camera *cam, const char *lights);

/* Distance to the first surface along o + t d, or INFINITY (also when the scene is busy). */
float scene_distance(ui_thread *u, vec3 o, vec3 d);
/* Zoom by factor (< 1 closer) about what is under the centre of the view, never through a wall. */
void nav_zoom(ui_thread *u, float factor);
/* Orbit and pan as ctl_orbit and ctl_pan, without passing through a wall. */
void nav_orbit(ui_thread *u, float dyaw, float dpitch);
void nav_pan(ui_thread *u, float dx, float dy);
/* Flies by a step along dir (unit), at a speed set by what is ahead, stopping short of walls. */
void nav_fly(ui_thread *u, vec3 dir, double dt);
/* A view of the whole scene, lit when possible. */
void frame_scene(ui_thread *u);
/* What the viewer renders, as a description has it (reference.h): material model, scene and its
 * hash, environment, variant, the scene's size, w x h, and the light edits lights. 0, or -1 with
 * err set (a file unreadable for hashing). */
int describe_view(ui_thread *u, reference_info *out, int w, int h, const light_edits *lights, char *err, size_t errlen);
/* Loads a reference after checking its description against the viewer's scene, environment,
 * size and light edits; returns 0 or -1 (refused, message shown). */
int open_reference(ui_thread *u, const char *path);
/* Back to the reference's camera; -1 (message set) without one. */
int reference_view(ui_thread *u);
/* Refreshes u->status and its notes (every UI frame). */
void update_status(ui_thread *u);

/* view_panel.c: the shortcut list, the window's fit to the image, pause and limits */
typedef struct {
    const char *keys, *action;
} view_shortcut;
extern const view_shortcut view_shortcuts[];
extern const int num_view_shortcuts;
void print_shortcuts(FILE *f);
/* Makes the window hold an image of image_w x image_h beside the panel. */
void view_fit_window(ui_thread *u, int image_w, int image_h);
/* Takes a new size of the place beside the panel as the render size (a new accumulation) once the
 * window has stopped changing size and the panel's edge is no longer dragged. */
void view_follow_size(ui_thread *u, double now);
/* The pause and limits of the controls, to the render thread. */
void push_refinement(ui_thread *u);
/* A script's `variant NAME` (or `default`): the switch asked for; 0, or -1 with a message. */
int panel_variant(ui_thread *u, const char *name, char *err, size_t errlen);
/* `set spp N`, `set time S`: 0, -1 with a message, or 1 for a name not theirs. */
int panel_set(ui_thread *u, const char *name, const char *value, char *err, size_t errlen);
/* pause, resume, sleep. Returns 0 while the script has to wait. */
int panel_script_action(ui_thread *u, const script_action *a);
/* More of a stats line: pause, limits, window, image and panel sizes. */
void print_panel_stats(ui_thread *u);
/* Before the panel: its keys, and the overlay's and help's part of st. After: its buttons. */
void panel_frame(ui_thread *u, ui_stats *st);
void panel_after(ui_thread *u);

/* view_input.c: controls, lights, keys and mouse */
void apply_controls(ui_thread *u, int camera_changed);
vec3 light_position(const ui_thread *u, int g);
int light_movable(const ui_thread *u, int g);
void update_light_screen(ui_thread *u);
int move_light(ui_thread *u, int g, vec3 delta, char *err, size_t errlen);
void reset_lights(ui_thread *u);
void press_key(ui_thread *u, int key, int mods);
void on_key(GLFWwindow *win, int key, int scancode, int action, int mods);
void on_scroll(GLFWwindow *win, double dx, double dy);
void on_drop(GLFWwindow *win, int count, const char **paths);
void note_input_callbacks(GLFWwindow *win);
int handle_input(ui_thread *u, double dt);
/* Whether the mouse drags the camera or a light in the image (a button held, the panel not under it). */
int view_dragging(ui_thread *u);

/* view_display.c: the published image, its error plot, captures, the panel drawn */
/* Takes what the render thread published: VIEW_NEW_IMAGE if an image, VIEW_NEW_NEWS if an error
 * measured, a message or a scene's description (0: nothing new to draw). */
enum { VIEW_NEW_IMAGE = 1, VIEW_NEW_NEWS = 2 };
int fetch_published(ui_thread *u);
/* Saves the image shown, linear and at the render's size (a preview magnified as the window
 * draws it), as an EXR with its description (numbered, never overwriting), written by a thread
 * of its own; capture_finish waits for those under way (before the viewer exits). */
void capture_image(ui_thread *u, const char *name);
void capture_finish(ui_thread *u);
void capture_window(ui_thread *u, int w, int h);
void draw_image_and_panel(ui_thread *u);

/* view_script_run.c */
void run_script(ui_thread *u);

#endif
