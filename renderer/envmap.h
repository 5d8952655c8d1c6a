/* glint — the environment map: an equirectangular image of the light arriving from infinitely
 * far away, looked up by direction, with the density light sampling draws directions from.
 * Direction convention (Blender's): image centre u = 0.5 is +X, u = 0.75 is +Z, the top row is +Y.
 * A map is immutable once made; whatever is derived from it for one estimator (the highlights'
 * vMF-prefiltered copy, envfilter.h) is owned by whoever renders with it. */
#ifndef GLINT_ENVMAP_H
#define GLINT_ENVMAP_H

#include <stddef.h>

#include "gmath.h"
#include "image_io.h"
#include "sampling.h"

typedef struct {
    image_rgb image; /* linear RGB */
    dist2d dist;     /* over (u, v), luminance * sin(theta), dilated for bilinear lookups */
    float rotation;  /* radians about +Y */
    float mean_luminance;
} env_map;

/* Takes the image (left empty). NULL with err set: out of memory. */
env_map *env_map_create(image_rgb *image, float rotation, char *err, size_t errlen);
void env_map_destroy(env_map *env); /* NULL is fine */
vec3 env_direction(const env_map *env, vec2 uv);
vec2 env_uv(const env_map *env, vec3 d);
/* Bilinear, wrapping in u and clamping in v. */
vec3 env_lookup(const env_map *env, vec2 uv);

#endif
