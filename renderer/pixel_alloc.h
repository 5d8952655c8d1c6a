/* glint — how many samples of one part of a many-light frame each pixel takes (directions through a
 * sharp glossy lobe, direct-light samples). The variance sits in few pixels (a chrome sphere
 * reflecting a lit patch, the floor under the spot's hot patch): samples go where one sample's
 * light varied most in the pixel's earlier frames (docs/design.md, "Where the samples go"). */
#ifndef GLINT_PIXEL_ALLOC_H
#define GLINT_PIXEL_ALLOC_H
#include <stdint.h>

/* One pixel's record of single-direction contributions (luminance), Welford's running form. */
typedef struct {
    float n, mean, m2;
} pixel_record;

typedef struct {
    int pixels;
    pixel_record *rec;
    uint8_t *samples; /* this frame's samples per pixel */
} pixel_alloc;

int pixel_alloc_init(pixel_alloc *a, int pixels);
void pixel_alloc_free(pixel_alloc *a);
void pixel_alloc_reset(pixel_alloc *a);
/* Sets every pixel's samples for the next frame: `budget` on average over the pixels with a
 * record, in proportion to the standard deviation of one sample's light there, within [1, max];
 * the others take the budget. The frame's own samples never decide its allocation, so each frame
 * stays unbiased. */
void pixel_alloc_plan(pixel_alloc *a, int budget, int max, uint64_t frame, uint64_t seed);

/* A pixel's highlight state with --adapt (session.c): not yet probed (reset), whether it has met a
 * sharp highlight lobe, or dim: its highlights left to the virtual lights' paths. */
enum { HL_PIXEL_UNPROBED = 0, HL_PIXEL_BROAD, HL_PIXEL_SHARP, HL_PIXEL_DIM };
#define HL_PIXEL_BRIGHT 0x80 /* while judging: the pixel's highlights came to more than the dim share */
/* Marks dim the probed pixels none of whose neighbours within HL_DIM_RADIUS (itself included) is
 * marked HL_PIXEL_BRIGHT. Judged again (`again`), a dim pixel with a bright neighbour turns broad
 * and the others keep their state: a dim pixel's highlights come from the virtual lights' paths,
 * and a highlight its first frames missed shows there later. Clears the marks. */
void hl_judge_dim(uint8_t *state, int width, int height, int again);
/* Whether the pixels are judged after this many frames: at HL_DIM_FRAMES, then each time the
 * frames double. */
int hl_judge_due(long long frames);

/* A pixel's highlights, merged (m) and traced (t) at the same secondary hits, over the frames it
 * took the merge with --merge auto (sums of their luminances, of squares and of the difference
 * d = t - m), and whether it was judged to take the trace. */
typedef struct {
    float n, m, mm, d, dd, tt;
    int traced;
} hl_merge_record;
/* Turns to the trace the pixels with a record where, summed over the pixels within HL_DIM_RADIUS,
 * the merge's squared bias (d's squared mean less its variance) exceeds what the trace adds to the
 * variance of the mean over the frames so far: the merge's error against the trace's. A pixel that
 * took the trace keeps it. Judged when hl_judge_due. Returns the pixels taking the trace, or -1 when
 * out of memory (nothing judged). */
int hl_judge_trace(hl_merge_record *rec, int width, int height);

static inline void hl_merge_record_add(hl_merge_record *r, float m, float t) {
    float d = t - m;
    r->n += 1.0f, r->m += m, r->mm += m * m, r->d += d, r->dd += d * d, r->tt += t * t;
}

static inline void pixel_record_add(pixel_record *r, float v) {
    r->n += 1.0f;
    float d = v - r->mean;
    r->mean += d / r->n;
    r->m2 += d * (v - r->mean);
}
#endif
