#define _POSIX_C_SOURCE 200809L
/* --method auto's samples and probe (docs/design.md, "Choosing the estimator"): a pixel's sample by
 * the estimator its tile takes (choice.h), each estimator's samples recorded with their work. */
#include <stdint.h>

#include "clock.h"
#include "pt.h"
#include "session_parts.h"

static float sample_luminance(const vec3 L[COMP_COUNT]) {
    vec3 sum = v3(0, 0, 0);
    for (int c = 0; c < COMP_COUNT; c++) sum = add3(sum, L[c]);
    return avg3(sum);
}

/* The work a worker's counters have counted, in rays (choice.h's cost: a count, not a clock, so
 * that a seed's render is the same render every time). */
static double counted_work(const render_stats *st) {
    return choice_work((double)session_rays_counted(st), (double)st->vl_connections);
}

/* `paths` path-traced samples of a pixel, the first through the camera hit `first` (along d), the
 * others at positions of their own (runs: their first directions, then their positions); their
 * mean into L (and G), each one with its work to est (NULL: none). */
static void traced_paths(render_session *rs, render_stats *st, const camera_raster *raster, int pixel, vec3 d,
                         const surface_hit *first, int paths, qmc_run dirs, qmc_run points, rng_state *rng,
                         est_moments *est, vec3 L[COMP_COUNT], vec3 *G) {
    for (int q = 0; q < COMP_COUNT; q++) L[q] = v3(0, 0, 0);
    if (G)
        for (int q = 0; q < COMP_COUNT; q++) G[q] = v3(0, 0, 0);
    for (int k = 0; k < paths; k++) {
        uint64_t t0 = clock_ns();
        double w0 = counted_work(st);
        vec3 dir = d, Lk[COMP_COUNT], Gk[COMP_COUNT];
        surface_hit hit;
        const surface_hit *h = first; /* pt_radiance counts the camera ray */
        if (k > 0) h = session_pixel_hit(rs, st, raster, pixel, qmc_run_r2(points, (uint32_t)(k - 1)), &dir, &hit);
        qmc_run run = dirs;
        run.index += (uint32_t)k;
        pt_radiance(rs->scene, rs->plan.max_depth, rs->params.pt_highlights, rs->cam.position, dir, h, run, rng, Lk,
                    G ? Gk : NULL, st->rays);
        for (int q = 0; q < COMP_COUNT; q++) {
            L[q] = madd3(L[q], Lk[q], 1.0f / (float)paths);
            if (G) G[q] = madd3(G[q], Gk[q], 1.0f / (float)paths);
        }
        st->pass_ns[PASS_PATHS] += clock_ns() - t0;
        st->auto_pt_paths++;
        if (est) est_moments_add(est, sample_luminance(Lk), counted_work(st) - w0);
    }
}

/* The virtual lights' sample of a pixel (many_light_sample), with its work to est (NULL: none). */
static void virtual_light_sample(render_session *rs, render_stats *st, const camera_raster *raster, int pixel, vec3 d,
                                 const surface_hit *first, rng_state *rng, int kind, est_moments *est,
                                 vec3 L[COMP_COUNT], vec3 *G) {
    double w0 = counted_work(st);
    session_many_light_sample(rs, st, raster, pixel, d, first, rng, NULL, kind, L, G);
    st->auto_vl_samples++;
    if (est) est_moments_add(est, sample_luminance(L), counted_work(st) - w0);
}

/* A pixel's sample with --method auto, its tile's estimator's (choice.h): path-traced (as many
 * paths as the tile was given, their mean) or the virtual lights'. It goes to the pixel's record
 * with its work, which later frames' choices read, and where the frame measures at the pixel
 * (choice_measures) the other estimator's sample too, for the record alone. An extra sample's go
 * nowhere. */
void session_auto_sample(render_session *rs, render_stats *st, const camera_raster *raster, int pixel, vec3 d,
                         const surface_hit *first, rng_state *rng, int kind, vec3 L[COMP_COUNT], vec3 *G) {
    estimator_choice *c = &rs->choice;
    choice_mode mode = choice_of(c, pixel);
    choice_record *rec = kind == SAMPLE_FILM ? &c->rec[pixel] : NULL;
    int measure = rec && choice_measures(c, pixel, rs->frames);
    int paths = mode == CHOICE_PT ? c->paths[choice_tile_of(c, pixel)] : measure;
    qmc_run dirs = {0}, points = {0}; /* hashed only where a path is traced */
    if (paths) {
        dirs = rec ? session_pixel_run(rs, pixel, RUN_AUTO_PATHS, rec->pt_taken, 1) : session_fresh_run(rng);
        points = rec ? session_pixel_run(rs, pixel, RUN_AUTO_POINTS, rec->pt_taken, 1) : session_fresh_run(rng);
    }
    if (rec) rec->pt_taken += (uint32_t)paths;
    if (mode == CHOICE_PT) {
        traced_paths(rs, st, raster, pixel, d, first, paths, dirs, points, rng, rec ? &rec->e[EST_PT] : NULL, L, G);
    } else {
        virtual_light_sample(rs, st, raster, pixel, d, first, rng, kind, rec ? &rec->e[EST_VL] : NULL, L, G);
        if (rec) rec->vl_weight += 1.0f;
    }
    if (!measure) return;
    vec3 other[COMP_COUNT];
    st->rays[RAY_CAMERA]--; /* one camera ray served both */
    if (mode == CHOICE_PT)
        virtual_light_sample(rs, st, raster, pixel, d, first, rng, SAMPLE_PROBE, &rec->e[EST_VL], other, NULL);
    else
        traced_paths(rs, st, raster, pixel, d, first, 1, dirs, points, rng, &rec->e[EST_PT], other, NULL);
}

/* The probe of a new accumulation, before its first frame: at a few pixels of every tile
 * (choice_probe_pixel), CHOICE_PROBE_SAMPLES samples of each estimator at positions of their own,
 * from random numbers no frame draws, to the records alone; the tiles are judged on them before
 * the film takes a sample, so that none of the film's is a wrong estimator's (docs/design.md,
 * "Choosing the estimator"). One of the tasks, a row of tiles. */
void session_auto_probe(void *ctx, int row, int worker) {
    render_session *rs = ctx;
    estimator_choice *c = &rs->choice;
    render_stats *st = &rs->workers[worker].st;
    camera_raster raster = camera_raster_make(&rs->cam, rs->params.width, rs->params.height);
    int y1 = (row + 1) * CHOICE_TILE < c->height ? (row + 1) * CHOICE_TILE : c->height;
    for (int y = row * CHOICE_TILE; y < y1; y++)
        for (int x = 0; x < c->width; x++) {
            int pixel = y * c->width + x;
            if (!choice_probe_pixel(c, pixel)) continue;
            rng_state rng = rng_for((uint64_t)pixel, UINT64_MAX >> 2, rs->params.seed); /* no frame's stream */
            for (int k = 0; k < CHOICE_PROBE_SAMPLES; k++) {
                vec3 d, L[COMP_COUNT];
                surface_hit hit;
                const surface_hit *h = session_pixel_hit(rs, st, &raster, pixel, rng_vec2(&rng), &d, &hit);
                traced_paths(rs, st, &raster, pixel, d, h, 1, session_fresh_run(&rng), session_fresh_run(&rng), &rng,
                             &c->rec[pixel].e[EST_PT], L, NULL);
                st->rays[RAY_CAMERA]--; /* one camera ray served both */
                virtual_light_sample(rs, st, &raster, pixel, d, h, &rng, SAMPLE_PROBE, &c->rec[pixel].e[EST_VL], L,
                                     NULL);
            }
        }
}

void session_vl_share(const render_session *rs, float *rgb) {
    const film *f = &rs->film;
    render_method m = rs->params.method;
    for (int i = 0; i < f->width * f->height; i++) {
        double n = (double)f->passes - (double)f->rejected[i];
        float share = m == METHOD_AUTO ? choice_vl_share(&rs->choice, i, n) : m != METHOD_PT && n > 0.0 ? 1.0f : 0.0f;
        rgb[3 * i] = rgb[3 * i + 1] = rgb[3 * i + 2] = share;
    }
}
