/* glint — the viewer's panel and display, Dear ImGui behind a C interface (ui.cpp is the only
 * file that sees C++). The viewer owns the controls; the panel edits them in place and reports
 * one-shot actions through flags the viewer clears. */
#ifndef GLINT_UI_H
#define GLINT_UI_H

#include <stddef.h>

#include "params.h"
#include "view_stats.h"

#ifdef __cplusplus
extern "C" {
#endif

struct GLFWwindow;

/* What the display shows: film components, their sum, in false colour the rays each pixel took
 * (against the image's most), which estimator took its samples (--method auto's choice) or the
 * sum's error against a reference. The error comes last: it is offered only with a reference. */
enum {
    UI_SHOW_ALL = 0,
    UI_SHOW_DIRECT,
    UI_SHOW_INDIRECT,
    UI_SHOW_HIGHLIGHTS,
    UI_SHOW_WORK,
    UI_SHOW_ESTIMATOR,
    UI_SHOW_ERROR,
    UI_SHOW_COUNT
};
/* Their names, as the panel and the script's `set show` give them. */
static inline const char *ui_show_name(int show) {
    static const char *const names[UI_SHOW_COUNT] = {"all",  "direct",    "indirect", "highlights",
                                                     "work", "estimator", "error"};
    return show >= 0 && show < UI_SHOW_COUNT ? names[show] : "";
}

typedef struct {
    /* estimator settings: a change resets the accumulation. The panel edits the method, max_depth
     * and vl (its defaults resolved, vl_params_resolve) through params_table. */
    render_params params;
    int camera; /* scene camera index, -1 for the free camera */
    /* the selected light and its intensity: a change of intensity resets */
    int light;        /* light group, -1 for none */
    float light_gain; /* its intensity multiplier */
    /* display settings: a change never resets (and params.look: exposure, tone mapper, denoise) */
    int show; /* UI_SHOW_* */
    int show_panel;
    /* one-shot actions, set by the panel, cleared by the viewer */
    int screenshot, export_exr, reset_view, load_scene, load_env, load_reference;
    char path[1024]; /* the panel's path field for loading */
    /* more one-shot actions (keys F, C, K; the panel may offer buttons): frame the whole scene,
     * return to the reference's camera, toggle a uniform sky */
    int frame_scene, reference_view, uniform_sky;
    /* refinement: paused, or stopped at a limit (0: none); the full image keeps its frames */
    int paused;
    long long spp_limit;
    double time_limit;                   /* seconds since the last reset */
    int show_help;                       /* the shortcut overlay */
    int bookmark_save, bookmark_restore; /* one-shot: a slot 1-9, 0 none */
    int variant;                         /* the scene's material variant, -1 for the default materials */
} ui_controls;

/* One curve of the error plot: relative L2 error against seconds since a reset, of the estimate
 * (the film) and of the image shown (the display's view of it, filtered while young). */
typedef struct {
    const char *label; /* the method and settings it was measured with */
    const float *seconds, *error;
    int n;
    const float *shown_seconds, *shown_error;
    int shown_n;
} ui_curve;

typedef struct {
    view_stats render; /* the render side's record (view_stats.h), as it stands */
    const char *scene_name;
    double spp;     /* whole frames of the state shown */
    double seconds; /* since the last reset (standing still while refinement is held) */
    /* a whole frame's time with the current settings (0: none yet) and before the last change of
     * estimator settings (0: unknown) */
    double cost_ms, cost_before_ms;
    int width, height; /* of the image shown */
    int num_cameras;
    int many_light;                 /* the current method uses virtual lights: show their settings */
    int highlights;                 /* the current method is vsl+hl: show the highlight settings */
    const char *const *light_names; /* the scene's light groups, "name (type)" */
    int num_lights;
    int light_movable;      /* the selected light has a position */
    const char *reference;  /* the reference image's path, NULL without one */
    double rel_error;       /* of the estimate (the film) against it; < 0: none yet */
    double shown_error;     /* of the image shown against it; < 0: none yet */
    const ui_curve *curves; /* the error plot, one curve per method and setting */
    int num_curves;
    const char *bookmarks;  /* which of bookmarks 1-9 are set, e.g. "1 3", and where they live */
    const char *message;    /* last export path or error, shown until replaced */
    const char *status;     /* standing notes (error plot paused, no light in the scene), "" for none */
    const char *method;     /* the current method's name, for the overlay */
    int held;               /* refinement stopped: paused or at a limit */
    double reference_noise; /* the reference's own relative L2 noise; < 0: unknown */
    unsigned bookmarks_set; /* bit N: bookmark N is set */
    const char *const *shortcut_keys, *const *shortcut_actions; /* the help overlay's lines */
    int num_shortcuts;
    const char *const *variant_labels; /* "default materials", then the scene's variants */
    int num_variants;                  /* variants (labels: one more); 0 hides the choice */
} ui_stats;

/* Sets up Dear ImGui for a window with a current OpenGL 3.3 context. Returns 0 or -1. */
int ui_init(struct GLFWwindow *window);
void ui_shutdown(void);
void ui_begin_frame(void);
/* The image as a textured quad over rect (x0, y0, x1, y1, window units). texture 0 draws nothing. */
void ui_draw_image(unsigned texture, const float rect[4]);
/* The width the panel docked at the window's right edge takes from the image, in window units: 0
 * while it is hidden, a narrow column for its title bar's arrow while collapsed. Before the first
 * frame, its default width. */
float ui_dock_width(const ui_controls *c);
/* The panel's width in a window that leaves image_w (window units) to the image. */
float ui_dock_width_beside(const ui_controls *c, float image_w);
/* Whether the user is dragging the panel's edge (its width changed since the button went down). */
int ui_panel_resizing(void);
/* The i-th visible button of the panel as last drawn: its label and rect (x0, y0, x1, y1, window
 * units). Returns 0 past the last one. */
int ui_drawn_button(int i, const char **label, float rect[4]);
/* Sizes in window units for the window's content scale (HiDPI), and that content scale. */
float ui_scale(void);
float ui_content_scale(void);
/* Markers over the image at the lights' window positions (2 floats per light; NaN: off
 * screen); the selected one stands out. */
void ui_draw_lights(const float *xy, int n, int selected);
/* The panel (when c->show_panel), the overlay on the image and the shortcut help (c->show_help). */
void ui_panel(ui_controls *c, const ui_stats *s);
void ui_end_frame(void);
/* Whether the panel has the mouse or keyboard (the viewer then ignores them for the camera). */
int ui_wants_mouse(void);
int ui_wants_keyboard(void);

#ifdef __cplusplus
}
#endif

#endif
