/* glint — pinhole cameras: making them and generating primary rays. */
#ifndef GLINT_CAMERA_H
#define GLINT_CAMERA_H

#include "scene.h"

/* A camera at eye looking at target; up need not be orthogonal to the view direction. */
camera camera_look_at(vec3 eye, vec3 target, vec3 up, float yfov);
/* The default view of a scene without cameras: from +Z toward the bounds' centre, far enough
 * back that the front face of the box fills the frame. */
camera camera_frame_bounds(bounds3 b, float yfov, float aspect);
/* The scene's camera `index` (-1 or out of range: the first one, or the framing default). */
camera scene_camera(const scene *s, int index, float aspect);

/* Unit direction through image position (x, y) in [0,1)^2, y downward, for width/height aspect;
 * tan_half_fov = tan(yfov / 2), computed once by callers that trace many rays. */
static inline vec3 camera_ray_dir_tan(const camera *c, float tan_half_fov, float aspect, float x, float y) {
    float th = tan_half_fov;
    float sx = (2.0f * x - 1.0f) * th * aspect;
    float sy = (1.0f - 2.0f * y) * th;
    return normalize3(add3(c->forward, add3(scale3(c->right, sx), scale3(c->up, sy))));
}

/* The same, for a single ray. */
static inline vec3 camera_ray_dir(const camera *c, float aspect, float x, float y) {
    return camera_ray_dir_tan(c, tanf(0.5f * c->yfov), aspect, x, y);
}

#endif
