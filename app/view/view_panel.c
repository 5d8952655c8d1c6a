/* glint view: what the panel adds to the viewer (UI thread, but for the render thread's hold):
 * the list of shortcuts the help overlay and --help share, the window fitted and followed around
 * the image beside the docked panel, pausing and the spp and time limits, and the panel's own keys
 * and buttons. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "view.h"

/* Every key and mouse action: `glint view --help` prints them, F1 shows them. */
const view_shortcut view_shortcuts[] = {
    {"left drag", "orbit around the point in front of the camera"},
    {"right or middle drag", "pan"},
    {"wheel", "zoom"},
    {"W A S D, Q E", "fly: forward, left, back, right; down, up"},
    {"R", "reset the view"},
    {"F", "frame the whole scene"},
    {"C", "back to the reference's camera"},
    {"K", "a uniform sky on or off"},
    {"1-9", "the scene's cameras"},
    {"ctrl+1-9", "save the view as bookmark N"},
    {"shift+1-9", "restore bookmark N"},
    {"arrows, PageUp/PageDown", "move the selected light"},
    {"ctrl+click", "select the light nearest the cursor"},
    {"ctrl+drag", "move the selected light with the cursor"},
    {"Space", "pause or resume refinement"},
    {"N", "the display's filter and its own samples on or off (the estimate is never filtered)"},
    {"F1 or ?", "show or hide this list"},
    {"F12", "screenshot of the image (PNG)"},
    {"F11", "export the image and its layers (EXR)"},
    {"Tab", "show or hide the panel"},
    {"Esc", "quit"},
    {"drop a file", ".gltf/.glb opens it, .exr/.hdr lights the scene"},
};
const int num_view_shortcuts = (int)(sizeof view_shortcuts / sizeof view_shortcuts[0]);

void print_shortcuts(FILE *f) {
    for (int i = 0; i < num_view_shortcuts; i++)
        fprintf(f, "  %-24s %s\n", view_shortcuts[i].keys, view_shortcuts[i].action);
}

/* ---- the image beside the panel -------------------------------------------------------------- */

void view_fit_window(ui_thread *u, int image_w, int image_h) {
    float dock = ui_dock_width_beside(&u->ctl, (float)image_w);
    if (dock > 0.0f) glfwSetWindowSize(u->win, image_w + (int)(dock + 0.5f), image_h);
}

/* A window being resized sends a stream of sizes: the last one is taken once they stop for this
 * long. A drag of the panel's edge ends with the button's release: its size is taken then. Until
 * then the image keeps its size and is shown scaled (view_image_rect), its accumulation kept. */
#define SIZE_SETTLE_SECONDS 0.2

void view_follow_size(ui_thread *u, double now) {
    int w, h, dragging = ui_panel_resizing();
    int dropped = u->panel_dragging && !dragging;
    u->panel_dragging = dragging;
    view_image_size(u, &w, &h);
    int rw, rh;
    controller_size(u->vc, &rw, &rh);
    int same = w == rw && h == rh;
    if (w <= 0 || h <= 0 || same) { /* minimised, or rendered at that size already */
        u->pending_w = u->pending_h = 0;
        return;
    }
    if (w != u->pending_w || h != u->pending_h || dragging) {
        u->pending_w = w;
        u->pending_h = h;
        u->pending_since = now;
    }
    if (dragging || (!dropped && now - u->pending_since < SIZE_SETTLE_SECONDS)) return;
    controller_set_size(u->vc, w, h);
    u->pending_w = u->pending_h = 0;
    send_change(u); /* a new aspect ratio: the camera too */
}

/* ---- pause and limits ------------------------------------------------------------------------ */

/* Held as asked, and the render thread stands: a frame already under way when the pause came
 * runs to its end (a stopped frame would leave part of its samples in the film). */
static int held(const ui_thread *u) {
    const ui_controls *c = &u->ctl;
    long long frames = frames_of_current_state(u);
    return frames >= 1 && u->stats.standing &&
           (c->paused || (c->spp_limit > 0 && frames >= c->spp_limit) ||
            (c->time_limit > 0.0 && seconds_since(u->stats.reset_at) >= c->time_limit));
}

void push_refinement(ui_thread *u) {
    controller_set_refinement(u->vc, u->ctl.paused, u->ctl.spp_limit, u->ctl.time_limit);
}

int panel_set(ui_thread *u, const char *name, const char *value, char *err, size_t errlen) {
    long long n;
    double x;
    if (strcmp(name, "spp") == 0) {
        if (cli_parse_int("spp", value, 0, 100000000, &n) != 0)
            return snprintf(err, errlen, "spp: 0 (no limit) to 100000000"), -1;
        u->ctl.spp_limit = n;
    } else if (strcmp(name, "time") == 0) {
        if (cli_parse_float("time", value, 0.0, 1e7, &x) != 0)
            return snprintf(err, errlen, "time: 0 (no limit) to 1e7 seconds"), -1;
        u->ctl.time_limit = x;
    } else {
        return 1;
    }
    push_refinement(u);
    return 0;
}

int panel_script_action(ui_thread *u, const script_action *a) {
    switch (a->kind) {
    case ACT_PAUSE:
    case ACT_RESUME:
        u->ctl.paused = a->kind == ACT_PAUSE;
        push_refinement(u);
        return 1;
    case ACT_WAIT_HELD:
        if (!u->script_waiting) { /* one drawn frame first: a key pressed just before acts in it */
            u->script_waiting = 1;
            return 0;
        }
        /* nothing holds refinement: nothing to wait for */
        if (!held(u) && (u->ctl.paused || u->ctl.spp_limit > 0 || u->ctl.time_limit > 0.0)) return 0;
        u->script_waiting = 0;
        return 1;
    case ACT_SLEEP:
        if (!u->script_waiting) {
            u->script_waiting = 1;
            u->sleep_until = cli_now() + a->a;
        }
        if (cli_now() < u->sleep_until) return 0;
        u->script_waiting = 0;
        return 1;
    default: return 1;
    }
}

void print_panel_stats(ui_thread *u) {
    int ww, wh, iw, ih;
    glfwGetWindowSize(u->win, &ww, &wh);
    view_image_window_size(u, &iw, &ih);
    printf(" paused=%d spp_limit=%lld time_limit=%g held=%d help=%d window=%dx%d image=%dx%d dock=%d content_scale=%g",
           u->ctl.paused, u->ctl.spp_limit, u->ctl.time_limit, held(u), u->ctl.show_help, ww, wh, iw, ih, ww - iw,
           (double)ui_content_scale());
    printf(" variant=%s", u->info.variant >= 0 ? u->info.variant_names[u->info.variant] : "-");
}

/* ---- the panel's keys and buttons ------------------------------------------------------------ */

/* Before the panel is drawn: F1 or ? (shift+/) toggles the help, Space pausing, N the display's
 * filter; after it, the
 * bookmark buttons. keys_pressed holds 1 + the modifiers of each key pressed this frame. */
static void panel_keys(ui_thread *u) {
    int slash = u->keys_pressed[GLFW_KEY_SLASH];
    if (u->keys_pressed[GLFW_KEY_F1] || (slash && ((slash - 1) & GLFW_MOD_SHIFT))) u->ctl.show_help = !u->ctl.show_help;
    if (u->keys_pressed[GLFW_KEY_SPACE]) u->ctl.paused = !u->ctl.paused;
    if (u->keys_pressed[GLFW_KEY_N]) u->ctl.params.look.denoise = !u->ctl.params.look.denoise;
}

void panel_frame(ui_thread *u, ui_stats *st) {
    panel_keys(u);
    st->method = method_name(u->ctl.params.method);
    st->held = held(u);
    if (st->held) { /* the image's time stands with it */
        if (!u->was_held) u->held_seconds = st->seconds;
        st->seconds = u->held_seconds;
    }
    u->was_held = st->held;
    st->reference_noise = u->reference.rgb ? u->reference_noise : -1.0;
    for (int k = 1; k <= 9; k++)
        if (u->bookmark_set[k]) st->bookmarks_set |= 1u << k;
    static const char *keys[64], *actions[64];
    for (int i = 0; i < num_view_shortcuts && i < 64; i++)
        keys[i] = view_shortcuts[i].keys, actions[i] = view_shortcuts[i].action;
    st->shortcut_keys = keys;
    st->shortcut_actions = actions;
    st->num_shortcuts = num_view_shortcuts < 64 ? num_view_shortcuts : 64;
    u->variant_labels[0] = "default materials";
    for (int i = 0; i < u->info.num_variants; i++) u->variant_labels[i + 1] = u->info.variant_names[i];
    st->variant_labels = u->variant_labels;
    st->num_variants = u->info.num_variants;
}

/* ---- material variants ----------------------------------------------------------------------- */

/* Whether the variant switch asked for has been tried and its outcome taken in. */
static int variant_settled(ui_thread *u) { return controller_load_settled(u->vc, u->variant_target, u->info_serial); }

/* The panel's choice against the scene shown: a switch reloads the scene with that variant (every
 * part of it follows the materials); one that failed puts the choice back. */
static void follow_variant(ui_thread *u) {
    if (u->variant_target) {
        if (!variant_settled(u)) return;
        u->variant_target = 0;
        u->ctl.variant = u->info.variant;
        return;
    }
    if (u->ctl.variant != u->info.variant) request_variant(u, u->ctl.variant);
}

int panel_variant(ui_thread *u, const char *name, char *err, size_t errlen) {
    int v = -2;
    if (strcmp(name, "default") == 0) v = -1;
    for (int i = 0; i < u->info.num_variants && v == -2; i++)
        if (strcmp(u->info.variant_names[i], name) == 0) v = i;
    if (v == -2) return snprintf(err, errlen, "no material variant '%s'", name), -1;
    u->ctl.variant = v;
    follow_variant(u);
    return 0;
}

void panel_after(ui_thread *u) {
    if (u->ctl.bookmark_save) bookmark_save(u, u->ctl.bookmark_save);
    if (u->ctl.bookmark_restore) bookmark_restore(u, u->ctl.bookmark_restore);
    u->ctl.bookmark_save = u->ctl.bookmark_restore = 0;
    push_refinement(u);
    follow_variant(u);
}
