/* glint view: the free camera (orbit, pan, zoom about a centre in front of it), as a camera and
 * from one (UI thread): plain geometry, below every other file of the viewer's UI. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>

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
