#define _POSIX_C_SOURCE 200809L
#include "session.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "clock.h"
#include "lights.h"
#include "pt.h"
#include "session_parts.h"

/* The plan for the session's parameters, less the passes of the components it does not render. */
static effect_plan session_make_plan(const render_session *rs) {
    const render_params *p = &rs->params;
    effect_plan plan = plan_make(&rs->analysis, p->method, p->max_depth, p->plan);
    if (p->only && p->method != METHOD_PT) {
        if (!(p->only & (1u << COMP_INDIRECT))) plan.virtual_lights = 0;
        if (!(p->only & (1u << COMP_HIGHLIGHTS))) plan.highlights = plan.env_prefilter = 0;
    }
    return plan;
}

render_session *session_create(const scene *s, const camera *cam, const render_params *params, char *err,
                               size_t errlen) {
    render_session *rs = calloc(1, sizeof(render_session));
    if (!rs) return snprintf(err, errlen, "out of memory"), NULL;
    rs->scene = s;
    rs->cam = *cam;
    rs->params = render_params_resolve_frame(params);
    rs->vl = vl_params_resolve(&rs->params.vl);
    render_params *p = &rs->params;
    if (film_init(&rs->film, p->width, p->height) != 0) {
        snprintf(err, errlen, "out of memory for a %dx%d image", p->width, p->height);
        free(rs);
        return NULL;
    }
    if (p->shard_count > 0 && film_enable_moments(&rs->film) != 0) {
        session_destroy(rs);
        return snprintf(err, errlen, "out of memory for a %dx%d image's moments", p->width, p->height), NULL;
    }
    rs->pool = threadpool_create(p->threads);
    if (rs->pool) rs->workers = calloc((size_t)threadpool_size(rs->pool), sizeof(worker_stats));
    if (!rs->pool || !rs->workers) {
        session_destroy(rs);
        return snprintf(err, errlen, "cannot start render threads"), NULL;
    }
    p->threads = threadpool_size(rs->pool); /* report what runs, not what was asked */
    if (scene_analyse(s, &rs->analysis, err, errlen) != 0) {
        session_destroy(rs);
        return NULL;
    }
    if (pixel_alloc_init(&rs->glossy, p->width * p->height) != 0 ||
        pixel_alloc_init(&rs->direct, p->width * p->height) != 0 ||
        !(rs->hl_state = calloc((size_t)p->width * (size_t)p->height, 1)) ||
        !(rs->direct_taken = calloc((size_t)p->width * (size_t)p->height, sizeof *rs->direct_taken)) ||
        !(rs->pixel_rays = calloc((size_t)p->width * (size_t)p->height, sizeof *rs->pixel_rays))) {
        session_destroy(rs);
        return snprintf(err, errlen, "out of memory for a %dx%d image", p->width, p->height), NULL;
    }
    rs->plan = session_make_plan(rs);
    rs->tiles_x = (p->width + TILE - 1) / TILE;
    rs->tiles_y = (p->height + TILE - 1) / TILE;
    return rs;
}

void session_destroy(render_session *rs) {
    if (!rs) return;
    threadpool_destroy(rs->pool);
    manylight_deinit(&rs->ml);
    pixel_alloc_free(&rs->glossy);
    pixel_alloc_free(&rs->direct);
    free(rs->hl_state);
    free(rs->direct_taken);
    free(rs->pixel_rays);
    free(rs->order);
    free(rs->hl_merge);
    choice_free(&rs->choice);
    env_vmf_filter_destroy(rs->envf);
    scene_analysis_free(&rs->analysis);
    free(rs->workers);
    film_deinit(&rs->film);
    free(rs);
}

/* The index of the next frame in the sequence of the whole render: a shard's frames are a run of
 * it (shard_frame_index), so the random numbers are the whole render's. */
static uint64_t next_frame_index(const render_session *rs) {
    const render_params *p = &rs->params;
    if (p->shard_count <= 0) return (uint64_t)rs->frames;
    return shard_frame_index(p->shard_spp_total, p->shard_index, p->shard_count, (uint64_t)rs->frames);
}

const surface_hit *session_pixel_hit(const render_session *rs, render_stats *st, const camera_raster *raster, int pixel,
                                     vec2 u, vec3 *dir, surface_hit *hit) {
    int w = rs->params.width;
    *dir = camera_raster_dir(raster, (float)(pixel % w) + u.x, (float)(pixel / w) + u.y);
    st->pixel_points++;
    return scene_intersect(rs->scene, rs->cam.position, *dir, INFINITY, hit) ? hit : NULL;
}

/* n camera hits spread over a pixel: the frame's own first (NULL: none), then more at R2
 * positions over the pixel. */
static void pixel_points(render_session *rs, render_stats *st, const camera_raster *raster, int pixel, vec3 d,
                         const surface_hit *first, shading_point *xs, int n) {
    const scene *s = rs->scene;
    const render_params *p = &rs->params;
    rng_state start = rng_for((uint64_t)pixel, UINT64_MAX - 1, p->seed);
    vec2 shift = rng_vec2(&start);
    for (int j = 0; j < n; j++) {
        const surface_hit *h = first;
        surface_hit hit;
        vec3 dir = d;
        if (j > 0) {
            int index = (int)((next_frame_index(rs) * (HL_PIXEL_POINTS - 1) + (uint64_t)j) & 0x3fffffff);
            st->rays[RAY_CAMERA]++;
            h = session_pixel_hit(rs, st, raster, pixel, sample_r2(index, shift), &dir, &hit);
        }
        if (h) {
            xs[j] = shading_point_at(s, h, dir);
        } else {
            memset(&xs[j], 0, sizeof xs[j]);
            xs[j].b.dropped = BSDF_ALL; /* no lobe: adds zero */
        }
    }
}

qmc_run session_pixel_run(const render_session *rs, int pixel, uint64_t stream, uint64_t taken, int own_count) {
    const render_params *p = &rs->params;
    uint64_t shard = own_count && p->shard_count > 0 ? (uint64_t)p->shard_index + 1 : 0;
    rng_state start = rng_for((uint64_t)pixel, UINT64_MAX - 2 - (shard * RUN_STREAMS + stream), p->seed);
    uint32_t sx = rng_next_u32(&start);
    return (qmc_run){(uint32_t)taken, sx, rng_next_u32(&start)};
}

qmc_run session_fresh_run(rng_state *rng) {
    uint32_t sx = rng_next_u32(rng);
    return (qmc_run){0, sx, rng_next_u32(rng)};
}

/* The direct light at a pixel, the mean of `samples` estimates. The first is at the frame's own
 * camera hit (first; NULL: none), the others each at a camera hit of its own, at the next points of
 * the pixel's run of them (its count of them kept in direct_taken: a run's points taken in a row
 * cover the pixel evenly, and with gaps, as a count of all samples would leave, they do not).
 * Sample k selects its light by (k + u) / samples: the samples' choice among the lights is
 * stratified. A light's reflection smaller than the pixel (a spot seen in a glossy sphere) varies
 * with the position, and where several lights shine a sample varies with the light it picks; more
 * samples at one hit, each picking at random, repeated the same shadow ray (docs/design.md, "Where
 * the samples go"). rec, when not NULL, records each one. */
static vec3 pixel_direct(render_session *rs, render_stats *st, const camera_raster *raster, int pixel, vec3 d,
                         const surface_hit *first, int samples, pixel_record *rec, rng_state *rng, vec3 *glossy) {
    const scene *s = rs->scene;
    qmc_run run = session_pixel_run(rs, pixel, RUN_DIRECT_POINTS, rs->direct_taken[pixel], 1);
    if (samples > 1) rs->direct_taken[pixel] += (uint32_t)(samples - 1); /* one: nothing written (extra samples) */
    float u_select = rng_float(rng);
    vec3 sum = v3(0, 0, 0), sum_g = v3(0, 0, 0);
    for (int k = 0; k < samples; k++) {
        vec3 dir = d;
        surface_hit hit;
        const surface_hit *h = first;
        if (k > 0) {
            h = session_pixel_hit(rs, st, raster, pixel, qmc_run_point(run, (uint32_t)(k - 1)), &dir, &hit);
        }
        float u = fminf(((float)k + u_select) / (float)samples, 0x1.fffffep-1f);
        vec3 g;
        vec3 L = pt_direct(s, rs->cam.position, dir, h, u, rng, glossy ? &g : NULL, st->rays);
        if (rec) pixel_record_add(rec, avg3(L));
        sum = add3(sum, L);
        if (glossy) sum_g = add3(sum_g, g);
    }
    if (glossy) *glossy = scale3(sum_g, 1.0f / (float)samples);
    return scale3(sum, 1.0f / (float)samples);
}

/* A pixel's first highlight state: whether a camera hit at a position of its own in the pixel has
 * a sharp highlight lobe. The position is drawn apart from the frames' samples, so the frame that
 * reads the state stays unbiased. Without the probe every pixel's first frame took one point, and a
 * speck smaller than the pixel was either missed by it or weighed a whole frame. */
static int probe_state(render_session *rs, render_stats *st, const camera_raster *raster, int pixel) {
    const render_params *p = &rs->params;
    rng_state r = rng_for((uint64_t)pixel, UINT64_MAX >> 1, p->seed); /* no frame's stream */
    vec3 dir;
    surface_hit h;
    st->rays[RAY_CAMERA]++;
    if (!session_pixel_hit(rs, st, raster, pixel, rng_vec2(&r), &dir, &h)) return HL_PIXEL_BROAD;
    shading_point x = shading_point_at(rs->scene, &h, dir);
    return hl_point_sharp(&rs->hl, &x) ? HL_PIXEL_SHARP : HL_PIXEL_BROAD;
}

/* Whether the pixels' highlights have been judged dim or bright (judge_dim_pixels), this frame
 * or earlier. */
static int dim_judged(const render_session *rs) {
    return rs->adapt && rs->plan.highlights && rs->plan.virtual_lights && rs->plan.max_depth > 1 &&
           rs->params.method != METHOD_PT && rs->hl.dim_share >= 0.0f && rs->frames >= HL_DIM_FRAMES;
}

/* The highlights of a pixel. A highlight is often smaller than the pixel (a curved mirror's image
 * of a lit speck), and there more positions in the pixel beat more rays from one: once the pixel
 * has met a sharp highlight lobe in an earlier frame or its probe (with --adapt), its secondary
 * rays start from HL_PIXEL_POINTS points spread over the pixel, and it takes HL_SHARP_RAY_FACTOR
 * times as many: few pixels see a sharp lobe, and each is worth more rays than a pixel's share.
 * Earlier frames decide this, so each frame's estimate stays unbiased; and a sharp lobe's members
 * take its image, not the sample's spread, so the merge's expectation does not depend on how many
 * rays it merged (docs/design.md, "Where the samples go"). */
static vec3 pixel_highlights(render_session *rs, render_stats *st, const camera_raster *raster, int pixel, vec3 d,
                             const surface_hit *first, rng_state *rng, int extra) {
    rng_state hl_rng = rng_fork(rng, 0x686967686c69ULL);
    hl_setup setup = rs->hl;
    if (dim_judged(rs)) { /* the pixel was kept: its highlights are bright */
        int n = setup.secondary_rays * HL_BRIGHT_RAY_FACTOR;
        setup.secondary_rays = n < HL_MAX_SECONDARY_RAYS ? n : HL_MAX_SECONDARY_RAYS;
        setup.clusters = 2 * setup.clusters < HL_MAX_CLUSTERS ? 2 * setup.clusters : HL_MAX_CLUSTERS;
    }
    int spread = rs->adapt && !extra && rs->hl_state[pixel] == HL_PIXEL_SHARP;
    int points = 1;
    if (spread) {
        int n = setup.secondary_rays * HL_SHARP_RAY_FACTOR;
        points = setup.secondary_rays < HL_PIXEL_POINTS ? setup.secondary_rays : HL_PIXEL_POINTS;
        setup.secondary_rays = n < HL_MAX_SECONDARY_RAYS ? n : HL_MAX_SECONDARY_RAYS;
    }
    if (!first && points == 1) return v3(0, 0, 0);
    shading_point xs[HL_PIXEL_POINTS];
    pixel_points(rs, st, raster, pixel, d, first, xs, points);
    /* --merge auto: a pixel judged to take the trace does; the others record the trace beside */
    hl_merge_record *rec = rs->adapt && setup.choose ? &rs->hl_merge[pixel] : NULL;
    if (rec && rec->traced) setup.mode = HL_TRACED, rec = NULL;
    if (extra) rec = NULL;
    int sharp = 0;
    /* Each point its own run (its rays' directions over frames); spread points get fresh ones. */
    qmc_run runs[HL_PIXEL_POINTS];
    for (int j = 0; j < points; j++) {
        runs[j] = extra ? session_fresh_run(&hl_rng)
                        : session_pixel_run(
                              rs, pixel, points > 1 ? RUN_HIGHLIGHT_POINTS + (uint64_t)j : RUN_HIGHLIGHTS,
                              next_frame_index(rs) * (uint64_t)hl_rays_of_point(setup.secondary_rays, points, j), 0);
    }
    vec3 traced;
    vec3 L = hl_estimate(&setup, rs->scene, xs, points, runs, &hl_rng, st, &sharp, rec ? &traced : NULL);
    if (rec && is_finite3(L) && is_finite3(traced)) hl_merge_record_add(rec, avg3(L), avg3(traced));
    if (sharp && !extra)
        rs->hl_state[pixel] = HL_PIXEL_SHARP; /* read from the next frame on: one sample a pixel a frame */
    return L;
}

/* The sample the film took at a pixel, to the sink. */
static void sink_put(const sample_sink *k, int pixel, const float sample[COMP_COUNT][3], const vec3 *glossy) {
    for (int c = 0; c < COMP_COUNT; c++) {
        memcpy(k->rgb[c] + 3 * (size_t)pixel, sample[c], sizeof sample[c]);
        if (!glossy) continue;
        float *g = k->glossy[c] + 3 * (size_t)pixel;
        g[0] = glossy[c].x, g[1] = glossy[c].y, g[2] = glossy[c].z;
    }
    k->stamp[pixel] = k->serial;
}

void session_many_light_sample(render_session *rs, render_stats *st, const camera_raster *raster, int pixel, vec3 d,
                               const surface_hit *first, rng_state *rng, const vec3 *shared_hl, int extra,
                               vec3 L[COMP_COUNT], vec3 *G) {
    const scene *s = rs->scene;
    const render_params *p = &rs->params;
    /* render_tile probed the pixel's highlight state */
    int spread = rs->adapt && !extra && rs->plan.highlights && rs->hl_state[pixel] == HL_PIXEL_SHARP;
    int dim = rs->adapt && rs->plan.highlights && rs->hl_state[pixel] == HL_PIXEL_DIM;
    int direct_samples = extra == SAMPLE_EXTRA ? 1 : rs->adapt ? rs->direct.samples[pixel] : MANYLIGHT_DIRECT_SAMPLES;
    for (int c = 0; c < COMP_COUNT; c++) L[c] = v3(0, 0, 0);
    if (G)
        for (int c = 0; c < COMP_COUNT; c++) G[c] = v3(0, 0, 0);
    /* into the void (and its other points too): every component is zero */
    if (!first && !s->env && !spread && direct_samples == 1) {
        st->rays[RAY_CAMERA]++;
        return;
    }
    int depth = rs->plan.max_depth;
    /* The shared direct estimator, then the virtual lights at the hit and the highlights, each
     * pass timed. */
    int record = rs->adapt && !extra;
    uint64_t t0 = clock_ns();
    if (!p->only || p->only & (1u << COMP_DIRECT))
        L[COMP_DIRECT] = pixel_direct(rs, st, raster, pixel, d, first, direct_samples,
                                      record ? &rs->direct.rec[pixel] : NULL, rng, G ? &G[COMP_DIRECT] : NULL);
    else
        st->rays[RAY_CAMERA]++;
    uint64_t t1 = clock_ns();
    st->pass_ns[PASS_DIRECT] += t1 - t0;
    if (first && depth > 1 && rs->plan.virtual_lights) {
        shading_point sp = shading_point_at(s, first, d);
        int split = rs->adapt ? rs->glossy.samples[pixel] : rs->ml.glossy_split;
        /* Directions taken so far: counted by the record with --adapt, else `split` a frame. */
        uint64_t taken = rs->adapt ? (uint64_t)rs->glossy.rec[pixel].n : next_frame_index(rs) * (uint64_t)split;
        L[COMP_INDIRECT] = manylight_indirect(
            &rs->ml, s, &sp, dim ? &L[COMP_HIGHLIGHTS] : NULL, G ? &G[COMP_INDIRECT] : NULL, depth, split,
            extra ? session_fresh_run(rng) : session_pixel_run(rs, pixel, RUN_PATH, taken, rs->adapt),
            record ? &rs->glossy.rec[pixel] : NULL, rng, st);
        uint64_t t2 = clock_ns();
        st->pass_ns[PASS_GATHER] += t2 - t1;
        t1 = t2;
    }
    if (depth > 1 && rs->plan.highlights && !dim) {
        L[COMP_HIGHLIGHTS] = shared_hl ? *shared_hl : pixel_highlights(rs, st, raster, pixel, d, first, rng, extra);
        st->pass_ns[PASS_HIGHLIGHTS] += clock_ns() - t1;
    }
    if (G) G[COMP_HIGHLIGHTS] = L[COMP_HIGHLIGHTS];
}

/* One sample of a pixel whose camera ray (along d) the caller traced: its hit, or NULL; its
 * highlights, when its block shared them, in shared_hl; into L, and with G (not NULL) the part of
 * each component that left the camera hit through its view-dependent lobes into G (pt_radiance;
 * the highlights are all such light). A display's extra sample (extra) reads the pixel's records
 * but writes none, takes its one direct sample at its own camera hit and draws its runs afresh from
 * rng. */
static void estimate_sample(render_session *rs, render_stats *st, const camera_raster *raster, int pixel, vec3 d,
                            const surface_hit *first, rng_state *rng, const vec3 *shared_hl, int extra,
                            vec3 L[COMP_COUNT], vec3 *G) {
    const render_params *p = &rs->params;
    if (p->method == METHOD_AUTO) {
        session_auto_sample(rs, st, raster, pixel, d, first, rng, extra ? SAMPLE_EXTRA : SAMPLE_FILM, L, G);
    } else if (p->method == METHOD_PT) {
        pt_radiance(rs->scene, rs->plan.max_depth, p->pt_highlights, rs->cam.position, d, first,
                    extra ? session_fresh_run(rng) : session_pixel_run(rs, pixel, RUN_PATH, next_frame_index(rs), 0),
                    rng, L, G, st->rays);
    } else {
        session_many_light_sample(rs, st, raster, pixel, d, first, rng, shared_hl, extra, L, G);
    }
}

/* The film's sample of a pixel (as estimate_sample), added, or dropped and counted when it is not
 * finite (a NaN or Inf never reaches the film); and to the sink. Its rays go to the map of work. */
static void render_sample(render_session *rs, render_stats *st, const camera_raster *raster, int pixel, vec3 d,
                          const surface_hit *first, rng_state *rng, const vec3 *shared_hl) {
    vec3 L[COMP_COUNT], G[COMP_COUNT];
    int split = rs->sink && rs->sink->glossy[0];
    uint64_t rays = session_rays_counted(st);
    estimate_sample(rs, st, raster, pixel, d, first, rng, shared_hl, 0, L, split ? G : NULL);
    rs->pixel_rays[pixel] += (float)(session_rays_counted(st) - rays);
    float sample[COMP_COUNT][3];
    int finite = 1;
    for (int c = 0; c < COMP_COUNT; c++) {
        finite &= is_finite3(L[c]);
        sample[c][0] = L[c].x;
        sample[c][1] = L[c].y;
        sample[c][2] = L[c].z;
    }
    if (finite) {
        film_add(&rs->film, pixel, (const float(*)[3])sample);
        if (rs->sink) sink_put(rs->sink, pixel, (const float(*)[3])sample, split ? G : NULL);
    } else {
        film_reject(&rs->film, pixel);
        st->rejected_samples++;
    }
}

/* The share of a pixel's light its highlights took in the film so far (0 where it has none). */
static double highlight_share(const film *f, int pixel) {
    double part = 0.0, all = 0.0;
    for (int c = 0; c < COMP_COUNT; c++) {
        const double *v = f->sum[c] + 3 * (size_t)pixel;
        all += v[0] + v[1] + v[2];
        if (c == COMP_HIGHLIGHTS) part = v[0] + v[1] + v[2];
    }
    return all > 0.0 && part > 0.0 ? part / all : 0.0;
}

/* Judges which pixels' highlights are dim (hl_judge_dim): those whose highlights, and their
 * neighbours', came to at most `share` of their light in the frames so far. The virtual lights'
 * paths take a dim pixel's highlights (docs/design.md, "Where the samples go"). The earlier
 * frames decide, so each later frame's estimate stays unbiased. */
static void judge_dim_pixels(render_session *rs, float share) {
    int w = rs->params.width, h = rs->params.height;
    for (int i = 0; i < w * h; i++)
        if (highlight_share(&rs->film, i) > (double)share) rs->hl_state[i] |= HL_PIXEL_BRIGHT;
    hl_judge_dim(rs->hl_state, w, h, rs->frames > HL_DIM_FRAMES);
}

/* The highlights of a packet's pixels whose camera hits have a broad highlight lobe, 2x2 blocks of
 * them sharing their secondary hits (hl_estimate_shared): such pixels see nearly the same lobe, so
 * each merges four pixels' hits for the cost of its own and the shadow rays to the others'. Pixels
 * that spread over sharp lobes keep their own. shared[i] is set where has_shared[i]. */
static void block_highlights(render_session *rs, render_stats *st, const int *pixel, const vec3 *d,
                             const surface_hit *hit, unsigned hits, int n, vec3 *shared, int *has_shared) {
    const render_params *p = &rs->params;
    uint64_t t0 = clock_ns(), frame = next_frame_index(rs);
    for (int block = 0; block < SCENE_PACKET / HL_SHARE_POINTS; block++) {
        shading_point xs[HL_SHARE_POINTS];
        int idx[HL_SHARE_POINTS], slot[HL_SHARE_POINTS], m = 0, corner = -1;
        rng_state rngs[HL_SHARE_POINTS];
        for (int i = 0; i < n; i++) {
            int px = pixel[i] % p->width, py = pixel[i] / p->width;
            if ((px / 2 % 2) + 2 * (py / 2 % 2) != block || !(hits >> i & 1u)) continue;
            if (rs->adapt && (rs->hl_state[pixel[i]] == HL_PIXEL_SHARP || rs->hl_state[pixel[i]] == HL_PIXEL_DIM))
                continue;
            corner = (py & ~1) * p->width + (px & ~1);
            xs[m] = shading_point_at(rs->scene, &hit[i], d[i]);
            idx[m] = i;
            slot[m] = (py & 1) * 2 + (px & 1);
            rngs[m] = rng_for((uint64_t)pixel[i], frame | (1ull << 63), p->seed); /* no other stream's */
            m++;
        }
        if (m == 0) continue;
        /* The block's run, named by its top-left pixel: a pixel's points never collide with it. */
        qmc_run run = session_pixel_run(rs, corner, RUN_HIGHLIGHT_BLOCK,
                                        frame * (uint64_t)(HL_SHARE_POINTS * rs->hl.secondary_rays), 0);
        vec3 out[HL_SHARE_POINTS];
        unsigned estimated = hl_estimate_shared(&rs->hl, rs->scene, xs, m, run, slot, rngs, st, out);
        for (int j = 0; j < m; j++)
            if (estimated >> j & 1u) shared[idx[j]] = out[j], has_shared[idx[j]] = 1;
    }
    st->pass_ns[PASS_HIGHLIGHTS] += clock_ns() - t0;
}

/* The packet of pixels from (bx, by), PACKET_W x PACKET_H of them where the image has them. Camera
 * rays go in packets: neighbours share most of their BVH traversal. A pixel's sample depends on the
 * frame, the pixel and its state (its 2x2 block's: inside the packet), which only begin_frame reads
 * across pixels, never on the packets rendered before it: a frame takes the same samples in any
 * order, whole or in parts (docs/design.md, "What a frame is"). */
static void render_packet(render_session *rs, render_stats *st, const camera_raster *raster, uint64_t frame, int bx,
                          int by) {
    const render_params *p = &rs->params;
    int x1 = bx + PACKET_W < p->width ? bx + PACKET_W : p->width;
    int y1 = by + PACKET_H < p->height ? by + PACKET_H : p->height;
    int pixel[SCENE_PACKET], n = 0;
    rng_state rng[SCENE_PACKET];
    vec3 d[SCENE_PACKET];
    surface_hit hit[SCENE_PACKET];
    for (int y = by; y < y1; y++) {
        for (int x = bx; x < x1; x++, n++) {
            pixel[n] = y * p->width + x;
            rng[n] = rng_for((uint64_t)pixel[n], frame, p->seed);
            /* A pixel's positions over frames follow the R2 sequence from a random start: any run
             * of frames covers the pixel evenly, so a small bright feature inside it (a highlight
             * seen in a curved mirror) converges faster than with independent positions, and each
             * frame's position is still uniform. */
            rng_state start = rng_for((uint64_t)pixel[n], UINT64_MAX, p->seed);
            vec2 j = sample_r2((int)(frame & 0x3fffffff), rng_vec2(&start));
            d[n] = camera_raster_dir(raster, (float)x + j.x, (float)y + j.y);
        }
    }
    int timed = p->method != METHOD_PT; /* camera rays belong to the direct pass */
    uint64_t t0 = timed ? clock_ns() : 0;
    unsigned hits = scene_intersect_packet(rs->scene, rs->cam.position, d, n, hit);
    if (timed) st->pass_ns[PASS_DIRECT] += clock_ns() - t0;
    /* Each pixel's highlight state before any pixel's highlights: a block shares only among pixels
     * that are not spread. */
    int highlights = p->method != METHOD_PT && rs->plan.highlights && rs->plan.max_depth > 1;
    for (int i = 0; highlights && rs->adapt && i < n; i++) {
        if (rs->hl_state[pixel[i]] == HL_PIXEL_UNPROBED)
            rs->hl_state[pixel[i]] = (uint8_t)probe_state(rs, st, raster, pixel[i]);
    }
    vec3 shared[SCENE_PACKET];
    int has_shared[SCENE_PACKET] = {0};
    if (highlights && rs->hl.share && rs->hl.secondary_rays <= HL_SHARE_MAX_RAYS)
        block_highlights(rs, st, pixel, d, hit, hits, n, shared, has_shared);
    for (int i = 0; i < n; i++)
        render_sample(rs, st, raster, pixel[i], d[i], (hits >> i & 1u) ? &hit[i] : NULL, &rng[i],
                      has_shared[i] ? &shared[i] : NULL);
}

/* A whole frame's task: a TILE x TILE tile, its packets in turn. */
static void render_tile(void *ctx, int tile, int worker) {
    render_session *rs = ctx;
    const render_params *p = &rs->params;
    render_stats *st = &rs->workers[worker].st;
    if (rs->abort_flag && atomic_load_explicit(rs->abort_flag, memory_order_relaxed)) return;
    int x0 = (tile % rs->tiles_x) * TILE, y0 = (tile / rs->tiles_x) * TILE;
    int x1 = x0 + TILE < p->width ? x0 + TILE : p->width;
    int y1 = y0 + TILE < p->height ? y0 + TILE : p->height;
    camera_raster raster = camera_raster_make(&rs->cam, p->width, p->height);
    const uint64_t frame = next_frame_index(rs);
    uint64_t tile_start = clock_ns();
    for (int by = y0; by < y1; by += PACKET_H)
        for (int bx = x0; bx < x1; bx += PACKET_W) render_packet(rs, st, &raster, frame, bx, by);
    if (p->method == METHOD_PT) st->pass_ns[PASS_PATHS] += clock_ns() - tile_start;
}

/* A part's task: a chunk of its packets. */
static void render_chunk(void *ctx, int chunk, int worker) {
    render_session *rs = ctx;
    const render_params *p = &rs->params;
    const part_job *job = &rs->part;
    render_stats *st = &rs->workers[worker].st;
    if (rs->abort_flag && atomic_load_explicit(rs->abort_flag, memory_order_relaxed)) return;
    camera_raster raster = camera_raster_make(&rs->cam, p->width, p->height);
    const uint64_t frame = next_frame_index(rs);
    uint64_t chunk_start = clock_ns();
    int end = (chunk + 1) * job->chunk < job->packets ? (chunk + 1) * job->chunk : job->packets;
    for (int k = chunk * job->chunk; k < end; k++) {
        int i, j;
        if (job->list) {
            i = (int)(job->list[k] % (uint32_t)job->cols), j = (int)(job->list[k] / (uint32_t)job->cols);
        } else {
            i = job->cell.x + job->cell.a * (k % job->cols), j = job->cell.y + job->cell.b * (k / job->cols);
        }
        render_packet(rs, st, &raster, frame, PACKET_W * i, PACKET_H * j);
    }
    if (p->method == METHOD_PT) st->pass_ns[PASS_PATHS] += clock_ns() - chunk_start;
}

/* A frame's work before its pixels (allocation plans, the prefiltered map, the highlight settings,
 * the virtual lights, the judgements): 0, or -1 with rs->error set. */
static int begin_frame(render_session *rs) {
    const render_params *p = &rs->params;
    const uint64_t frame = next_frame_index(rs);
    rs->adapt = p->method != METHOD_PT && rs->vl.adapt == VL_ADAPT_ON;
    if (p->method == METHOD_AUTO && !rs->choice.rec && choice_init(&rs->choice, p->width, p->height) != 0) {
        snprintf(rs->error, sizeof rs->error, "out of memory for a %dx%d image", p->width, p->height);
        return -1;
    }
    if (rs->adapt) {
        pixel_alloc_plan(&rs->direct, MANYLIGHT_DIRECT_SAMPLES, MANYLIGHT_MAX_DIRECT_SAMPLES, frame,
                         p->seed ^ 0x646972656374ULL);
        if (rs->plan.virtual_lights)
            pixel_alloc_plan(&rs->glossy, rs->vl.glossy_rays, VL_MAX_GLOSSY_RAYS, frame, p->seed);
    }
    if (rs->plan.highlights) {
        if (rs->plan.env_prefilter && (!rs->envf || rs->envf_map != rs->scene->env)) {
            env_vmf_filter_destroy(rs->envf);
            rs->envf_map = rs->scene->env;
            if (!(rs->envf = env_vmf_filter_create(rs->scene->env, rs->error, sizeof rs->error))) return -1;
        }
        rs->totals.env_filter_bytes = rs->plan.env_prefilter ? env_vmf_filter_bytes(rs->envf) : 0;
        rs->hl = hl_setup_from(rs->scene, &rs->params.vl, rs->plan.env_prefilter ? rs->envf : NULL);
        if (rs->adapt && rs->hl.choose && !rs->hl_merge &&
            !(rs->hl_merge = calloc((size_t)p->width * (size_t)p->height, sizeof *rs->hl_merge))) {
            snprintf(rs->error, sizeof rs->error, "out of memory for a %dx%d image", p->width, p->height);
            return -1;
        }
    }
    if (rs->plan.virtual_lights) {
        uint64_t t0 = clock_ns();
        if (manylight_begin_frame(&rs->ml, rs->scene, &rs->cam, &rs->params, &rs->plan, (long long)frame, rs->pool,
                                  &rs->totals, rs->error, sizeof rs->error) != 0)
            return -1;
        rs->totals.pass_ns[PASS_VIRTUAL_LIGHTS] += clock_ns() - t0;
    }
    if (p->method == METHOD_AUTO) { /* its virtual lights made: a new accumulation's probe, then judged */
        if (rs->frames == 0) threadpool_run(rs->pool, session_auto_probe, rs, rs->choice.tiles_y);
        if (choice_judge_due(rs->frames)) {
            choice_judge(&rs->choice);
            rs->totals.auto_vl_tiles = (uint64_t)rs->choice.vl_tiles;
        }
    }
    if (dim_judged(rs) && hl_judge_due(rs->frames)) judge_dim_pixels(rs, rs->hl.dim_share);
    if (rs->plan.highlights && rs->adapt && rs->hl.choose && hl_judge_due(rs->frames)) {
        int traced = hl_judge_trace(rs->hl_merge, p->width, p->height); /* out of memory: judged next time */
        if (traced >= 0) rs->totals.hl_traced_pixels = (uint64_t)traced;
    }
    return 0;
}

/* The workers' counters into the totals, and cleared. */
static void gather_stats(render_session *rs) {
    for (int w = 0; w < threadpool_size(rs->pool); w++) {
        render_stats_add(&rs->totals, &rs->workers[w].st);
        memset(&rs->workers[w].st, 0, sizeof rs->workers[w].st);
    }
}

/* parts clamped to a power of two in [1, SESSION_MAX_PARTS], the nearest below. */
static int allowed_parts(int parts) {
    int k = 1;
    while (k < SESSION_MAX_PARTS && 2 * k <= parts) k *= 2;
    return k;
}

part_cell session_part_cell(int parts, int rank) {
    parts = allowed_parts(parts);
    int k = 0;
    while (1 << k < parts) k++;
    int bits_x = (k + 1) / 2, bits_y = k / 2;
    part_cell c = {1 << bits_x, 1 << bits_y, 0, 0};
    /* The rank's bits from the lowest name the cell's from the highest: consecutive ranks land far
     * apart. An odd k's extra x bit first (the two halves of a 2:1 lattice are square), then pairs as
     * in Bayer's matrix [[0, 2], [3, 1]]: the first bit of a pair moves x and y (the diagonal), the
     * second x. */
    unsigned r = (unsigned)rank & (unsigned)(parts - 1);
    int bx = bits_x - 1, by = bits_y - 1;
    if (k & 1) {
        c.x |= (int)(r & 1u) << bx--;
        r >>= 1;
    }
    for (; by >= 0; bx--, by--, r >>= 2) {
        c.x |= (int)((r ^ r >> 1) & 1u) << bx;
        c.y |= (int)(r & 1u) << by;
    }
    return c;
}

/* The frame's packets the neediest first, a need's in the lattice's order from the frame's first
 * part on (a counting sort on need and rank): 0, or -1 out of memory. */
static int order_by_need(render_session *rs, int packets_x, int packets_y) {
    int parts = rs->frame_parts;
    size_t n = (size_t)packets_x * (size_t)packets_y, keys = (size_t)SESSION_NEED_LEVELS * (size_t)parts;
    if (rs->order_size < n) {
        uint32_t *o = realloc(rs->order, sizeof(uint32_t) * n);
        if (!o) return -1;
        rs->order = o, rs->order_size = n;
    }
    uint32_t *key = malloc(sizeof(uint32_t) * n), *start = calloc(keys + 1, sizeof(uint32_t));
    if (!key || !start) return free(key), free(start), -1;
    int rank_of[SESSION_MAX_PARTS];
    part_cell lattice = session_part_cell(parts, 0);
    for (int r = 0; r < parts; r++) {
        part_cell c = session_part_cell(parts, r);
        rank_of[c.y * lattice.a + c.x] = (r - rs->first_part + parts) % parts;
    }
    for (int j = 0; j < packets_y; j++)
        for (int i = 0; i < packets_x; i++) {
            size_t q = (size_t)j * (size_t)packets_x + (size_t)i;
            int need = rs->need[q] < SESSION_NEED_LEVELS ? rs->need[q] : SESSION_NEED_LEVELS - 1;
            key[q] = (uint32_t)((SESSION_NEED_LEVELS - 1 - need) * parts +
                                rank_of[j % lattice.b * lattice.a + i % lattice.a]);
            start[key[q] + 1]++;
        }
    for (size_t k = 0; k < keys; k++) start[k + 1] += start[k];
    for (size_t q = 0; q < n; q++) rs->order[start[key[q]]++] = (uint32_t)q;
    free(key);
    free(start);
    return 0;
}

int session_render_part(render_session *rs, int parts, int *frame_done) {
    if (frame_done) *frame_done = 0;
    int packets_x = (rs->params.width + PACKET_W - 1) / PACKET_W;
    int packets_y = (rs->params.height + PACKET_H - 1) / PACKET_H;
    if (!rs->frame_parts) {
        if (begin_frame(rs) != 0) return -1;
        rs->frame_begun = 1;
        rs->frame_parts = allowed_parts(parts);
        rs->parts_done = 0;
        rs->first_part = rs->next_part % rs->frame_parts;
        rs->part.list = NULL;
        if (rs->need && rs->frame_parts > 1 && order_by_need(rs, packets_x, packets_y) != 0) {
            rs->frame_parts = 0;
            snprintf(rs->error, sizeof rs->error, "out of memory for a frame's order");
            return -1;
        }
        if (rs->need && rs->frame_parts > 1) rs->part.list = rs->order;
    }
    int rank = (rs->first_part + rs->parts_done) % rs->frame_parts;
    rs->next_part = rank + 1; /* begun, whatever comes of it: the rotation never depends on timing */
    if (rs->frame_parts == 1) {
        threadpool_run(rs->pool, render_tile, rs, rs->tiles_x * rs->tiles_y);
    } else {
        part_job *job = &rs->part;
        if (job->list) { /* part p: the p-th of frame_parts equal runs of the order */
            size_t n = (size_t)packets_x * (size_t)packets_y, p = (size_t)rs->parts_done, k = (size_t)rs->frame_parts;
            size_t b = n * p / k, e = n * (p + 1) / k;
            job->list = rs->order + b;
            job->cols = packets_x;
            job->packets = (int)(e - b);
        } else {
            job->cell = session_part_cell(rs->frame_parts, rank);
            /* cell.x < a: 0 where the image is too small for the cell (an empty part) */
            job->cols = (packets_x - job->cell.x + job->cell.a - 1) / job->cell.a;
            job->packets = job->cols * ((packets_y - job->cell.y + job->cell.b - 1) / job->cell.b);
        }
        int chunks = PART_CHUNKS_A_THREAD * threadpool_size(rs->pool);
        job->chunk = (job->packets + chunks - 1) / chunks;
        job->chunk = job->chunk < 1 ? 1 : job->chunk > PART_CHUNK ? PART_CHUNK : job->chunk;
        threadpool_run(rs->pool, render_chunk, rs, (job->packets + job->chunk - 1) / job->chunk);
    }
    gather_stats(rs);
    if (rs->abort_flag && atomic_load(rs->abort_flag)) {
        rs->frame_parts = 0; /* abandoned: the caller resets */
        return 1;
    }
    if (++rs->parts_done == rs->frame_parts) {
        film_end_pass(&rs->film);
        rs->frames++;
        rs->frame_parts = 0;
        if (frame_done) *frame_done = 1;
    }
    return 0;
}

int session_render_frame(render_session *rs) {
    int done = 0, status;
    do status = session_render_part(rs, 1, &done);
    while (status == 0 && !done);
    return status;
}

/* One request of session_render_extra: its samples from a stream of their own (the call's, the
 * request's), at R2 positions over the pixel from a random start. */
static void render_extra(void *ctx, int task, int worker) {
    render_session *rs = ctx;
    extra_request *q = &rs->extra[task];
    memset(q->sum, 0, sizeof q->sum);
    memset(q->sumsq, 0, sizeof q->sumsq);
    q->taken = 0;
    const render_params *p = &rs->params;
    if (q->pixel < 0 || q->pixel >= p->width * p->height) return;
    if (rs->abort_flag && atomic_load_explicit(rs->abort_flag, memory_order_relaxed)) return;
    render_stats *st = &rs->workers[worker].st;
    camera_raster raster = camera_raster_make(&rs->cam, p->width, p->height);
    rng_state rng = rng_for((uint64_t)task, (1ull << 62) | rs->extra_calls, p->seed); /* no frame's stream */
    vec2 shift = rng_vec2(&rng);
    int x = q->pixel % p->width, y = q->pixel / p->width;
    for (int k = 0; k < q->samples; k++) {
        vec2 u = sample_r2(k, shift);
        vec3 d = camera_raster_dir(&raster, (float)x + u.x, (float)y + u.y), L[COMP_COUNT];
        surface_hit hit;
        const surface_hit *first = scene_intersect(rs->scene, rs->cam.position, d, INFINITY, &hit) ? &hit : NULL;
        estimate_sample(rs, st, &raster, q->pixel, d, first, &rng, NULL, 1, L, NULL);
        int finite = 1;
        for (int c = 0; c < COMP_COUNT; c++) finite &= is_finite3(L[c]);
        if (!finite) {
            st->rejected_samples++;
            continue;
        }
        for (int c = 0; c < COMP_COUNT; c++) {
            float l = q->weight[0] * L[c].x + q->weight[1] * L[c].y + q->weight[2] * L[c].z;
            q->sum[c][0] += L[c].x, q->sum[c][1] += L[c].y, q->sum[c][2] += L[c].z;
            q->sumsq[c] += l * l;
        }
        q->taken++;
    }
}

int session_render_extra(render_session *rs, extra_request *req, int n) {
    for (int i = 0; i < n; i++) req[i].taken = 0;
    if (!rs->frame_begun || (rs->abort_flag && atomic_load(rs->abort_flag))) return 1;
    rs->extra = req;
    threadpool_run(rs->pool, render_extra, rs, n);
    rs->extra = NULL;
    rs->extra_calls++;
    gather_stats(rs);
    return 0;
}

int session_frame_parts(const render_session *rs) { return rs->frame_parts; }
int session_frame_parts_done(const render_session *rs) { return rs->frame_parts ? rs->parts_done : 0; }

void session_set_sink(render_session *rs, const sample_sink *sink) { rs->sink = sink; }

void session_set_packet_need(render_session *rs, const uint8_t *need) { rs->need = need; }

void session_set_abort_flag(render_session *rs, const atomic_int *flag) { rs->abort_flag = flag; }

const char *session_error(const render_session *rs) { return rs->error; }

void session_work_map(const render_session *rs, float *rgb) {
    size_t n = (size_t)rs->params.width * (size_t)rs->params.height;
    float most = 0.0f;
    for (size_t i = 0; i < n; i++) most = fmaxf(most, rs->pixel_rays[i]);
    for (size_t i = 0; i < n; i++)
        rgb[3 * i] = rgb[3 * i + 1] = rgb[3 * i + 2] = most > 0.0f ? rs->pixel_rays[i] / most : 0.0f;
}

void session_reset(render_session *rs) {
    film_clear(&rs->film);
    pixel_alloc_reset(&rs->glossy);
    pixel_alloc_reset(&rs->direct);
    memset(rs->hl_state, HL_PIXEL_UNPROBED, (size_t)rs->params.width * (size_t)rs->params.height);
    memset(rs->direct_taken, 0, (size_t)rs->params.width * (size_t)rs->params.height * sizeof *rs->direct_taken);
    memset(rs->pixel_rays, 0, (size_t)rs->params.width * (size_t)rs->params.height * sizeof *rs->pixel_rays);
    if (rs->hl_merge)
        memset(rs->hl_merge, 0, (size_t)rs->params.width * (size_t)rs->params.height * sizeof *rs->hl_merge);
    choice_reset(&rs->choice);
    rs->frames = 0;
    rs->frame_parts = 0; /* a frame under way is abandoned; next_part stays, so the next part differs */
    rs->frame_begun = 0;
    memset(&rs->totals, 0, sizeof rs->totals); /* statistics describe the running mean */
}

int session_scene_changed(render_session *rs) {
    scene_analysis a;
    if (scene_analyse(rs->scene, &a, rs->error, sizeof rs->error) != 0) return -1;
    scene_analysis_free(&rs->analysis);
    rs->analysis = a;
    if (rs->envf_map != rs->scene->env) { /* another map (a light edit keeps the filter) */
        env_vmf_filter_destroy(rs->envf);
        rs->envf = NULL;
    }
    rs->plan = session_make_plan(rs);
    session_reset(rs);
    return 0;
}

void session_set_camera(render_session *rs, const camera *cam) {
    rs->cam = *cam;
    session_reset(rs);
}

const camera *session_camera(const render_session *rs) { return &rs->cam; }

static void take_params(render_session *rs, const render_params *params) {
    render_params p = *params;
    p.width = rs->params.width;
    p.height = rs->params.height;
    p.threads = rs->params.threads;
    p = render_params_resolve_frame(&p);
    rs->params = p;
    rs->vl = vl_params_resolve(&p.vl);
    rs->plan = session_make_plan(rs);
}

void session_set_params(render_session *rs, const render_params *params) {
    take_params(rs, params);
    session_reset(rs);
}

void session_restart(render_session *rs, const render_params *params, const camera *cam) {
    take_params(rs, params);
    rs->cam = *cam;
    session_reset(rs);
}

long long session_frames(const render_session *rs) { return rs->frames; }
const film *session_film(const render_session *rs) { return &rs->film; }
const render_params *session_params(const render_session *rs) { return &rs->params; }
render_stats session_stats(const render_session *rs) { return rs->totals; }
const scene_analysis *session_analysis(const render_session *rs) { return &rs->analysis; }
const effect_plan *session_plan(const render_session *rs) { return &rs->plan; }
