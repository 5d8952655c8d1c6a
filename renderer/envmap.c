/* The environment map (envmap.h). */
#include "envmap.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

vec3 env_direction(const env_map *env, vec2 uv) {
    float phi = 2.0f * PI_F * (uv.x - 0.5f) + env->rotation;
    float theta = PI_F * uv.y;
    float st = sinf(theta);
    return v3(st * cosf(phi), cosf(theta), st * sinf(phi));
}

vec2 env_uv(const env_map *env, vec3 d) {
    float phi = atan2f(d.z, d.x) - env->rotation;
    float u = 0.5f + phi * INV_2PI_F;
    u -= floorf(u);
    float v = acosf(clampf(d.y, -1.0f, 1.0f)) * INV_PI_F;
    return v2(u, v);
}

static vec3 env_texel(const image_rgb *img, int x, int y) {
    const float *p = img->rgb + 3 * ((size_t)y * (size_t)img->width + (size_t)x);
    return v3(p[0], p[1], p[2]);
}

/* Bilinear, wrapping in u and clamping in v. */
vec3 env_lookup(const env_map *env, vec2 uv) {
    const image_rgb *img = &env->image;
    float x = uv.x * (float)img->width - 0.5f, y = uv.y * (float)img->height - 0.5f;
    float fx = floorf(x), fy = floorf(y);
    float ax = x - fx, ay = y - fy;
    int x0 = (int)fx, y0 = (int)fy;
    int x1 = x0 + 1, y1 = y0 + 1;
    x0 = ((x0 % img->width) + img->width) % img->width;
    x1 = ((x1 % img->width) + img->width) % img->width;
    y0 = y0 < 0 ? 0 : (y0 >= img->height ? img->height - 1 : y0);
    y1 = y1 < 0 ? 0 : (y1 >= img->height ? img->height - 1 : y1);
    vec3 a = lerp3(env_texel(img, x0, y0), env_texel(img, x1, y0), ax);
    vec3 b = lerp3(env_texel(img, x0, y1), env_texel(img, x1, y1), ax);
    return lerp3(a, b, ay);
}

env_map *env_map_create(image_rgb *image, float rotation, char *err, size_t errlen) {
    int w = image->width, h = image->height;
    if (w <= 0 || h <= 0 || !image->rgb) {
        image_rgb_free(image);
        snprintf(err, errlen, "empty environment image");
        return NULL;
    }
    env_map *env = calloc(1, sizeof(env_map));
    float *func = malloc(sizeof(float) * (size_t)w * (size_t)h);
    if (!env || !func) {
        free(env);
        free(func);
        image_rgb_free(image);
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    env->image = *image;
    *image = (image_rgb){0};
    env->rotation = rotation;
    /* Sampling density: luminance times sin(theta) (the equirectangular Jacobian), each texel
     * dilated to the maximum of its neighbours so that wherever bilinear lookup is non-zero the
     * density is too (otherwise those directions could never be sampled: bias). */
    double sum = 0.0, weight = 0.0;
    for (int y = 0; y < h; y++) {
        float st = sinf(PI_F * ((float)y + 0.5f) / (float)h);
        for (int x = 0; x < w; x++) {
            float m = 0.0f;
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++) {
                    int yy = y + dy, xx = ((x + dx) % w + w) % w;
                    if (yy < 0 || yy >= h) continue;
                    m = fmaxf(m, luminance3(env_texel(&env->image, xx, yy)));
                }
            func[(size_t)y * (size_t)w + (size_t)x] = m * st;
            sum += (double)(luminance3(env_texel(&env->image, x, y)) * st);
            weight += (double)st;
        }
    }
    env->mean_luminance = weight > 0.0 ? (float)(sum / weight) : 0.0f;
    int status = dist2d_init(&env->dist, func, w, h);
    free(func);
    if (status != 0) {
        env_map_destroy(env);
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    return env;
}

void env_map_destroy(env_map *env) {
    if (!env) return;
    image_rgb_free(&env->image);
    dist2d_deinit(&env->dist);
    free(env);
}
