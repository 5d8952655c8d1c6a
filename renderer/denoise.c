/* The display's à-trous filter (docs/design.md, "The display: denoising"). Images are held as
 * planes (structure of arrays) inside a MARGIN of empty pixels, so that no tap leaves its plane
 * and none needs a bounds test: a margin pixel has no sample and takes no weight. A row is cut
 * into runs of CHUNK pixels, and every inner loop goes over one run with its taps fixed (a tap and
 * its mirror together), so that the compiler vectorises it; the geometry's weights are computed
 * once per tap for all components. */
#include "denoise.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define CHUNK 128
#define MARGIN (2 << (DENOISE_MAX_LEVELS - 1)) /* the farthest tap of the last pass */

/* Counts are held scaled so that no weight a = h w n is over 1/2 and no weighted sum of finite
 * values can overflow: n COUNT_SCALE <= 1/2, and after each pass the count is divided by 25, the
 * most it can grow by (Cauchy-Schwarz over 25 taps). COUNT_MAX (a trillion samples) caps it. */
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
/* Weights are handled as their base-2 logarithms. One below 2^EXP2_FLOOR (2e-35) is taken as that:
 * it counts for nothing, and keeps the sums normal floats. */
#define EXP2_FLOOR (-115.0f)
#define LOG2E 1.44269504f
/* An escaped ray's depth: no hit's depth is near it, so the depth stop keeps the two apart (and
 * escaped rays together, compared by direction through the stored normal). */
#define DEPTH_SKY (-1e20f)
/* Below this many samples the variance comes (in part) from the neighbours, as in SVGF. */
#define YOUNG 4.0f

static const float B3[5] = {1.0f / 16.0f, 1.0f / 4.0f, 3.0f / 8.0f, 1.0f / 4.0f, 1.0f / 16.0f};
static const float G3[3] = {0.25f, 0.5f, 0.25f}; /* the 3x3 Gaussian that steadies the variance */
/* Half of the 5x5 and of the 7x7 taps (dx, dy) around the centre: each goes with its mirror. */
static const signed char PAIRS5[12][2] = {{1, 0}, {2, 0},  {-2, 1}, {-1, 1}, {0, 1}, {1, 1},
                                          {2, 1}, {-2, 2}, {-1, 2}, {0, 2},  {1, 2}, {2, 2}};
static const signed char PAIRS7[24][2] = {{1, 0}, {2, 0},  {3, 0},  {-3, 1}, {-2, 1}, {-1, 1}, {0, 1}, {1, 1},
                                          {2, 1}, {3, 1},  {-3, 2}, {-2, 2}, {-1, 2}, {0, 2},  {1, 2}, {2, 2},
                                          {3, 2}, {-3, 3}, {-2, 3}, {-1, 3}, {0, 3},  {1, 3},  {2, 3}, {3, 3}};

/* The inner loops hold no conversion between int and float and no nested ?: : either keeps gcc
 * from vectorising a loop. An integer k, |k| < 2^22, is the low bits of the float k + ROUNDER. */
#define ROUNDER 0x1.8p23f
#define ROUNDER_BITS 0x4b400000u

static inline uint32_t bits_of(float f) {
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u;
}
static inline float float_of(uint32_t u) {
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

/* 2^x for x <= 0: 2^k from the exponent bits times 2^f, |f| <= 1/2, by a degree-3 fit exact at
 * f = 0 (so 2^0 is 1). Relative error under 1.0e-4 + 1e-7 |x| (the fit; the rounding of x): ample
 * for a weight. Below EXP2_FLOOR, and for NaN, it is 2^EXP2_FLOOR. */
static inline float exp2_neg(float x) {
    x = x > EXP2_FLOOR ? x : EXP2_FLOOR;
    float kr = x + ROUNDER; /* x rounded to an integer k, held as k + ROUNDER */
    float f = x - (kr - ROUNDER);
    float p = 1.0f + f * (0.69328293f + f * (0.242210964f + f * 0.0550089153f));
    return float_of(bits_of(p) + ((bits_of(kr) - ROUNDER_BITS) << 23));
}

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
    float *l;         /* its luminance, within +-LUM_MAX */
    float *s2;        /* the variance of one sample's luminance */
    float *n;         /* samples behind the value, scaled (COUNT_SCALE, then 1/25 a pass); 0: a hole */
} planes;

#define PLANES_EACH 6
#define PLANES_GEOMETRY 6

struct denoiser {
    int width, height;
    ptrdiff_t stride; /* floats a plane row: MARGIN, the width rounded up to CHUNK, MARGIN */
    size_t plane_size;
    float *mem;
    float *z, *nx, *ny, *nz; /* depth (DEPTH_SKY: escaped), shading normal */
    float *gx, *gy;          /* the depth's screen gradient, robust at edges */
    planes buf[2][COMP_COUNT];
    float kappa[DENOISE_MAX_LEVELS]; /* see level_row */
};

static ptrdiff_t at(const denoiser *d, int y, int x) { return (ptrdiff_t)(y + MARGIN) * d->stride + MARGIN + x; }

/* kappa[i]: how much the open cascade's effective count 1 / sum K^2 really grows at pass i, over
 * the 1 / sum h^2 that the pass's weights would promise to independent taps. */
static void cascade_kappa(float *kappa) {
    enum { LEN = 4 * ((1 << DENOISE_MAX_LEVELS) - 1) + 1 };
    double k[LEN] = {0}, next[LEN];
    int r = 0; /* the composite kernel's radius so far */
    k[LEN / 2] = 1.0;
    double sum_h2 = 0.0, prev = 1.0;
    for (int t = 0; t < 5; t++) sum_h2 += (double)B3[t] * (double)B3[t];
    for (int i = 0; i < DENOISE_MAX_LEVELS; i++) {
        memset(next, 0, sizeof next);
        for (int x = LEN / 2 - r; x <= LEN / 2 + r; x++)
            for (int t = 0; t < 5; t++) next[x + (t - 2) * (1 << i)] += k[x] * (double)B3[t];
        memcpy(k, next, sizeof k);
        r += 2 << i;
        double s = 0.0;
        for (int x = 0; x < LEN; x++) s += k[x] * k[x];
        double count = 1.0 / (s * s); /* 2D: the kernel is separable */
        kappa[i] = (float)(count / prev * sum_h2 * sum_h2);
        prev = count;
    }
}

denoiser *denoiser_create(int width, int height) {
    if (width <= 0 || height <= 0 || width > (1 << 16) || height > (1 << 16)) return NULL;
    denoiser *d = calloc(1, sizeof(denoiser));
    if (!d) return NULL;
    d->width = width;
    d->height = height;
    d->stride = 2 * MARGIN + (width + CHUNK - 1) / CHUNK * CHUNK;
    d->plane_size = (size_t)d->stride * (size_t)(height + 2 * MARGIN);
    int count = PLANES_GEOMETRY + 2 * COMP_COUNT * PLANES_EACH;
    /* calloc: the margins stay 0, and a component never used is never touched (nor resident) */
    d->mem = calloc((size_t)count * d->plane_size, sizeof(float));
    if (!d->mem) {
        free(d);
        return NULL;
    }
    float *m = d->mem;
    float **geometry[PLANES_GEOMETRY] = {&d->z, &d->nx, &d->ny, &d->nz, &d->gx, &d->gy};
    for (int i = 0; i < PLANES_GEOMETRY; i++, m += d->plane_size) *geometry[i] = m;
    for (int b = 0; b < 2; b++)
        for (int c = 0; c < COMP_COUNT; c++) {
            planes *p = &d->buf[b][c];
            float **each[PLANES_EACH] = {&p->r, &p->g, &p->b, &p->l, &p->s2, &p->n};
            for (int i = 0; i < PLANES_EACH; i++, m += d->plane_size) *each[i] = m;
        }
    cascade_kappa(d->kappa);
    return d;
}

void denoiser_destroy(denoiser *d) {
    if (!d) return;
    free(d->mem);
    free(d);
}

typedef struct {
    denoiser *d;
    const denoise_input *in;
    const denoise_output *out;
    int comps;
    float sigma_z, sigma_n, sigma_l;
    /* the pass */
    int step, src, last;
    float kappa;
    float inv_sqrt_unit; /* 1 / sqrt(the samples a scaled count of 1 stands for), before the pass */
    float out_unit;      /* ... and after it */
} job;

static inline float sane_depth(float z) { return z > 0.0f ? (z < DEPTH_MAX ? z : DEPTH_MAX) : 0.0f; }
static inline float sane_unit(float v) { return v > -1.0f ? (v < 1.0f ? v : 1.0f) : (v <= -1.0f ? -1.0f : 0.0f); }

/* The depth's slope at z from its neighbours before (zm) and after (zp), 0 where absent or escaped:
 * the smaller one-sided difference, so a pixel at an edge takes its own surface's slope. */
static float slope(float zm, float z, float zp) {
    if (z == 0.0f) return 0.0f;
    if (zm == 0.0f) return zp == 0.0f ? 0.0f : zp - z;
    if (zp == 0.0f) return z - zm;
    return fabsf(z - zm) < fabsf(zp - z) ? z - zm : zp - z;
}

/* Row y of the input into the planes: geometry, and each component's light, luminance, variance and
 * scaled count; anything not finite is a hole (count 0). The run's tail past the image stays 0. */
static void prep_row(void *ctx, int y, int worker) {
    (void)worker;
    const job *j = ctx;
    denoiser *d = j->d;
    const gbuffer *g = j->in->g;
    int w = d->width, h = d->height;
    const float *depth = g->depth + (size_t)y * (size_t)w;
    ptrdiff_t p0 = at(d, y, 0);
    for (int x = 0; x < w; x++) {
        size_t i = (size_t)y * (size_t)w + (size_t)x;
        ptrdiff_t p = p0 + x;
        float z = sane_depth(depth[x]);
        d->z[p] = z > 0.0f ? z : DEPTH_SKY;
        d->nx[p] = sane_unit(g->normal[3 * i]);
        d->ny[p] = sane_unit(g->normal[3 * i + 1]);
        d->nz[p] = sane_unit(g->normal[3 * i + 2]);
        d->gx[p] = slope(x > 0 ? sane_depth(depth[x - 1]) : 0.0f, z, x + 1 < w ? sane_depth(depth[x + 1]) : 0.0f);
        d->gy[p] = slope(y > 0 ? sane_depth(depth[x - w]) : 0.0f, z, y + 1 < h ? sane_depth(depth[x + w]) : 0.0f);
    }
    for (int c = 0; c < j->comps; c++) {
        planes *pl = &d->buf[0][c];
        const float *rgb_row = j->in->light[c] + 3 * (size_t)y * (size_t)w;
        const float *count = j->in->count[c] + (size_t)y * (size_t)w;
        const float *var = j->in->variance[c] ? j->in->variance[c] + (size_t)y * (size_t)w : NULL;
        for (int x = 0; x < w; x++) {
            ptrdiff_t p = p0 + x;
            const float *rgb = rgb_row + 3 * x;
            float n = count[x], v = var ? var[x] : 0.0f;
            int ok = n > 0.0f && isfinite(rgb[0]) && isfinite(rgb[1]) && isfinite(rgb[2]);
            pl->n[p] = ok ? (n < COUNT_MAX ? n : COUNT_MAX) * COUNT_SCALE : 0.0f;
            pl->r[p] = ok ? rgb[0] : 0.0f;
            pl->g[p] = ok ? rgb[1] : 0.0f;
            pl->b[p] = ok ? rgb[2] : 0.0f;
            pl->l[p] = lum_of(pl->r[p], pl->g[p], pl->b[p]);
            pl->s2[p] = ok && v > 0.0f ? (v < S2_MAX ? v : S2_MAX) : 0.0f;
        }
    }
}

/* The geometry weights h w_z w_n, as base-2 logarithms, of the taps at plane offsets +off and -off,
 * (dx, dy) and its mirror, for the run of pixels from p, into wa and wb; log2h is the kernel's
 * weight. The two taps share the depth gradient's step 1 / (sigma_z |grad z . (dx, dy)| + eps). */
static void pair_geometry(const denoiser *d, const job *j, ptrdiff_t p, ptrdiff_t off, float dx, float dy, float log2h,
                          float *restrict wa, float *restrict wb) {
    const float *restrict z = d->z + p, *restrict za = d->z + p + off, *restrict zb = d->z + p - off;
    const float *restrict nx = d->nx + p, *restrict ny = d->ny + p, *restrict nz = d->nz + p;
    const float *restrict nxa = d->nx + p + off, *restrict nya = d->ny + p + off, *restrict nza = d->nz + p + off;
    const float *restrict nxb = d->nx + p - off, *restrict nyb = d->ny + p - off, *restrict nzb = d->nz + p - off;
    const float *restrict gx = d->gx + p, *restrict gy = d->gy + p;
    float sz = j->sigma_z, sn = j->sigma_n;
    for (int i = 0; i < CHUNK; i++) {
        float zp = z[i];
        float inv = LOG2E / (sz * fabsf(gx[i] * dx + gy[i] * dy) + EPS_Z * fabsf(zp) + EPS_TINY);
        float ca = nx[i] * nxa[i] + ny[i] * nya[i] + nz[i] * nza[i];
        float cb = nx[i] * nxb[i] + ny[i] * nyb[i] + nz[i] * nzb[i];
        ca = ca < 1.0f ? ca : 1.0f;
        ca = ca > 1e-30f ? ca : 1e-30f;
        cb = cb < 1.0f ? cb : 1.0f;
        cb = cb > 1e-30f ? cb : 1e-30f;
        wa[i] = log2h + sn * log2_unit(ca) - fabsf(zp - za[i]) * inv;
        wb[i] = log2h + sn * log2_unit(cb) - fabsf(zp - zb[i]) * inv;
    }
}

/* SVGF's spatial variance where a pixel has fewer than YOUNG samples: the 7x7 neighbours on the
 * same surface (geometry weights w), each mean counted by its samples n, give
 *     s^2 = sum w n (l - lbar)^2 / D,   D = sum w - sum w^2 n / sum w n,
 * unbiased for equal means (D: its degrees of freedom). It is pooled with the given variance by
 * degrees of freedom, D against n - 1: a mean of one sample brings none of its own. Differences
 * are taken from the centre's luminance, so that the sums do not cancel. */
typedef struct {
    float w[CHUNK], wn[CHUNK], wnd[CHUNK], wnd2[CHUNK], w2n[CHUNK];
} moments;

static void add_moments(moments *restrict m, const planes *pl, ptrdiff_t p, ptrdiff_t off, const float *restrict w) {
    const float *restrict l = pl->l + p, *restrict lq = pl->l + p + off, *restrict nq = pl->n + p + off;
    for (int i = 0; i < CHUNK; i++) {
        float wn = w[i] * nq[i], dl = lq[i] - l[i];
        m->w[i] += nq[i] > 0.0f ? w[i] : 0.0f;
        m->wn[i] += wn;
        m->wnd[i] += wn * dl;
        m->wnd2[i] += wn * dl * dl;
        m->w2n[i] += w[i] * wn;
    }
}

static void spatial_row(void *ctx, int y, int worker) {
    (void)worker;
    const job *j = ctx;
    const denoiser *d = j->d;
    const planes *pl = d->buf[0];
    for (int x0 = 0; x0 < d->width; x0 += CHUNK) {
        ptrdiff_t p = at(d, y, x0);
        int young = 0;
        for (int c = 0; c < j->comps; c++) {
            const float *restrict n = pl[c].n + p;
            for (int i = 0; i < CHUNK; i++) young |= n[i] > 0.0f && n[i] < YOUNG * COUNT_SCALE;
        }
        if (!young) continue;
        moments m[COMP_COUNT];
        for (int c = 0; c < j->comps; c++) {
            const float *restrict n = pl[c].n + p;
            for (int i = 0; i < CHUNK; i++) {
                m[c].w[i] = n[i] > 0.0f ? 1.0f : 0.0f;
                m[c].wn[i] = m[c].w2n[i] = n[i];
                m[c].wnd[i] = m[c].wnd2[i] = 0.0f;
            }
        }
        for (int k = 0; k < 24; k++) {
            ptrdiff_t off = (ptrdiff_t)PAIRS7[k][1] * d->stride + PAIRS7[k][0];
            float lnw[2][CHUNK], w[CHUNK];
            pair_geometry(d, j, p, off, (float)PAIRS7[k][0], (float)PAIRS7[k][1], 0.0f, lnw[0], lnw[1]);
            for (int t = 0; t < 2; t++) {
                for (int i = 0; i < CHUNK; i++) w[i] = exp2_neg(lnw[t][i]);
                for (int c = 0; c < j->comps; c++) add_moments(&m[c], &pl[c], p, t == 0 ? off : -off, w);
            }
        }
        for (int c = 0; c < j->comps; c++) {
            for (int i = 0; i < CHUNK; i++) {
                float n = pl[c].n[p + i];
                if (!(n > 0.0f && n < YOUNG * COUNT_SCALE)) continue;
                const moments *mc = &m[c];
                double wn = (double)mc->wn[i], dof = (double)mc->w[i] - (double)mc->w2n[i] / wn;
                double ss = (double)mc->wnd2[i] - (double)mc->wnd[i] * (double)mc->wnd[i] / wn;
                double spatial = dof > 0.0 && ss > 0.0 ? ss / (dof * (double)COUNT_SCALE) : 0.0;
                double own = (double)(n / COUNT_SCALE) - 1.0; /* the given variance's degrees of freedom */
                if (own < 0.0) own = 0.0;
                if (dof < 0.0) dof = 0.0;
                if (dof + own > 0.0) {
                    double v = (dof * spatial + own * (double)pl[c].s2[p + i]) / (dof + own);
                    pl[c].s2[p + i] = v < (double)S2_MAX ? (float)v : S2_MAX;
                }
            }
        }
    }
}

/* log2 e / (sigma_l sqrt(var) + eps) for the run of pixels from p: var, the variance of the pixel's
 * current value, is the 3x3 Gaussian of its neighbours' one-sample variance (holes left out) over
 * its own count, so that a young neighbour's variance does not loosen a converged pixel's stop.
 * 0 at a hole: it has no luminance to compare, and is filled by geometry alone. */
static void luminance_stop(const denoiser *d, const job *j, const planes *pl, ptrdiff_t p, float *restrict il) {
    float gw[CHUNK] = {0}, gs[CHUNK] = {0};
    for (int oy = -1; oy <= 1; oy++)
        for (int ox = -1; ox <= 1; ox++) {
            float k = G3[oy + 1] * G3[ox + 1];
            const float *restrict nq = pl->n + p + oy * d->stride + ox;
            const float *restrict s2 = pl->s2 + p + oy * d->stride + ox;
            for (int i = 0; i < CHUNK; i++) {
                float kk = nq[i] > 0.0f ? k : 0.0f;
                gw[i] += kk;
                gs[i] += kk * s2[i];
            }
        }
    const float *restrict n = pl->n + p, *restrict l = pl->l + p;
    float unit = j->inv_sqrt_unit, sigma = j->sigma_l;
    for (int i = 0; i < CHUNK; i++) {
        int has = n[i] > 0.0f;
        float v = gs[i] / (gw[i] > 0.0f ? gw[i] : 1.0f); /* gw > 0 wherever has */
        float sd = sqrtf(v / (has ? n[i] : 1.0f)) * unit;
        float inv = LOG2E / (sigma * sd + EPS_L * fabsf(l[i]) + EPS_TINY);
        il[i] = has ? inv : 0.0f;
    }
}

/* A pass's sums for one component over a run: a = h w n (weight by samples), b = a^2 / n (what the
 * mean's variance takes: SVGF's squared weights, over each tap's own count). */
typedef struct {
    float a[CHUNK], r[CHUNK], g[CHUNK], b[CHUNK], bb[CHUNK], bs[CHUNK];
} sums;

/* Adds the taps at +off and -off, whose h w_z w_n are 2^lnw_a, 2^lnw_b; il is log2 e over the
 * luminance stop's scale. The stop compares colours by the luminance's weights on each channel's
 * absolute difference: |l_p - l_q| itself when the light changes in brightness alone, but no
 * longer blind to a change of colour at equal luminance (docs/design.md). */
static void add_pair(sums *restrict s, const planes *pl, ptrdiff_t p, ptrdiff_t off, const float *restrict lnw_a,
                     const float *restrict lnw_b, const float *restrict il) {
    const float *restrict rp = pl->r + p, *restrict gp = pl->g + p, *restrict bp = pl->b + p;
    const float *restrict na = pl->n + p + off, *restrict nb = pl->n + p - off;
    const float *restrict ra = pl->r + p + off, *restrict rb = pl->r + p - off;
    const float *restrict ga = pl->g + p + off, *restrict gb = pl->g + p - off;
    const float *restrict ba = pl->b + p + off, *restrict bb = pl->b + p - off;
    const float *restrict sa = pl->s2 + p + off, *restrict sb = pl->s2 + p - off;
    for (int i = 0; i < CHUNK; i++) {
        float da = luminance3(v3(fabsf(rp[i] - ra[i]), fabsf(gp[i] - ga[i]), fabsf(bp[i] - ba[i])));
        float db = luminance3(v3(fabsf(rp[i] - rb[i]), fabsf(gp[i] - gb[i]), fabsf(bp[i] - bb[i])));
        float ea = exp2_neg(lnw_a[i] - da * il[i]), eb = exp2_neg(lnw_b[i] - db * il[i]);
        float wa = ea * na[i], wb = eb * nb[i], qa = wa * ea, qb = wb * eb;
        s->a[i] += wa + wb;
        s->r[i] += wa * ra[i] + wb * rb[i];
        s->g[i] += wa * ga[i] + wb * gb[i];
        s->b[i] += wa * ba[i] + wb * bb[i];
        s->bb[i] += qa + qb;
        s->bs[i] += qa * sa[i] + qb * sb[i];
    }
}

/* The sums into the next planes: the weighted mean, the b-weighted mean of the one-sample variance,
 * and the effective count (sum a)^2 / sum b times kappa / TAPS (see level_row); a hole that stays
 * where no tap had a sample. */
static void finish(const sums *restrict a, float *restrict r, float *restrict g, float *restrict b, float *restrict l,
                   float *restrict n, float *restrict s2, float kappa) {
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
        s2[i] = has ? a->bs[i] / bb : 0.0f;
    }
}

/* One à-trous pass over row y, from the src planes into the others (the last also into the output).
 * Each tap weighs h w_z w_n w_l n. The count after the pass is the effective count (sum a)^2 / sum b
 * times kappa: the sum alone would treat the taps as independent, but from pass 1 on they share
 * samples, and kappa is how much less the open cascade's count really grows. Without it the count
 * after 5 passes would be ~100 times too high, and the late passes' luminance stops that much too
 * tight (docs/design.md). */
static void level_row(void *ctx, int y, int worker) {
    (void)worker;
    const job *j = ctx;
    const denoiser *d = j->d;
    const planes *pl = d->buf[j->src], *to = d->buf[!j->src];
    const int s = j->step;
    const float hc = B3[2] * B3[2];
    for (int x0 = 0; x0 < d->width; x0 += CHUNK) {
        ptrdiff_t p = at(d, y, x0);
        float il[COMP_COUNT][CHUNK];
        sums acc[COMP_COUNT];
        for (int c = 0; c < j->comps; c++) {
            luminance_stop(d, j, &pl[c], p, il[c]);
            const float *restrict n = pl[c].n + p, *restrict r = pl[c].r + p, *restrict g = pl[c].g + p;
            const float *restrict b = pl[c].b + p, *restrict s2 = pl[c].s2 + p;
            sums *restrict a = &acc[c];
            for (int i = 0; i < CHUNK; i++) {
                float w = hc * n[i];
                a->a[i] = w;
                a->r[i] = w * r[i];
                a->g[i] = w * g[i];
                a->b[i] = w * b[i];
                a->bb[i] = w * hc;
                a->bs[i] = w * hc * s2[i];
            }
        }
        for (int k = 0; k < 12; k++) {
            int dx = PAIRS5[k][0] * s, dy = PAIRS5[k][1] * s;
            ptrdiff_t off = (ptrdiff_t)dy * d->stride + dx;
            float lnw[2][CHUNK], log2h = log2f(B3[PAIRS5[k][0] + 2] * B3[PAIRS5[k][1] + 2]);
            pair_geometry(d, j, p, off, (float)dx, (float)dy, log2h, lnw[0], lnw[1]);
            for (int c = 0; c < j->comps; c++) {
                add_pair(&acc[c], &pl[c], p, off, lnw[0], lnw[1], il[c]);
            }
        }
        int tail = d->width - x0 < CHUNK ? d->width - x0 : CHUNK;
        for (int c = 0; c < j->comps; c++) {
            const planes *dst = &to[c];
            finish(&acc[c], dst->r + p, dst->g + p, dst->b + p, dst->l + p, dst->n + p, dst->s2 + p, j->kappa / TAPS);
            for (int i = tail; i < CHUNK; i++) /* the run's tail past the image: no sample */
                to[c].r[p + i] = to[c].g[p + i] = to[c].b[p + i] = to[c].l[p + i] = to[c].n[p + i] = to[c].s2[p + i] =
                    0.0f;
            if (!j->last) continue;
            size_t o = (size_t)y * (size_t)d->width + (size_t)x0;
            float *out = j->out->light[c] + 3 * o, *count = j->out->count[c] ? j->out->count[c] + o : NULL;
            for (int i = 0; i < tail; i++) {
                out[3 * i] = to[c].r[p + i];
                out[3 * i + 1] = to[c].g[p + i];
                out[3 * i + 2] = to[c].b[p + i];
                if (count) count[i] = clampf_to(to[c].n[p + i] * j->out_unit, FLT_MAX);
            }
        }
    }
}

/* No pass: the input as it came in (holes 0). */
static void copy_row(void *ctx, int y, int worker) {
    (void)worker;
    const job *j = ctx;
    const denoiser *d = j->d;
    for (int c = 0; c < j->comps; c++) {
        const planes *pl = &d->buf[0][c];
        for (int x = 0; x < d->width; x++) {
            ptrdiff_t p = at(d, y, x);
            size_t o = (size_t)y * (size_t)d->width + (size_t)x;
            float *out = j->out->light[c] + 3 * o;
            out[0] = pl->r[p];
            out[1] = pl->g[p];
            out[2] = pl->b[p];
            if (j->out->count[c]) j->out->count[c][o] = pl->n[p] / COUNT_SCALE;
        }
    }
}

static void run_rows(threadpool *pool, task_fn fn, job *j) {
    if (pool) {
        threadpool_run(pool, fn, j, j->d->height);
    } else {
        for (int y = 0; y < j->d->height; y++) fn(j, y, 0);
    }
}

static float sigma_or(float v, float fallback) { return v > 0.0f && v <= 1e30f ? v : fallback; }

int denoise_run(denoiser *d, const denoise_input *in, const denoise_params *p, const denoise_output *out,
                threadpool *pool) {
    if (!d || !in || !out || !in->g || in->g->width != d->width || in->g->height != d->height) return -1;
    if (in->components < 1 || in->components > COMP_COUNT) return -1;
    for (int c = 0; c < in->components; c++)
        if (!in->light[c] || !in->count[c] || !out->light[c]) return -1;
    denoise_params none = {0};
    if (!p) p = &none;
    job j = {.d = d, .in = in, .out = out, .comps = in->components};
    j.sigma_z = sigma_or(p->sigma_z, 1.0f);
    j.sigma_n = sigma_or(p->sigma_n, 128.0f);
    j.sigma_l = sigma_or(p->sigma_l, 4.0f);
    int levels = p->levels < 0 ? 0 : (p->levels > DENOISE_MAX_LEVELS ? DENOISE_MAX_LEVELS : p->levels);
    run_rows(pool, prep_row, &j);
    if (levels == 0) {
        run_rows(pool, copy_row, &j);
        return 0;
    }
    run_rows(pool, spatial_row, &j);
    double unit = 1.0 / (double)COUNT_SCALE; /* samples a scaled count of 1 stands for */
    for (int i = 0; i < levels; i++) {
        j.step = 1 << i;
        j.src = i & 1;
        j.last = i == levels - 1;
        j.kappa = d->kappa[i];
        j.inv_sqrt_unit = (float)(1.0 / sqrt(unit));
        unit *= (double)TAPS;
        j.out_unit = (float)unit;
        run_rows(pool, level_row, &j);
    }
    return 0;
}
