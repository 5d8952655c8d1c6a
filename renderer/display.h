/* glint — what the viewer shows while the estimate refines (docs/design.md, "The display while
 * things move"): a view of the film's samples, never the film. Each pixel keeps a history of the
 * samples that landed on its surface point, per film component, divided by the point's albedo;
 * when the camera moves, the history follows the point to where it lands in the new view
 * (reprojection through a G-buffer of the pixels' centre rays), keeping of a glossy lobe's share
 * less the sharper the lobe and the more the view turned; new samples blend in; the image shown
 * is the history, filtered while it is young (denoise.h). Exports, references and glint bench
 * read the session's film, which this never touches. */
#ifndef GLINT_DISPLAY_H
#define GLINT_DISPLAY_H

#include <stdint.h>

#include "film.h"
#include "gbuffer.h"
#include "session.h"

/* Why the view changed (display_change_view), a mask. */
enum {
    DISPLAY_CAMERA = 1,  /* the camera moved: each point's history follows it */
    DISPLAY_LIGHTS = 2,  /* a light moved or changed: what it lit changed, history is kept briefly */
    DISPLAY_RESTART = 4, /* another scene, estimator or size: nothing carries over */
};

typedef struct {
    uint64_t updates;  /* display_take_samples calls that brought samples */
    uint64_t samples;  /* samples taken in all */
    long long carried; /* pixels whose history the last view change carried over... */
    long long lost;    /* ...and those it lost (disocclusions, another surface) */
    double mean_count; /* samples behind the average pixel's light at the last resolve */
    int levels;        /* the filter's levels at the last resolve (0: not filtered) */
    double view_ms;    /* the last view change: G-buffer and reprojection... */
    double gbuffer_ms; /* ...of which the G-buffer */
    double resolve_ms; /* the last resolve: filter and modulation... */
    double filter_ms;  /* ...of which the filter (denoise_run) */
    uint64_t extra;    /* extra samples taken (display_take_extra) */
} display_stats;

typedef struct display display;

/* A display for width x height images, on threads threads (0: one per core). Returns NULL with err
 * set (out of memory, no threads). Its history starts empty. */
display *display_create(int width, int height, int threads, char *err, size_t errlen);
void display_destroy(display *d);

/* Where the session writes each update's samples (session_set_sink): the display reads the pixels
 * stamped with the sink's serial at display_take_samples. */
const sample_sink *display_sink(const display *d);

/* The view changed for the reasons in `change` (DISPLAY_*): the G-buffer is traced for cam, and
 * each pixel's history carried over from the last view as far as the change leaves it right. The
 * first call (and DISPLAY_RESTART) starts from nothing. s must be the scene the samples render. */
void display_change_view(display *d, const scene *s, const camera *cam, unsigned change);

/* Blends in the samples the session wrote into the sink since the last call, and opens the sink
 * for the next update. Returns how many it took. */
long long display_take_samples(display *d);

/* What each packet of pixels needs now (session_set_packet_need, before a frame begins), in
 * SESSION_NEED_LEVELS levels: packets with a pixel whose spread is still unknown (fewer than two
 * samples) in the upper half, by the lack of samples in their history, 1 / (1 + samples) on
 * average; the others in the lower half, by how much a sample of each of their pixels would take
 * off the error shown, against the mean packet's. The sky needs nothing. One entry per packet, row
 * major, the display's own until the next call. */
const uint8_t *display_packet_need(display *d);

/* Extra samples for the display alone (session_render_extra), where they take most off the error
 * shown: a pixel of one-sample spread s (its variance's square root, times its albedo) with n
 * samples errs by s^2 / n, and the least sum of that over the image for `budget` samples more has
 * each pixel's n + k in proportion to its s (k >= 0; docs/design.md, "Extra samples where the
 * image errs most"). A single sample's s is its own value; a hole (no sample yet) counts as half a
 * sample, its s its hardest neighbour's, or among holes only the average pixel's; the sky takes
 * none. Writes at most max requests (pixel, samples, luminance weights) and returns how many. The plan
 * reads the samples so far, so the display's mean is no longer unbiased where it takes them: a
 * view, like the filter. */
int display_plan_extra(display *d, int budget, extra_request *req, int max);
/* Blends the requests' samples (session_render_extra's) into the history; while a light change is
 * judged they are evidence for their tiles, as the film's are. */
void display_take_extra(display *d, const extra_request *req, int n);

/* The image shown, of the components in mask (bit c = film component c), into rgb (3 floats a
 * pixel, width x height): the history times the albedo, filtered when denoise is set (its
 * strength follows each pixel's noise: a converged pixel comes back as it is). Finite. */
void display_resolve(display *d, unsigned mask, int denoise, float *rgb);

display_stats display_get_stats(const display *d);
const gbuffer *display_gbuffer(const display *d);

#endif
