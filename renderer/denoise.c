/* The display's à-trous filter (docs/design.md, "The display: denoising"): the interface, the
 * input into planes, the plan of the passes, and the half grid's passes; denoise_pyramid.c pools
 * the input into the half grid and brings the result back up. */
#include <stdlib.h>
#if defined(__SSE__)
#include <xmmintrin.h>
#endif

#include "denoise_parts.h"

/* Half of the 5x5 taps (dx, dy) around the centre: each goes with its mirror. */
static const signed char PAIRS5[12][2] = {{1, 0}, {2, 0},  {-2, 1}, {-1, 1}, {0, 1}, {1, 1},
                                          {2, 1}, {-2, 2}, {-1, 2}, {0, 2},  {1, 2}, {2, 2}};

/* ---- the plan: how much each step really lets the count grow ---------------------------------- */

typedef struct {
    int coarse; /* passes on the half grid (holes 1, 2, ... of its pixels) */
    float kappa_fine, kappa_pool, kappa_coarse[DENOISE_MAX_LEVELS], kappa_up;
} plan;

/* The open cascade's composite kernel in one dimension (it is separable), for the output pixel at
 * KO, over the input's pixels. */
enum { KLEN = 512, KO = KLEN / 2 };

static double dot_k(const double *a, const double *b) {
    double s = 0.0;
    for (int u = 0; u < KLEN; u++) s += a[u] * b[u];
    return s;
}

/* out(u) = sum_t h_t k(u - t step): a pass with holes `step` input pixels apart. */
static void conv_k(const double *k, double *out, int step, const float *h) {
    memset(out, 0, sizeof(double) * KLEN);
    for (int u = 0; u < KLEN; u++)
        for (int t = 0; t < 5; t++) {
            int v = u - (t - 2) * step;
            if (v >= 0 && v < KLEN) out[u] += (double)h[t] * k[v];
        }
}

/* k shifted by d input pixels (the kernel of the pixel d to the right). */
static void shift_k(const double *k, double *out, int d) {
    memset(out, 0, sizeof(double) * KLEN);
    for (int u = 0; u < KLEN; u++)
        if (u - d >= 0 && u - d < KLEN) out[u] = k[u - d];
}

static double sum_sq_2d(const float *h, int taps) {
    double s = 0.0;
    for (int i = 0; i < taps; i++) s += (double)h[i] * (double)h[i];
    return s * s;
}

/* kappa: how much the open cascade's effective count 1 / sum K^2 really grows at a step, over what
 * the step's rule (sum a)^2 / sum (a^2 / n) promises independent taps (see level_row). Counts here
 * are 2D, squares of the 1D ones; the input's pixels are independent, each of count 1. */
static plan make_plan(int levels) {
    plan p = {.coarse = levels - 1};
    double k[KLEN] = {0}, t[KLEN], kf[KLEN], kc[KLEN], far[KLEN];
    k[KO] = 1.0;
    /* the full image's 3x3 pass */
    conv_k(k, kf, 1, B1);
    double nf = 1.0 / (dot_k(kf, kf) * dot_k(kf, kf));
    p.kappa_fine = (float)(nf * sum_sq_2d(B1, 5));
    /* the half grid's pixel 0: K4 x K4 on the 4x4 from full pixel -1 on, which is the 3x3 pass on
     * full pixels 0 and 1, averaged */
    shift_k(kf, t, 1);
    for (int u = 0; u < KLEN; u++) kc[u] = 0.5 * (kf[u] + t[u]);
    double nc = 1.0 / (dot_k(kc, kc) * dot_k(kc, kc));
    p.kappa_pool = (float)(nc * sum_sq_2d(K4, 4));
    for (int i = 0; i < p.coarse; i++) {
        conv_k(kc, t, 2 << i, B3);
        memcpy(kc, t, sizeof kc);
        double n2 = 1.0 / (dot_k(kc, kc) * dot_k(kc, kc));
        p.kappa_coarse[i] = (float)(n2 / nc * sum_sq_2d(B3, 5));
        nc = n2;
    }
    /* back up, for full pixel 0: the 3x3 pass's value (weight UP_OWN nf) and the half grid's pixels
     * 0 (near, 3/4 a side) and -1 (far, 1/4), of kernels kf, kc and kc shifted: not separable, but
     * its sum K^2 is a sum of products of separable terms' */
    shift_k(kc, far, -2);
    double ao = (double)UP_OWN * nf, bn = 0.75, bf = 0.25, total = ao + nc;
    double cross = bn * dot_k(kf, kc) + bf * dot_k(kf, far), kk = dot_k(kf, kf);
    double q = bn * bn * dot_k(kc, kc) + 2.0 * bn * bf * dot_k(kc, far) + bf * bf * dot_k(far, far);
    double sum_k2 = (ao * ao * kk * kk + 2.0 * ao * nc * cross * cross + nc * nc * q * q) / (total * total);
    double bil2 = (bn * bn + bf * bf) * (bn * bn + bf * bf);
    double naive = total * total / ((double)UP_OWN * (double)UP_OWN * nf + nc * bil2);
    p.kappa_up = (float)(1.0 / sum_k2 / naive);
    return p;
}

/* ---- memory ---------------------------------------------------------------------------------- */

static float *take_geometry(geometry *g, float *m, size_t size) {
    float **each[PLANES_GEOMETRY] = {&g->z, &g->nx, &g->ny, &g->nz, &g->gx, &g->gy, &g->sn};
    for (int i = 0; i < PLANES_GEOMETRY; i++, m += size) *each[i] = m;
    return m;
}

/* with_l: the half grid's planes keep the luminance (the full image's is computed where needed) */
static float *take_planes(planes *p, float *m, size_t size, int with_l) {
    float **each[PLANES_EACH] = {&p->r, &p->g, &p->b, &p->s2, &p->n, &p->l};
    for (int i = 0; i < PLANES_EACH - !with_l; i++, m += size) *each[i] = m;
    return m;
}

denoiser *denoiser_create(int width, int height) {
    if (width <= 0 || height <= 0 || width > (1 << 16) || height > (1 << 16)) return NULL;
    denoiser *d = calloc(1, sizeof(denoiser));
    if (!d) return NULL;
    d->width = width;
    d->height = height;
    d->half_width = (width + 1) / 2;
    d->half_height = (height + 1) / 2;
    d->stride = 2 * MARGIN + (d->half_width + CHUNK - 1) / CHUNK * CHUNK;
    size_t full = (size_t)d->stride * (size_t)(height + 2 * MARGIN);
    size_t half = (size_t)d->stride * (size_t)(d->half_height + 2 * MARGIN);
    size_t n_full = 2 * (PLANES_GEOMETRY + COMP_COUNT * (PLANES_EACH - 1)); /* two parities, no l */
    size_t n_half = PLANES_GEOMETRY + 2 + 2 * COMP_COUNT * PLANES_EACH;     /* rx, ry; two buffers */
    /* calloc: the margins stay 0, and a component never used is never touched (nor resident) */
    d->mem = calloc(n_full * full + n_half * half, sizeof(float));
    if (!d->mem) {
        free(d);
        return NULL;
    }
    float *m = d->mem;
    for (int ph = 0; ph < 2; ph++) {
        m = take_geometry(&d->full_geo[ph], m, full);
        for (int c = 0; c < COMP_COUNT; c++) m = take_planes(&d->full[ph][c], m, full, 0);
    }
    m = take_geometry(&d->half_geo, m, half);
    for (int b = 0; b < 2; b++)
        for (int c = 0; c < COMP_COUNT; c++) m = take_planes(&d->half[b][c], m, half, 1);
    d->rx = m;
    d->ry = m + half;
    return d;
}

void denoiser_destroy(denoiser *d) {
    if (!d) return;
    free(d->mem);
    free(d);
}

static inline float sane_depth(float z) { return z > 0.0f ? (z < DEPTH_MAX ? z : DEPTH_MAX) : 0.0f; }
static inline float sane_unit(float v) { return v > -1.0f ? (v < 1.0f ? v : 1.0f) : (v <= -1.0f ? -1.0f : 0.0f); }

/* The depth's slope at z from its neighbours before (zm) and after (zp), 0 where absent or escaped:
 * the smaller one-sided difference, so a pixel at an edge takes its own surface's slope. */
static inline float slope(float zm, float z, float zp) {
    float dm = z - zm, dp = zp - z;
    float s = fabsf(dm) < fabsf(dp) ? dm : dp;
    float only_after = zp == 0.0f ? 0.0f : dp;
    s = zp == 0.0f ? dm : s;
    s = zm == 0.0f ? only_after : s;
    return z == 0.0f ? 0.0f : s;
}

/* n items of k floats from src into a run, 0 past them (the run's tail past the image). */
static void load_run(float *restrict dst, const float *restrict src, int n, int k) {
    memcpy(dst, src, sizeof(float) * (size_t)(n * k));
    memset(dst + n * k, 0, sizeof(float) * (size_t)((RUN - n) * k));
}

/* A run's pixels into the planes of their parity. */
static void split_pairs(const float *restrict run, float *restrict even, float *restrict odd) {
    for (int i = 0; i < CHUNK; i++) {
        even[i] = run[2 * i];
        odd[i] = run[2 * i + 1];
    }
}

/* A run's geometry (into g: z, nx, ny, nz, gx, gy, sn): zs its depths (0: none) with its left and
 * right neighbours', za and zb those above and below, nrm its normals (3 floats each), gloss and
 * alpha its glossy lobes (normal_stop with sigma_n). */
static void prep_geometry(const float *restrict zs, const float *restrict za, const float *restrict zb,
                          const float *restrict nrm, const float *restrict gloss, const float *restrict alpha,
                          float sigma_n, float (*restrict g)[RUN]) {
    for (int i = 0; i < RUN; i++) {
        float zi = zs[i + 1];
        g[0][i] = zi > 0.0f ? zi : DEPTH_SKY;
        g[1][i] = sane_unit(nrm[3 * i]);
        g[2][i] = sane_unit(nrm[3 * i + 1]);
        g[3][i] = sane_unit(nrm[3 * i + 2]);
        g[4][i] = slope(zs[i], zi, zs[i + 2]);
        g[5][i] = slope(za[i], zi, zb[i]);
        g[6][i] = normal_stop(sigma_n, gloss[i], alpha[i]);
    }
}

/* A run of one component's light (3 floats each), counts and variances into v: r, g, b, s2, n. */
static void prep_light(const float *restrict rgb, const float *restrict count, const float *restrict var, float cap,
                       float (*restrict v)[RUN]) {
    for (int i = 0; i < RUN; i++) {
        float vr = rgb[3 * i], vg = rgb[3 * i + 1], vb = rgb[3 * i + 2], k = count[i], s = var[i];
        float finite = (vr - vr) + (vg - vg) + (vb - vb); /* x - x: 0 for a finite x, NaN otherwise */
        float has = k > 0.0f && finite == 0.0f ? 1.0f : 0.0f;
        vr = has > 0.0f ? vr : 0.0f;
        vg = has > 0.0f ? vg : 0.0f;
        vb = has > 0.0f ? vb : 0.0f;
        k = k < cap ? k : cap;
        s = s < S2_MAX ? s : S2_MAX;
        v[0][i] = vr;
        v[1][i] = vg;
        v[2][i] = vb;
        v[3][i] = has > 0.0f && s > 0.0f ? s : 0.0f;
        v[4][i] = has > 0.0f ? k * COUNT_SCALE : 0.0f;
    }
}

/* Row y of the input into the full image's planes: geometry, and each component's light, variance
 * and scaled count; anything not finite is a hole (count 0). Pixels past the image are 0. A whole
 * run is read where it lies, the image's last through a copy. */
static void prep_row(void *ctx, int y, int worker) {
    (void)worker;
    const job *j = ctx;
    denoiser *d = j->d;
    const gbuffer *g = j->in->g;
    int w = d->width, h = d->height;
    size_t row = (size_t)y * (size_t)w;
    static const float none[3 * RUN];
    for (int x0 = 0; x0 < w; x0 += RUN) {
        int n = w - x0 < RUN ? w - x0 : RUN, whole = n == RUN;
        ptrdiff_t p = at(d, y, x0 / 2);
        size_t i0 = row + (size_t)x0;
        /* depths (0: none) of the run and of its neighbours left, right, above and below */
        float zs[RUN + 2], za[RUN], zb[RUN], nrm_run[3 * RUN];
        load_run(zs + 1, g->depth + i0, n, 1);
        zs[0] = x0 > 0 ? g->depth[i0 - 1] : 0.0f;
        zs[n + 1] = x0 + n < w ? g->depth[i0 + (size_t)n] : 0.0f;
        load_run(za, y > 0 ? g->depth + i0 - (size_t)w : none, y > 0 ? n : 0, 1);
        load_run(zb, y + 1 < h ? g->depth + i0 + (size_t)w : none, y + 1 < h ? n : 0, 1);
        for (int i = 0; i < RUN; i++) {
            za[i] = sane_depth(za[i]);
            zb[i] = sane_depth(zb[i]);
        }
        for (int i = 0; i < RUN + 2; i++) zs[i] = sane_depth(zs[i]);
        const float *nrm = g->normal + 3 * i0, *gloss = g->gloss + i0, *alpha = g->alpha + i0;
        float gloss_run[RUN], alpha_run[RUN];
        if (!whole) {
            load_run(nrm_run, nrm, n, 3), nrm = nrm_run;
            load_run(gloss_run, gloss, n, 1), gloss = gloss_run;
            load_run(alpha_run, alpha, n, 1), alpha = alpha_run;
        }
        float v[PLANES_GEOMETRY][RUN];
        prep_geometry(zs, za, zb, nrm, gloss, alpha, j->sigma_n, v);
        for (int i = n; i < RUN; i++) v[0][i] = 0.0f; /* past the image: nothing */
        const geometry *g0 = &d->full_geo[0], *g1 = &d->full_geo[1];
        float *even[PLANES_GEOMETRY] = {g0->z, g0->nx, g0->ny, g0->nz, g0->gx, g0->gy, g0->sn};
        float *odd[PLANES_GEOMETRY] = {g1->z, g1->nx, g1->ny, g1->nz, g1->gx, g1->gy, g1->sn};
        for (int k = 0; k < PLANES_GEOMETRY; k++) split_pairs(v[k], even[k] + p, odd[k] + p);
        for (int c = 0; c < j->comps; c++) {
            float rgb_run[3 * RUN], count_run[RUN], var_run[RUN];
            const float *rgb = j->in->light[c] + 3 * i0, *count = j->in->count[c] + i0;
            const float *var = j->in->variance[c] ? j->in->variance[c] + i0 : none;
            if (!whole || !j->in->variance[c]) {
                load_run(rgb_run, rgb, n, 3);
                load_run(count_run, count, n, 1);
                load_run(var_run, var, j->in->variance[c] ? n : 0, 1);
                rgb = rgb_run, count = count_run, var = var_run;
            }
            prep_light(rgb, count, var, j->count_cap, v);
            const planes *e = &d->full[0][c], *o = &d->full[1][c];
            float *pe[PLANES_EACH - 1] = {e->r, e->g, e->b, e->s2, e->n};
            float *po[PLANES_EACH - 1] = {o->r, o->g, o->b, o->s2, o->n};
            for (int k = 0; k < PLANES_EACH - 1; k++) split_pairs(v[k], pe[k] + p, po[k] + p);
        }
    }
}

/* add_pair with SVGF's stop, on luminance alone (|l_p - l_q|, of the planes' l): what the half grid's
 * passes use. A colour that changes at equal luminance blurs there, but the light at full
 * resolution (the pooling, the 3x3 pass and the way back up) is compared channel by channel, so
 * the half grid's light is taken only where it agrees in colour too (docs/design.md). */
static void add_pair_lum(sums *restrict s, const float *restrict lp, tap ta, const float *restrict la, tap tb,
                         const float *restrict lb, const float *restrict lnw_a, const float *restrict lnw_b,
                         const float *restrict il) {
    const float *restrict na = ta.n, *restrict nb = tb.n;
    const float *restrict ra = ta.r, *restrict rb = tb.r;
    const float *restrict ga = ta.g, *restrict gb = tb.g;
    const float *restrict ba = ta.b, *restrict bb = tb.b;
    for (int i = 0; i < CHUNK; i++) {
        float da = fabsf(lp[i] - la[i]), db = fabsf(lp[i] - lb[i]);
        float ea = exp2_neg(lnw_a[i] - da * il[i]), eb = exp2_neg(lnw_b[i] - db * il[i]);
        float wa = ea * na[i], wb = eb * nb[i];
        s->a[i] += wa + wb;
        s->r[i] += wa * ra[i] + wb * rb[i];
        s->g[i] += wa * ga[i] + wb * gb[i];
        s->b[i] += wa * ba[i] + wb * bb[i];
        s->bb[i] += wa * ea + wb * eb;
    }
}

/* One à-trous pass over row y of the half grid, from the src planes into the others. Each tap
 * weighs h w_z w_n w_l n. The count after the pass is the effective count (sum a)^2 / sum b times
 * kappa: the sum alone would treat the taps as independent, but they share samples, and kappa is
 * how much less the open cascade's count really grows. Without it the count after 5 passes would
 * be ~100 times too high, and the late passes' luminance stops that much too tight
 * (docs/design.md). */
static void level_row(void *ctx, int y, int worker) {
    (void)worker;
    const job *j = ctx;
    const denoiser *d = j->d;
    const planes *pl = d->half[j->src], *to = d->half[!j->src];
    const geometry *g = &d->half_geo;
    const int s = j->step;
    for (int x0 = 0; x0 < d->half_width; x0 += CHUNK) {
        ptrdiff_t p = at(d, y, x0), off[12];
        float lnw[12][2][CHUNK];
        for (int k = 0; k < 12; k++) {
            int dx = PAIRS5[k][0] * s, dy = PAIRS5[k][1] * s;
            off[k] = (ptrdiff_t)dy * d->stride + dx;
            float log2h = log2f(B3[PAIRS5[k][0] + 2] * B3[PAIRS5[k][1] + 2]);
            pair_geometry(j, g, p, g, p + off[k], g, p - off[k], (float)dx, (float)dy, log2h, lnw[k][0], lnw[k][1]);
        }
        int tail = d->half_width - x0 < CHUNK ? d->half_width - x0 : CHUNK;
        for (int c = 0; c < j->comps; c++) {
            sums acc;
            float il[CHUNK];
            luminance_stop(j, pl[c].n + p, pl[c].l + p, d->half[1][c].s2 + p, j->inv_sqrt_unit, il);
            add_own(&acc, tap_at(&pl[c], p), B3[2] * B3[2], 1.0f);
            for (int k = 0; k < 12; k++)
                add_pair_lum(&acc, pl[c].l + p, tap_at(&pl[c], p + off[k]), pl[c].l + p + off[k],
                             tap_at(&pl[c], p - off[k]), pl[c].l + p - off[k], lnw[k][0], lnw[k][1], il);
            const planes *dst = &to[c];
            finish(&acc, dst->r + p, dst->g + p, dst->b + p, dst->l + p, dst->n + p, j->kappa / TAPS);
            for (int i = tail; i < CHUNK; i++) /* the run's tail past the image: no sample */
                dst->r[p + i] = dst->g[p + i] = dst->b[p + i] = dst->l[p + i] = dst->n[p + i] = 0.0f;
        }
    }
}

/* No pass: the input as it came in (holes 0). */
static void copy_row(void *ctx, int y, int worker) {
    (void)worker;
    const job *j = ctx;
    const denoiser *d = j->d;
    for (int c = 0; c < j->comps; c++) {
        for (int x = 0; x < d->width; x++) {
            const planes *pl = &d->full[x & 1][c];
            ptrdiff_t p = at(d, y, x >> 1);
            size_t o = (size_t)y * (size_t)d->width + (size_t)x;
            float *out = j->out->light[c] + 3 * o;
            out[0] = pl->r[p];
            out[1] = pl->g[p];
            out[2] = pl->b[p];
            if (j->out->count[c]) j->out->count[c][o] = pl->n[p] / COUNT_SCALE;
        }
    }
}

/* While the filter's rows run, results too small for a normal float are flushed to zero and such
 * inputs read as zero (x86's FTZ and DAZ, restored after each row: the pool's threads render too).
 * A weight of 2^-115 times a small count is one: it counts for nothing, and handled as a denormal
 * it costs a hundred times a normal float, which doubled the passes over a sparse image. */
static void row_task(void *ctx, int y, int worker) {
    job *j = ctx;
#if defined(__SSE__)
    unsigned csr = _mm_getcsr();
    _mm_setcsr(csr | 0x8040u);
    j->row(ctx, y, worker);
    _mm_setcsr(csr);
#else
    j->row(ctx, y, worker);
#endif
}

static void run_rows(threadpool *pool, task_fn fn, job *j, int rows) {
    j->row = fn;
    if (pool) {
        threadpool_run(pool, row_task, j, rows);
    } else {
        for (int y = 0; y < rows; y++) row_task(j, y, 0);
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
    j.count_cap =
        p->count_cap >= 1.0f && p->count_cap < COUNT_MAX ? p->count_cap : COUNT_MAX; /* below one sample: none */
    int levels = p->levels < 0 ? 0 : (p->levels > DENOISE_MAX_LEVELS ? DENOISE_MAX_LEVELS : p->levels);
    run_rows(pool, prep_row, &j, d->height);
    if (levels == 0) {
        run_rows(pool, copy_row, &j, d->height);
        return 0;
    }
    plan pl = make_plan(levels);
    double unit = 1.0 / (double)COUNT_SCALE; /* samples a scaled count of 1 stands for */
    j.kappa = pl.kappa_pool;
    j.inv_sqrt_unit = (float)(1.0 / sqrt(unit));
    run_rows(pool, denoise_pool_row, &j, d->half_height);
    run_rows(pool, denoise_variance_row, &j, d->half_height);
    double coarse = unit * 16.0; /* see finish */
    for (int i = 0; i < pl.coarse; i++) {
        j.step = 1 << i;
        j.src = i & 1;
        j.kappa = pl.kappa_coarse[i];
        j.inv_sqrt_unit = (float)(1.0 / sqrt(coarse));
        coarse *= (double)TAPS;
        run_rows(pool, level_row, &j, d->half_height);
    }
    j.coarse = pl.coarse & 1;
    j.kappa_fine = pl.kappa_fine;
    j.inv_sqrt_unit = (float)(1.0 / sqrt(unit));
    j.fine_inv_sqrt_unit = (float)(1.0 / sqrt(unit * (double)TAPS));
    j.fine_to_coarse = (float)(unit * (double)TAPS / coarse);
    j.kappa = pl.kappa_up;
    j.out_unit = (float)(coarse * 5.0);
    run_rows(pool, denoise_upsample_row, &j, d->height);
    return 0;
}
