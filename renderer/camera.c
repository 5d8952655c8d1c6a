#include "camera.h"

#include <stdio.h>
#include <string.h>

camera camera_look_at(vec3 eye, vec3 target, vec3 up, float yfov) {
    camera c;
    memset(&c, 0, sizeof c);
    c.position = eye;
    c.forward = normalize3(sub3(target, eye));
    vec3 r = cross3(c.forward, up);
    if (length_sq3(r) < 1e-12f) r = cross3(c.forward, fabsf(c.forward.y) < 0.9f ? v3(0, 1, 0) : v3(1, 0, 0));
    c.right = normalize3(r);
    c.up = cross3(c.right, c.forward);
    c.yfov = yfov;
    return c;
}

camera camera_frame_bounds(bounds3 b, float yfov, float aspect) {
    vec3 centre = bounds_center(b);
    vec3 half = scale3(sub3(b.hi, b.lo), 0.5f);
    float t = tanf(0.5f * yfov);
    float dist = fmaxf(half.y / t, half.x / (t * aspect)) * 1.05f + half.z;
    if (!(dist > 0.0f)) dist = 1.0f;
    camera c = camera_look_at(v3(centre.x, centre.y, centre.z + dist), centre, v3(0, 1, 0), yfov);
    snprintf(c.name, sizeof c.name, "default view");
    return c;
}

camera scene_camera(const scene *s, int index, float aspect) {
    if (s->num_cameras > 0) return s->cameras[index >= 0 && index < s->num_cameras ? index : 0];
    return camera_frame_bounds(s->bounds, 0.8f, aspect);
}

int camera_same_view(const camera *a, const camera *b, float scale) {
    return length3(sub3(a->position, b->position)) <= 1e-4f * scale && dot3(a->forward, b->forward) >= 1.0f - 1e-5f &&
           dot3(a->up, b->up) >= 1.0f - 1e-5f && fabsf(a->yfov - b->yfov) <= 1e-4f;
}
