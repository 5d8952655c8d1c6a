/* glint — the display's parts (docs/design.md, "The display while things move"): what display.c
 * (history, reprojection, light changes, the image shown) and display_extra.c (the display's own
 * samples) share. display.h is the interface; nothing else includes this. */
#ifndef GLINT_DISPLAY_PARTS_H
#define GLINT_DISPLAY_PARTS_H

#include <string.h>

#include "denoise.h"
#include "display.h"
#include "threadpool.h"

/* One pixel's history, per film component: the mean of its samples divided by the pixel's albedo,
 * how many samples it stands for (fractional once part of it was let go), and the mean of their
 * squared luminance (the spread the filter needs); and how far the view has turned at the point
 * since its samples were taken (radians, their mean). One cache line: reprojection reads four. */
typedef struct {
    struct {
        float mean[3], count, m2;
    } c[COMP_COUNT];
    float turn;
} pixel_history;
_Static_assert(sizeof(pixel_history) == 64, "a pixel's history is one cache line");

/* History a camera move carries over is capped at this many samples: each reprojection resamples
 * (blurs) it a little, and a cap lets new samples take over at a steady pace while moving. */
#define DISPLAY_MAX_CARRIED 64.0f
/* A component whose history holds less than this share of its light after a camera move is
 * kept only as a last resort, DISPLAY_LAST_RESORT samples: any new sample within the filter's reach
 * outweighs a whole neighbourhood of it (at a low count that still counted, the filter, whose
 * weights are relative, showed a stale reflection over a whole panel as it was), and where none is
 * it is still shown, not a black hole. */
#define DISPLAY_MIN_HELD 0.5f
#define DISPLAY_LAST_RESORT 1e-6f
/* A light change sets the history aside (stale) until new samples show, tile by tile, whether
 * the light there changed: a tile of TILE_PX x TILE_PX pixels is judged once it has
 * JUDGE_MIN_SAMPLES new samples beside stale history (docs/design.md, "The display while things move"). Until then
 * stale history is a last resort where a pixel has no new sample (DISPLAY_LAST_RESORT samples): it
 * fills holes that no new sample's light reaches. */
#define TILE_PX 16
#define JUDGE_MIN_SAMPLES 16
#define JUDGE_MAX_SAMPLES 64
/* ...but not where a pixel's light is mostly its glossy lobe's (mostly_glossy): a light's
 * reflection moves with the light. */
#define STALE_GLOSSY 0.5f
/* Reprojection's tests: a surface point's old pixel is the same point if its normal is within
 * this cosine and it lies within this many pixel footprints of the old point's plane. */
#define REPROJECT_MIN_COS 0.9f
#define REPROJECT_PLANE_PIXELS 2.0f
/* The filter's levels: three reach about 15 pixels, enough where most pixels have samples (more blur
 * the image for no less noise); where many have none yet (a new view, the sparse updates while the
 * camera moves) the levels reach as far as the holes are wide. */
#define DENOISE_LEVELS 3
/* display_plan_extra's histogram of the pixels' s / n (the spread of one sample over the samples)
 * over EXTRA_BINS bins, eight an octave from 2^EXTRA_LOW, per thread. */
#define EXTRA_BINS 1024
#define EXTRA_LOW (-64)
typedef struct extra_histogram {
    int count[EXTRA_BINS];
    double s[EXTRA_BINS], n[EXTRA_BINS];
    double spread_sum; /* ...and the pixels' spreads summed, and counted */
    long long spread_n;
} extra_histogram;
/* The filter counts no pixel as more than COUNT_CAP_MEAN times the average pixel's samples, nor
 * fewer than COUNT_CAP_MIN: a pixel that took many extra samples (display_plan_extra) is sure of
 * its own light, not of its neighbours'. */
#define COUNT_CAP_MEAN 4.0f
#define COUNT_CAP_MIN 4.0f

/* A tile's evidence since the last light change: new samples' luminance (every component, divided
 * by the albedo) less the stale history's at the same pixels, its variance, the stale total. */
enum { TILE_UNKNOWN = 0, TILE_SAME, TILE_CHANGED };
typedef struct {
    double diff, var, base;
    int n, state;
} light_tile;

struct display {
    int width, height;
    threadpool *pool;
    gbuffer g[2];        /* g[cur] the view shown, the other the one before */
    pixel_history *h[2]; /* h[cur] the view shown, the other the one before */
    int cur;
    int have_view;
    sample_sink sink;
    /* resolve's scratch: the filter's input per component (demodulated mean, samples, one sample's
     * luminance variance) and its output */
    float *light[COMP_COUNT], *count[COMP_COUNT], *variance[COMP_COUNT], *out[COMP_COUNT];
    float *out_count[COMP_COUNT]; /* the samples behind the filter's value... */
    float *gap[COMP_COUNT];       /* ...its squared gap to the pixel's own mean (gap_row)... */
    denoiser *dn;
    int active[COMP_COUNT]; /* a component had a sample other than zero since the last restart */
    /* after a light change: the history before it, and per tile what new samples say of it */
    pixel_history *stale;
    int judging;
    uint8_t *relit; /* per pixel: its stale direct light was moved by the punctual lights' change */
    light *seen;    /* the scene's punctual lights as the display last saw them... */
    int num_seen, cap_seen;
    uint64_t seen_rest; /* ...and a fingerprint of its other light (display_light.c) */
    int tiles_x, tiles_y;
    light_tile *tiles;
    uint8_t *need;               /* per packet (display_packet_need)... */
    float *need_gain;            /* ...and its scratch */
    float *spread, *spread_own;  /* per pixel, display_plan_extra's scratch: spreads... */
    float *plan_n;               /* ...the samples it reckons (plan_count)... */
    uint8_t *plan_kind;          /* ...whether a hole or young (PLAN_HOLE, PLAN_YOUNG)... */
    int *extra_pixels;           /* ...the pixels it plans for... */
    extra_histogram *extra_hist; /* ...a histogram per thread... */
    float spread_mean;           /* ...and the average pixel's spread */
    display_stats st;
};

/* Light changes (display_light.c): the punctual lights that changed since the display last saw
 * the scene, as they were (was) and are (now), how many (up to RELIGHT_MAX; -1 where more did, or
 * other light changed too); the history set aside and judged from new samples, the direct light
 * relit by that change (begin_judging), the judgement's evidence and verdicts, its end when the
 * camera moves first; the lights the next change is measured against (rest_unchanged: their
 * fingerprint is known to be the one kept, changed_punctual having found so, not taken again). */
#define RELIGHT_MAX 8
int changed_punctual(const display *d, const scene *s, light *was, light *now);
void begin_judging(display *d, const scene *s, const light *was, const light *now, int changed);
void end_judging(display *d, pixel_history *h);
void gather_evidence(display *d, size_t i, const vec3 *e, float k_samples);
void judge_tiles(display *d);
void display_lights_seen(display *d, const scene *s, int rest_unchanged);

/* The light-change tile of pixel i. */
static inline int tile_of(const display *d, size_t i) {
    int x = (int)(i % (size_t)d->width), y = (int)(i / (size_t)d->width);
    return (y / TILE_PX) * d->tiles_x + x / TILE_PX;
}

/* Whether pixel i's light is mostly its glossy lobe's (gbuffer_glossy_share over STALE_GLOSSY): its
 * light moves with a moved light, and over its surface as the view turns. */
static inline int mostly_glossy(const gbuffer *g, size_t i) {
    return gbuffer_glossy_share(g->gloss[i], g->alpha[i]) > STALE_GLOSSY;
}

static inline vec3 get3(const float *a, size_t i) { return v3(a[3 * i], a[3 * i + 1], a[3 * i + 2]); }

/* k samples more into history p, each component's their mean e[c] (over the albedo) and the mean
 * of their squared luminance q[c] (the film's samples one at a time, the display's own in
 * batches): a running mean, and the view's turn since they were taken 0. */
static inline void history_add(display *d, pixel_history *p, const vec3 *e, const float *q, float k) {
    float old = p->c[COMP_DIRECT].count;
    p->turn *= old / (old + k);
    for (int c = 0; c < COMP_COUNT; c++) {
        d->active[c] |= !is_black3(e[c]);
        float t = p->c[c].count + k, *m = p->c[c].mean;
        m[0] += (e[c].x - m[0]) * k / t;
        m[1] += (e[c].y - m[1]) * k / t;
        m[2] += (e[c].z - m[2]) * k / t;
        p->c[c].m2 += (q[c] - p->c[c].m2) * k / t;
        p->c[c].count = t;
    }
}

/* Component c of b's samples added to a's, counted at most cap. */
static inline void history_merge_one(pixel_history *a, const pixel_history *b, int c, float cap) {
    float nb = fminf(b->c[c].count, cap), na = a->c[c].count, n = na + nb;
    if (!(nb > 0.0f)) return;
    for (int e = 0; e < 3; e++) a->c[c].mean[e] = (na * a->c[c].mean[e] + nb * b->c[c].mean[e]) / n;
    a->c[c].m2 = (na * a->c[c].m2 + nb * b->c[c].m2) / n;
    a->c[c].count = n;
}

/* One sample's variance from n samples' moments (their mean's luminance l, the mean of their squared
 * luminance m2): the moments give the population's, n / (n - 1) of it is unbiased; 0 below two. */
static inline float sample_variance(float m2, float l, float n) {
    return n > 1.0f ? fmaxf(m2 - l * l, 0.0f) * n / (n - 1.0f) : 0.0f;
}

/* Component c's one-sample variance in history p as shown, times a^2 (a the albedo's luminance);
 * -1 where it has fewer than two samples (its spread unknown). */
static inline float shown_spread(const pixel_history *p, int c, float a) {
    float n = p->c[c].count;
    if (!(n >= 2.0f)) return -1.0f;
    float l = luminance3(v3(p->c[c].mean[0], p->c[c].mean[1], p->c[c].mean[2]));
    return sample_variance(p->c[c].m2, l, n) * a * a;
}

/* The 3x3 neighbourhood passes (the plan's holes, the image shown's mix) take a row WINDOW_CHUNK
 * pixels at a time, a loop count gcc vectorises at -O2 (vecmath.h), each pixel with nine
 * neighbours and the loop with no branch: a chunk reads pixels x0 - 1 .. x0 + WINDOW_CHUNK of rows
 * y - 1 .. y + 1 where they lie in the image, and a copy padded with `pad` (which the pass must not
 * take) where they pass its edge. */
#define WINDOW_CHUNK 64
#define WINDOW_SPAN (WINDOW_CHUNK + 2)
static inline void window_row_copy(void *out, const void *a, int w, int h, int x0, int y, const void *pad) {
    char *o = out;
    int from = x0 - 1, skip = from < 0 ? -from : 0;
    int have = y >= 0 && y < h ? (w - from < WINDOW_SPAN ? w - from : WINDOW_SPAN) - skip : 0;
    for (int x = 0; x < WINDOW_SPAN; x++) memcpy(o + 4 * x, pad, 4);
    if (have > 0)
        memcpy(o + 4 * skip, (const char *)a + 4 * ((size_t)y * (size_t)w + (size_t)(from + skip)), 4 * (size_t)have);
}
static inline int window_inside(int w, int h, int x0, int y) {
    return x0 >= 1 && x0 + WINDOW_CHUNK < w && y >= 0 && y < h;
}
/* Row y of plane a from pixel x0 - 1, in the plane or in buf. */
static inline const float *window_row(float buf[WINDOW_SPAN], const float *a, int w, int h, int x0, int y, float pad) {
    if (window_inside(w, h, x0, y)) return a + (size_t)y * (size_t)w + (size_t)(x0 - 1);
    window_row_copy(buf, a, w, h, x0, y, &pad);
    return buf;
}
static inline const int32_t *window_row_int(int32_t buf[WINDOW_SPAN], const int32_t *a, int w, int h, int x0, int y,
                                            int32_t pad) {
    if (window_inside(w, h, x0, y)) return a + (size_t)y * (size_t)w + (size_t)(x0 - 1);
    window_row_copy(buf, a, w, h, x0, y, &pad);
    return buf;
}

#endif
