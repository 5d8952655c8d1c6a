/* glint view: the UI thread's input. The panel's controls, keys and mouse move the camera and the
 * lights and change the settings; each change goes to the render thread as a request in the
 * shared state. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <string.h>

#include "image_io.h"
#include "view.h"

/* ---- the controls ---------------------------------------------------------------------------- */

static unsigned show_mask_of(int show) {
    switch (show) {
    case UI_SHOW_DIRECT: return 1u << COMP_DIRECT;
    case UI_SHOW_INDIRECT: return 1u << COMP_INDIRECT;
    case UI_SHOW_HIGHLIGHTS: return 1u << COMP_HIGHLIGHTS;
    case UI_SHOW_WORK: return SHOW_WORK_MAP;
    case UI_SHOW_ESTIMATOR: return SHOW_ESTIMATOR_SHARE;
    default: return COMP_MASK_ALL;
    }
}

/* Sends what changed in the controls since the last call: estimator settings reset the
 * accumulation; display settings only change how the image is shown. */
void apply_controls(ui_thread *u, int camera_changed) {
    const render_params *p = &u->ctl.params, *was = &u->applied_ctl.params;
    int estimator_changed = params_differ(p, was, PARAM_GROUPS_LIVE); /* any entry of the table a viewer takes */
    /* the panel compares the new settings' cost with the last ones' (once a full frame measured it) */
    if (estimator_changed && u->stats.frames_generation >= u->cost_generation)
        u->cost_before_ms = u->stats.full_frame_ms;
    camera_changed |= estimator_changed;
    /* Picking another light shows its intensity; changing the intensity changes the light. */
    if (u->ctl.light < 0 || u->ctl.light >= u->info.num_lights) u->ctl.light = -1;
    if (u->ctl.light != u->applied_ctl.light) {
        u->ctl.light_gain = u->ctl.light >= 0 ? u->lights.gain[u->ctl.light] : 1.0f;
    } else if (u->ctl.light >= 0 && u->ctl.light_gain != u->applied_ctl.light_gain) {
        u->lights.gain[u->ctl.light] = u->ctl.light_gain;
        camera_changed = 1;
    }
    if (camera_changed) send_change(u);
    if (estimator_changed) u->cost_generation = u->sent_generation;
    /* the look (the table's display entries, and the component shown): never the estimate */
    if (params_differ(p, was, PARAM_GROUPS_LOOK)) u->need_tonemap = 1;
    if (u->ctl.show != u->applied_ctl.show || p->look.denoise != was->look.denoise) {
        controller_set_look(u->vc, show_mask_of(u->ctl.show), p->look.denoise);
        u->need_tonemap = 1;
    }
    u->applied_ctl = u->ctl;
}

/* ---- lights ---------------------------------------------------------------------------------- */

vec3 light_position(const ui_thread *u, int g) { return add3(u->info.lights[g].center, u->lights.offset[g]); }

int light_movable(const ui_thread *u, int g) {
    return g >= 0 && g < u->info.num_lights && u->info.lights[g].type != LIGHT_DIRECTIONAL;
}

/* World units per window unit at distance z in front of the camera. */
static float pixel_footprint(ui_thread *u, float z) {
    float r[4];
    view_image_rect(u, r);
    return 2.0f * z * tanf(0.5f * u->cam.yfov) / fmaxf(r[3] - r[1], 1.0f);
}

/* Where each light appears in the window (for markers and picking): on the image as drawn. */
void update_light_screen(ui_thread *u) {
    float r[4];
    view_image_rect(u, r);
    float ww = fmaxf(r[2] - r[0], 1.0f), wh = fmaxf(r[3] - r[1], 1.0f);
    camera c = ctl_camera(&u->cam);
    float t = tanf(0.5f * c.yfov), aspect = ww / wh;
    for (int g = 0; g < u->info.num_lights; g++) {
        vec3 d = sub3(light_position(u, g), c.position);
        float z = dot3(d, c.forward);
        u->light_xy[2 * g] = u->light_xy[2 * g + 1] = NAN;
        if (!light_movable(u, g) || !(z > 1e-6f)) continue;
        float x = dot3(d, c.right) / (z * t * aspect), y = dot3(d, c.up) / (z * t);
        u->light_xy[2 * g] = r[0] + 0.5f * (x + 1.0f) * ww;
        u->light_xy[2 * g + 1] = r[1] + 0.5f * (1.0f - y) * wh;
    }
}

/* The light drawn nearest to window position (x, y), within a few pixels (scaled as the markers
 * are, for HiDPI); -1 for none. */
static int pick_light(ui_thread *u, double x, double y) {
    update_light_screen(u);
    int best = -1;
    double reach = 24.0 * (double)ui_scale(), best_d2 = reach * reach;
    for (int g = 0; g < u->info.num_lights; g++) {
        double dx = (double)u->light_xy[2 * g] - x, dy = (double)u->light_xy[2 * g + 1] - y;
        double d2 = dx * dx + dy * dy;
        if (d2 < best_d2) best_d2 = d2, best = g;
    }
    return best;
}

/* Moves light g by delta (world units); the caller sends the change. Returns 0, or -1 with a
 * message when g has no position. */
int move_light(ui_thread *u, int g, vec3 delta, char *err, size_t errlen) {
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
void reset_lights(ui_thread *u) {
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

/* ---- keys and mouse -------------------------------------------------------------------------- */

/* keys_pressed holds 1 + the modifier bits of each press since the last frame. */
void press_key(ui_thread *u, int key, int mods) {
    if (key >= 0 && key <= GLFW_KEY_LAST) u->keys_pressed[key] = 1 + mods;
}

void on_key(GLFWwindow *win, int key, int scancode, int action, int mods) {
    (void)scancode;
    ui_thread *u = glfwGetWindowUserPointer(win);
    u->input_events++;
    if (action == GLFW_PRESS && !ui_wants_keyboard()) press_key(u, key, mods);
}

void on_scroll(GLFWwindow *win, double dx, double dy) {
    (void)dx;
    ui_thread *u = glfwGetWindowUserPointer(win);
    u->input_events++;
    /* Over the image only: the panel's hover state is the last frame's, and a cursor that has
     * just moved onto the panel would zoom instead of scrolling it. */
    double x, y;
    float r[4];
    glfwGetCursorPos(win, &x, &y);
    view_image_rect(u, r);
    int over_image = x >= (double)r[0] && x < (double)r[2] && y >= (double)r[1] && y < (double)r[3];
    if (!ui_wants_mouse() && over_image) u->scroll += dy;
}

void on_drop(GLFWwindow *win, int count, const char **paths) {
    ui_thread *u = glfwGetWindowUserPointer(win);
    u->input_events++;
    if (count < 1) return;
    /* An image is an environment map; anything else is taken for a scene. */
    const char *dot = strrchr(paths[0], '.');
    int env = dot && (strcmp(dot, ".exr") == 0 || strcmp(dot, ".hdr") == 0);
    request_load(u, env ? LOAD_ENV : LOAD_SCENE, paths[0]);
}

/* The other input, counted only: a frame is drawn after any (the panel's widgets answer it). */
static void note_input(GLFWwindow *win) { ((ui_thread *)glfwGetWindowUserPointer(win))->input_events++; }
static void on_cursor(GLFWwindow *win, double x, double y) { (void)x, (void)y, note_input(win); }
static void on_button(GLFWwindow *win, int button, int action, int mods) {
    (void)button, (void)action, (void)mods, note_input(win);
}
static void on_char(GLFWwindow *win, unsigned c) { (void)c, note_input(win); }
static void on_enter(GLFWwindow *win, int entered) { (void)entered, note_input(win); }
static void on_focus(GLFWwindow *win, int focused) { (void)focused, note_input(win); }
static void on_size(GLFWwindow *win, int w, int h) { (void)w, (void)h, note_input(win); }
static void on_refresh(GLFWwindow *win) { note_input(win); }

/* Installed before Dear ImGui's backend, which chains to them. */
void note_input_callbacks(GLFWwindow *win) {
    glfwSetCursorPosCallback(win, on_cursor);
    glfwSetMouseButtonCallback(win, on_button);
    glfwSetCharCallback(win, on_char);
    glfwSetCursorEnterCallback(win, on_enter);
    glfwSetWindowFocusCallback(win, on_focus);
    glfwSetFramebufferSizeCallback(win, on_size);
    glfwSetWindowRefreshCallback(win, on_refresh);
}

static int button_held(ui_thread *u) {
    return glfwGetMouseButton(u->win, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS ||
           glfwGetMouseButton(u->win, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS ||
           glfwGetMouseButton(u->win, GLFW_MOUSE_BUTTON_MIDDLE) == GLFW_PRESS;
}

/* Set by handle_input once a held button has moved the camera or a light: the press itself is
 * drawn (the panel decides whether it is its own), the drag's moves are not. */
int view_dragging(ui_thread *u) { return u->dragging_view && button_held(u); }

/* Keys, mouse and the panel's actions. Returns 1 when the camera changed. */
int handle_input(ui_thread *u, double dt) {
    int changed = 0;
    float speed = 0.25f * u->info.diag; /* for lights: scene sizes per second */
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
            nav_fly(u, normalize3(move), dt);
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
        nav_orbit(u, (float)(u->spin_rate * dt * 3.14159265358979 / 180.0), 0.0f);
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
    if (!button_held(u)) u->dragging_view = 0;
    if (u->dragging_light) {
        int g = u->ctl.light;
        u->dragging_view = 1;
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
            nav_orbit(u, (float)dx * 3.0f * scale, (float)-dy * 3.0f * scale);
            changed = u->dragging_view = 1;
        } else if (glfwGetMouseButton(u->win, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS ||
                   glfwGetMouseButton(u->win, GLFW_MOUSE_BUTTON_MIDDLE) == GLFW_PRESS) {
            nav_pan(u, (float)-dx * scale, (float)dy * scale);
            changed = u->dragging_view = 1;
        }
    }
    if (u->scroll != 0.0) {
        nav_zoom(u, powf(0.85f, (float)u->scroll));
        u->scroll = 0.0;
        changed = 1;
    }
    if (u->keys_pressed[GLFW_KEY_R]) u->ctl.reset_view = 1;
    if (u->keys_pressed[GLFW_KEY_F12]) u->ctl.screenshot = 1;
    if (u->keys_pressed[GLFW_KEY_F11]) u->ctl.export_exr = 1;
    if (u->keys_pressed[GLFW_KEY_TAB]) u->ctl.show_panel = !u->ctl.show_panel;
    if (u->keys_pressed[GLFW_KEY_ESCAPE]) u->quit = 1;
    if (u->keys_pressed[GLFW_KEY_F]) u->ctl.frame_scene = 1;
    if (u->keys_pressed[GLFW_KEY_C]) u->ctl.reference_view = 1;
    if (u->keys_pressed[GLFW_KEY_K]) u->ctl.uniform_sky = 1;
    /* 1-9 the scene's cameras; with ctrl, save bookmark N; with shift, restore it. */
    for (int k = 1; k <= 9; k++) {
        int pressed = u->keys_pressed[GLFW_KEY_0 + k];
        int mods = pressed - 1;
        if (!pressed) continue;
        if (mods & GLFW_MOD_CONTROL)
            bookmark_save(u, k);
        else if (mods & GLFW_MOD_SHIFT)
            bookmark_restore(u, k);
        else if (k - 1 < u->info.num_cameras)
            u->ctl.camera = k - 1;
    }
    memset(u->keys_pressed, 0, sizeof u->keys_pressed);

    if (u->ctl.camera != u->applied_ctl.camera) u->ctl.reset_view = 1;
    if (u->ctl.reset_view) {
        reset_view(u);
        u->ctl.reset_view = 0;
        changed = 1;
    }
    if (u->ctl.frame_scene) {
        frame_scene(u);
        changed = 1;
    }
    if (u->ctl.reference_view && reference_view(u) == 0) changed = 1;
    if (u->ctl.uniform_sky) { /* a toggle: the uniform sky on, or off again */
        char env[1024];
        controller_env(u->vc, env, sizeof env);
        int sky = strcmp(env, ENV_SKY) == 0;
        request_load(u, sky ? LOAD_NO_ENV : LOAD_SKY, "");
    }
    u->ctl.frame_scene = u->ctl.reference_view = u->ctl.uniform_sky = 0;
    if (u->ctl.screenshot) take_screenshot(u, "glint-screenshot.png");
    if (u->ctl.export_exr) request_export(u, "glint-export.exr");
    if (u->ctl.load_scene) request_load(u, LOAD_SCENE, u->ctl.path);
    if (u->ctl.load_env) request_load(u, LOAD_ENV, u->ctl.path);
    if (u->ctl.load_reference) open_reference(u, u->ctl.path);
    u->ctl.screenshot = u->ctl.export_exr = u->ctl.load_scene = u->ctl.load_env = u->ctl.load_reference = 0;
    return changed;
}
