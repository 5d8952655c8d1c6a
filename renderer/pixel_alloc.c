#include "pixel_alloc.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "params.h"
#include "rng.h"

/* Fewer single-direction samples than this: the pixel keeps the budget (its variance is not known). */
#define PIXEL_MIN_RECORD 16.0f

int pixel_alloc_init(pixel_alloc *a, int pixels) {
    a->pixels = pixels;
    a->rec = calloc((size_t)pixels, sizeof *a->rec);
    a->samples = calloc((size_t)pixels, 1);
    return a->rec && a->samples ? 0 : -1;
}

void pixel_alloc_free(pixel_alloc *a) {
    free(a->rec);
    free(a->samples);
    memset(a, 0, sizeof *a);
}

void pixel_alloc_reset(pixel_alloc *a) { memset(a->rec, 0, (size_t)a->pixels * sizeof *a->rec); }

/* The spread of one direction's light at the pixel. */
static double record_sd(const pixel_record *r) { return sqrt(fmax((double)r->m2 / ((double)r->n - 1.0), 0.0)); }

void pixel_alloc_plan(pixel_alloc *a, int budget, int max, uint64_t frame, uint64_t seed) {
    double sum = 0.0;
    int known = 0;
    for (int i = 0; i < a->pixels; i++) {
        const pixel_record *r = &a->rec[i];
        if (r->n < PIXEL_MIN_RECORD) continue;
        sum += record_sd(r);
        known++;
    }
    double mean = known ? sum / known : 0.0;
    for (int i = 0; i < a->pixels; i++) {
        const pixel_record *r = &a->rec[i];
        if (r->n < PIXEL_MIN_RECORD || !(mean > 0.0)) {
            a->samples[i] = (uint8_t)budget;
            continue;
        }
        double want = budget * record_sd(r) / mean;
        rng_state rng = rng_for((uint64_t)i, frame, seed ^ 0x676c6f7373ULL);
        int n = (int)floor(want + (double)rng_float(&rng)); /* stochastic rounding: the mean is kept */
        a->samples[i] = (uint8_t)(n < 1 ? 1 : n > max ? max : n);
    }
}

void hl_judge_dim(uint8_t *state, int width, int height, int again) {
    for (int y = 0; y < height; y++)
        for (int x = 0; x < width; x++) {
            uint8_t *st = &state[y * width + x];
            uint8_t was = *st & (uint8_t)~HL_PIXEL_BRIGHT;
            if (was == HL_PIXEL_UNPROBED || (again && was != HL_PIXEL_DIM)) continue;
            int dim = 1;
            for (int qy = y - HL_DIM_RADIUS; dim && qy <= y + HL_DIM_RADIUS; qy++)
                for (int qx = x - HL_DIM_RADIUS; dim && qx <= x + HL_DIM_RADIUS; qx++)
                    if (qy >= 0 && qy < height && qx >= 0 && qx < width)
                        dim = !(state[qy * width + qx] & HL_PIXEL_BRIGHT);
            /* a pixel turned dim was not bright itself, so no neighbour still to judge loses a mark */
            if (dim)
                *st = HL_PIXEL_DIM;
            else if (again)
                *st = (uint8_t)(HL_PIXEL_BROAD | (*st & HL_PIXEL_BRIGHT));
        }
    for (int i = 0; i < width * height; i++) state[i] &= (uint8_t)~HL_PIXEL_BRIGHT;
}

int hl_judge_due(long long frames) {
    while (frames > HL_DIM_FRAMES && frames % 2 == 0) frames /= 2;
    return frames == HL_DIM_FRAMES;
}

/* The merge's squared bias less the trace's added variance of the mean, at one pixel (0 without two
 * frames): positive where the trace would have erred less over the same frames. */
static double trace_gain(const hl_merge_record *r) {
    double n = r->n;
    if (n < 2.0) return 0.0;
    double md = (double)r->d / n, mm = (double)r->m / n, mt = mm + md;
    double var_d = ((double)r->dd - n * md * md) / (n - 1.0);
    double var_m = ((double)r->mm - n * mm * mm) / (n - 1.0);
    double var_t = ((double)r->tt - n * mt * mt) / (n - 1.0);
    return md * md - var_d / n - (var_t - var_m) / n;
}

int hl_judge_trace(hl_merge_record *rec, int width, int height) {
    double *gain = malloc((size_t)width * (size_t)height * sizeof *gain);
    if (!gain) return -1;
    for (int i = 0; i < width * height; i++) gain[i] = trace_gain(&rec[i]);
    for (int y = 0; y < height; y++)
        for (int x = 0; x < width; x++) {
            hl_merge_record *r = &rec[y * width + x];
            if (r->traced || r->n < 2.0f) continue;
            double sum = 0.0;
            for (int qy = y - HL_DIM_RADIUS; qy <= y + HL_DIM_RADIUS; qy++)
                for (int qx = x - HL_DIM_RADIUS; qx <= x + HL_DIM_RADIUS; qx++)
                    if (qy >= 0 && qy < height && qx >= 0 && qx < width) sum += gain[qy * width + qx];
            r->traced = sum > 0.0;
        }
    free(gain);
    int traced = 0;
    for (int i = 0; i < width * height; i++) traced += rec[i].traced;
    return traced;
}
