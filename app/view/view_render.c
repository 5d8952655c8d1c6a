/* glint view: the render thread. It owns the scene, the render session and the display pipeline;
 * between updates it takes the UI's requests from the shared state, and after each update publishes
 * the image shown and its statistics there (view_render.h; the UI asks and takes through
 * view_controller.h).
 *
 * An update renders one part of a frame (session_render_part), as many parts to a frame as keep an
 * update near UPDATE_MS, and the display (display.h) takes that part's samples, carries history
 * over camera and light changes, and filters: the window shows the full resolution at every
 * update, moving or not, and the film behind it is the estimate glint render makes. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "camera.h"
#include "cli.h"
#include "display.h"
#include "envmap.h"
#include "lights.h"
#include "metrics.h"
#include "reference.h"
#include "view_render.h"

/* An update (a part and the display's work) takes about UPDATE_MS while things move and for
 * YOUNG_SECONDS after a change, so the image follows motion 10 times a second: 90 ms, as what an
 * update costs beside its budget varies (a part's cost, the window's share of the cores), and at
 * 100 ms the viewer made 9 a second (docs/benchmarks.md); once the
 * steps of a drag have stopped coming, REST_UPDATE_MS: the display's fixed cost (about half of a
 * young update's) paid half as often, so that more of the first seconds after a stop go to
 * samples. A new estimator's first frame, its cost unknown, comes in FIRST_PARTS parts. */
#define UPDATE_MS 90.0
#define REST_UPDATE_MS 200.0
#define YOUNG_SECONDS 0.5
#define FIRST_PARTS 64
/* Of what an update may render, this share goes to the display's own samples (display_plan_extra):
 * where the image shown errs most, a bright speck in a curved mirror, the film's one sample a
 * frame is far too few, and a few hundred there take more off the error than a part's thousands
 * spread evenly (docs/benchmarks.md). At most EXTRA_REQUESTS pixels an update. */
#define EXTRA_SHARE 0.2
#define EXTRA_REQUESTS 4096
/* Light edits are analysed (the plan made again) once they rest this long, not at every step of a
 * drag. */
#define SETTLE_SECONDS 0.3

/* Loads go to a thread of their own, which reads files while frames go on: only a load that
 * succeeds stops the frame in flight, so a failed one leaves the accumulation as it was. One at a
 * time: the loader takes the next request once the render thread has taken the last result. */
typedef struct {
    int active; /* taken from the requests, not yet applied (under sh->lock) */
    int done;   /* read (under sh->lock); the fields below are then the render thread's */
    int ok;
    int kind;
    char path[1024], env[1024];
    char variant[64]; /* LOAD_SCENE: the material variant to show ("": the defaults)... */
    int keep_view;    /* ...in place of the last scene, from the same view */
    scene *scene;     /* LOAD_SCENE's result, with the environment env */
    image_rgb image;  /* LOAD_ENV's */
    char err[1200];
} load_job;

/* Written and read by the render thread alone (the UI sees only shared_state). */
struct render_thread {
    shared_state *sh;
    pthread_t thread;
    scene *scene;
    render_session *session;
    display *disp;
    image_buf back;             /* the next image, swapped with the shared one when published */
    light_edits lights_applied; /* the edits the scene has */
    image_rgb reference;        /* for the error of each frame */
    float *combined;            /* the film's whole image, or the display's, for the error */
    size_t combined_len;
    int scene_edited; /* lights changed since the plan was made */
    pthread_t loader;
    int loader_running;
    load_job job;
    int film_partial; /* a stopped part left samples in the film; cleared by the next frame that ends */
    /* What an update costs with the current settings (0: not measured): a frame's rendering
     * without its set-up, the set-up a frame begins with (the virtual lights), the rest of an
     * update (the display's work: the view's change, the extra samples' plan, the image shown). */
    double frame_ms, setup_ms, display_ms;
    double extra_ms;        /* an extra sample's (display_plan_extra), 0: not measured */
    extra_request *extra;   /* EXTRA_REQUESTS of them */
    uint64_t accumulations; /* begun since the thread started: each its own random numbers */
    render_params params_applied;
    camera cam_applied;
    unsigned shown_mask; /* what the last image published showed */
    int shown_denoise;
};

static void set_message(render_thread *rt, const char *fmt, const char *a, const char *b) {
    shared_state *sh = rt->sh;
    pthread_mutex_lock(&sh->lock);
    snprintf(sh->message, sizeof sh->message, fmt, a, b);
    sh->message_serial++;
    pthread_mutex_unlock(&sh->lock);
}

/* Under the lock: whether refinement of a view with `frames` whole frames stops here (paused, or at
 * a limit). */
static int refinement_held(const shared_state *sh, long long frames) {
    if (frames < 1) return 0; /* every new view gets one whole frame */
    return sh->paused || (sh->spp_limit > 0 && frames >= sh->spp_limit) ||
           (sh->time_limit > 0.0 && cli_now() - sh->stats.reset_at >= sh->time_limit);
}

/* Without the lock: waits a little, and returns with the lock taken. */
static void refinement_hold(shared_state *sh) {
    double t0 = cli_now();
    nanosleep(&(struct timespec){0, 10 * 1000 * 1000}, NULL);
    pthread_mutex_lock(&sh->lock);
    sh->stats.reset_at += cli_now() - t0; /* time held is not refinement time */
}

/* Each accumulation its own random numbers: while the camera moves every update starts one, and
 * with one seed each would draw the same virtual lights, whose blotches the display's history would
 * then never average away. The first keeps the seed asked for: a view never left renders exactly as
 * glint render --seed renders it. */
static uint64_t accumulation_seed(uint64_t seed, uint64_t k) {
    return k == 0 ? seed : seed ^ (k * 0x9e3779b97f4a7c15ull);
}

/* (Re)creates the session and the display for the current scene at w x h. Returns 0 or -1
 * (message set). */
static int make_sessions(render_thread *rt, int w, int h, const camera *cam, const render_params *params) {
    session_destroy(rt->session);
    display_destroy(rt->disp);
    rt->session = NULL;
    rt->disp = NULL;
    render_params p = *params;
    char err[512];
    p.width = w;
    p.height = h;
    p.seed = accumulation_seed(params->seed, rt->accumulations++);
    rt->session = session_create(rt->scene, cam, &p, err, sizeof err);
    if (rt->session) rt->disp = display_create(w, h, p.threads, err, sizeof err);
    if (!rt->session || !rt->disp) {
        set_message(rt, "%s%s", err, "");
        return -1;
    }
    session_set_abort_flag(rt->session, &rt->sh->abort_frame);
    session_set_sink(rt->session, display_sink(rt->disp));
    display_change_view(rt->disp, rt->scene, cam, DISPLAY_RESTART);
    rt->film_partial = 0; /* a new film */
    rt->frame_ms = rt->setup_ms = rt->extra_ms = 0.0;
    rt->params_applied = *params;
    rt->cam_applied = *cam;
    return 0;
}

/* Gives s the environment named by source (a map's path, ENV_SKY, or "" for none). The scene
 * must not be rendering. Returns 0, or -1 with err set (the scene keeps its old map). */
static int set_environment(scene *s, const char *source, char *err, size_t errlen) {
    if (strcmp(source, ENV_SKY) == 0) { /* a constant radiance of 1 from every direction */
        image_rgb sky = {8, 4, malloc(sizeof(float) * 3 * 8 * 4)};
        if (!sky.rgb) return snprintf(err, errlen, "uniform sky: out of memory"), -1;
        for (int i = 0; i < 3 * 8 * 4; i++) sky.rgb[i] = 1.0f;
        return scene_set_env_image(s, &sky, 0.0f, err, errlen);
    }
    if (source[0]) return scene_set_env(s, source, 0.0f, err, errlen);
    if (!s->env) return 0;
    env_map *old = s->env;
    s->env = NULL;
    if (scene_build_lights(s, err, errlen) != 0) {
        s->env = old;
        char ignored[256];
        scene_build_lights(s, ignored, sizeof ignored);
        return -1;
    }
    env_map_destroy(old);
    return 0;
}

static void load_failed(render_thread *rt, const char *err) {
    cli_error("%s", err);
    set_message(rt, "%s%s", err, "");
}

/* Reads what the job names: a scene (given the viewer's environment) or a map. */
static int load_files(load_job *j) {
    if (j->kind == LOAD_SCENE) {
        if (!(j->scene = scene_load(j->path, cli_print_warning, NULL, j->err, sizeof j->err))) return 0;
        if (j->variant[0] && scene_select_variant(j->scene, j->variant, j->err, sizeof j->err) != 0) return 0;
        /* The environment stays with the viewer, not with the scene. */
        if (j->env[0] && set_environment(j->scene, j->env, j->err, sizeof j->err) != 0) {
            cli_warning("%s; %s opens without it", j->err, j->path);
            j->env[0] = 0;
        }
        return 1;
    }
    if (j->kind == LOAD_ENV) return image_rgb_load(j->path, &j->image, j->err, sizeof j->err) == 0;
    return 1; /* the uniform sky, no environment: nothing to read */
}

static void *loader_main(void *arg) {
    render_thread *rt = arg;
    shared_state *sh = rt->sh;
    load_job *j = &rt->job;
    pthread_mutex_lock(&sh->lock);
    for (;;) {
        while (!sh->quit && !(sh->load_kind && !j->active)) pthread_cond_wait(&sh->load_cond, &sh->lock);
        if (sh->quit) break;
        *j = (load_job){.active = 1, .kind = sh->load_kind};
        snprintf(j->path, sizeof j->path, "%s", sh->load_path);
        snprintf(j->env, sizeof j->env, "%s", sh->env_now);
        snprintf(j->variant, sizeof j->variant, "%s", sh->load_variant);
        j->keep_view = sh->load_keep_view;
        sh->load_kind = LOAD_NONE;
        pthread_mutex_unlock(&sh->lock);
        int ok = load_files(j);
        pthread_mutex_lock(&sh->lock);
        j->ok = ok;
        j->done = 1;
        sh->requests++;
    }
    pthread_mutex_unlock(&sh->lock);
    return NULL;
}

static void load_job_free(load_job *j) {
    if (j->scene) scene_destroy(j->scene);
    image_rgb_free(&j->image);
    memset(j, 0, sizeof *j);
}

/* Puts scene s (its environment env) in place of the current one, seen from keep when given
 * (another variant of the same scene), else from its own default view. */
static void replace_scene(render_thread *rt, scene *s, const char *env, const char *path, const render_params *params,
                          const camera *keep) {
    shared_state *sh = rt->sh;
    /* The session and the display read the old scene: replace them with it. */
    int w = session_params(rt->session)->width, h = session_params(rt->session)->height;
    session_destroy(rt->session);
    display_destroy(rt->disp);
    rt->session = NULL;
    rt->disp = NULL;
    pthread_rwlock_wrlock(&sh->scene_lock);
    scene_destroy(rt->scene);
    rt->scene = s;
    sh->scene_now = s;
    pthread_rwlock_unlock(&sh->scene_lock);
    clear_light_edits(&rt->lights_applied);
    camera c = keep ? *keep : scene_camera(s, -1, (float)w / (float)h);
    make_sessions(rt, w, h, &c, params);
    pthread_mutex_lock(&sh->lock);
    fill_scene_info(&sh->info, s);
    sh->info.kept_view = keep != NULL;
    sh->info_serial++;
    snprintf(sh->env_now, sizeof sh->env_now, "%s", env);
    pthread_mutex_unlock(&sh->lock);
    set_message(rt, "loaded %s%s", path, "");
}

/* A finished load job, between frames. Returns 1 when the scene changed (the accumulation
 * restarts), 0 when the load failed and nothing changed. */
static int finish_load(render_thread *rt, load_job *j, const camera *cam, const render_params *params) {
    char err[1200];
    shared_state *sh = rt->sh;
    int kind = j->kind;
    if (!j->ok) return load_failed(rt, j->err), 0;
    if (kind == LOAD_SCENE) {
        replace_scene(rt, j->scene, j->env, j->path, params, j->keep_view ? cam : NULL);
        j->scene = NULL; /* the render thread's now */
        return 1;
    }
    const char *source = kind == LOAD_SKY ? ENV_SKY : kind == LOAD_NO_ENV ? "" : j->path;
    pthread_rwlock_wrlock(&sh->scene_lock);
    char sub[512];
    int failed = kind == LOAD_ENV ? scene_set_env_image(rt->scene, &j->image, 0.0f, sub, sizeof sub) != 0
                                  : set_environment(rt->scene, source, sub, sizeof sub) != 0;
    pthread_rwlock_unlock(&sh->scene_lock);
    if (failed) {
        snprintf(err, sizeof err, "%.600s: %.500s",
                 kind == LOAD_ENV ? j->path
                 : source[0]      ? "uniform sky"
                                  : "no environment",
                 sub);
        return load_failed(rt, err), 0;
    }
    pthread_mutex_lock(&sh->lock);
    snprintf(sh->env_now, sizeof sh->env_now, "%s", source);
    pthread_mutex_unlock(&sh->lock);
    /* The plan depends on the map (its prefiltering, its light); the display keeps what the map
     * did not change. */
    if (session_scene_changed(rt->session) != 0) load_failed(rt, session_error(rt->session));
    session_set_camera(rt->session, cam);
    display_change_view(rt->disp, rt->scene, cam, DISPLAY_LIGHTS);
    set_message(rt,
                kind == LOAD_SKY      ? "uniform sky%s%s"
                : kind == LOAD_NO_ENV ? "no environment%s%s"
                                      : "environment %s%s",
                kind == LOAD_ENV ? j->path : "", "");
    return 1;
}

/* Brings the scene's lights to the wanted offsets and gains (render thread, between frames). */
static void apply_light_edits(render_thread *rt, const light_edits *wanted) {
    char err[512];
    light_edits *done = &rt->lights_applied;
    pthread_rwlock_wrlock(&rt->sh->scene_lock); /* moving a light rebuilds the BVH */
    for (int g = 0; g < MAX_LIGHT_GROUPS; g++) {
        vec3 d = sub3(wanted->offset[g], done->offset[g]);
        float gain = wanted->gain[g];
        int failed = !is_black3(d) && scene_move_light(rt->scene, g, d, err, sizeof err) != 0;
        failed = failed || (gain != done->gain[g] && scene_set_light_gain(rt->scene, g, gain, err, sizeof err) != 0);
        if (failed) {
            cli_error("%s", err);
            set_message(rt, "%s%s", err, "");
        }
        /* Taken as applied either way: a failed edit is reported once, not every frame. */
        rt->scene_edited |= !is_black3(d) || gain != done->gain[g];
        done->offset[g] = wanted->offset[g];
        done->gain[g] = gain;
    }
    pthread_rwlock_unlock(&rt->sh->scene_lock);
}

/* The relative L2 error of img (w x h, every component) against the reference; -1 without a
 * reference of this size. */
static double image_error(const render_thread *rt, const float *img, int w, int h) {
    const image_rgb *ref = &rt->reference;
    if (!ref->rgb || ref->width != w || ref->height != h) return -1.0;
    return metric_rel_l2(img, ref->rgb, 3 * (size_t)w * (size_t)h);
}

/* The film's whole image (the estimate, every component) into rt->combined; NULL out of memory. */
static const float *estimate_image(render_thread *rt) {
    const film *f = session_film(rt->session);
    size_t n = 3 * (size_t)f->width * (size_t)f->height;
    if (rt->combined_len != n) {
        free(rt->combined);
        rt->combined = malloc(sizeof(float) * n);
        rt->combined_len = rt->combined ? n : 0;
        if (!rt->combined) return NULL;
    }
    film_resolve(f, COMP_MASK_ALL, rt->combined);
    return rt->combined;
}

/* What an update did, for publish. */
typedef struct {
    int measure;          /* the view is the reference's: errors count */
    int frame_done;       /* the update ended a frame */
    int rendered;         /* it rendered a part (not only a new look at the display) */
    double part_ms;       /* its last part's time */
    uint64_t resets_seen; /* the accumulation it belongs to */
    uint64_t gen;
} update_info;

/* Resolves the display with the components shown and the filter as asked, and publishes it with
 * the update's statistics; at the end of a frame also the estimate's error. */
static void publish(render_thread *rt, const update_info *up) {
    shared_state *sh = rt->sh;
    render_session *rs = rt->session;
    const film *f = session_film(rs);
    if (rt->back.width != f->width || rt->back.height != f->height) {
        free(rt->back.rgb);
        rt->back.rgb = malloc(sizeof(float) * 3 * (size_t)f->width * (size_t)f->height);
        rt->back.width = rt->back.rgb ? f->width : 0;
        rt->back.height = rt->back.rgb ? f->height : 0;
        if (!rt->back.rgb) return;
    }
    pthread_mutex_lock(&sh->lock);
    unsigned mask = sh->show_mask;
    int denoise = sh->denoise;
    pthread_mutex_unlock(&sh->lock);
    if (mask == SHOW_ESTIMATOR_SHARE)
        session_vl_share(rs, rt->back.rgb);
    else if (mask == SHOW_WORK_MAP)
        session_work_map(rs, rt->back.rgb);
    else
        display_resolve(rt->disp, mask, denoise, rt->back.rgb);
    rt->shown_mask = mask;
    rt->shown_denoise = denoise;
    display_stats ds = display_get_stats(rt->disp);
    rt->back.full_w = f->width;
    rt->back.full_h = f->height;
    rt->back.generation = up->gen;
    rt->back.cam = *session_camera(rs); /* what its samples were rendered from, whatever asked since */
    rt->back.lights = rt->lights_applied;
    rt->back.frames = session_frames(rs);
    rt->back.seed = session_params(rs)->seed;
    rt->back.denoise = denoise;
    rt->back.mask = mask;
    rt->back.published_at = cli_now();
    /* what is shown against the reference (the whole image only: another component has none) */
    double shown_error =
        up->measure && mask == COMP_MASK_ALL ? image_error(rt, rt->back.rgb, f->width, f->height) : -1.0;
    /* the estimate's, at the end of each frame */
    double rel_error = -1.0;
    if (up->measure && up->frame_done && rt->reference.rgb) {
        const float *est = estimate_image(rt);
        if (est) rel_error = image_error(rt, est, f->width, f->height);
    }
    render_stats st = session_stats(rs);
    uint64_t rays = 0;
    for (int k = 0; k < RAY_KIND_COUNT; k++) rays += st.rays[k];
    pthread_mutex_lock(&sh->lock);
    if (sh->stats.resets == up->resets_seen) { /* drop an update of a state already replaced */
        image_buf t = sh->image;
        sh->image = rt->back;
        rt->back = t;
        sh->image_serial++;
        sh->stats.frames_generation = up->gen;
        sh->stats.frames = session_frames(rs);
        if (up->frame_done) sh->stats.frames_total++;
        sh->stats.updates++;
        sh->stats.parts = session_frame_parts(rs);
        sh->stats.parts_done = session_frame_parts_done(rs);
        if (up->rendered) sh->stats.part_ms = up->part_ms;
        sh->stats.view_ms = ds.view_ms;
        sh->stats.resolve_ms = ds.resolve_ms;
        sh->stats.mean_count = ds.mean_count;
        sh->stats.extra_samples = ds.extra;
        sh->stats.carried = ds.carried;
        sh->stats.lost = ds.lost;
        sh->stats.denoised = ds.levels > 0;
        sh->stats.frame_ms = rt->frame_ms + rt->setup_ms;
        double secs = cli_now() - sh->stats.reset_at;
        sh->stats.rays_per_second = secs > 0.0 ? (double)rays / secs : 0.0;
        sh->stats.rejected = st.rejected_samples;
        if (rel_error >= 0.0) {
            sh->stats.rel_error = rel_error;
            sh->stats.rel_error_at = secs;
            sh->stats.rel_error_resets = sh->stats.resets;
            sh->stats.rel_error_serial++;
        }
        if (shown_error >= 0.0) {
            sh->stats.shown_error = shown_error;
            sh->stats.shown_error_at = secs;
            sh->stats.shown_error_resets = sh->stats.resets;
            sh->stats.shown_error_serial++;
        }
        sh->stats.error_paused = !up->measure;
        if (up->frame_done) {
            sh->stats.full_frame_ms = rt->frame_ms + rt->setup_ms;
            plan_summary(session_plan(rs), sh->stats.plan, sizeof sh->stats.plan);
            sh->stats.plan_highlights = session_plan(rs)->highlights;
            sh->stats.virtual_lights = st.virtual_lights;
            sh->stats.hl_points = st.hl_points;
            sh->stats.hl_lobes = st.hl_lobes;
            double thread_ns = 1e6 * sh->stats.full_frame_ms * (double)session_params(rs)->threads *
                               (double)(session_frames(rs) > 0 ? session_frames(rs) : 1);
            sh->stats.hl_merge_share = thread_ns > 0.0 ? (double)st.hl_merge_ns / thread_ns : 0.0;
        }
    }
    pthread_mutex_unlock(&sh->lock);
    if (sh->wake) sh->wake(); /* the UI thread, waiting for events, takes the image now */
}

/* How long an update may render: what the update time of the image's age leaves beside the
 * display's work. While the camera moves (and for a while after) the update rate comes first, and
 * rendering gets what is left, a fifth at least; at rest rendering gets at least as long as the
 * display, so that on a slow machine (or a sanitizer's build) frames still come. */
static double render_budget(const render_thread *rt, double age) {
    if (age < YOUNG_SECONDS) return fmax(UPDATE_MS - rt->display_ms, 0.2 * UPDATE_MS);
    return fmax(REST_UPDATE_MS - rt->display_ms, rt->display_ms);
}

/* How many parts the next frame takes: as few as keep a part (and the frame's set-up) within what
 * a young update may render; at rest an update renders as many of them as its budget holds. */
static int parts_for(const render_thread *rt) {
    if (!(rt->frame_ms > 0.0)) return FIRST_PARTS;
    double budget = fmax(UPDATE_MS - rt->display_ms - rt->setup_ms, 0.2 * UPDATE_MS);
    int parts = 1;
    while (parts < SESSION_MAX_PARTS && rt->frame_ms / parts > budget) parts *= 2;
    return parts;
}

/* A cost learnt: the new measurement blended in (the first taken as it is). */
static void smooth(double *cost, double ms) {
    const double a = 0.3;
    *cost = *cost > 0.0 ? (1.0 - a) * *cost + a * ms : ms;
}

/* Learns a part's cost: ms for it, which began a frame of `parts` parts when `began` (then setup_ms
 * of it was the frame's set-up). Smoothed over parts. */
static void learn_costs(render_thread *rt, double ms, int parts, int began, double setup_ms) {
    smooth(&rt->frame_ms, fmax(ms - (began ? setup_ms : 0.0), 0.0) * parts);
    if (began) smooth(&rt->setup_ms, setup_ms);
}

/* ... and the rest of an update's: all of its time but what rendered (parts and extra samples), so
 * that an update takes about what render_budget aims at, whatever the display's work includes. */
static void learn_display(render_thread *rt, double ms) { smooth(&rt->display_ms, fmax(ms, 0.0)); }

/* The display's own samples for about ms (display_plan_extra), at what one cost so far (at first,
 * a film's pixel's). Returns the time they took, without the plan's: the plan (a few ms at 960x540)
 * is not counted against them, which left the young image of the first half second after a stop
 * almost none (atelier's orbit, 1 s after the stop: 0.28 and 0.29 in two runs, against 0.12 and
 * 0.15), but against the update's render budget, as the rest of the display's work is. */
static double add_extra_samples(render_thread *rt, double ms) {
    const render_params *p = session_params(rt->session);
    double each = rt->extra_ms > 0.0 ? rt->extra_ms : rt->frame_ms / ((double)p->width * (double)p->height);
    if (!rt->extra || !(each > 0.0) || !(ms > 0.0)) return 0.0;
    double want = ms / each;
    int n = display_plan_extra(rt->disp, want < 1e6 ? (int)want : 1000000, rt->extra, EXTRA_REQUESTS);
    if (n <= 0) return 0.0;
    double t0 = cli_now();
    if (session_render_extra(rt->session, rt->extra, n) != 0) return 1e3 * (cli_now() - t0);
    long long taken = 0;
    for (int k = 0; k < n; k++) taken += rt->extra[k].samples;
    display_take_extra(rt->disp, rt->extra, n);
    double took = 1e3 * (cli_now() - t0);
    if (taken > 0) smooth(&rt->extra_ms, took / (double)taken);
    return took;
}

/* Whether two requests render the same estimate (the panel sends its parameters with their defaults
 * resolved; the command line's may not be). */
static int same_estimator(const render_params *a, const render_params *b) {
    vl_params va = vl_params_resolve(&a->vl), vb = vl_params_resolve(&b->vl);
    return a->method == b->method && a->max_depth == b->max_depth && memcmp(&va, &vb, sizeof va) == 0;
}

static void export_film(render_thread *rt, const char *path) {
    char err[1200];
    /* Highlights are a layer of their own when the film has them split off (as glint render). */
    const render_params *fp = session_params(rt->session);
    int split = fp->pt_highlights || fp->method == METHOD_VSL_HL;
    const unsigned layers = (1u << COMP_DIRECT) | (1u << COMP_INDIRECT) | (split ? 1u << COMP_HIGHLIGHTS : 0u);
    if (film_save_exr(session_film(rt->session), layers, path, WRITE_NO_REPLACE, err, sizeof err) != 0) {
        cli_error("%s", err);
        set_message(rt, "%s%s", err, "");
    } else {
        printf("glint: wrote %s\n", path);
        fflush(stdout);
        set_message(rt, "wrote %s%s", path, "");
    }
}

static void *render_main(void *arg) {
    render_thread *rt = arg;
    shared_state *sh = rt->sh;
    uint64_t applied = 0;
    pthread_mutex_lock(&sh->lock);
    for (;;) {
        render_session *rs = rt->session;
        if (!sh->quit) atomic_store(&sh->abort_frame, 0); /* a change stopped a part: it is taken below */
        /* Exports and loads first: a quit right after an export request still writes it. The film
         * is a mean only between frames: an export waits for the frame under way to end. */
        if (sh->export_pending && !rt->film_partial && session_frame_parts(rs) > 0) {
            /* the frame under way first, before any change: the export is of the view it was asked in */
            pthread_mutex_unlock(&sh->lock);
            if (session_render_frame(rs) == 1) rt->film_partial = 1;
            display_take_samples(rt->disp);
            pthread_mutex_lock(&sh->lock);
            continue;
        }
        if (sh->export_pending && !rt->film_partial) {
            char path[1024];
            snprintf(path, sizeof path, "%s", sh->export_path);
            sh->export_pending = 0;
            pthread_mutex_unlock(&sh->lock);
            export_film(rt, path);
            pthread_mutex_lock(&sh->lock);
            continue;
        }
        if (sh->quit && !(sh->export_pending && !rt->film_partial)) break;
        load_job *job = &rt->job;
        if (job->active && job->done) { /* a load read (or failed): apply it between updates */
            camera cam = sh->cam;
            render_params params = sh->params;
            pthread_mutex_unlock(&sh->lock);
            int changed = finish_load(rt, job, &cam, &params);
            load_job_free(job);
            pthread_mutex_lock(&sh->lock);
            if (changed) applied = 0; /* re-apply the camera and parameters: a new accumulation */
            sh->loads_done++;
            pthread_cond_signal(&sh->load_cond); /* the loader may take the next */
            continue;
        }
        const film *ff = session_film(rs);
        int resize = ff->width != sh->render_w || ff->height != sh->render_h;
        uint64_t gen = sh->generation;
        camera cam = sh->cam;
        render_params params = sh->params;
        double age = cli_now() - sh->changed_at;
        /* Measured against the reference only from its camera (when its description names one). */
        int measure = !sh->reference_cam_valid || camera_same_view(&cam, &sh->reference_cam, rt->scene->diag);
        int lights_measured = sh->reference_cam_valid; /* a described reference: its lights too */
        char reference_lights[sizeof sh->reference_lights];
        snprintf(reference_lights, sizeof reference_lights, "%s", sh->reference_lights);
        int rw = sh->render_w, rh = sh->render_h;
        /* Light requests made for a scene since replaced are stale: the new one starts as loaded. */
        int edit_lights = gen != applied && sh->lights_scene == sh->info_serial;
        light_edits lights;
        if (edit_lights) lights = sh->lights;
        if (sh->reference_pending) {
            image_rgb_free(&rt->reference);
            rt->reference = sh->reference_new;
            sh->reference_new = (image_rgb){0};
            sh->reference_pending = 0;
        }
        if (gen != applied || resize) {
            sh->stats.resets++;
            sh->stats.reset_at = cli_now();
            sh->stats.frames = 0;
        }
        uint64_t resets_seen = sh->stats.resets, requests_seen = sh->requests;
        /* Held between frames: the frame under way when the pause came runs to its end (the film,
         * its count and what the display shows then agree). */
        int held = gen == applied && !resize && session_frame_parts(rs) == 0 && refinement_held(sh, session_frames(rs));
        int look_changed = sh->show_mask != rt->shown_mask || sh->denoise != rt->shown_denoise;
        int own_samples = sh->denoise; /* the display's own samples go with its filter */
        sh->stats.standing = held;
        /* a change stops a rest update's part, not a young one's (abort_frame) */
        sh->preemptible = !held && age >= YOUNG_SECONDS;
        pthread_mutex_unlock(&sh->lock);
        update_info up = {.measure = measure, .resets_seen = resets_seen, .gen = gen};
        double began_at = cli_now();
        if (held) { /* paused, or at the spp or time limit; the display may still change its look */
            if (look_changed) publish(rt, &up);
            refinement_hold(sh);
            continue;
        }

        unsigned change = 0;
        if (edit_lights) {
            light_edits before = rt->lights_applied;
            apply_light_edits(rt, &lights);
            if (memcmp(&before, &rt->lights_applied, sizeof before) != 0) change |= DISPLAY_LIGHTS;
        }
        /* ...and with the lights it was rendered with */
        if (measure && lights_measured) {
            char now[sizeof reference_lights];
            light_edits_text(&rt->lights_applied, now, sizeof now);
            up.measure = reference_lights_same(now, reference_lights);
        }
        /* The scene's analysis follows light edits once they settle, not at every step of a drag;
         * it restarts the film, but the light is what it was: the display keeps its history. */
        int restart_film = gen != applied;
        if (rt->scene_edited && age >= SETTLE_SECONDS) {
            if (session_scene_changed(rs) != 0) set_message(rt, "%s%s", session_error(rs), "");
            rt->scene_edited = 0;
            restart_film = 1;
        }
        if (resize) {
            if (make_sessions(rt, rw, rh, &cam, &params) != 0) break;
            rs = rt->session;
            applied = gen;
        } else if (restart_film) {
            if (!same_estimator(&params, &rt->params_applied)) change |= DISPLAY_RESTART;
            if (memcmp(&cam, &rt->cam_applied, sizeof cam) != 0) change |= DISPLAY_CAMERA;
            /* every accumulation its own random numbers, or the display would take the same samples twice */
            render_params p = params;
            p.seed = accumulation_seed(params.seed, rt->accumulations++);
            session_restart(rs, &p, &cam);
            if (change) display_change_view(rt->disp, rt->scene, &cam, change);
            rt->params_applied = params;
            rt->cam_applied = cam;
            rt->film_partial = 0; /* a new film */
            if (change & DISPLAY_RESTART)
                rt->frame_ms = rt->setup_ms = rt->extra_ms = 0.0; /* another estimator's costs */
            applied = gen;
        }
        /* Parts until the update's budget is spent, a frame ends, or a request comes. */
        double budget = render_budget(rt, age), spent = 0.0;
        double film_budget = own_samples ? (1.0 - EXTRA_SHARE) * budget : budget;
        int r = 0;
        for (;;) {
            int began = session_frame_parts(rs) == 0;
            int parts = began ? parts_for(rt) : session_frame_parts(rs);
            render_stats before = session_stats(rs);
            double t0 = cli_now();
            /* a frame begins with the pixels the display lacks most */
            if (began) session_set_packet_need(rs, display_packet_need(rt->disp));
            r = session_render_part(rs, parts, &up.frame_done);
            double ms = 1e3 * (cli_now() - t0);
            spent += ms;
            if (r == 1) rt->film_partial = 1; /* stopped: quitting, or a change at rest */
            if (r < 0) set_message(rt, "%s%s", session_error(rs), "");
            if (r != 0) break;
            up.rendered = 1;
            up.part_ms = ms;
            render_stats after = session_stats(rs);
            /* a reset in between zeroes the statistics: then the set-up is not known from them */
            double setup =
                after.pass_ns[PASS_VIRTUAL_LIGHTS] >= before.pass_ns[PASS_VIRTUAL_LIGHTS]
                    ? 1e-6 * (double)(after.pass_ns[PASS_VIRTUAL_LIGHTS] - before.pass_ns[PASS_VIRTUAL_LIGHTS])
                    : 0.0;
            learn_costs(rt, ms, parts, began, setup);
            if (up.frame_done) {
                rt->film_partial = 0;
                break;
            }
            pthread_mutex_lock(&sh->lock);
            int asked = sh->requests != requests_seen;
            pthread_mutex_unlock(&sh->lock);
            if (asked || spent + rt->frame_ms / session_frame_parts(rs) > film_budget) break;
        }
        display_take_samples(rt->disp);
        pthread_mutex_lock(&sh->lock);
        sh->preemptible = 0;
        int preempted = r == 1 && !sh->quit;
        sh->stats.preempted_parts += (uint64_t)preempted;
        if (preempted) continue; /* the change's first image is the next one shown, not this view's */
        pthread_mutex_unlock(&sh->lock);
        if (r == 0 && up.rendered && own_samples) spent += add_extra_samples(rt, EXTRA_SHARE * budget);
        publish(rt, &up);
        learn_display(rt, 1e3 * (cli_now() - began_at) - spent);
        if (r < 0)
            refinement_hold(sh);
        else
            pthread_mutex_lock(&sh->lock);
        if (r == 0 && sh->requests != requests_seen) sh->stats.late_parts++;
    }
    pthread_mutex_unlock(&sh->lock);
    return NULL;
}

render_thread *render_thread_start(shared_state *sh, scene *s) {
    render_thread *rt = calloc(1, sizeof *rt);
    if (!rt) {
        snprintf(sh->message, sizeof sh->message, "out of memory");
        return NULL;
    }
    rt->sh = sh;
    rt->scene = s;
    rt->extra = calloc(EXTRA_REQUESTS, sizeof *rt->extra); /* none: no extra samples */
    sh->scene_now = s;
    clear_light_edits(&rt->lights_applied);
    sh->stats.reset_at = cli_now();      /* the first accumulation starts now, not at the clock's origin */
    sh->changed_at = sh->stats.reset_at; /* a young image: small parts first */
    if (make_sessions(rt, sh->render_w, sh->render_h, &sh->cam, &sh->params) != 0) {
        session_destroy(rt->session); /* before the scene they read, which stays the caller's */
        display_destroy(rt->disp);
        free(rt->extra);
        free(rt);
        return NULL;
    }
    if (pthread_create(&rt->loader, NULL, loader_main, rt) != 0) {
        snprintf(sh->message, sizeof sh->message, "cannot start the loading thread");
        session_destroy(rt->session);
        display_destroy(rt->disp);
        free(rt->extra);
        free(rt);
        return NULL;
    }
    rt->loader_running = 1;
    pthread_create(&rt->thread, NULL, render_main, rt);
    return rt;
}

void render_thread_stop(render_thread *rt) {
    pthread_mutex_lock(&rt->sh->lock);
    rt->sh->quit = 1;
    rt->sh->requests++;
    pthread_cond_broadcast(&rt->sh->load_cond);
    /* The part in flight stops at its next chunk (unless an export waits for it). */
    if (!rt->sh->export_pending) atomic_store(&rt->sh->abort_frame, 1);
    pthread_mutex_unlock(&rt->sh->lock);
    pthread_join(rt->thread, NULL);
    if (rt->loader_running) pthread_join(rt->loader, NULL); /* a load under way is waited for */
    load_job_free(&rt->job);
    session_destroy(rt->session);
    display_destroy(rt->disp);
    scene_destroy(rt->scene);
    free(rt->back.rgb);
    free(rt->combined);
    image_rgb_free(&rt->reference);
    free(rt->extra);
    free(rt);
}
