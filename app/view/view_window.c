/* glint view: the window's layout and what the UI asks of the render side (UI thread): the image's
 * place beside the docked panel, the changes and loads it requests, the cost of the settings
 * shown. The lowest of the viewer's UI files but the camera's: the others call these, and these
 * call none of theirs. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>

#include "view.h"

/* ---- the requests ---------------------------------------------------------------------------- */

/* Sends the camera, estimator settings and lights to the render side; each call is a change that
 * resets the accumulation. */
void send_change(ui_thread *u) {
    camera cam = ctl_camera(&u->cam);
    u->sent_generation = controller_change(u->vc, &cam, &u->ctl.params, &u->lights, u->info_serial);
    u->sent_at = cli_now();
    u->step_ms = -1.0;
}

/* Full-resolution frames rendered in the state the UI last asked for. */
long long frames_of_current_state(const ui_thread *u) {
    return u->stats.frames_generation == u->sent_generation ? u->stats.frames : 0;
}

void request_export(ui_thread *u, const char *name) {
    char path[1024];
    if (unique_path(name, path, sizeof path) != 0) {
        snprintf(u->message, sizeof u->message, "%s: no free file name", name);
        return;
    }
    controller_export(u->vc, path);
}

static void request(ui_thread *u, int kind, const char *path, const char *variant, int keep_view) {
    u->script_load_target = controller_load(u->vc, kind, path, variant, keep_view);
}

void request_load(ui_thread *u, int kind, const char *path) { request(u, kind, path, "", 0); }

void request_variant(ui_thread *u, int v) {
    request(u, LOAD_SCENE, u->info.name, v >= 0 && v < u->info.num_variants ? u->info.variant_names[v] : "", 1);
    u->variant_target = u->script_load_target;
}

/* ---- the image beside the panel -------------------------------------------------------------- */

void view_image_window_size(ui_thread *u, int *w, int *h) {
    int ww, wh;
    glfwGetWindowSize(u->win, &ww, &wh);
    int dock = (int)(ui_dock_width(&u->ctl) + 0.5f);
    *w = ww - dock > 1 ? ww - dock : 1;
    *h = wh > 1 ? wh : 1;
}

void view_image_size(ui_thread *u, int *w, int *h) {
    int ww, wh, fw, fh;
    glfwGetWindowSize(u->win, &ww, &wh);
    glfwGetFramebufferSize(u->win, &fw, &fh);
    if (fw <= 0 || fh <= 0) { /* minimised */
        *w = *h = 0;
        return;
    }
    double ratio = ww > 0 ? (double)fw / ww : 1.0;
    int dock = (int)(ratio * (double)ui_dock_width(&u->ctl) + 0.5);
    *w = fw - dock > 1 ? fw - dock : 1;
    *h = fh > 1 ? fh : 1;
}

void view_image_rect(ui_thread *u, float rect[4]) {
    int w, h;
    view_image_window_size(u, &w, &h);
    float rw = (float)w, rh = (float)h, fit_w = rw, fit_h = rh;
    if (u->front.full_w > 0 && u->front.full_h > 0) {
        float aspect = (float)u->front.full_w / (float)u->front.full_h;
        fit_w = fminf(rw, rh * aspect);
        fit_h = fminf(rh, rw / aspect);
    }
    if (rw - fit_w < 1.0f && rh - fit_h < 1.0f) fit_w = rw, fit_h = rh; /* rounding: pixel for pixel */
    rect[0] = 0.5f * (rw - fit_w);
    rect[1] = 0.5f * (rh - fit_h);
    rect[2] = rect[0] + fit_w;
    rect[3] = rect[1] + fit_h;
}

double view_cost_ms(const ui_thread *u) {
    return u->stats.frames_generation >= u->cost_generation && u->stats.full_frame_ms > 0.0 ? u->stats.full_frame_ms
                                                                                            : 0.0;
}
