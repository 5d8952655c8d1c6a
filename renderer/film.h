/* glint — the film: per-component sums and per-pixel sample counts in double (thousands of
 * frames accumulate without drift), resolved to means on demand; global tone operators and
 * sRGB encoding for display. */
#ifndef GLINT_FILM_H
#define GLINT_FILM_H

#include <stddef.h>
#include <stdint.h>

#include "image_io.h"
#include "params.h"

/* Path-space components, each in its own buffer: the image is their sum. */
typedef enum {
    COMP_DIRECT = 0, /* emitted + direct lighting at the first hit */
    COMP_INDIRECT,   /* everything after the first bounce (minus highlights when those are on) */
    COMP_HIGHLIGHTS, /* E-glossy-glossy-light paths of the highlight estimator */
    COMP_COUNT
} film_component;

#define COMP_MASK_ALL ((1u << COMP_COUNT) - 1u)

extern const char *const film_component_names[COMP_COUNT]; /* "direct", "indirect", "highlights" */

/* Accumulated in passes: each pass gives every pixel one sample, added (film_add) or dropped
 * (film_reject), then film_end_pass. So the per-pixel sample count is passes − rejected and
 * needs no per-pixel store on the hot path. */
typedef struct {
    int width, height;
    double *sum[COMP_COUNT]; /* 3 per pixel */
    uint32_t *rejected;      /* per pixel: dropped samples (NaN or Inf) */
    long long passes;
    /* Sums of squared samples, 3 per pixel, per component and (FILM_TOTAL) of the whole image,
     * whose variance is not the components' (they covary): what merging shards exactly needs.
     * NULL until film_enable_moments, so a render that does not keep them pays nothing. */
    double *sumsq[COMP_COUNT + 1];
} film;

#define FILM_TOTAL COMP_COUNT /* sumsq's index of the whole image */

int film_init(film *f, int width, int height); /* 0 or -1 (out of memory) */
void film_deinit(film *f);
void film_clear(film *f);

/* Keeps the sums of squares from now on (call on a clear film). 0, or -1 out of memory. */
int film_enable_moments(film *f);
/* film_add's second moments, out of line: only shards keep them. */
void film_add_squares(film *f, int i, const float rgb[COMP_COUNT][3]);

/* Adds one sample (3 floats per component) to pixel i. A component that is zero is not
 * touched: the film is tens of megabytes, and a ray into the void or an unused component
 * would otherwise cost a cache miss per buffer. */
static inline void film_add(film *f, int i, const float rgb[COMP_COUNT][3]) {
    for (int c = 0; c < COMP_COUNT; c++) {
        if (rgb[c][0] == 0.0f && rgb[c][1] == 0.0f && rgb[c][2] == 0.0f) continue;
        double *s = f->sum[c] + 3 * (size_t)i;
        s[0] += (double)rgb[c][0];
        s[1] += (double)rgb[c][1];
        s[2] += (double)rgb[c][2];
    }
    if (f->sumsq[0]) film_add_squares(f, i, rgb);
}

/* Pixel i's sample of this pass was dropped: the pixel's mean is over its good samples. */
static inline void film_reject(film *f, int i) { f->rejected[i]++; }
static inline void film_end_pass(film *f) { f->passes++; }

/* Mean radiance of the components in mask (bit c = component c) into rgb (3 floats per pixel),
 * finite by construction: a mean beyond float's range is written as +-FLT_MAX. Returns how many
 * values were clamped so. */
size_t film_resolve(const film *f, unsigned mask, float *rgb);
/* The variance of one sample about the pixel's mean (population form: the sum of squared
 * deviations over the count), of the components in mask, 3 floats per pixel; every value 0 without
 * moments. A mask of all components is the whole image's variance (FILM_TOTAL). */
void film_resolve_variance(const film *f, unsigned mask, float *var);

/* The EXR channels that carry the moments (written by film_save_exr_attrs when the film keeps
 * them, read back by glint merge): MOMENTS_VAR_PREFIX ".R,G,B" is the image's variance,
 * MOMENTS_VAR_PREFIX ".direct.R,G,B" a component's, and MOMENTS_REJECTED ".R" (G and B the same)
 * the pixel's dropped samples, so its count is the frames less them. */
#define MOMENTS_VAR_PREFIX "moments.var"
#define MOMENTS_REJECTED "moments.rejected"
/* The variance layer's name of layer ("" the image, "direct", ...): "moments.var[.LAYER]". */
void film_moments_var_layer(const char *layer, char *out, size_t n);

/* Values film_save_exr would clamp: in the whole image and in the layers of layers_mask. */
size_t film_count_clamped(const film *f, unsigned layers_mask);

/* The tone operators (tonemap_op, params.h: a render's look chooses one). */
extern const char *const tonemap_names[TONEMAP_COUNT]; /* "reinhard", "clamp", "exponential" */
int tonemap_from_name(const char *name);               /* -1 when unknown */

typedef struct {
    float exposure; /* stops: the scaled luminance is multiplied by 2^exposure */
    float key;      /* Reinhard's key value a (0 = 0.18) */
    float white;    /* smallest scaled luminance mapped to white (0 = infinity: L/(1+L)) */
    tonemap_op op;  /* 0: Reinhard */
} tonemap_params;

/* Tone-maps with p->op. */
void tonemap_apply(const float *rgb, int num_pixels, const tonemap_params *p, uint8_t *srgb8);
/* Reinhard et al. 2002, global operator: scale by key / log-average luminance, compress
 * luminance, keep chromaticity; then the sRGB transfer function to 8 bits. */
void tonemap_reinhard(const float *rgb, int num_pixels, const tonemap_params *p, uint8_t *srgb8);
float srgb_encode(float linear);
/* The byte of srgb_encode(linear): (uint8_t)(srgb_encode(linear) * 255 + 0.5), from tables. */
uint8_t srgb8_of(float linear);

/* Exports (atomic; see image_io.h for write_mode). The EXR holds R,G,B (the sum of the
 * components) plus one layer per component in layers_mask ("direct.R", ...), the moments of
 * the same layers when the film keeps them (above), and in its header
 * the string attributes attrs (film_save_exr_attrs; NULL when num_attrs is 0). The PNG is the
 * sum, tone-mapped with tp->op. Return 0, or -1 with err = "PATH: problem". */
int film_save_exr(const film *f, unsigned layers_mask, const char *path, write_mode mode, char *err, size_t errlen);
int film_save_exr_attrs(const film *f, unsigned layers_mask, const char *path, const exr_text_attr *attrs,
                        int num_attrs, write_mode mode, char *err, size_t errlen);
/* The same with more layers of the caller's after the film's (a view of it, such as the display's
 * filtered image: never in place of the film's own). */
int film_save_exr_extra(const film *f, unsigned layers_mask, const char *path, const exr_text_attr *attrs,
                        int num_attrs, const exr_layer *extra, int num_extra, write_mode mode, char *err,
                        size_t errlen);
int film_save_png(const film *f, unsigned mask, const tonemap_params *tp, const char *path, write_mode mode, char *err,
                  size_t errlen);

#endif
