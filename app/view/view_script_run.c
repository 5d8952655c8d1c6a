/* glint view: runs a script's actions (view_script.h) through the viewer's own input paths, one
 * UI frame at a time, so tests drive the real window. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "view.h"

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
    /* One line, whole: a capture's thread says "glint: wrote" on stdout too. */
    flockfile(stdout);
    printf("stats lights=%d light=%d light_intensity=%g light_pos=%.5f,%.5f,%.5f light_xy=%.1f,%.1f mean=%.6g "
           "rel_error=%.6g displayed_error=%.6g time=%.3f cam=%.5f,%.5f,%.5f bookmarks=%s ",
           u->info.num_lights, u->ctl.light, (double)u->ctl.light_gain, (double)lp.x, (double)lp.y, (double)lp.z,
           (double)lx, (double)ly, mean, u->rel_error, u->shown_error, seconds_since(u->started_at),
           (double)u->cam.pos.x, (double)u->cam.pos.y, (double)u->cam.pos.z, nb ? marks : "-");
    printf("scene=%s frames=%lld width=%d height=%d show=%s ", u->info.name, frames_of_current_state(u), u->front.width,
           u->front.height, ui_show_name(u->ctl.show));
    /* The environment, and the standing notes (the panel's status line) as flags. */
    char env[1024];
    controller_env(u->vc, env, sizeof env);
    if (!env[0]) snprintf(env, sizeof env, "-");
    printf("env=%s unlit_note=%d paused_note=%d step_ms=%.1f cost_ms=%.1f cost_before_ms=%.1f", env,
           strstr(u->status, "no light") != NULL, strstr(u->status, "paused") != NULL, u->step_ms, view_cost_ms(u),
           u->cost_before_ms);
    /* Images taken from the render side (what the window showed), those at full resolution, their
     * pixels in all, and the size they render at: updates a second and their resolution. */
    printf(" images=%llu images_full=%llu image_pixels=%llu render_size=%dx%d", u->images_shown, u->images_full,
           u->image_pixels, u->front.full_w, u->front.full_h);
    printf(" frames_drawn=%llu", u->frames_drawn); /* the window's: only when something changed */
    view_stats_print(&u->stats);                   /* the render side's record, as it names its fields */
    print_panel_stats(u);
    /* Every parameter of the table, as `set` takes it (vsl-count=128 is vsl_count=128). */
    int nparams;
    const param_desc *table = params_table(&nparams);
    for (int i = 0; i < nparams; i++) {
        if (table[i].group == PARAM_SETUP) continue; /* the size: width= and height= above */
        char name[64], value[64];
        snprintf(name, sizeof name, "%s", table[i].name);
        for (char *c = name; *c; c++) *c = *c == '-' ? '_' : *c;
        param_format(&table[i], &u->ctl.params, value, sizeof value);
        printf(" %s=%s", name, value);
    }
    printf("\n");
    fflush(stdout);
    funlockfile(stdout);
}

/* A live parameter by its command-line name. Returns 0, or -1 with a message. */
static int set_parameter(ui_thread *u, const char *name, const char *value, char *err, size_t errlen) {
    char opt[80];
    snprintf(opt, sizeof opt, "--%s", name);
    long long n;
    double x;
    /* The method, the path depth and the many-light settings, as glint render's options (the
     * parameter table). */
    char why[256];
    int limit = panel_set(u, name, value, err, errlen); /* spp, time */
    if (limit <= 0) return limit;
    const unsigned live = PARAM_GROUPS_LIVE | PARAM_GROUPS_LOOK;
    const param_desc *setup = param_find(name);
    if (setup && !(live >> setup->group & 1u))
        return snprintf(err, errlen, "%s: given when the viewer opens (--%s)", name, name), -1;
    int applied = params_set(&u->ctl.params, live, name, value, why, sizeof why);
    if (applied < 0) return snprintf(err, errlen, "%s: %s", name, why), -1;
    if (applied > 0) return 0;
    if (strcmp(name, "show") == 0) {
        int found = -1;
        for (int i = 0; i < UI_SHOW_COUNT; i++)
            if (strcmp(value, ui_show_name(i)) == 0) found = i;
        if (found < 0)
            return snprintf(err, errlen, "show: one of all, direct, indirect, highlights, work, estimator, error"), -1;
        if (found == UI_SHOW_ERROR && !u->reference.rgb)
            return snprintf(err, errlen, "show error: no reference loaded"), -1;
        u->ctl.show = found;
    } else if (strcmp(name, "light") == 0) {
        if (cli_parse_int(opt, value, 0, u->info.num_lights - 1, &n) != 0)
            return snprintf(err, errlen, "no light %s", value), -1;
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

/* A key by name, with "ctrl+" or "shift+" in front for the modifier (into *mods). */
static int key_from_name(const char *name, int *mods) {
    *mods = 0;
    if (strncmp(name, "ctrl+", 5) == 0)
        *mods = GLFW_MOD_CONTROL, name += 5;
    else if (strncmp(name, "shift+", 6) == 0)
        *mods = GLFW_MOD_SHIFT, name += 6;
    if (strcmp(name, "r") == 0) return GLFW_KEY_R;
    if (strcmp(name, "f11") == 0) return GLFW_KEY_F11;
    if (strcmp(name, "f12") == 0) return GLFW_KEY_F12;
    if (strcmp(name, "tab") == 0) return GLFW_KEY_TAB;
    if (strcmp(name, "escape") == 0) return GLFW_KEY_ESCAPE;
    if (strcmp(name, "f") == 0) return GLFW_KEY_F;
    if (strcmp(name, "c") == 0) return GLFW_KEY_C;
    if (strcmp(name, "k") == 0) return GLFW_KEY_K;
    if (strcmp(name, "n") == 0) return GLFW_KEY_N;
    if (strcmp(name, "f1") == 0) return GLFW_KEY_F1;
    if (strcmp(name, "space") == 0) return GLFW_KEY_SPACE;
    if (strcmp(name, "slash") == 0) return GLFW_KEY_SLASH;
    if (strlen(name) == 1 && name[0] >= '0' && name[0] <= '9') return GLFW_KEY_0 + (name[0] - '0');
    return -1;
}

/* Whether the last load asked for has been tried and its outcome (a new scene) taken in. */
static int load_settled(ui_thread *u) { return controller_load_settled(u->vc, u->script_load_target, u->info_serial); }

/* Actions that only move the camera or a light, or wait. */
static int moves_only(int kind) {
    return kind == ACT_ORBIT || kind == ACT_PAN || kind == ACT_ZOOM || kind == ACT_MOVE_LIGHT || kind == ACT_SLEEP ||
           kind == ACT_WAIT || kind == ACT_WAIT_FILE;
}

/* Runs script actions until one has to wait. */
void run_script(ui_thread *u) {
    if (u->window_shot[0]) return; /* later actions wait for the capture (a frame or two on) */
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
            if (u->script_waiting) { /* `set denoise`: until an image resolved so is shown */
                if (u->front.denoise != u->ctl.params.look.denoise) return;
                u->script_waiting = 0;
                break;
            }
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
            if (strcmp(a->name, "denoise") == 0 && u->front.denoise != u->ctl.params.look.denoise) {
                u->script_waiting = 1;
                return;
            }
            break;
        case ACT_ORBIT:
            nav_orbit(u, (float)(a->a * 3.14159265358979 / 180.0), (float)(a->b * 3.14159265358979 / 180.0));
            send_change(u);
            break;
        case ACT_PAN:
            nav_pan(u, (float)a->a, (float)a->b);
            send_change(u);
            break;
        case ACT_ZOOM:
            nav_zoom(u, (float)a->a); /* as the wheel zooms */
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
        case ACT_REFERENCE: open_reference(u, a->text); break;
        case ACT_FRAME:
            frame_scene(u);
            send_change(u);
            break;
        case ACT_REFERENCE_CAMERA:
            if (reference_view(u) != 0) {
                cli_error("%s:%d: %s", u->script_path_for_errors, a->line, u->message);
                u->script_errors++;
            } else {
                send_change(u);
            }
            break;
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
        case ACT_CAPTURE: capture_image(u, a->text); break;
        case ACT_LOAD:
        case ACT_ENV:
        case ACT_SKY:
            if (!u->script_waiting) {
                int kind = a->kind == ACT_LOAD            ? LOAD_SCENE
                           : a->kind == ACT_SKY           ? LOAD_SKY
                           : strcmp(a->text, "none") == 0 ? LOAD_NO_ENV
                                                          : LOAD_ENV;
                request_load(u, kind, a->text);
                u->script_waiting = 1;
            }
            if (!load_settled(u)) return;
            u->script_waiting = 0;
            break;
        case ACT_VARIANT:
            if (!u->script_waiting) {
                if (panel_variant(u, a->text, err, sizeof err) != 0) {
                    cli_error("%s:%d: %s", u->script_path_for_errors, a->line, err);
                    u->script_errors++;
                    break;
                }
                u->script_waiting = 1;
            }
            if (!load_settled(u)) return;
            u->script_waiting = 0;
            break;
        case ACT_WINDOW_SHOT: /* taken once the panel settled: later actions wait for it */
            snprintf(u->window_shot, sizeof u->window_shot, "%s", a->text);
            u->script_pos++;
            return;
        case ACT_WHEEL: /* through the wheel's own handler, before this frame updates the panel's hover */
            glfwSetCursorPos(u->win, a->a, a->b);
            on_scroll(u->win, 0.0, a->c);
            break;
        case ACT_WAIT_FILE: /* a test's input events are sent */
            if (access(a->text, F_OK) != 0) return;
            break;
        case ACT_STATS: print_stats(u); break;
        case ACT_BUTTONS: {
            const char *label;
            float r[4];
            for (int i = 0; ui_drawn_button(i, &label, r); i++)
                printf("button %.0f %.0f %.0f %.0f %s\n", (double)r[0], (double)r[1], (double)r[2], (double)r[3],
                       label);
            fflush(stdout);
            break;
        }
        case ACT_QUIT: u->quit = 1; break;
        case ACT_PAUSE:
        case ACT_RESUME:
        case ACT_WAIT_HELD:
        case ACT_SLEEP:
            if (!panel_script_action(u, a)) return;
            break;
        }
        /* a move is shown by the image it brings, as a mouse drag's is; the rest by a frame drawn */
        if (!moves_only(a->kind)) u->script_shown++;
        u->script_pos++;
    }
}
