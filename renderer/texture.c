/* Texture images: stored as 8-bit RGBA, decoded to linear floats at lookup. */
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "scene.h"

/* sRGB decoding of an 8-bit value, and the identity scaling, as lookup tables built once. */
static float srgb_table[256];
static float linear_table[256];
static pthread_once_t tables_once = PTHREAD_ONCE_INIT;

static void build_tables(void) {
    for (int i = 0; i < 256; i++) {
        float c = (float)i / 255.0f;
        srgb_table[i] = c <= 0.04045f ? c / 12.92f : powf((c + 0.055f) / 1.055f, 2.4f);
        linear_table[i] = c;
    }
}

int scene_add_image(scene *s, int width, int height, int channels, int bits, const void *pixels) {
    if (width <= 0 || height <= 0 || channels < 1 || channels > 4 || (bits != 8 && bits != 16) || !pixels) return -1;
    if ((size_t)width * (size_t)height > ((size_t)1 << 28)) return -1;
    pthread_once(&tables_once, build_tables);
    if (s->num_images == s->cap_images) {
        int cap = s->cap_images ? s->cap_images * 2 : 8;
        scene_image *n = realloc(s->images, sizeof(scene_image) * (size_t)cap);
        if (!n) return -1;
        s->images = n;
        s->cap_images = cap;
    }
    size_t count = (size_t)width * (size_t)height;
    uint8_t *rgba = malloc(count * 4);
    if (!rgba) return -1;
    const uint8_t *p8 = pixels;
    const uint16_t *p16 = pixels;
    for (size_t i = 0; i < count; i++) {
        uint8_t c[4] = {0, 0, 0, 255};
        for (int k = 0; k < channels; k++)
            c[k] = bits == 8 ? p8[i * (size_t)channels + (size_t)k]
                             : (uint8_t)((p16[i * (size_t)channels + (size_t)k] + 128u) / 257u);
        /* Grey and grey+alpha images spread their value over RGB. */
        if (channels <= 2) {
            uint8_t a = channels == 2 ? c[1] : 255;
            c[1] = c[2] = c[0];
            c[3] = a;
        }
        memcpy(rgba + i * 4, c, 4);
    }
    s->images[s->num_images] = (scene_image){width, height, rgba};
    return s->num_images++;
}

const float *texture_srgb_table(void) {
    pthread_once(&tables_once, build_tables);
    return srgb_table;
}

int texture_wrap(int i, int n, wrap_mode mode) {
    switch (mode) {
    case WRAP_CLAMP: return i < 0 ? 0 : (i >= n ? n - 1 : i);
    case WRAP_MIRROR: {
        int period = 2 * n;
        int m = i % period;
        if (m < 0) m += period;
        return m < n ? m : period - 1 - m;
    }
    case WRAP_REPEAT:
    default: {
        int m = i % n;
        return m < 0 ? m + n : m;
    }
    }
}

vec4 texture_lookup(const scene *s, texture_slot slot, vec2 uv0, vec2 uv1, int srgb) {
    const scene_texture *t = &s->textures[slot.texture];
    const scene_image *img = &s->images[t->image];
    vec2 uv = slot.texcoord == 1 ? uv1 : uv0;
    if (slot.transformed) { /* KHR_texture_transform */
        const float *m = slot.uv_xf;
        uv = v2(m[0] * uv.x + m[1] * uv.y + m[2], m[3] * uv.x + m[4] * uv.y + m[5]);
    }
    /* Texel centres at half-integers; floor via a large positive shift keeps negative uv exact. */
    float x = uv.x * (float)img->width - 0.5f, y = uv.y * (float)img->height - 0.5f;
    if (!isfinite(x) || !isfinite(y) || fabsf(x) > 1e8f || fabsf(y) > 1e8f) x = y = 0.0f;
    float fx = floorf(x), fy = floorf(y);
    float ax = x - fx, ay = y - fy;
    int x0 = (int)fx, y0 = (int)fy;
    int xs[2] = {texture_wrap(x0, img->width, t->wrap_s), texture_wrap(x0 + 1, img->width, t->wrap_s)};
    int ys[2] = {texture_wrap(y0, img->height, t->wrap_t), texture_wrap(y0 + 1, img->height, t->wrap_t)};
    float w[4] = {(1 - ax) * (1 - ay), ax * (1 - ay), (1 - ax) * ay, ax * ay};
    const float *colour = srgb ? srgb_table : linear_table;
    float acc[4] = {0, 0, 0, 0};
    for (int k = 0; k < 4; k++) {
        const uint8_t *px = img->rgba + ((size_t)ys[k >> 1] * (size_t)img->width + (size_t)xs[k & 1]) * 4;
        acc[0] += w[k] * colour[px[0]];
        acc[1] += w[k] * colour[px[1]];
        acc[2] += w[k] * colour[px[2]];
        acc[3] += w[k] * linear_table[px[3]];
    }
    return (vec4){acc[0], acc[1], acc[2], acc[3]};
}
