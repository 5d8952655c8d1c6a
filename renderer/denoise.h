/* glint — the display's spatial filter: an edge-avoiding à-trous wavelet (Dammertz et al. 2010)
 * with SVGF's variance-guided weights (Schied et al. 2017), on the CPU, its wide passes on a
 * half-resolution grid (a pyramid). It filters each film component's light divided by the pixel's
 * albedo (the caller multiplies back), guided by a G-buffer; each sample counts by how many
 * samples stand behind it, and holes (pixels with no sample yet) are filled from their neighbours
 * by geometry alone. A pixel whose glossy lobe is sharp tells normals apart as sharply as the lobe
 * does (a light's speck in a curved mirror stays a speck). Only the display reads the result: the
 * film is never filtered.
 * docs/design.md, "The display: denoising". */
#ifndef GLINT_DENOISE_H
#define GLINT_DENOISE_H

#include "film.h"
#include "gbuffer.h"
#include "threadpool.h"

/* The farthest-reaching pass has holes 2^(DENOISE_MAX_LEVELS - 1) pixels: five levels reach about 65. */
#define DENOISE_MAX_LEVELS 5

typedef struct {
    float sigma_z, sigma_n, sigma_l; /* the edge stops (depth, normal, luminance); 0: SVGF's 1, 128, 4 */
    int levels;                      /* how far it reaches: the input pooled into the half grid, levels - 1
                                      * passes there (holes 2, 4, 8, ... pixels), the way back up with the
                                      * full image's 3x3 pass; 0: none (the output is the input, holes stay
                                      * holes); at most DENOISE_MAX_LEVELS */
    float count_cap;                 /* a pixel counts as this many samples at most (below 1: no cap): where a
                                      * few pixels have far more samples than their neighbours (the
                                      * display's extra samples), their own value is sure, but no surer
                                      * a guide to their neighbours' light than any pixel's */
} denoise_params;

typedef struct {
    int components;                    /* the first `components` film components, <= COMP_COUNT */
    const float *light[COMP_COUNT];    /* 3 floats a pixel: the mean light over the albedo */
    const float *count[COMP_COUNT];    /* per pixel: samples behind that mean (fractional when history is
                                        * kept in part); 0 (or not finite): no sample, a hole to fill */
    const float *variance[COMP_COUNT]; /* per pixel: the variance of ONE sample's luminance (of the light
                                        * over the albedo), unbiased (n / (n - 1) times film's); the mean's
                                        * is variance / count. Below 4 samples it is pooled with an estimate
                                        * from the neighbours; from 4 on it is trusted, and 0 (or NULL) says
                                        * the mean is exact: the pixel keeps its value */
    const gbuffer *g;                  /* the geometry (depth, normal) of the same pixels */
} denoise_input;

typedef struct {
    float *light[COMP_COUNT]; /* 3 floats a pixel, written; may be the input's light (in place) */
    float *count[COMP_COUNT]; /* NULL, or per pixel: the effective number of samples behind the output
                               * (see docs/design.md); 0 where no pass reached a sample: a hole that
                               * stays, whose light is 0 */
} denoise_output;

typedef struct denoiser denoiser;

/* Scratch for width x height images: planes of (width / 2 rounded up to 128, + 32) floats a row,
 * the full image's (height + 32 rows, 7 of geometry and 5 per component used, twice: a plane for
 * each column parity) and the half grid's (height / 2 + 32 rows, 9 of geometry, 12 per component
 * used): 64 MB for two components at 960x540. NULL when out of memory or the size is not in
 * 1..65536. */
denoiser *denoiser_create(int width, int height);
void denoiser_destroy(denoiser *d); /* NULL is fine */

/* Filters in's components into out with p (NULL: all defaults, so no pass) on pool's threads (NULL:
 * the calling thread); one run at a time per denoiser. Every value written is finite, whatever the
 * input. Returns 0, or -1 when in's G-buffer is not the denoiser's size, components is outside
 * 1..COMP_COUNT or a component's light, count or output is NULL (nothing written). */
int denoise_run(denoiser *d, const denoise_input *in, const denoise_params *p, const denoise_output *out,
                threadpool *pool);

#endif
