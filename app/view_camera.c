/* glint view: the free camera (orbit, pan, zoom about a centre in front of it), the scene's
 * cameras, and camera bookmarks 1-9 kept in a file beside the scene (UI thread). */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "image_io.h"
#include "view.h"

static vec3 ctl_forward(const cam_ctl *c) {
    return v3(cosf(c->pitch) * sinf(c->yaw), sinf(c->pitch), -cosf(c->pitch) * cosf(c->yaw));
}

camera ctl_camera(const cam_ctl *c) {
    return camera_look_at(c->pos, add3(c->pos, ctl_forward(c)), v3(0, 1, 0), c->yfov);
}

cam_ctl ctl_from_camera(const camera *cam, const scene_info *info) {
    cam_ctl c;
    c.pos = cam->position;
    c.yaw = atan2f(cam->forward.x, -cam->forward.z);
    c.pitch = asinf(clampf(cam->forward.y, -0.999f, 0.999f));
    c.yfov = cam->yfov;
    float d = dot3(sub3(bounds_center(info->bounds), cam->position), cam->forward);
    c.dist = fmaxf(d, 0.05f * info->diag);
    return c;
}

void ctl_orbit(cam_ctl *c, float dyaw, float dpitch) {
    vec3 target = madd3(c->pos, ctl_forward(c), c->dist);
    c->yaw += dyaw;
    c->pitch = clampf(c->pitch + dpitch, -1.55f, 1.55f);
    c->pos = madd3(target, ctl_forward(c), -c->dist);
}

void ctl_pan(cam_ctl *c, float dx, float dy) {
    camera cam = ctl_camera(c);
    c->pos = add3(c->pos, add3(scale3(cam.right, dx * c->dist), scale3(cam.up, dy * c->dist)));
}

void ctl_zoom(cam_ctl *c, float factor) {
    vec3 target = madd3(c->pos, ctl_forward(c), c->dist);
    c->dist *= factor;
    c->pos = madd3(target, ctl_forward(c), -c->dist);
}

void reset_view(ui_thread *u) {
    int w, h;
    view_image_size(u, &w, &h); /* the image's shape, beside the panel */
    float aspect = h > 0 ? (float)w / (float)h : 16.0f / 9.0f;
    camera c = u->ctl.camera >= 0 && u->ctl.camera < u->info.num_cameras
                   ? u->info.cameras[u->ctl.camera]
                   : (u->info.num_cameras > 0 ? u->info.cameras[0] : camera_frame_bounds(u->info.bounds, 0.8f, aspect));
    u->cam = ctl_from_camera(&c, &u->info);
}

/* ---- camera bookmarks ------------------------------------------------------------------------ */

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
