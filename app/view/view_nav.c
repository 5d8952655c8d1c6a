/* glint view: navigation that cannot get lost (UI thread). Zoom and fly take their steps from the
 * distance to what the view looks at, found by tracing the render thread's scene under its lock,
 * and never step through a wall in one go; F frames the whole scene, R resets the view, and camera
 * bookmarks 1-9 are kept in a file beside the scene. Also the reference: its image (for the error
 * view and plot), its description (checked as glint bench checks it) and camera, and the standing
 * notes the panel shows: the error plot paused away from the reference's camera, a scene without
 * light. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image_io.h"
#include "reference.h"
#include "view.h"

/* Never waits: while the render side loads or edits the scene, navigation goes on without it. */
float scene_distance(ui_thread *u, vec3 o, vec3 d) { return controller_scene_distance(u->vc, o, d); }

void nav_zoom(ui_thread *u, float factor) {
    cam_ctl *c = &u->cam;
    vec3 f = ctl_camera(c).forward;
    float floor_dist = 1e-5f * u->info.diag;
    /* The step is relative to what is under the centre of the view, which becomes the orbit
     * centre; without anything there, to the orbit distance. */
    float ahead = scene_distance(u, c->pos, f);
    if (isfinite(ahead) && ahead > floor_dist) c->dist = ahead;
    float step = c->dist * (1.0f - factor); /* > 0: forward */
    if (step < 0.0f) {                      /* backward: at most half-way to the wall behind */
        float behind = scene_distance(u, c->pos, scale3(f, -1.0f));
        if (isfinite(behind)) step = fmaxf(step, -0.5f * behind);
    }
    c->pos = madd3(c->pos, f, step);
    c->dist = fmaxf(c->dist - step, floor_dist);
}

void nav_fly(ui_thread *u, vec3 dir, double dt) {
    cam_ctl *c = &u->cam;
    float diag = u->info.diag;
    /* Half the distance to what the view looks at per second: slow near a detail, quick across a
     * hall, whatever the scene's size. */
    float ahead = scene_distance(u, c->pos, ctl_camera(c).forward);
    float speed = isfinite(ahead) ? clampf(0.5f * ahead, 1e-4f * diag, 0.25f * diag) : 0.25f * diag;
    float step = speed * (float)dt;
    float free = scene_distance(u, c->pos, dir); /* at most half-way to a wall */
    if (isfinite(free)) step = fminf(step, 0.5f * free);
    c->pos = madd3(c->pos, dir, step);
}

void nav_orbit(ui_thread *u, float dyaw, float dpitch) {
    cam_ctl *c = &u->cam;
    ctl_orbit(c, dyaw, dpitch);
    /* As a camera on a boom: when a wall stands between the orbit centre and the camera, the
     * camera comes in front of it (from just off the centre, which may lie on a surface). */
    vec3 back = scale3(ctl_camera(c).forward, -1.0f);
    vec3 target = madd3(c->pos, back, -c->dist);
    float eps = 1e-3f * u->info.diag;
    if (c->dist <= 2.0f * eps) return;
    float wall = scene_distance(u, madd3(target, back, eps), back);
    if (isfinite(wall) && eps + wall < c->dist) {
        c->dist = eps + 0.9f * wall;
        c->pos = madd3(target, back, c->dist);
    }
}

void nav_pan(ui_thread *u, float dx, float dy) {
    cam_ctl *c = &u->cam;
    camera cam = ctl_camera(c);
    vec3 d = add3(scale3(cam.right, dx * c->dist), scale3(cam.up, dy * c->dist));
    float len = length3(d);
    if (!(len > 0.0f)) return;
    float free = scene_distance(u, c->pos, scale3(d, 1.0f / len)); /* at most half-way to a wall */
    if (isfinite(free) && len > 0.5f * free) d = scale3(d, 0.5f * free / len);
    c->pos = add3(c->pos, d);
}

/* Whether the view from cam towards the scene's centre first meets a surface on the scene's
 * bounding box: the outside of a wall that closes the scene. */
static int walled_off(ui_thread *u, const camera *cam, vec3 centre) {
    vec3 dir = normalize3(sub3(centre, cam->position));
    float t = scene_distance(u, cam->position, dir);
    if (!isfinite(t)) return 0;
    vec3 p = madd3(cam->position, dir, t), lo = u->info.bounds.lo, hi = u->info.bounds.hi;
    float edge = fminf(fminf(fminf(fabsf(p.x - lo.x), fabsf(p.x - hi.x)), fminf(fabsf(p.y - lo.y), fabsf(p.y - hi.y))),
                       fminf(fabsf(p.z - lo.z), fabsf(p.z - hi.z)));
    return edge <= 0.01f * u->info.diag;
}

void frame_scene(ui_thread *u) {
    int w, h;
    view_image_size(u, &w, &h);
    float aspect = h > 0 ? (float)w / (float)h : 16.0f / 9.0f;
    bounds3 b = u->info.bounds;
    vec3 centre = bounds_center(b);
    camera cam = camera_frame_bounds(b, u->cam.yfov > 0.0f ? u->cam.yfov : 0.8f, aspect);
    /* A closed room framed from outside shows only its unlit walls: then move in along the same
     * line until the centre is in sight, just inside the wall that hid it. */
    if (walled_off(u, &cam, centre)) {
        vec3 back = normalize3(sub3(cam.position, centre));
        float wall = scene_distance(u, centre, back);
        if (isfinite(wall) && wall > 0.02f * u->info.diag)
            cam = camera_look_at(madd3(centre, back, 0.9f * wall), centre, v3(0, 1, 0), cam.yfov);
    }
    u->cam = ctl_from_camera(&cam, &u->info);
    u->ctl.camera = u->applied_ctl.camera = -1; /* a free camera, not the scene's */
    snprintf(u->message, sizeof u->message, "framed the whole scene");
}

/* ---- the reference --------------------------------------------------------------------------- */

/* Loads a reference for the error view and plot, measured from cam with lights when cam is not
 * NULL (its description's), else from any view: it must match the render size. Returns 0, or -1
 * with the message shown (the previous reference stays). */
int load_reference(ui_thread *u, const char *path, const camera *cam, const char *lights) {
    image_rgb img;
    char err[1200];
    if (image_rgb_load(path, &img, err, sizeof err) != 0) {
        snprintf(u->message, sizeof u->message, "%s", err);
        cli_error("%s", err);
        return -1;
    }
    int w, h;
    controller_size(u->vc, &w, &h);
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
    u->reference_cam_valid = cam != NULL;
    if (cam) u->reference_cam = *cam;
    snprintf(u->reference_lights, sizeof u->reference_lights, "%s", cam ? lights : "");
    /* the render side's own copy, for the errors of its images */
    controller_set_reference(u->vc, &copy, cam, u->reference_lights);
    image_rgb_free(&u->reference);
    u->reference = img;
    snprintf(u->reference_path, sizeof u->reference_path, "%s", path);
    /* Its own noise, when glint render described it: the error plot's floor. */
    reference_info info;
    char why[1200];
    u->reference_noise = reference_load(path, &info, why, sizeof why) == 0 && info.has_noise ? info.rel_l2_noise : -1.0;
    u->rel_error = u->shown_error = -1.0;
    u->num_curves = 0; /* errors against another image do not compare */
    u->current_curve = -1;
    u->need_tonemap = 1;
    snprintf(u->message, sizeof u->message, "reference %s", path);
    return 0;
}

static int refuse(ui_thread *u, const char *why) {
    snprintf(u->message, sizeof u->message, "%.1150s; reference not used", why);
    cli_error("%s", u->message);
    return -1;
}

int describe_view(ui_thread *u, reference_info *out, int w, int h, const light_edits *lights, char *err,
                  size_t errlen) {
    char env[1024];
    memset(out, 0, sizeof *out);
    snprintf(out->model, sizeof out->model, "%s", BSDF_MODEL_STAMP);
    controller_env(u->vc, env, sizeof env);
    out->width = w;
    out->height = h;
    snprintf(out->scene, sizeof out->scene, "%s", u->info.name);
    if (reference_hash_file(out->scene, out->scene_hash, err, errlen) != 0) return -1;
    if (strcmp(env, ENV_SKY) == 0) { /* no file renders it */
        snprintf(out->env, sizeof out->env, "the uniform sky");
        snprintf(out->env_hash, sizeof out->env_hash, "uniform-sky");
    } else if (env[0]) {
        snprintf(out->env, sizeof out->env, "%s", env);
        if (reference_hash_file(env, out->env_hash, err, errlen) != 0) return -1;
    }
    if (u->info.variant >= 0) snprintf(out->variant, sizeof out->variant, "%s", u->info.variant_names[u->info.variant]);
    out->scene_diag = u->info.diag;
    light_edits_text(lights, out->lights, sizeof out->lights);
    return 0;
}

int open_reference(ui_thread *u, const char *path) {
    reference_info have, want;
    char err[1200];
    int described = reference_load(path, &have, err, sizeof err);
    if (described < 0) return refuse(u, err);
    if (described == 0) { /* what this view renders, against what the reference was rendered from */
        int w, h;
        controller_size(u->vc, &w, &h);
        if (describe_view(u, &want, w, h, &u->lights, err, sizeof err) != 0) return refuse(u, err);
        /* The view may be anywhere: the reference's camera is where the error is measured. */
        want.camera_index = have.camera_index;
        want.cam = have.cam;
        if (reference_check(path, &have, &want, err, sizeof err) != 0) return refuse(u, err);
    }
    if (load_reference(u, path, described == 0 ? &have.cam : NULL, have.lights) != 0) return -1;
    u->error_paused_shown = 0;
    if (described == 1) {
        snprintf(u->message, sizeof u->message, "reference %s: no description, its scene and camera unchecked", path);
        cli_warning("%s", u->message);
    }
    return 0;
}

int reference_view(ui_thread *u) {
    if (!u->reference.rgb || !u->reference_cam_valid) {
        snprintf(u->message, sizeof u->message, "no reference camera (a reference with a description has one)");
        return -1;
    }
    u->cam = ctl_from_camera(&u->reference_cam, &u->info);
    u->ctl.camera = u->applied_ctl.camera = -1;
    snprintf(u->message, sizeof u->message, "the reference's camera");
    return 0;
}

/* ---- standing notes -------------------------------------------------------------------------- */

void update_status(ui_thread *u) {
    char env[1024];
    controller_env(u->vc, env, sizeof env);
    int len = 0;
    u->status[0] = 0;
    if (u->info.unlit && !env[0]) {
        len += snprintf(u->status, sizeof u->status, "no light in the scene: the image is black (K: a uniform sky)");
        if (u->unlit_noted != u->info_serial + 1) { /* once per scene in the terminal */
            cli_warning("%s has no light; K (or the script's sky) lights it with a uniform sky", u->info.name);
            u->unlit_noted = u->info_serial + 1;
        }
    }
    camera now = ctl_camera(&u->cam);
    char lights[sizeof u->reference_lights];
    light_edits_text(&u->lights, lights, sizeof lights);
    int described = u->reference.rgb && u->reference_cam_valid;
    int away = described && !camera_same_view(&now, &u->reference_cam, u->info.diag);
    int relit = described && !reference_lights_same(lights, u->reference_lights); /* lights unlike its */
    int paused = away || relit;
    if (paused && len < (int)sizeof u->status)
        snprintf(u->status + len, sizeof u->status - (size_t)len, "%serror plot paused: %s", len ? "; " : "",
                 away ? "away from the reference's camera (C returns)" : "lights edited unlike the reference's");
    if (paused != u->error_paused_shown) { /* the message line says it when it happens */
        snprintf(u->message, sizeof u->message, "%s",
                 !paused ? "error plot resumed: the reference's camera"
                 : away  ? "error plot paused: the view left the reference's camera (C returns to it)"
                         : "error plot paused: the lights differ from the reference's");
        u->error_paused_shown = paused;
    }
}

/* ---- resets and camera bookmarks ------------------------------------------------------------- */

void reset_view(ui_thread *u) {
    int w, h;
    view_image_size(u, &w, &h); /* the image's shape, beside the panel */
    float aspect = h > 0 ? (float)w / (float)h : 16.0f / 9.0f;
    camera c = u->ctl.camera >= 0 && u->ctl.camera < u->info.num_cameras
                   ? u->info.cameras[u->ctl.camera]
                   : (u->info.num_cameras > 0 ? u->info.cameras[0] : camera_frame_bounds(u->info.bounds, 0.8f, aspect));
    u->cam = ctl_from_camera(&c, &u->info);
}

/* Beside the scene file; a built-in scene has none, so NAME.glint-bookmarks in the current
 * directory. */
void bookmarks_load(ui_thread *u) {
    memset(u->bookmark_set, 0, sizeof u->bookmark_set);
    const char *builtin = scene_builtin_name(u->info.name);
    if (builtin)
        snprintf(u->bookmarks_path, sizeof u->bookmarks_path, "%s.glint-bookmarks", builtin);
    else
        snprintf(u->bookmarks_path, sizeof u->bookmarks_path, "%s.bookmarks", u->info.name);
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
        snprintf(u->message, sizeof u->message,
                 "%s:%d: not a bookmark line (N x y z yaw pitch distance fov); file ignored", u->bookmarks_path, bad);
        cli_warning("%s", u->message);
        return;
    }
    for (int i = 1; i <= 9; i++)
        if (set[i]) u->bookmarks[i] = marks[i], u->bookmark_set[i] = 1;
}

/* Saves the current view as bookmark slot (1-9), rewriting the file atomically. Returns 0 or -1. */
int bookmark_save(ui_thread *u, int slot) {
    u->bookmarks[slot] = u->cam;
    u->bookmark_set[slot] = 1;
    char buf[2048], err[1200];
    int len = snprintf(buf, sizeof buf,
                       "# glint camera bookmarks: N, position x y z, yaw and pitch (radians), orbit distance, "
                       "vertical fov (radians)\n");
    for (int i = 1; i <= 9; i++) {
        const cam_ctl *c = &u->bookmarks[i];
        if (u->bookmark_set[i] && len < (int)sizeof buf)
            len += snprintf(buf + len, sizeof buf - (size_t)len, "%d %.9g %.9g %.9g %.9g %.9g %.9g %.9g\n", i,
                            (double)c->pos.x, (double)c->pos.y, (double)c->pos.z, (double)c->yaw, (double)c->pitch,
                            (double)c->dist, (double)c->yfov);
    }
    if (len >= (int)sizeof buf ||
        write_file_atomic(u->bookmarks_path, buf, (size_t)len, WRITE_REPLACE, err, sizeof err) != 0) {
        if (len >= (int)sizeof buf) snprintf(err, sizeof err, "%s: bookmarks too long", u->bookmarks_path);
        snprintf(u->message, sizeof u->message, "%s", err);
        cli_error("%s", err);
        return -1;
    }
    snprintf(u->message, sizeof u->message, "bookmark %d saved to %s", slot, u->bookmarks_path);
    return 0;
}

/* Returns 0, or -1 (message set) when the slot is empty. */
int bookmark_restore(ui_thread *u, int slot) {
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

void describe_bookmarks(ui_thread *u) {
    int len = 0;
    for (int i = 1; i <= 9; i++)
        if (u->bookmark_set[i])
            len += snprintf(u->bookmarks_text + len, sizeof u->bookmarks_text - (size_t)len, "%d ", i);
    snprintf(u->bookmarks_text + len, sizeof u->bookmarks_text - (size_t)len, "%s(%s)", len ? "" : "none ",
             u->bookmarks_path);
}
