/* --method auto: which estimator each tile's samples take, path tracing or the virtual lights,
 * from what each one's samples measured there before the frame: the spread of one sample's light
 * and the work it took (docs/design.md, "Choosing the estimator"). Renderer code: the session owns
 * one, probes and measures for it and asks it per pixel; nothing here traces a ray. */
#ifndef GLINT_CHOICE_H
#define GLINT_CHOICE_H

#include <stdint.h>

#define CHOICE_TILE 16         /* pixels a side of a tile that chooses as one */
#define CHOICE_PROBE_STEP 4    /* a new accumulation's probe: one pixel in each 4x4 block ... */
#define CHOICE_PROBE_SAMPLES 4 /* ... takes this many samples of each estimator */
#define CHOICE_MEASURE_STEP 8  /* a frame measures the other estimator at one pixel in 8x8 */
#define CHOICE_MAX_PATHS 8     /* path-traced samples at most a pixel a frame */

/* The estimators a pixel's sample may take. */
enum { EST_PT = 0, EST_VL, EST_COUNT };

/* What a pixel's sample takes in a frame. */
typedef enum {
    CHOICE_VL = 0, /* the virtual lights */
    CHOICE_PT,     /* path tracing, choice.paths[tile] paths, their mean */
} choice_mode;

/* One estimator's samples at a pixel: how many, the mean of their luminance and the sum of their
 * squared deviations from it (Welford's), and the work they took (choice_work). */
typedef struct {
    float n, mean, m2, work;
} est_moments;

/* A pixel's record: each estimator's samples, the probe's, the film's and those a frame measures
 * beside the film's (choice_measures). */
typedef struct {
    est_moments e[EST_COUNT];
    float vl_weight;   /* the film's samples the virtual lights gave (the map) */
    uint32_t pt_taken; /* the path-traced samples' run: points taken so far */
} choice_record;

typedef struct tile_sums tile_sums; /* choice.c's */

typedef struct {
    int width, height, tiles_x, tiles_y;
    choice_record *rec; /* per pixel */
    uint8_t *mode;      /* per tile, choice_mode, this frame */
    uint8_t *paths;     /* per tile taking CHOICE_PT: its pixels' paths a frame */
    int vl_tiles;       /* tiles taking the virtual lights, at the last judgement */
    int judgements;     /* made since the last reset (the first after the probe) */
    tile_sums *sums;    /* per tile, a judgement's sums of its records */
} estimator_choice;

/* 0, or -1 out of memory (c left empty). */
int choice_init(estimator_choice *c, int width, int height);
void choice_free(estimator_choice *c);
/* Everything measured forgotten (a new view or new parameters): the next frame is a new
 * accumulation's first, probed before it. */
void choice_reset(estimator_choice *c);
/* Every tile judged by what its pixels measured so far: the probe's samples and the frames'. */
void choice_judge(estimator_choice *c);
/* Whether the frame after `frames` whole frames of an accumulation begins with a judgement: the
 * first (after the probe), then at each power of two. What came before the frame decides: its
 * samples stay unbiased where both estimators are. */
static inline int choice_judge_due(long long frames) { return frames >= 0 && (frames & (frames - 1)) == 0; }

/* Whether the probe samples a pixel: one in each CHOICE_PROBE_STEP block, at a place of its own
 * (a regular one would line up with a scene's regular features). */
static inline int choice_probe_pixel(const estimator_choice *c, int pixel) {
    unsigned x = (unsigned)(pixel % c->width), y = (unsigned)(pixel / c->width);
    unsigned h = (x / CHOICE_PROBE_STEP) * 0x9e37u + (y / CHOICE_PROBE_STEP) * 0x85ebu;
    h ^= h >> 7;
    return x % CHOICE_PROBE_STEP == (h & 3u) && y % CHOICE_PROBE_STEP == (h >> 2 & 3u);
}
/* Whether frame `frame` of an accumulation also measures, at a pixel, the estimator its tile does
 * not take: one pixel in each CHOICE_MEASURE_STEP block a frame, each in turn, so that a tile's
 * judgement of the other one keeps learning (a few percent of a frame's work). */
static inline int choice_measures(const estimator_choice *c, int pixel, long long frame) {
    unsigned x = (unsigned)(pixel % c->width), y = (unsigned)(pixel / c->width);
    unsigned cell = x % CHOICE_MEASURE_STEP + CHOICE_MEASURE_STEP * (y % CHOICE_MEASURE_STEP);
    return cell == (unsigned)((frame * 37 + 11) % (CHOICE_MEASURE_STEP * CHOICE_MEASURE_STEP));
}

static inline int choice_tile_of(const estimator_choice *c, int pixel) {
    return (pixel / c->width / CHOICE_TILE) * c->tiles_x + (pixel % c->width) / CHOICE_TILE;
}
static inline choice_mode choice_of(const estimator_choice *c, int pixel) {
    return (choice_mode)c->mode[choice_tile_of(c, pixel)];
}

/* A sample's cost in rays, from what it counted: the rays it traced and its connections to virtual
 * lights, a connection weighed as 4.2 rays (a vsl frame's thread time less its rays' at the path
 * tracer's time a ray, over its connections, fitted on bay, doorway, atelier, showcase and the
 * Cornell box: 3.6 to 5.4 rays; docs/benchmarks.md). Counted, not timed: a clock would make a
 * seed's render differ from run to run. */
#define CHOICE_CONNECTION_RAYS 4.2
static inline double choice_work(double rays, double connections) {
    return rays + CHOICE_CONNECTION_RAYS * connections;
}

/* One sample of an estimator at a pixel's record: its luminance and work. */
static inline void est_moments_add(est_moments *m, float lum, double work) {
    m->n += 1.0f;
    float d = lum - m->mean;
    m->mean += d / m->n;
    m->m2 += d * (lum - m->mean);
    m->work += (float)work;
}

/* The share of a pixel's film samples the virtual lights gave (0 where it has none). */
float choice_vl_share(const estimator_choice *c, int pixel, double film_samples);

#endif
