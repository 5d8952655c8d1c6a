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
/* Whether two cameras are the same view: positions within 1e-4 scale (scale: the scene's size,
 * its diagonal), directions and field of view within float noise. The viewer measures against a
 * reference only from its view, and glint compare refuses images of two views, by this test. */
int camera_same_view(const camera *a, const camera *b, float scale);

/* Unit direction through image position (x, y) in [0,1)^2, y downward, for width/height aspect. */
static inline vec3 camera_ray_dir(const camera *c, float aspect, float x, float y) {
    float th = tanf(0.5f * c->yfov);
    float sx = (2.0f * x - 1.0f) * th * aspect;
    float sy = (1.0f - 2.0f * y) * th;
    return normalize3(add3(c->forward, add3(scale3(c->right, sx), scale3(c->up, sy))));
}

/* Primary rays of a width x height image, set up once per frame: the direction through pixel
 * coordinates (px, py) (y downward) is corner + px dx + py dy, normalized. */
typedef struct {
    vec3 corner, dx, dy;
} camera_raster;

static inline camera_raster camera_raster_make(const camera *c, int width, int height) {
    float th = tanf(0.5f * c->yfov), aspect = (float)width / (float)height;
    camera_raster r;
    r.dx = scale3(c->right, 2.0f * th * aspect / (float)width);
    r.dy = scale3(c->up, -2.0f * th / (float)height);
    r.corner = add3(c->forward, add3(scale3(c->right, -th * aspect), scale3(c->up, th)));
    return r;
}

static inline vec3 camera_raster_dir(const camera_raster *r, float px, float py) {
    return normalize3(madd3(madd3(r->corner, r->dx, px), r->dy, py));
}

#endif
