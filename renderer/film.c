#include "film.h"

#include <float.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *const film_component_names[COMP_COUNT] = {"direct", "indirect", "highlights"};

int film_init(film *f, int width, int height) {
    memset(f, 0, sizeof *f);
    if (width <= 0 || height <= 0) return -1;
    size_t n = (size_t)width * (size_t)height;
    f->width = width;
    f->height = height;
    int ok = (f->rejected = calloc(n, sizeof(uint32_t))) != NULL;
    for (int c = 0; c < COMP_COUNT; c++) ok &= (f->sum[c] = calloc(3 * n, sizeof(double))) != NULL;
    if (!ok) {
        film_deinit(f);
        return -1;
    }
    return 0;
}

void film_deinit(film *f) {
    for (int c = 0; c < COMP_COUNT; c++) free(f->sum[c]);
    for (int c = 0; c <= COMP_COUNT; c++) free(f->sumsq[c]);
    free(f->rejected);
    memset(f, 0, sizeof *f);
}

void film_clear(film *f) {
    size_t n = (size_t)f->width * (size_t)f->height;
    for (int c = 0; c < COMP_COUNT; c++) memset(f->sum[c], 0, 3 * n * sizeof(double));
    memset(f->rejected, 0, n * sizeof(uint32_t));
    for (int c = 0; c <= COMP_COUNT && f->sumsq[0]; c++) memset(f->sumsq[c], 0, 3 * n * sizeof(double));
    f->passes = 0;
}

void film_moments_var_layer(const char *layer, char *out, size_t n) {
    snprintf(out, n, "%s%s%s", MOMENTS_VAR_PREFIX, layer[0] ? "." : "", layer);
}

int film_enable_moments(film *f) {
    size_t n = 3 * (size_t)f->width * (size_t)f->height;
    for (int c = 0; c <= COMP_COUNT; c++) {
        if (f->sumsq[c]) continue;
        if (!(f->sumsq[c] = calloc(n, sizeof(double)))) {
            for (int k = 0; k <= COMP_COUNT; k++) free(f->sumsq[k]), f->sumsq[k] = NULL;
            return -1;
        }
    }
    return 0;
}

void film_add_squares(film *f, int i, const float rgb[COMP_COUNT][3]) {
    double total[3] = {0, 0, 0};
    for (int c = 0; c < COMP_COUNT; c++) {
        if (rgb[c][0] == 0.0f && rgb[c][1] == 0.0f && rgb[c][2] == 0.0f) continue;
        double *q = f->sumsq[c] + 3 * (size_t)i;
        for (int k = 0; k < 3; k++) {
            q[k] += (double)rgb[c][k] * (double)rgb[c][k];
            total[k] += (double)rgb[c][k];
        }
    }
    double *q = f->sumsq[FILM_TOTAL] + 3 * (size_t)i;
    for (int k = 0; k < 3; k++) q[k] += total[k] * total[k];
}

void film_resolve_variance(const film *f, unsigned mask, float *var) {
    size_t n = (size_t)f->width * (size_t)f->height;
    int one = -1; /* the component alone in mask, else FILM_TOTAL (all of them) */
    for (int c = 0; c < COMP_COUNT; c++)
        if (mask == 1u << c) one = c;
    if (!f->sumsq[0] || (one < 0 && mask != COMP_MASK_ALL)) {
        memset(var, 0, sizeof(float) * 3 * n);
        return;
    }
    const double *sq = f->sumsq[one < 0 ? FILM_TOTAL : one];
    for (size_t i = 0; i < n; i++) {
        long long count = f->passes - (long long)f->rejected[i];
        double inv = count > 0 ? 1.0 / (double)count : 0.0;
        for (int k = 0; k < 3; k++) {
            double sum = 0.0;
            for (int c = 0; c < COMP_COUNT; c++)
                if (mask & (1u << c)) sum += f->sum[c][3 * i + (size_t)k];
            double mean = sum * inv, v = sq[3 * i + (size_t)k] * inv - mean * mean;
            v = v > 0.0 ? v : 0.0; /* rounding can take a constant pixel's below zero */
            var[3 * i + (size_t)k] = v < (double)FLT_MAX ? (float)v : FLT_MAX;
        }
    }
}

size_t film_resolve(const film *f, unsigned mask, float *rgb) {
    size_t n = (size_t)f->width * (size_t)f->height, clamped = 0;
    for (size_t i = 0; i < n; i++) {
        double acc[3] = {0, 0, 0};
        for (int c = 0; c < COMP_COUNT; c++) {
            if (!(mask & (1u << c))) continue;
            const double *s = f->sum[c] + 3 * i;
            acc[0] += s[0];
            acc[1] += s[1];
            acc[2] += s[2];
        }
        long long count = f->passes - (long long)f->rejected[i];
        double inv = count > 0 ? 1.0 / (double)count : 0.0;
        for (int k = 0; k < 3; k++) {
            /* Finite samples can still add up past float's range; the conversion would give Inf. */
            double v = acc[k] * inv;
            if (fabs(v) > (double)FLT_MAX) v = copysign((double)FLT_MAX, v), clamped++;
            rgb[3 * i + (size_t)k] = (float)v;
        }
    }
    return clamped;
}

size_t film_count_clamped(const film *f, unsigned layers_mask) {
    float *rgb = malloc(sizeof(float) * 3 * (size_t)f->width * (size_t)f->height);
    if (!rgb) return 0;
    size_t n = film_resolve(f, COMP_MASK_ALL, rgb);
    for (int c = 0; c < COMP_COUNT; c++)
        if (layers_mask & (1u << c)) n += film_resolve(f, 1u << c, rgb);
    free(rgb);
    return n;
}

float srgb_encode(float x) {
    if (!(x > 0.0f)) return 0.0f;
    if (x >= 1.0f) return 1.0f;
    return x <= 0.0031308f ? 12.92f * x : 1.055f * powf(x, 1.0f / 2.4f) - 0.055f;
}

/* srgb8_encode's tables: where each byte value begins (the least x that rounds to it), and per
 * bucket of x's float bits, 2^SRGB8_BITS to an octave from 2^SRGB8_LOW_OCTAVE to 1, the byte
 * at the bucket's start. Below the buckets the byte is 0 or 1 (the linear segment, 3295 x). The
 * curve's slope keeps each bucket within one step of bytes. */
#define SRGB8_BITS 7 /* of the mantissa: 128 buckets an octave */
#define SRGB8_LOW_OCTAVE (-13)
#define SRGB8_BUCKETS (-SRGB8_LOW_OCTAVE << SRGB8_BITS)
static float srgb8_start[257];
static uint8_t srgb8_bucket[SRGB8_BUCKETS];
static pthread_once_t srgb8_once = PTHREAD_ONCE_INIT;

static uint8_t srgb8_exact(float x) { return (uint8_t)(srgb_encode(x) * 255.0f + 0.5f); }

static uint32_t float_bits(float x) {
    uint32_t b;
    memcpy(&b, &x, sizeof b);
    return b;
}

static float bits_float(uint32_t b) {
    float x;
    memcpy(&x, &b, sizeof x);
    return x;
}

static void srgb8_tables(void) {
    srgb8_start[0] = -INFINITY;
    srgb8_start[256] = INFINITY;
    for (int k = 1; k < 256; k++) { /* bisection over the bits of x in [0, 1]: rounding is monotone */
        uint32_t lo = 0, hi = float_bits(1.0f);
        while (lo < hi) {
            uint32_t mid = lo + (hi - lo) / 2;
            if (srgb8_exact(bits_float(mid)) >= k)
                hi = mid;
            else
                lo = mid + 1;
        }
        srgb8_start[k] = bits_float(lo);
    }
    uint32_t first = float_bits(ldexpf(1.0f, SRGB8_LOW_OCTAVE));
    for (int i = 0; i < SRGB8_BUCKETS; i++)
        srgb8_bucket[i] = srgb8_exact(bits_float(first + ((uint32_t)i << (23 - SRGB8_BITS))));
}

/* (uint8_t)(srgb_encode(x) * 255 + 0.5), without its powf: the display tone-maps every pixel of
 * every image shown. */
static inline uint8_t srgb8_encode(float x) {
    if (!(x > 0.0f)) return 0;
    if (x >= 1.0f) return 255;
    uint32_t b = float_bits(x), first = float_bits(ldexpf(1.0f, SRGB8_LOW_OCTAVE));
    if (b < first) return x >= srgb8_start[1] ? 1 : 0;
    int k = srgb8_bucket[(b - first) >> (23 - SRGB8_BITS)];
    return (uint8_t)(x >= srgb8_start[k + 1] ? k + 1 : k);
}

uint8_t srgb8_of(float x) {
    pthread_once(&srgb8_once, srgb8_tables);
    return srgb8_encode(x);
}

static float lum(const float *c) { return 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2]; }

void tonemap_reinhard(const float *rgb, int num_pixels, const tonemap_params *p, uint8_t *out) {
    pthread_once(&srgb8_once, srgb8_tables);
    /* Log-average luminance (Reinhard's eq. 1), delta guarding log(0). */
    double log_sum = 0.0;
    int counted = 0;
    for (int i = 0; i < num_pixels; i++) {
        float l = lum(rgb + 3 * (size_t)i);
        if (!isfinite(l)) continue;
        log_sum += (double)logf(1e-4f + fmaxf(l, 0.0f));
        counted++;
    }
    double avg = counted ? exp(log_sum / counted) : 1.0;
    float key = p->key > 0.0f ? p->key : 0.18f;
    float scale = (float)((double)key / avg) * exp2f(p->exposure);
    float inv_white2 = p->white > 0.0f ? 1.0f / (p->white * p->white) : 0.0f;
    for (int i = 0; i < num_pixels; i++) {
        const float *c = rgb + 3 * (size_t)i;
        float l = lum(c);
        float ls = l * scale;
        float ld = ls * (1.0f + ls * inv_white2) / (1.0f + ls);
        float k = l > 0.0f && isfinite(l) ? ld / l : 0.0f;
        for (int j = 0; j < 3; j++) out[3 * (size_t)i + (size_t)j] = srgb8_encode(c[j] * k);
    }
}

const char *const tonemap_names[TONEMAP_COUNT] = {"reinhard", "clamp", "exponential"};

int tonemap_from_name(const char *name) {
    for (int i = 0; i < TONEMAP_COUNT; i++)
        if (strcmp(name, tonemap_names[i]) == 0) return i;
    return -1;
}

/* The exposure-only operators: a fixed curve per channel. */
static void tonemap_curve(const float *rgb, int num_pixels, float exposure, int exponential, uint8_t *out) {
    float scale = exp2f(exposure);
    for (size_t i = 0; i < 3 * (size_t)num_pixels; i++) {
        float x = rgb[i] * scale;
        if (!isfinite(x)) x = 0.0f;
        out[i] = srgb8_encode(exponential ? 1.0f - expf(-x) : x);
    }
}

void tonemap_apply(const float *rgb, int num_pixels, const tonemap_params *p, uint8_t *out) {
    pthread_once(&srgb8_once, srgb8_tables);
    switch (p->op) {
    case TONEMAP_CLAMP: tonemap_curve(rgb, num_pixels, p->exposure, 0, out); break;
    case TONEMAP_EXPONENTIAL: tonemap_curve(rgb, num_pixels, p->exposure, 1, out); break;
    default: tonemap_reinhard(rgb, num_pixels, p, out); break;
    }
}

int film_save_exr(const film *f, unsigned layers_mask, const char *path, write_mode mode, char *err, size_t errlen) {
    return film_save_exr_attrs(f, layers_mask, path, NULL, 0, mode, err, errlen);
}

int film_save_exr_attrs(const film *f, unsigned layers_mask, const char *path, const exr_text_attr *attrs,
                        int num_attrs, write_mode mode, char *err, size_t errlen) {
    return film_save_exr_extra(f, layers_mask, path, attrs, num_attrs, NULL, 0, mode, err, errlen);
}

#define FILM_MAX_EXTRA 4
int film_save_exr_extra(const film *f, unsigned layers_mask, const char *path, const exr_text_attr *attrs,
                        int num_attrs, const exr_layer *extra, int num_extra, write_mode mode, char *err,
                        size_t errlen) {
    size_t n = 3 * (size_t)f->width * (size_t)f->height;
    enum { MAX_LAYERS = 2 * (1 + COMP_COUNT) + 1 + FILM_MAX_EXTRA };
    if (num_extra < 0 || num_extra > FILM_MAX_EXTRA) return snprintf(err, errlen, "%s: too many layers", path), -1;
    float *planes[MAX_LAYERS] = {0};
    exr_layer layers[MAX_LAYERS];
    char names[COMP_COUNT + 1][64];
    int nl = 0, status = -1;
    /* The means, then (with moments) the variances of the same layers and the dropped samples */
    for (int pass = 0; pass < (f->sumsq[0] ? 2 : 1); pass++) {
        for (int c = -1; c < COMP_COUNT; c++) {
            if (c >= 0 && !(layers_mask & (1u << c))) continue;
            if (!(planes[nl] = malloc(sizeof(float) * n))) {
                snprintf(err, errlen, "%s: out of memory", path);
                goto done;
            }
            unsigned mask = c < 0 ? COMP_MASK_ALL : 1u << c;
            const char *name = c < 0 ? "" : film_component_names[c];
            if (pass == 0) {
                film_resolve(f, mask, planes[nl]);
                layers[nl] = (exr_layer){name, planes[nl]};
            } else {
                film_resolve_variance(f, mask, planes[nl]);
                film_moments_var_layer(name, names[c + 1], sizeof names[c + 1]);
                layers[nl] = (exr_layer){names[c + 1], planes[nl]};
            }
            nl++;
        }
    }
    if (f->sumsq[0]) {
        if (!(planes[nl] = malloc(sizeof(float) * n))) {
            snprintf(err, errlen, "%s: out of memory", path);
            goto done;
        }
        for (size_t i = 0; i < n; i++) planes[nl][i] = (float)f->rejected[i / 3];
        layers[nl] = (exr_layer){MOMENTS_REJECTED, planes[nl]};
        nl++;
    }
    int own = nl;
    for (int i = 0; i < num_extra; i++) layers[nl++] = extra[i];
    status = exr_save_layers_attrs(path, f->width, f->height, layers, nl, attrs, num_attrs, mode, err, errlen);
    nl = own;
done:
    for (int i = 0; i < nl; i++) free(planes[i]);
    return status;
}

int film_save_png(const film *f, unsigned mask, const tonemap_params *tp, const char *path, write_mode mode, char *err,
                  size_t errlen) {
    size_t n = (size_t)f->width * (size_t)f->height;
    float *rgb = malloc(sizeof(float) * 3 * n);
    uint8_t *px = malloc(3 * n);
    int status = -1;
    if (!rgb || !px) {
        snprintf(err, errlen, "%s: out of memory", path);
    } else {
        film_resolve(f, mask, rgb);
        tonemap_apply(rgb, (int)n, tp, px);
        status = png_save_rgb8(path, f->width, f->height, px, mode, err, errlen);
    }
    free(rgb);
    free(px);
    return status;
}
