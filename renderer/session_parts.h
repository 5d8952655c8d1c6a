/* glint — the render session's parts (docs/design.md, "What a frame is"): what session.c (frames,
 * parts, the methods' samples) and session_auto.c (--method auto's samples and probe) share.
 * session.h is the interface; nothing else includes this. */
#ifndef GLINT_SESSION_PARTS_H
#define GLINT_SESSION_PARTS_H

#include "camera.h"
#include "choice.h"
#include "envfilter.h"
#include "highlights.h"
#include "manylight.h"
#include "pixel_alloc.h"
#include "rng.h"
#include "sampling.h"
#include "session.h"
#include "threadpool.h"

#define TILE 16
#define PACKET_W SESSION_PACKET /* PACKET_W x PACKET_H = SCENE_PACKET, dividing TILE */
#define PACKET_H SESSION_PACKET

/* Per-worker counters, padded so threads never share a cache line. */
typedef struct {
    render_stats st;
    char pad[64];
} worker_stats;

/* Direct-light samples at each camera hit in a many-light frame. Such a frame costs several path
 * tracer frames (the gather), so one direct sample a frame leaves the direct light noisier than
 * the path tracer's at equal time. 4 took the whole image's noise x time down 1.7x on doorway and
 * 2.4x on showcase at 14% more time a frame; 8 did better there but cost atelier (whose direct
 * light is easy) a third of its frames for little (docs/benchmarks.md). */
#define MANYLIGHT_DIRECT_SAMPLES 4
#define MANYLIGHT_MAX_DIRECT_SAMPLES 64 /* per pixel, with --adapt */
#define HL_PIXEL_POINTS 8     /* camera hits a pixel's highlight rays start from, once it has met a sharp lobe */
#define HL_SHARP_RAY_FACTOR 4 /* ... and N times this many secondary rays (docs/benchmarks.md, 2026-11-28) */

/* One part of a frame: the packets (x + a i, y + b j) of a lattice cell, cols of them a row, row
 * major, handed out `chunk` at a time. */
typedef struct {
    part_cell cell;
    int cols, packets, chunk;
    const uint32_t *list; /* or, in a frame ordered by need, these packets (y * packets_x + x) */
} part_job;
#define PART_CHUNK 16          /* packets at most a task: the atomic counter is read once per chunk */
#define PART_CHUNKS_A_THREAD 8 /* ... and at least this many chunks a thread where the part has them */

struct render_session {
    const scene *scene;
    camera cam;
    render_params params;
    vl_params vl; /* params.vl with its defaults, resolved once (take_params) */
    film film;
    long long frames;
    threadpool *pool;
    worker_stats *workers;
    render_stats totals;
    int tiles_x, tiles_y;
    manylight ml; /* vpl, vsl, vsl+hl: this frame's virtual lights */
    /* Many-light frames with --adapt: each pixel's directions through sharp lobes and direct-light
     * samples, from the spread of one sample's light in earlier frames */
    int adapt;
    pixel_alloc glossy, direct;
    uint32_t *direct_taken;    /* per pixel: the points of its direct samples' run taken so far */
    float *pixel_rays;         /* per pixel: the rays its film samples traced since the reset (the map of work) */
    uint8_t *hl_state;         /* per pixel, HL_PIXEL_*: sharp ones spread their highlights over the pixel */
    hl_merge_record *hl_merge; /* per pixel with --merge auto: merge against trace; NULL until used */
    hl_setup hl;               /* vsl+hl: this frame's highlight settings */
    estimator_choice choice;   /* auto: which estimator each tile takes (allocated for auto alone) */
    env_vmf_filter *envf;      /* vsl+hl under a map: the map prefiltered, built on first use */
    const env_map *envf_map;   /* ... the map it was built from */
    scene_analysis analysis;
    effect_plan plan;
    const atomic_int *abort_flag; /* polled per tile or chunk; NULL: none */
    const sample_sink *sink;      /* NULL: none */
    /* A frame in parts (session_render_part): its count (0: no frame under way), the parts done and
     * the rank of its first; the rank after the last part begun, which session_reset keeps. */
    int frame_parts, parts_done, first_part, next_part;
    part_job part;       /* the part being rendered */
    const uint8_t *need; /* per packet, the caller's (session_set_packet_need); NULL: none */
    uint32_t *order;     /* the frame's packets by need, when it is ordered (else NULL) */
    size_t order_size;
    int frame_begun;      /* a frame began since the last reset: its estimators serve extra samples */
    uint64_t extra_calls; /* session_render_extra's calls: each its own random numbers */
    extra_request *extra; /* the call's requests */
    char error[256];
};

/* The pixel's run of the low-discrepancy sequence for one of its estimators (stream, < 16): the
 * same scramble every frame, starting after the `taken` points its earlier frames used. Counted in
 * the whole render's frames (next_frame_index) where a frame's count is fixed, so a shard's points
 * are the whole render's and merged shards equal one render; a count only this session knows
 * (own_count: the record's, with --adapt) gets a scramble per shard, so shards never repeat each
 * other's points. */
enum {
    RUN_PATH = 0,
    RUN_HIGHLIGHTS = 1,
    RUN_HIGHLIGHT_POINTS = 2,
    RUN_HIGHLIGHT_BLOCK = 2 + HL_PIXEL_POINTS,
    RUN_DIRECT_POINTS,
    RUN_AUTO_PATHS,  /* auto: the path-traced samples' first directions */
    RUN_AUTO_POINTS, /* ... and their positions in the pixel past the frame's own */
    RUN_STREAMS = 16
};
qmc_run session_pixel_run(const render_session *rs, int pixel, uint64_t stream, uint64_t taken, int own_count);
/* A display-only sample's run (session_render_extra): scrambled afresh from its own stream. */
qmc_run session_fresh_run(rng_state *rng);
/* The rays a worker's counters have counted, of every kind. */
static inline uint64_t session_rays_counted(const render_stats *st) {
    uint64_t rays = 0;
    for (int k = 0; k < RAY_KIND_COUNT; k++) rays += st->rays[k];
    return rays;
}

/* The camera ray through position u ([0,1)^2) of a pixel past the frame's own: its direction to
 * *dir, its hit to *hit, returned (NULL: none). Counts the point; its camera ray is the caller's. */
const surface_hit *session_pixel_hit(const render_session *rs, render_stats *st, const camera_raster *raster, int pixel,
                                     vec2 u, vec3 *dir, surface_hit *hit);

/* What a sample is for: the film's; a display's extra one (as estimate_sample says); a probe's
 * (auto's measurement, as an extra one but with the film's direct samples, whose cost it measures;
 * their run's points it takes are the film's no more). */
enum { SAMPLE_FILM = 0, SAMPLE_EXTRA, SAMPLE_PROBE };

/* A many-light method's sample of a pixel whose camera ray (along d) the caller traced (its hit,
 * or NULL), `extra` a SAMPLE_ kind: the shared direct estimator's, the virtual lights' at the hit
 * and the highlights' (shared_hl: its block's, or NULL), into L and with G (not NULL) the part of
 * each component that left the camera hit through its view-dependent lobes. */
void session_many_light_sample(render_session *rs, render_stats *st, const camera_raster *raster, int pixel, vec3 d,
                               const surface_hit *first, rng_state *rng, const vec3 *shared_hl, int extra,
                               vec3 L[COMP_COUNT], vec3 *G);

/* --method auto (session_auto.c): a pixel's sample as its tile takes it (as many_light_sample's),
 * and the probe of a new accumulation's first frame, a task per row of choice tiles. */
void session_auto_sample(render_session *rs, render_stats *st, const camera_raster *raster, int pixel, vec3 d,
                         const surface_hit *first, rng_state *rng, int kind, vec3 L[COMP_COUNT], vec3 *G);
void session_auto_probe(void *ctx, int row, int worker);

#endif
