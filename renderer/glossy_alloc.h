/* glint — how many directions each pixel traces through a sharp glossy lobe at its camera hit.
 * The traced part's variance sits in few pixels (a chrome sphere reflecting a lit patch, the
 * floor under the spot's hot patch): directions go where one direction's contribution varies
 * most, from the pixel's earlier frames (docs/design.md, "Where the traced directions go"). */
#ifndef GLINT_GLOSSY_ALLOC_H
#define GLINT_GLOSSY_ALLOC_H
#include <stdint.h>

/* One pixel's record of single-direction contributions (luminance), Welford's running form. */
typedef struct {
    float n, mean, m2;
} glossy_record;

typedef struct {
    int pixels;
    glossy_record *rec;
    uint8_t *split; /* this frame's directions per pixel */
} glossy_alloc;

int glossy_alloc_init(glossy_alloc *a, int pixels);
void glossy_alloc_free(glossy_alloc *a);
void glossy_alloc_reset(glossy_alloc *a);
/* Sets every pixel's directions for the next frame: mean `budget` over the pixels that have a
 * record, in proportion to their contributions' standard deviations, within [1, max]. The
 * frame's own samples never decide its allocation, so each frame stays unbiased. */
void glossy_alloc_plan(glossy_alloc *a, int budget, int max, uint64_t frame, uint64_t seed);
static inline void glossy_record_add(glossy_record *r, float v) {
    r->n += 1.0f;
    float d = v - r->mean;
    r->mean += d / r->n;
    r->m2 += d * (v - r->mean);
}
#endif
