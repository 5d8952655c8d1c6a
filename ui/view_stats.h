/* glint view: what the viewer's render side reports of its updates, frames and the image shown.
 * One record, declared once, here: the render side (app/view/view_controller.c) fills it, the panel
 * (ui.h, ui_stats.render) shows it, and a script's `stats` line prints it (view_stats_print) under
 * the names given below. */
#ifndef GLINT_VIEW_STATS_H
#define GLINT_VIEW_STATS_H

#include <stdint.h>

/* X(kind, field, name in the stats line or NULL for none, what it is). kind: U64, I64, INT, DBL. */
#define VIEW_STATS(X)                                                                                                  \
    X(U64, frames_generation, NULL, "the request generation the frames below show")                                    \
    X(I64, frames, NULL, "whole frames since the last reset (the stats line's frames: of the state asked last)")       \
    X(U64, frames_total, "frames_total", "whole frames ever")                                                          \
    X(U64, resets, "resets", "accumulations begun since the viewer opened, less one")                                  \
    X(DBL, reset_at, NULL, "when the last accumulation began (cli_now), less the time refinement was held")            \
    X(DBL, frame_ms, "frame_ms", "a whole frame's time with these settings, from its parts")                           \
    X(DBL, full_frame_ms, NULL, "... as measured at the last whole frame")                                             \
    X(DBL, rays_per_second, NULL, "of the accumulation so far")                                                        \
    X(U64, updates, "updates", "images published, ever")                                                               \
    X(INT, parts, "parts", "the frame under way: its parts (0: between frames)...")                                    \
    X(INT, parts_done, "parts_done", "... and those done")                                                             \
    X(DBL, part_ms, "part_ms", "the last update's part")                                                               \
    X(DBL, view_ms, "view_ms", "the display's last view change: G-buffer and reprojection")                            \
    X(DBL, resolve_ms, "resolve_ms", "the display's last resolve: the filter and the mix")                             \
    X(DBL, mean_count, "mean_count", "samples behind the average pixel shown")                                         \
    X(U64, extra_samples, "extra_samples", "the display's own samples, where the image shown erred most")              \
    X(I64, carried, "carried", "pixels the last view change carried over...")                                          \
    X(I64, lost, "lost", "... and those it lost")                                                                      \
    X(INT, denoised, "denoised", "the last image was filtered")                                                        \
    X(DBL, shown_error, NULL, "the image shown against the reference (the whole image; the line's displayed_error)")   \
    X(DBL, shown_error_at, NULL, "... its seconds since the reset")                                                    \
    X(U64, shown_error_serial, NULL, "... counted")                                                                    \
    X(U64, shown_error_resets, NULL, "... the accumulation it belongs to")                                             \
    X(DBL, rel_error, NULL, "the estimate against the reference at the last whole frame (the line's rel_error)")       \
    X(DBL, rel_error_at, NULL, "... its seconds since the reset")                                                      \
    X(U64, rel_error_serial, "errors_measured", "... counted")                                                         \
    X(U64, rel_error_resets, NULL, "... the accumulation it belongs to")                                               \
    X(U64, rejected, "rejected", "NaN or Inf samples dropped")                                                         \
    X(U64, virtual_lights, "virtual_lights", "deposited since the last reset")                                         \
    X(INT, plan_highlights, "plan_highlights", "the effect plan runs the highlight pass")                              \
    X(U64, hl_points, NULL, "camera hits the highlight pass worked at, over the frames")                               \
    X(U64, hl_lobes, "hl_lobes", "lobes it lit")                                                                       \
    X(DBL, hl_merge_share, NULL, "its share of the render threads' time spent merging")                                \
    X(U64, late_parts, "late_parts",                                                                                   \
      "parts that ran to their end though a request (a change, a load, quit) came while they rendered")                \
    X(U64, preempted_parts, "preempted_parts", "rest updates' parts a change stopped (shown sooner)")                  \
    X(INT, error_paused, "error_paused", "the last update was not of the reference's view: no error")                  \
    X(INT, standing, NULL, "refinement held: the image stands still")

#define VIEW_STATS_TYPE_U64 uint64_t
#define VIEW_STATS_TYPE_I64 long long
#define VIEW_STATS_TYPE_INT int
#define VIEW_STATS_TYPE_DBL double

typedef struct {
#define VIEW_STATS_FIELD(kind, field, name, doc) VIEW_STATS_TYPE_##kind field;
    VIEW_STATS(VIEW_STATS_FIELD)
#undef VIEW_STATS_FIELD
    char plan[1200]; /* the effect plan, "pass: why" a line; empty before the first frame */
} view_stats;

#endif
