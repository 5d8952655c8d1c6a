/* glint — a render session: the scene (read-only), a camera, the parameters, the film and the
 * statistics. Each frame is one pass of fresh samples over the image (one camera sample per
 * pixel); the image is the running mean. A frame renders whole or in interleaved parts, with the
 * same samples either way (docs/design.md, "What a frame is"). */
#ifndef GLINT_SESSION_H
#define GLINT_SESSION_H

#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

#include "film.h"
#include "params.h"
#include "plan.h"
#include "scene.h"

typedef struct render_session render_session;

/* Creates a session rendering s from cam. The scene must outlive the session. Returns NULL with
 * err set on failure. */
render_session *session_create(const scene *s, const camera *cam, const render_params *params, char *err,
                               size_t errlen);
void session_destroy(render_session *rs);

/* Renders one frame (all threads; returns when done), or the rest of a frame under way in parts
 * (session_render_part). Returns 0, or -1 with the reason in session_error() when a frame could
 * not be prepared (out of memory; the film is unchanged), or 1 when the abort flag stopped it: the
 * frame is not counted, but the tiles rendered before the stop are in the film, so the caller must
 * reset the accumulation. */
int session_render_frame(render_session *rs);
/* Renders the next part of the frame under way, beginning a frame (in `parts` parts) when none is:
 * the image's 4x4-pixel packets in `parts` interleaved parts, each call one part. Packet (i, j) lies
 * in cell (i mod a, j mod b) of a lattice of a x b = parts cells (session_part_cell), and part p of a
 * frame is the packets of the cell of rank p (or, given what each packet needs, the p-th run of the
 * packets by need: session_set_packet_need). A frame begins at the part after the last one begun
 * (in whatever frame, stopped or not, mod the new frame's count; session_reset does not forget it),
 * so a caller who resets before every call still renders a different part each time; it ends after
 * its last part: *frame_done is then 1 (0 otherwise; frame_done may be NULL). The film after a frame
 * is the same, bit for bit, in whatever parts the frame was rendered; between parts it holds the
 * parts so far, so its mean is a frame's only once the frame ends. `parts` is read when a frame
 * begins: a power of two, 1 .. SESSION_MAX_PARTS, others clamped to the nearest allowed value below
 * (1 below 1); a frame under way keeps its own count. Returns as session_render_frame: 0 (a part
 * rendered), -1 (the frame could not begin: nothing rendered), or 1 when the abort flag stopped it
 * (the frame is abandoned, uncounted; the caller must reset). The statistics count every part. */
#define SESSION_MAX_PARTS 256
int session_render_part(render_session *rs, int parts, int *frame_done);
/* The frame under way: its part count (0: none, between frames) and the parts of it done. */
int session_frame_parts(const render_session *rs);
int session_frame_parts_done(const render_session *rs);
/* The lattice of `parts` parts (clamped as session_render_part does) and the cell of rank `rank`
 * (taken mod parts): a = 2^ceil(k/2) by b = 2^floor(k/2) cells for parts = 2^k, ranked in ordered-
 * dither (Bayer) order: every aligned run of 2^m ranks puts one cell in each block of
 * (a >> ceil(m/2)) x (b >> floor(m/2)) cells, and on a square lattice also in each block of
 * (a >> floor(m/2)) x (b >> ceil(m/2)): the frame's first parts spread evenly over the image. */
typedef struct {
    int a, b; /* the lattice's size, in packets */
    int x, y; /* the cell: packets (x + a i, y + b j) */
} part_cell;
part_cell session_part_cell(int parts, int rank);
/* What each packet needs, 0 .. SESSION_NEED_LEVELS - 1 (packets_x x packets_y of them, row major,
 * packets of SESSION_PACKET x SESSION_PACKET pixels; the caller's memory, read when a frame in
 * parts begins; NULL: nothing). Such a frame renders its packets the neediest first, a need's
 * packets in the lattice's order from the frame's first part on, in `parts` parts of equal size: a
 * display that carried history over a move has the pixels it lacks rendered first. A frame is the
 * same, bit for bit, in whatever order its packets came. */
#define SESSION_PACKET 4
#define SESSION_NEED_LEVELS 16
void session_set_packet_need(render_session *rs, const uint8_t *need);

/* Where every sample the film takes also goes (whole frames or parts), for a display that reads
 * each part's fresh samples: per film component the sample's 3 floats at the pixel (zeros included;
 * arrays of the image's size), with glossy (all set, or glossy[0] NULL: none) the part of it that
 * left the camera hit through its view-dependent lobes (pt_radiance's glossy, manylight_indirect's;
 * the highlights all of theirs), and the pixel's stamp set to serial. A sample the film drops (NaN or
 * Inf) writes nothing. The caller owns the memory and keeps the struct alive while it is set: the
 * render threads read it and write the arrays while a call renders, so the caller sets serial (and
 * reads the arrays) between calls. */
typedef struct {
    float *rgb[COMP_COUNT];    /* 3 floats a pixel each: the pixel's sample, per film component... */
    float *glossy[COMP_COUNT]; /* ...and its view-dependent lobes' part */
    uint32_t *stamp;           /* one a pixel: set to serial where the pixel took a sample */
    uint32_t serial;
} sample_sink;
/* NULL: none (the default). */
void session_set_sink(render_session *rs, const sample_sink *sink);

/* Samples for a display only (display.h): for each request, `samples` more samples of its pixel,
 * each through a camera ray of its own (their positions spread evenly over the pixel), with the
 * estimators of the frame under way or the last one, summed per film component, and each sample's
 * luminance (weight . rgb, by the caller's weights) squared and summed. The film, the per-pixel
 * records the frames keep and every later frame are untouched: a render with extra samples between
 * its parts has the same film, bit for bit, as one without. Returns 0, or 1 (nothing rendered) when
 * no frame has begun since the last reset or the abort flag is set. */
typedef struct {
    int pixel, samples;       /* asked */
    float weight[3];          /* a sample's luminance, as the caller reckons it */
    float sum[COMP_COUNT][3]; /* written: the finite samples' sum, per film component... */
    float sumsq[COMP_COUNT];  /* ...their luminances squared, summed... */
    int taken;                /* ...and how many (a sample not finite is dropped) */
} extra_request;
int session_render_extra(render_session *rs, extra_request *req, int n);

/* A flag the session polls before each tile (in a part, each chunk of its packets): while it is
 * non-zero, frames stop early (above). For interactive use, where the change that sets it resets
 * the accumulation anyway. NULL: none. */
void session_set_abort_flag(render_session *rs, const atomic_int *flag);
const char *session_error(const render_session *rs);
/* Clears the accumulation (the next frame starts a new mean) and the statistics with it, and
 * abandons a frame under way in parts (nothing of it counted). */
void session_reset(render_session *rs);
void session_set_camera(render_session *rs, const camera *cam);
/* The camera its frames are rendered from. */
const camera *session_camera(const render_session *rs);
/* The scene changed (a light moved or dimmed, another environment map): analyses it again,
 * re-makes the plan, drops what was derived from the old map and resets.
 * Returns 0, or -1 with session_error() set (out of memory; the old analysis stays). */
int session_scene_changed(render_session *rs);
/* Takes new estimator parameters (method, max_depth, seed; the size and thread count stay) and
 * resets the accumulation. */
void session_set_params(render_session *rs, const render_params *params);
/* Both, with one reset: a reset clears the film (about 90 MB at 960x540). */
void session_restart(render_session *rs, const render_params *params, const camera *cam);

long long session_frames(const render_session *rs);
const film *session_film(const render_session *rs);
const render_params *session_params(const render_session *rs);
render_stats session_stats(const render_session *rs);
/* What the scene calls for (analysed when the session is created) and the passes it runs. */
const scene_analysis *session_analysis(const render_session *rs);
const effect_plan *session_plan(const render_session *rs);
/* The share of each pixel's film samples the virtual lights gave, 0 to 1, as RGB (three equal
 * floats a pixel): --method auto's map of its choice; 1 with vpl, vsl and vsl+hl, 0 with pt; 0
 * before a pixel's first sample. */
void session_vl_share(const render_session *rs, float *rgb);
/* The rays traced for each pixel's film samples since the reset (their camera rays counted, and
 * auto's measuring samples beside them; highlights a block of pixels shares, not), over the
 * image's most, 0 to 1, as RGB: where the work goes (the adaptive allocation's budgets, auto's
 * paths a tile). 0 everywhere before a sample. */
void session_work_map(const render_session *rs, float *rgb);

#endif
