/* glint view: the image shown (UI thread): tone-mapped, or as its error against a reference in
 * false colour, into the GL texture the window draws; and saved as a PNG. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image_io.h"
#include "view.h"

/* A false colour's three floats in [0, 1] as pixel i's bytes. */
static void put_colour(unsigned char *out, int i, const float rgb[3]) {
    for (int k = 0; k < 3; k++) out[3 * (size_t)i + (size_t)k] = (unsigned char)(255.0f * rgb[k] + 0.5f);
}

/* Per-pixel relative error |I - R| / (|R| + eps) as colours on a log scale: blue 1%, green 10%,
 * red 100% and more. eps, a hundredth of the mean reference, keeps black pixels from glaring. */
static void false_colour_error(const float *img, const float *ref, int num_pixels, unsigned char *out) {
    size_t n = 3 * (size_t)num_pixels;
    double mean = 0.0;
    for (size_t i = 0; i < n; i++) mean += (double)ref[i];
    float eps = (float)(0.01 * mean / (double)(n ? n : 1)) + 1e-20f;
    for (int i = 0; i < num_pixels; i++) {
        const float *a = img + 3 * (size_t)i, *r = ref + 3 * (size_t)i;
        float d2 = 0.0f, r2 = 0.0f;
        for (int k = 0; k < 3; k++) {
            d2 += (a[k] - r[k]) * (a[k] - r[k]);
            r2 += r[k] * r[k];
        }
        float e = sqrtf(d2) / (sqrtf(r2) + eps);
        float t = isfinite(e) ? clampf(0.5f * (log10f(fmaxf(e, 1e-6f)) + 2.0f), 0.0f, 1.0f) : 1.0f;
        float rgb[3] = {clampf(2.0f * t - 1.0f, 0.0f, 1.0f), 1.0f - fabsf(2.0f * t - 1.0f),
                        clampf(1.0f - 2.0f * t, 0.0f, 1.0f)};
        put_colour(out, i, rgb);
    }
}

/* The share of a pixel's samples the virtual lights gave (SHOW_ESTIMATOR_SHARE's image) as a
 * colour from blue (path tracing) to orange (the virtual lights); a pixel of both is in between.
 * Before its first sample a pixel shows blue. */
static void false_colour_share(const float *share, int num_pixels, unsigned char *out) {
    for (int i = 0; i < num_pixels; i++) {
        float s = clampf(share[3 * (size_t)i], 0.0f, 1.0f);
        float rgb[3] = {0.15f + 0.8f * s, 0.35f + 0.2f * s, 0.9f - 0.8f * s};
        put_colour(out, i, rgb);
    }
}

/* A pixel's rays against the image's most (SHOW_WORK_MAP's image, 0 to 1) as black through red
 * (half) to yellow (the most). */
static void false_colour_work(const float *work, int num_pixels, unsigned char *out) {
    for (int i = 0; i < num_pixels; i++) {
        float t = clampf(work[3 * (size_t)i], 0.0f, 1.0f);
        float rgb[3] = {fminf(2.0f * t, 1.0f), fmaxf(2.0f * t - 1.0f, 0.0f), 0.0f};
        put_colour(out, i, rgb);
    }
}

/* The texture the image is drawn from; black until the first image (it has no storage yet).
 * Linear filtering: an image shown in a place of another size is scaled smoothly. */
void make_texture(ui_thread *u) {
    if (u->texture) return;
    GLuint t;
    glGenTextures(1, &t);
    u->texture = t;
    glBindTexture(GL_TEXTURE_2D, t);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
}

/* The image shown, tone-mapped (or its error in false colour), into the texture drawn. */
void tonemap_and_upload(ui_thread *u) {
    int w = u->front.width, h = u->front.height;
    if (!u->front.rgb || w <= 0 || h <= 0) return;
    if (w * h > u->pixels_cap) {
        free(u->pixels);
        u->pixels = malloc(3 * (size_t)w * (size_t)h);
        u->pixels_cap = u->pixels ? w * h : 0;
        if (!u->pixels) return;
    }
    const image_rgb *ref = &u->reference;
    if (u->front.mask == SHOW_ESTIMATOR_SHARE) {
        false_colour_share(u->front.rgb, w * h, u->pixels);
    } else if (u->front.mask == SHOW_WORK_MAP) {
        false_colour_work(u->front.rgb, w * h, u->pixels);
    } else if (u->ctl.show == UI_SHOW_ERROR && ref->rgb && ref->width == w && ref->height == h) {
        false_colour_error(u->front.rgb, ref->rgb, w * h, u->pixels);
    } else { /* also an image of another size than the reference's */
        const look_params *look = &u->ctl.params.look;
        tonemap_params tp = {look->exposure, 0.0f, 0.0f, (tonemap_op)look->tonemap};
        tonemap_apply(u->front.rgb, w * h, &tp, u->pixels);
    }
    make_texture(u);
    glBindTexture(GL_TEXTURE_2D, u->texture);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    if (w != u->tex_w || h != u->tex_h) {
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB8, w, h, 0, GL_RGB, GL_UNSIGNED_BYTE, u->pixels);
        u->tex_w = w;
        u->tex_h = h;
    } else {
        glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, w, h, GL_RGB, GL_UNSIGNED_BYTE, u->pixels);
    }
}

/* Saves the image as shown, without the panel, as a PNG (numbered, never overwriting). */
void take_screenshot(ui_thread *u, const char *name) {
    char path[1024], err[1200];
    if (u->need_tonemap) { /* a newer image or exposure than the one drawn last: save what is current */
        tonemap_and_upload(u);
        u->need_tonemap = 0;
    }
    if (!u->front.rgb || !u->pixels) {
        snprintf(u->message, sizeof u->message, "%s: nothing rendered yet", name);
        cli_error("%s", u->message);
        return;
    }
    if (unique_path(name, path, sizeof path) != 0) {
        snprintf(u->message, sizeof u->message, "%s: no free file name", name);
        cli_error("%s", u->message);
        return;
    }
    if (png_save_rgb8(path, u->front.width, u->front.height, u->pixels, WRITE_NO_REPLACE, err, sizeof err) != 0) {
        snprintf(u->message, sizeof u->message, "%s", err);
        cli_error("%s", err);
        return;
    }
    snprintf(u->message, sizeof u->message, "wrote %s", path);
    printf("glint: wrote %s\n", path);
    fflush(stdout);
}
