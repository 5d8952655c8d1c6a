/* glint — the display filter's parts (docs/design.md, "The display: denoising"): what denoise.c
 * (the interface, the input, the plan, the half grid's passes) and denoise_pyramid.c (pooling into
 * the half grid, and back up) share. denoise.h is the interface; nothing else includes this.
 *
 * Images are held as planes (structure of arrays) inside a MARGIN of empty pixels, so that no tap
 * leaves its plane and none needs a bounds test: a margin pixel has no sample and takes no weight.
 * A row is cut into runs of CHUNK pixels, and every inner loop goes over one run with its taps
 * fixed (a tap and its mirror together), so that the compiler vectorises it; the geometry's weights
 * are computed once per tap for all components. */
#ifndef GLINT_DENOISE_PARTS_H
#define GLINT_DENOISE_PARTS_H

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "denoise.h"
#include "gbuffer.h"
#include "vecmath.h"

#define CHUNK 128
#define MARGIN (2 << (DENOISE_MAX_LEVELS - 2)) /* the farthest tap of the half grid's last pass */

/* Counts are held scaled so that no weight a = h w n is over 1/2 and no weighted sum of finite
 * values can overflow: n COUNT_SCALE <= 1/2, and after each step the count is divided by the most
 * it can grow by, its number of taps (Cauchy-Schwarz): 16 pooling, 25 a pass, 5 back up. COUNT_MAX
 * (a trillion samples) caps it. */
#define COUNT_MAX 0x1p40f
#define COUNT_SCALE 0x1p-41f
#define TAPS 25.0f
/* Luminance only steers the weights: it is held within +-LUM_MAX, so its differences and squares
 * stay finite; so are variances and depths. */
#define LUM_MAX 1e15f
#define S2_MAX 1e30f
#define DEPTH_MAX 1e18f
/* The edge stops' epsilons, relative to the pixel's own depth or luminance, so the filter does not
 * depend on the scene's units: a few times float's own resolution of such a value, so that equal
 * values in all but rounding still meet, and no real step gets through. EPS_TINY keeps 0 / 0 out. */
#define EPS_Z 1e-5f
#define EPS_L 1e-6f
#define EPS_TINY 1e-20f
/* Weights are handled as their base-2 logarithms. One below 2^EXP2_FLOOR (vecmath.h) is taken as
 * that: it counts for nothing (times a count it may be too small for a normal float: see row_task). */
/* An escaped ray's depth: no hit's depth is near it, so the depth stop keeps the two apart (and
 * escaped rays together, compared by direction through the stored normal). */
#define DEPTH_SKY (-1e20f)
/* Below this many samples a pixel's own variance says little, and its neighbours' spread stands in
 * for it, as in SVGF (see pool_variance). */
#define YOUNG 4.0f

static const float B3[5] = {1.0f / 16.0f, 1.0f / 4.0f, 3.0f / 8.0f, 1.0f / 4.0f, 1.0f / 16.0f};
static const float B1[5] = {0.0f, 0.25f, 0.5f, 0.25f, 0.0f}; /* a 3x3 pass: B1 within B3's layout */
static const float K4[4] = {0.125f, 0.375f, 0.375f, 0.125f}; /* B1 over a 2x2 block */
/* The input is read in runs of RUN pixels, CHUNK of each parity. */
#define RUN (2 * CHUNK)

/* log2 x for x in [1e-30, 1]: x = 2^e m with m in [2/3, 4/3), log2 m = r P(r) with r = m - 1 and
 * P a degree-5 fit of log2(1 + r) / r (relative error 7.2e-6): under 1e-6 on [0.9, 1], where it
 * matters (x^128 takes 128 times it). */
static inline float log2_unit(float x) {
    uint32_t e = (uint32_t)((int32_t)(bits_of(x) - 0x3f2aaaabu) >> 23); /* 0x3f2aaaab: 2/3 */
    float r = float_of(bits_of(x) - (e << 23)) - 1.0f;
    float p = 1.44270538f +
              r * (-0.721376643f + r * (0.479251757f + r * (-0.358505738f + r * (0.326720598f + r * -0.279155602f))));
    return (float_of(ROUNDER_BITS + e) - ROUNDER) + r * p;
}

static inline float clampf_to(float v, float lim) {
    v = v < lim ? v : lim;
    return v > -lim ? v : -lim;
}
static inline float lum_of(float r, float g, float b) {
    return luminance3(v3(clampf_to(r, LUM_MAX), clampf_to(g, LUM_MAX), clampf_to(b, LUM_MAX)));
}

/* One component's image, a plane each. */
typedef struct {
    float *r, *g, *b; /* the light over the albedo */
    float *l;         /* its luminance, within +-LUM_MAX (the half grid's; the full image has none) */
    float *s2;        /* the variance of one sample's luminance */
    float *n;         /* samples behind the value, scaled (COUNT_SCALE, then 1/16, 1/25 a pass); 0: a hole */
} planes;

typedef struct {
    float *z, *nx, *ny, *nz; /* depth (DEPTH_SKY: escaped), shading normal */
    float *gx, *gy;          /* the depth's slope per pixel of its grid, robust at edges */
    float *sn;               /* the normal stop's exponent seen from this pixel, less sigma_n
                              * (normal_stop): 0 in the margins, as where no lobe is sharp */
} geometry;

#define PLANES_EACH 6
#define PLANES_GEOMETRY 7

/* Two grids share one shape of plane, MARGIN, half the image's width rounded up to CHUNK, MARGIN
 * floats a row: the half grid (2x2 blocks pooled, where the passes run) and the full image, whose
 * pixel x of a row is held at column x / 2 of the plane of its parity (so that a block's pixels,
 * and a pixel's neighbours, are each a run of consecutive floats). */
struct denoiser {
    int width, height, half_width, half_height;
    ptrdiff_t stride;
    float *mem;
    geometry full_geo[2];       /* [x & 1] */
    planes full[2][COMP_COUNT]; /* [x & 1] */
    geometry half_geo;          /* the geometry of one pixel of each block... */
    float *rx, *ry;             /* ...which (0 or 1 across, down) */
    planes half[2][COMP_COUNT]; /* two buffers: a pass goes from one to the other; half[0]'s s2 is
                                  * the pooled variance (pool_variance), half[1]'s that steadied,
                                  * which every later stop goes by (denoise_variance_row) */
};

static inline ptrdiff_t at(const denoiser *d, int y, int m) { return (ptrdiff_t)(y + MARGIN) * d->stride + MARGIN + m; }

/* Weight of a pixel's own value beside the half grid's when brought back up (their bilinear
 * weights sum to 1), as in a pass: the centre tap's h. */
#define UP_OWN (B3[2] * B3[2])

typedef struct {
    task_fn row; /* the step: one row of it */
    denoiser *d;
    const denoise_input *in;
    const denoise_output *out;
    int comps;
    float sigma_z, sigma_n, sigma_l;
    float kappa;
    float count_cap;     /* a pixel's count, at most: denoise_params' */
    float inv_sqrt_unit; /* 1 / sqrt(the samples a scaled count of 1 stands for), before the step */
    int step, src;       /* a pass on the half grid: holes, buffer */
    /* back up: the half grid's result (buffer coarse), the full image's 3x3 pass */
    int coarse;
    float kappa_fine, fine_inv_sqrt_unit;
    float fine_to_coarse; /* a count after the 3x3 pass in the half grid's counts' unit */
    float out_unit;       /* the samples an output count of 1 stands for */
} job;

/* The normal stop's exponent seen from a pixel whose glossy lobe (gloss, alpha) may bring a share s
 * of its light (gbuffer_glossy_share), less sigma_n: SVGF's sigma_n, or, for a lobe so sharp that
 * it is more, s / alpha^2. A turn of the normal by t turns the reflected lobe by 2 t, and the light it gathers
 * changes over a turn of about alpha: cos(t)^(s / alpha^2) ~ exp(-s t^2 / (2 alpha^2)), so a
 * mirror's pixels take nothing from neighbours that reflect something else (a light's speck in a
 * curved mirror stays a speck), while a flat or rough surface is filtered as before. */
static inline float normal_stop(float sigma_n, float gloss, float alpha) {
    float a = alpha > 1e-3f ? alpha : 1e-3f;
    float sharp = gbuffer_glossy_share(gloss, alpha) / (a * a);
    return sharp > sigma_n ? sharp - sigma_n : 0.0f;
}

/* sigma_n log2 of a normals' cosine, kept within [1e-30, 1] */
static inline float normal_log2(float cosine, float sigma_n) {
    cosine = cosine < 1.0f ? cosine : 1.0f;
    cosine = cosine > 1e-30f ? cosine : 1e-30f;
    return sigma_n * log2_unit(cosine);
}

/* log2 e / (sigma_z |grad z . (dx, dy)| + eps): the depth stop's scale for a tap (dx, dy) away */
static inline float depth_scale(float z, float gx, float gy, float dx, float dy, float sigma_z) {
    return LOG2E / (sigma_z * fabsf(gx * dx + gy * dy) + EPS_Z * fabsf(z) + EPS_TINY);
}

/* The geometry weights h w_z w_n, as base-2 logarithms, of a pair of taps, (dx, dy) and its mirror
 * from the run of pixels at c + p: a at ga + pa, b at gb + pb, into wa and wb; log2h is the
 * kernel's weight. The two taps share the depth gradient's step 1 / (sigma_z |grad z . (dx, dy)| +
 * eps). */
static inline void pair_geometry(const job *j, const geometry *c, ptrdiff_t p, const geometry *ga, ptrdiff_t pa,
                                 const geometry *gb, ptrdiff_t pb, float dx, float dy, float log2h, float *restrict wa,
                                 float *restrict wb) {
    const float *restrict z = c->z + p, *restrict za = ga->z + pa, *restrict zb = gb->z + pb;
    const float *restrict nx = c->nx + p, *restrict ny = c->ny + p, *restrict nz = c->nz + p;
    const float *restrict nxa = ga->nx + pa, *restrict nya = ga->ny + pa, *restrict nza = ga->nz + pa;
    const float *restrict nxb = gb->nx + pb, *restrict nyb = gb->ny + pb, *restrict nzb = gb->nz + pb;
    const float *restrict gx = c->gx + p, *restrict gy = c->gy + p, *restrict sn = c->sn + p;
    float sz = j->sigma_z, sn0 = j->sigma_n;
    for (int i = 0; i < CHUNK; i++) {
        float zp = z[i];
        float inv = depth_scale(zp, gx[i], gy[i], dx, dy, sz);
        float ca = nx[i] * nxa[i] + ny[i] * nya[i] + nz[i] * nza[i];
        float cb = nx[i] * nxb[i] + ny[i] * nyb[i] + nz[i] * nzb[i];
        wa[i] = log2h + normal_log2(ca, sn0 + sn[i]) - fabsf(zp - za[i]) * inv;
        wb[i] = log2h + normal_log2(cb, sn0 + sn[i]) - fabsf(zp - zb[i]) * inv;
    }
}

/* log2 e / (sigma_l sqrt(var) + eps) for a run of pixels of counts n and luminances l: var, the
 * variance of the pixel's current value, is the one-sample variance v over its own count (so a
 * converged pixel's stop stays shut however young its neighbours). 0 at a hole: it has no
 * luminance to compare, and is filled by geometry alone. */
static inline void luminance_stop(const job *j, const float *restrict n, const float *restrict l,
                                  const float *restrict v, float inv_sqrt_unit, float *restrict il) {
    float sigma = j->sigma_l;
    for (int i = 0; i < CHUNK; i++) {
        int has = n[i] > 0.0f;
        float sd = sqrtf(v[i] / (has ? n[i] : 1.0f)) * inv_sqrt_unit;
        float inv = LOG2E / (sigma * sd + EPS_L * fabsf(l[i]) + EPS_TINY);
        il[i] = has ? inv : 0.0f;
    }
}

/* A step's sums for one component over a run: a = h w n (weight by samples), b = a^2 / n (what the
 * mean's variance takes: SVGF's squared weights, over each tap's own count). */
typedef struct {
    float a[CHUNK], r[CHUNK], g[CHUNK], b[CHUNK], bb[CHUNK];
} sums;

/* A tap's values for a run of pixels: light and scaled count. */
typedef struct {
    const float *r, *g, *b, *n;
} tap;

static inline tap tap_at(const planes *pl, ptrdiff_t p) { return (tap){pl->r + p, pl->g + p, pl->b + p, pl->n + p}; }

/* The run's sums, started with the pixels' own values t at kernel weight h, their counts taken u
 * times (in the unit of the taps to come). */
static inline void add_own(sums *restrict a, tap t, float h, float u) {
    const float *restrict n = t.n, *restrict r = t.r, *restrict g = t.g, *restrict b = t.b;
    for (int i = 0; i < CHUNK; i++) {
        float w = h * u * n[i];
        a->a[i] = w;
        a->r[i] = w * r[i];
        a->g[i] = w * g[i];
        a->b[i] = w * b[i];
        a->bb[i] = w * h;
    }
}

/* Adds taps ta and tb, whose h w_z w_n are 2^lnw_a, 2^lnw_b, to the sums of pixels whose own light is
 * (rp, gp, bp); il is log2 e over the luminance stop's scale. The stop compares colours by the
 * luminance's weights on each channel's absolute difference: |l_p - l_q| itself when the light
 * changes in brightness alone, but no longer blind to a change of colour at equal luminance
 * (docs/design.md). best keeps the largest lnw of a tap with samples. */
static inline void add_pair(sums *restrict s, const float *restrict rp, const float *restrict gp,
                            const float *restrict bp, tap ta, tap tb, const float *restrict lnw_a,
                            const float *restrict lnw_b, const float *restrict il, float *restrict best) {
    const float *restrict na = ta.n, *restrict nb = tb.n;
    const float *restrict ra = ta.r, *restrict rb = tb.r;
    const float *restrict ga = ta.g, *restrict gb = tb.g;
    const float *restrict ba = ta.b, *restrict bb = tb.b;
    for (int i = 0; i < CHUNK; i++) {
        float da = luminance3(v3(fabsf(rp[i] - ra[i]), fabsf(gp[i] - ga[i]), fabsf(bp[i] - ba[i])));
        float db = luminance3(v3(fabsf(rp[i] - rb[i]), fabsf(gp[i] - gb[i]), fabsf(bp[i] - bb[i])));
        float ea = exp2_neg(lnw_a[i] - da * il[i]), eb = exp2_neg(lnw_b[i] - db * il[i]);
        float wa = ea * na[i], wb = eb * nb[i];
        s->a[i] += wa + wb;
        s->r[i] += wa * ra[i] + wb * rb[i];
        s->g[i] += wa * ga[i] + wb * gb[i];
        s->b[i] += wa * ba[i] + wb * bb[i];
        s->bb[i] += wa * ea + wb * eb;
        float la = na[i] > 0.0f ? lnw_a[i] : -FLT_MAX, lb = nb[i] > 0.0f ? lnw_b[i] : -FLT_MAX;
        la = la > lb ? la : lb;
        best[i] = la > best[i] ? la : best[i];
    }
}

/* The sums into the next planes: the weighted mean and the effective count (sum a)^2 / sum b times
 * kappa / the most taps (see level_row); a hole that stays where no tap had a sample. */
static inline void finish(const sums *restrict a, float *restrict r, float *restrict g, float *restrict b,
                          float *restrict l, float *restrict n, float kappa) {
    for (int i = 0; i < CHUNK; i++) {
        float sa = a->a[i];
        int has = sa >= FLT_MIN;
        float inv = 1.0f / (has ? sa : 1.0f), bb = a->bb[i] > FLT_MIN ? a->bb[i] : FLT_MIN;
        float vr = clampf_to(a->r[i] * inv, FLT_MAX), vg = clampf_to(a->g[i] * inv, FLT_MAX);
        float vb = clampf_to(a->b[i] * inv, FLT_MAX);
        float vn = kappa * sa * (sa / bb);
        vn = vn < 0.5f ? vn : 0.5f;
        r[i] = has ? vr : 0.0f;
        g[i] = has ? vg : 0.0f;
        b[i] = has ? vb : 0.0f;
        l[i] = lum_of(r[i], g[i], b[i]);
        n[i] = has ? vn : 0.0f;
    }
}

/* One row of a step (a task_fn): pooling the input into the half grid, its variance steadied, and
 * the output from both. */
void denoise_pool_row(void *ctx, int y, int worker);
void denoise_variance_row(void *ctx, int y, int worker);
void denoise_upsample_row(void *ctx, int y, int worker);

#endif
