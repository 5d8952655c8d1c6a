/* The display's own samples, where the image shown errs most (display_plan_extra,
 * display_take_extra; docs/design.md, "Extra samples where the image errs most"). */
#include <math.h>
#include <string.h>

#include "display_parts.h"

/* A ratio's bin: a float's exponent and its mantissa's top three bits. */
#define EXTRA_FIRST ((127 + EXTRA_LOW) * 8) /* the first bin's bits >> 20 */
/* Samples a request at most: a pixel's many go as several requests, shared out over the threads. */
#define EXTRA_CHUNK 16
/* A hole's samples as the plan reckons them: its first sample is worth two of a pixel with one. */
#define HOLE_COUNT 0.5f
/* Below this many samples a pixel's own spread may miss what its few samples did not hit (a speck
 * in a mirror that one neighbour's sample found): it takes its neighbours' on the same surface,
 * their mean where that is more. */
#define SPREAD_YOUNG 4.0f

static int extra_bin(float ratio) {
    uint32_t u;
    memcpy(&u, &ratio, sizeof u); /* ratio > 0 */
    int b = (int)(u >> 20) - EXTRA_FIRST;
    return b < 0 ? 0 : b >= EXTRA_BINS ? EXTRA_BINS - 1 : b;
}

/* The least ratio of bin b. */
static double extra_edge(int b) {
    uint32_t u = (uint32_t)(b + EXTRA_FIRST) << 20;
    float f;
    memcpy(&f, &u, sizeof f);
    return (double)f;
}

static float plan_count(const pixel_history *p) {
    float n = p->c[COMP_DIRECT].count;
    return n >= 1.0f ? n : HOLE_COUNT;
}

/* Pixel i's one-sample spread as shown: the square root of its components' variances summed,
 * times its albedo's luminance; from a single sample, that sample's own value (a Monte Carlo
 * sample is typically as spread as it is bright). -1 where it has no sample (a hole). */
static float pixel_spread(const display *d, size_t i) {
    const pixel_history *p = &d->h[d->cur][i];
    float a = luminance3(get3(d->g[d->cur].albedo, i)), s2 = 0.0f;
    if (!(p->c[COMP_DIRECT].count >= 1.0f)) return -1.0f;
    for (int c = 0; c < COMP_COUNT; c++) {
        if (!d->active[c]) continue;
        float v = shown_spread(p, c, a);
        if (v < 0.0f) {
            float l = luminance3(v3(p->c[c].mean[0], p->c[c].mean[1], p->c[c].mean[2])) * a;
            v = l * l;
        }
        s2 += v;
    }
    float s = sqrtf(s2);
    return isfinite(s) ? s : 0.0f;
}

/* Whether pixel i's light is mostly its glossy lobe's and the view has turned at it since its
 * samples were taken by more than the lobe is wide: what they say of its light is mostly stale (a
 * light's speck in a mirror has moved), and the plan takes it as it takes a hole. */
static int turned(const display *d, size_t i) {
    const gbuffer *g = &d->g[d->cur];
    float a = fmaxf(g->alpha[i], 1e-3f), t = d->h[d->cur][i].turn;
    return t > a && mostly_glossy(g, i);
}

/* What the plan reads of each pixel's history, once: its own spread into d->spread_own (0: none to
 * plan for, -1: a hole to plan for), the samples it reckons (d->plan_n) and whether it plans for it
 * as a hole or a young pixel (d->plan_kind), a row a task; the spreads' sum and count per worker.
 * The passes after it read these, not the history: a pixel's history is a cache line, and reading
 * it again in each was most of the plan's time. */
enum { PLAN_HOLE = 1, PLAN_YOUNG = 2 };
static void spread_row(void *ctx, int y, int worker) {
    display *d = ctx;
    const gbuffer *g = &d->g[d->cur];
    const pixel_history *h = d->h[d->cur];
    extra_histogram *k = &d->extra_hist[worker];
    for (size_t i = (size_t)y * (size_t)d->width; i < (size_t)(y + 1) * (size_t)d->width; i++) {
        float own = g->material[i] < 0 ? 0.0f : pixel_spread(d, i);
        d->spread_own[i] = own;
        if (own > 0.0f) k->spread_sum += (double)own, k->spread_n++;
        int hole = own < 0.0f || turned(d, i);
        int young = !hole && g->material[i] >= 0 && !(h[i].c[COMP_DIRECT].count >= SPREAD_YOUNG);
        d->plan_kind[i] = (uint8_t)((hole ? PLAN_HOLE : 0) | (young ? PLAN_YOUNG : 0));
        d->plan_n[i] = plan_count(&h[i]);
    }
}

/* The spread the plan goes by, into d->spread. A hole (no sample yet, not the sky) takes the largest
 * of its neighbours' own: the filter fills it from them, so it is as hard as the hardest of them (a
 * hole beside a bright speck in a mirror is filled with the speck); one among holes only, the
 * average pixel's (d->spread_mean): nothing is known of it, and its first sample says where the
 * rest should go (a chrome sphere after a jump, all holes, whose streak waited for the film). A
 * young pixel (under SPREAD_YOUNG samples) takes the mean of its own and its neighbours' on the
 * same surface where that is more than its own: a speck's neighbours, whose few samples missed
 * it, may be as hard as it is (the mean, not the largest: in a young image every pixel has some
 * bright neighbour, and the largest spreads the budget over all of them). Then each pixel's ratio
 * into its worker's histogram. */

/* One neighbour of a pixel (hole_window): its own spread o into the largest of all, and where it
 * lies on the pixel's surface (mat == me) into the sum and count of those. */
static inline void hole_tap(float o, int32_t mat, int32_t me, float *most, float *sum, float *m) {
    *most = o > *most ? o : *most;
    float mine = mat == me ? o : -1.0f; /* another surface's: none */
    *sum += mine >= 0.0f ? mine : 0.0f;
    *m += mine >= 0.0f ? 1.0f : 0.0f;
}

/* A chunk's pixels' spreads as a hole and as a young pixel (hole_row), from the rows of own spreads
 * and materials about it (window_row). Not inlined: in hole_row's loops gcc does not vectorise it. */
__attribute__((noinline)) static void hole_window(const float *const own[3], const int32_t *const mat[3],
                                                  float spread_mean, float *restrict as_hole,
                                                  float *restrict as_young) {
    const float *restrict o0 = own[0], *restrict o1 = own[1], *restrict o2 = own[2];
    const int32_t *restrict m0 = mat[0], *restrict m1 = mat[1], *restrict m2 = mat[2];
    for (int x = 0; x < WINDOW_CHUNK; x++) {
        float most = 0.0f, sum = 0.0f, m = 0.0f;
        int32_t me = m1[x + 1];
        hole_tap(o0[x], m0[x], me, &most, &sum, &m);
        hole_tap(o0[x + 1], m0[x + 1], me, &most, &sum, &m);
        hole_tap(o0[x + 2], m0[x + 2], me, &most, &sum, &m);
        hole_tap(o1[x], m1[x], me, &most, &sum, &m);
        hole_tap(o1[x + 1], me, me, &most, &sum, &m);
        hole_tap(o1[x + 2], m1[x + 2], me, &most, &sum, &m);
        hole_tap(o2[x], m2[x], me, &most, &sum, &m);
        hole_tap(o2[x + 1], m2[x + 1], me, &most, &sum, &m);
        hole_tap(o2[x + 2], m2[x + 2], me, &most, &sum, &m);
        float s = o1[x + 1] > 0.0f ? o1[x + 1] : 0.0f;
        float mean = sum / (m > 1.0f ? m : 1.0f); /* m >= 1 for a young pixel: itself */
        float largest = most > 0.0f ? most : spread_mean;
        as_young[x] = mean > s ? mean : s;
        as_hole[x] = largest > s ? largest : s;
    }
}

static void hole_row(void *ctx, int y, int worker) {
    display *d = ctx;
    int w = d->width;
    extra_histogram *k = &d->extra_hist[worker];
    for (int x0 = 0; x0 < w; x0 += WINDOW_CHUNK) {
        float buf_own[3][WINDOW_SPAN];
        int32_t buf_mat[3][WINDOW_SPAN];
        const float *own[3];
        const int32_t *mat[3];
        for (int r = 0; r < 3; r++) { /* outside the image: a hole's spread (-1), which neither kind takes */
            own[r] = window_row(buf_own[r], d->spread_own, w, d->height, x0, y - 1 + r, -1.0f);
            mat[r] = window_row_int(buf_mat[r], d->g[d->cur].material, w, d->height, x0, y - 1 + r, -1);
        }
        /* a hole takes the largest of its neighbours' own spreads (holes' -1 and the sky's 0 add
         * nothing to it), a young pixel the mean over those on its surface */
        float as_hole[WINDOW_CHUNK], as_young[WINDOW_CHUNK];
        hole_window(own, mat, d->spread_mean, as_hole, as_young);
        for (int x = 0; x < WINDOW_CHUNK && x0 + x < w; x++) {
            size_t i = (size_t)y * (size_t)w + (size_t)(x0 + x);
            float s = own[1][x + 1] > 0.0f ? own[1][x + 1] : 0.0f;
            s = d->plan_kind[i] & PLAN_HOLE ? as_hole[x] : d->plan_kind[i] & PLAN_YOUNG ? as_young[x] : s;
            d->spread[i] = s;
            if (!(s > 0.0f)) continue;
            float pn = d->plan_n[i];
            int b = extra_bin(s / pn);
            k->count[b]++, k->s[b] += (double)s, k->n[b] += (double)pn;
        }
    }
}

/* The samples pixel i wants at multiplier mu: as many more as bring its count to s mu. */
static double extra_wanted(const display *d, size_t i, double mu) {
    double k = (double)d->spread[i] * mu - (double)d->plan_n[i];
    return k > 0.0 ? k : 0.0;
}

/* What the m pixels want at multiplier mu, in all. */
static double extra_total(const display *d, const int *pixels, int m, double mu) {
    double want = 0.0;
    for (int k = 0; k < m; k++) want += extra_wanted(d, (size_t)pixels[k], mu);
    return want;
}

int display_plan_extra(display *d, int budget, extra_request *req, int max) {
    if (budget <= 0 || max <= 0) return 0;
    const gbuffer *g = &d->g[d->cur];
    size_t np = (size_t)d->width * (size_t)d->height;
    int workers = threadpool_size(d->pool);
    for (int k = 0; k < workers; k++) d->extra_hist[k].spread_sum = 0.0, d->extra_hist[k].spread_n = 0;
    threadpool_run(d->pool, spread_row, d, d->height);
    double spread_sum = 0.0;
    long long spread_n = 0;
    for (int k = 0; k < workers; k++) {
        spread_sum += d->extra_hist[k].spread_sum, spread_n += d->extra_hist[k].spread_n;
        memset(d->extra_hist[k].count, 0, sizeof d->extra_hist[k].count);
        memset(d->extra_hist[k].s, 0, sizeof d->extra_hist[k].s);
        memset(d->extra_hist[k].n, 0, sizeof d->extra_hist[k].n);
    }
    d->spread_mean = spread_n ? (float)(spread_sum / (double)spread_n) : 0.0f;
    threadpool_run(d->pool, hole_row, d, d->height);
    for (int k = 1; k < workers; k++)
        for (int b = 0; b < EXTRA_BINS; b++) {
            d->extra_hist[0].count[b] += d->extra_hist[k].count[b];
            d->extra_hist[0].s[b] += d->extra_hist[k].s[b];
            d->extra_hist[0].n[b] += d->extra_hist[k].n[b];
        }
    const int *count = d->extra_hist[0].count;
    const double *sum_s = d->extra_hist[0].s, *sum_n = d->extra_hist[0].n;
    /* the lowest bin whose edge, as 1 / mu, has the pixels above it want the budget, or as low as
     * leaves at most max of them */
    int b = EXTRA_BINS - 1, m = 0;
    double s_above = 0.0, n_above = 0.0;
    for (; b > 0; b--) {
        if (m + count[b] > max) {
            b++;
            break;
        }
        m += count[b], s_above += sum_s[b], n_above += sum_n[b];
        double mu = 1.0 / extra_edge(b - 1); /* where the next bin's pixels begin to want samples */
        if (s_above * mu - n_above >= (double)budget) break;
    }
    /* those pixels, in raster order, and mu where they want the budget: hi doubled until they do,
     * then halved to it */
    m = 0;
    int *cand = d->extra_pixels;
    for (size_t i = 0; i < np && m < max; i++)
        if (d->spread[i] > 0.0f && extra_bin(d->spread[i] / d->plan_n[i]) >= b) cand[m++] = (int)i;
    double lo = 0.0, hi = 2.0 / extra_edge(b);
    for (int it = 0; it < 64 && extra_total(d, cand, m, hi) < (double)budget; it++) lo = hi, hi *= 2.0;
    for (int it = 0; it < 40; it++) {
        double mu = 0.5 * (lo + hi);
        *(extra_total(d, cand, m, mu) > (double)budget ? &hi : &lo) = mu;
    }
    static const float W[3] = {0.2126f, 0.7152f, 0.0722f}; /* luminance3's */
    int out = 0;
    for (int k = 0; k < m && out < max; k++) {
        size_t i = (size_t)cand[k];
        double want = extra_wanted(d, i, lo) + 0.5;
        long long left = want < (double)budget ? (long long)want : budget;
        for (; left > 0 && out < max; left -= EXTRA_CHUNK) {
            extra_request *q = &req[out++];
            q->pixel = (int)i;
            q->samples = left < EXTRA_CHUNK ? (int)left : EXTRA_CHUNK;
            for (int e = 0; e < 3; e++) q->weight[e] = W[e] / g->albedo[3 * i + (size_t)e];
        }
    }
    return out;
}

void display_take_extra(display *d, const extra_request *req, int n) {
    const gbuffer *g = &d->g[d->cur];
    pixel_history *h = d->h[d->cur];
    size_t np = (size_t)d->width * (size_t)d->height;
    for (int r = 0; r < n; r++) {
        const extra_request *q = &req[r];
        if (q->taken <= 0 || q->pixel < 0 || (size_t)q->pixel >= np) continue;
        size_t i = (size_t)q->pixel;
        float k = (float)q->taken, mean_sq[COMP_COUNT];
        vec3 e[COMP_COUNT];
        for (int c = 0; c < COMP_COUNT; c++) {
            e[c] = div3(scale3(v3(q->sum[c][0], q->sum[c][1], q->sum[c][2]), 1.0f / k), get3(g->albedo, i));
            mean_sq[c] = q->sumsq[c] / k;
        }
        if (d->judging) gather_evidence(d, i, e, k); /* a light change's tile waits for them too */
        history_add(d, &h[i], e, mean_sq, k);
        d->st.extra += (uint64_t)q->taken;
    }
}
