/* glint view: the render thread. It owns the scene and the render sessions; between frames it takes
 * the UI's requests from the shared state, and after each frame publishes the image and its
 * statistics there (see view.h). */
#define _POSIX_C_SOURCE 200809L
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "metrics.h"
#include "view.h"

#define PREVIEW_DIVISOR 3 /* preview resolution = full / 3 on each axis, or coarser... */
#define PREVIEW_MAX_DIVISOR 8
#define PREVIEW_TARGET_MS 70.0 /* ...so that a preview frame takes about this long */
#define PREVIEW_HOLD_SECONDS 0.3

/* Written and read by the render thread alone (the UI sees only shared_state). */
struct render_thread {
    shared_state *sh;
    pthread_t thread;
    scene *scene;
    render_session *full, *preview;
    image_buf back;             /* the next image, swapped with the shared one when published */
    light_edits lights_applied; /* the edits the scene has */
    image_rgb reference;        /* for the error of each frame */
    float *combined;            /* the whole image when another part is shown */
    size_t combined_len;
    int preview_divisor;
    int scene_edited;      /* lights changed since the plan was made */
    int full_film_partial; /* a stopped frame left samples in the full film; cleared
                                         * by the next full frame that completes */
};

void shared_state_init(shared_state *sh) {
    memset(sh, 0, sizeof *sh);
    pthread_mutex_init(&sh->lock, NULL);
    clear_light_edits(&sh->lights);
    sh->show_mask = COMP_MASK_ALL;
    sh->changed_at = -1e9;
}

void shared_state_deinit(shared_state *sh) {
    image_rgb_free(&sh->reference_new);
    free(sh->image.rgb);
    pthread_mutex_destroy(&sh->lock);
}

void fill_scene_info(scene_info *info, const scene *s) {
    snprintf(info->name, sizeof info->name, "%s", s->path);
    info->num_cameras = s->num_cameras < MAX_VIEW_CAMERAS ? s->num_cameras : MAX_VIEW_CAMERAS;
    for (int i = 0; i < info->num_cameras; i++) info->cameras[i] = s->cameras[i];
    info->bounds = s->bounds;
    info->diag = s->diag;
    int n = scene_light_groups(s, info->lights, MAX_LIGHT_GROUPS); /* -1 (out of memory): none listed */
    info->num_lights = n < 0 ? 0 : n < MAX_LIGHT_GROUPS ? n : MAX_LIGHT_GROUPS;
}

void clear_light_edits(light_edits *e) {
    for (int g = 0; g < MAX_LIGHT_GROUPS; g++) {
        e->offset[g] = v3(0, 0, 0);
        e->gain[g] = 1.0f;
    }
}

static void set_message(render_thread *rt, const char *fmt, const char *a, const char *b) {
    shared_state *sh = rt->sh;
    pthread_mutex_lock(&sh->lock);
    snprintf(sh->message, sizeof sh->message, fmt, a, b);
    sh->message_serial++;
    pthread_mutex_unlock(&sh->lock);
}

/* A preview session at the full session's size / divisor. NULL with err set on failure. */
static render_session *create_preview(render_thread *rt, int divisor, const camera *cam, const render_params *params,
                                      char *err, size_t errlen) {
    const render_params *fp = session_params(rt->full);
    render_params p = *params;
    p.width = fp->width / divisor > 0 ? fp->width / divisor : 1;
    p.height = fp->height / divisor > 0 ? fp->height / divisor : 1;
    /* No abort flag: while things move every preview frame must finish, or none would be shown. */
    return session_create(rt->scene, cam, &p, err, errlen);
}

/* (Re)creates both sessions for the current scene at w x h. Returns 0 or -1 (message set). */
static int make_sessions(render_thread *rt, int w, int h, const camera *cam, const render_params *params) {
    session_destroy(rt->full);
    session_destroy(rt->preview);
    rt->full = rt->preview = NULL;
    render_params p = *params;
    char err[512];
    p.width = w;
    p.height = h;
    rt->full = session_create(rt->scene, cam, &p, err, sizeof err);
    if (rt->full) session_set_abort_flag(rt->full, &rt->sh->abort_frame);
    rt->full_film_partial = 0; /* a new film */
    if (rt->preview_divisor < PREVIEW_DIVISOR) rt->preview_divisor = PREVIEW_DIVISOR;
    if (rt->full) rt->preview = create_preview(rt, rt->preview_divisor, cam, params, err, sizeof err);
    if (!rt->full || !rt->preview) {
        set_message(rt, "%s%s", err, "");
        return -1;
    }
    return 0;
}

/* Coarser previews when their frames are slow (a large window, a costly method, a busy
 * machine), finer again when they are quick, so the image follows motion at about 10 frames a
 * second or more. The thresholds leave room: one step changes the time by a factor of 0.56 to
 * 0.77, less than their ratio. */
static void adapt_preview(render_thread *rt, double frame_ms, const camera *cam, const render_params *params) {
    int d = rt->preview_divisor;
    if (frame_ms > 1.3 * PREVIEW_TARGET_MS && d < PREVIEW_MAX_DIVISOR)
        d++;
    else if (frame_ms < 0.45 * PREVIEW_TARGET_MS && d > PREVIEW_DIVISOR)
        d--;
    if (d == rt->preview_divisor) return;
    char err[512];
    render_session *p = create_preview(rt, d, cam, params, err, sizeof err);
    if (!p) return; /* keep the one there is */
    session_destroy(rt->preview);
    rt->preview = p;
    rt->preview_divisor = d;
}

static void handle_load(render_thread *rt, int kind, const char *path, const camera *cam, const render_params *params) {
    char err[1024];
    if (kind == 1) {
        scene *s = scene_load(path, cli_print_warning, NULL, err, sizeof err);
        if (!s) {
            cli_error("%s", err);
            set_message(rt, "%s%s", err, "");
            return;
        }
        /* The sessions read the old scene: replace them with it. */
        int w = session_params(rt->full)->width, h = session_params(rt->full)->height;
        session_destroy(rt->full);
        session_destroy(rt->preview);
        rt->full = rt->preview = NULL;
        scene_destroy(rt->scene);
        rt->scene = s;
        clear_light_edits(&rt->lights_applied);
        camera c = scene_camera(s, -1, (float)w / (float)h);
        make_sessions(rt, w, h, &c, params);
        pthread_mutex_lock(&rt->sh->lock);
        fill_scene_info(&rt->sh->info, s);
        rt->sh->info_serial++;
        pthread_mutex_unlock(&rt->sh->lock);
        set_message(rt, "loaded %s%s", path, "");
    } else {
        if (scene_set_env(rt->scene, path, 0.0f, err, sizeof err) != 0) {
            cli_error("%s", err);
            set_message(rt, "%s%s", err, "");
            return;
        }
        /* The plan depends on the map (its prefiltering, its light) */
        if (session_scene_changed(rt->full) != 0 || session_scene_changed(rt->preview) != 0) {
            cli_error("%s", session_error(rt->full));
            set_message(rt, "%s%s", session_error(rt->full), "");
            return;
        }
        session_set_camera(rt->full, cam);
        session_set_camera(rt->preview, cam);
        set_message(rt, "environment %s%s", path, "");
    }
}

/* Brings the scene's lights to the wanted offsets and gains (render thread, between frames). */
static void apply_light_edits(render_thread *rt, const light_edits *wanted) {
    char err[512];
    light_edits *done = &rt->lights_applied;
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
}

/* The relative L2 error of the whole image (every component, whatever is shown) against the
 * reference; -1 without a reference of this size. shown is the image resolved with mask. */
static double frame_error(render_thread *rt, const film *f, unsigned mask, const float *shown) {
    const image_rgb *ref = &rt->reference;
    if (!ref->rgb || ref->width != f->width || ref->height != f->height) return -1.0;
    size_t n = 3 * (size_t)f->width * (size_t)f->height;
    const float *img = shown;
    if (mask != COMP_MASK_ALL) {
        if (rt->combined_len != n) {
            free(rt->combined);
            rt->combined = malloc(sizeof(float) * n);
            rt->combined_len = rt->combined ? n : 0;
            if (!rt->combined) return -1.0;
        }
        film_resolve(f, COMP_MASK_ALL, rt->combined);
        img = rt->combined;
    }
    return metric_rel_l2(img, ref->rgb, n);
}

/* before: the session's statistics before the frame, so the frame's own work is the difference.
 * The film is resolved with the components shown now, not when the frame started: a frame after a
 * display change shows that change. */
static void publish(render_thread *rt, render_session *rs, int preview, double frame_ms, const render_stats *before,
                    uint64_t resets_seen, uint64_t gen) {
    shared_state *sh = rt->sh;
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
    pthread_mutex_unlock(&sh->lock);
    film_resolve(f, mask, rt->back.rgb);
    rt->back.preview = preview;
    double rel_error = preview ? -1.0 : frame_error(rt, f, mask, rt->back.rgb);
    render_stats st = session_stats(rs);
    uint64_t rays = 0;
    for (int k = 0; k < RAY_KIND_COUNT; k++) rays += st.rays[k];
    double thread_ns = 1e6 * frame_ms * (double)session_params(rs)->threads;
    double merge_share = thread_ns > 0.0 ? (double)(st.hl_merge_ns - before->hl_merge_ns) / thread_ns : 0.0;
    pthread_mutex_lock(&sh->lock);
    if (sh->stats.resets == resets_seen) { /* drop a frame of a state already replaced */
        image_buf t = sh->image;
        sh->image = rt->back;
        rt->back = t;
        sh->image_serial++;
        if (!preview) {
            sh->stats.frames_generation = gen;
            sh->stats.frames = session_frames(rs);
            sh->stats.frames_total++;
        }
        sh->stats.frame_ms = frame_ms;
        double secs = seconds_since(sh->stats.reset_at);
        sh->stats.rays_per_second = secs > 0.0 && !preview ? (double)rays / secs : 0.0;
        sh->stats.rejected = st.rejected_samples;
        if (preview) sh->stats.preview_frames++;
        if (!preview && rel_error >= 0.0) {
            sh->stats.rel_error = rel_error;
            sh->stats.rel_error_at = secs;
            sh->stats.rel_error_resets = sh->stats.resets;
            sh->stats.rel_error_serial++;
        }
        if (!preview) {
            plan_summary(session_plan(rs), sh->stats.plan, sizeof sh->stats.plan);
            sh->stats.plan_highlights = session_plan(rs)->highlights;
            sh->stats.virtual_lights = st.virtual_lights;
            sh->stats.hl_points = st.hl_points - before->hl_points;
            sh->stats.hl_lobes = st.hl_lobes - before->hl_lobes;
            sh->stats.hl_merge_share = merge_share;
        }
    }
    pthread_mutex_unlock(&sh->lock);
}

static void *render_main(void *arg) {
    render_thread *rt = arg;
    shared_state *sh = rt->sh;
    uint64_t applied = 0;
    pthread_mutex_lock(&sh->lock);
    for (;;) {
        /* Exports and loads first: a quit right after an export request still writes it. Not
         * while a stopped frame's samples are in the film: after the next full frame. */
        if (sh->export_pending && !rt->full_film_partial) {
            char path[1024], err[1200];
            snprintf(path, sizeof path, "%s", sh->export_path);
            sh->export_pending = 0;
            pthread_mutex_unlock(&sh->lock);
            /* Highlights are a layer of their own when the film has them split off (as glint render). */
            const render_params *fp = session_params(rt->full);
            int split = fp->pt_highlights || fp->method == METHOD_VSL_HL;
            const unsigned layers = (1u << COMP_DIRECT) | (1u << COMP_INDIRECT) | (split ? 1u << COMP_HIGHLIGHTS : 0u);
            if (film_save_exr(session_film(rt->full), layers, path, WRITE_NO_REPLACE, err, sizeof err) != 0) {
                cli_error("%s", err);
                set_message(rt, "%s%s", err, "");
            } else {
                printf("glint: wrote %s\n", path);
                fflush(stdout);
                set_message(rt, "wrote %s%s", path, "");
            }
            pthread_mutex_lock(&sh->lock);
            continue;
        }
        if (sh->quit && !(sh->export_pending && rt->full_film_partial)) break;
        if (sh->load_kind) {
            int kind = sh->load_kind;
            char path[1024];
            snprintf(path, sizeof path, "%s", sh->load_path);
            sh->load_kind = 0;
            camera cam = sh->cam;
            render_params params = sh->params;
            pthread_mutex_unlock(&sh->lock);
            handle_load(rt, kind, path, &cam, &params);
            pthread_mutex_lock(&sh->lock);
            applied = 0; /* re-apply the camera and parameters to the new sessions */
            continue;
        }
        const film *ff = session_film(rt->full);
        int resize = ff->width != sh->render_w || ff->height != sh->render_h;
        uint64_t gen = sh->generation;
        atomic_store(&sh->abort_frame, 0); /* this change is taken: frames of it run to the end */
        camera cam = sh->cam;
        render_params params = sh->params;
        int preview = seconds_since(sh->changed_at) < PREVIEW_HOLD_SECONDS;
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
        uint64_t resets_seen = sh->stats.resets;
        int held = !preview && gen == applied && !resize && refinement_held(sh, session_frames(rt->full));
        pthread_mutex_unlock(&sh->lock);
        if (held) { /* paused, or at the spp or time limit */
            refinement_hold(sh);
            continue;
        }

        if (edit_lights) apply_light_edits(rt, &lights);
        /* The scene's analysis follows light edits once they settle, not at every step of a drag. */
        if (rt->scene_edited && !preview) {
            if (session_scene_changed(rt->full) != 0 || session_scene_changed(rt->preview) != 0)
                set_message(rt, "%s%s", session_error(rt->full), "");
            rt->scene_edited = 0;
        }
        if (resize) {
            if (make_sessions(rt, rw, rh, &cam, &params) != 0) break;
            applied = gen;
        } else if (gen != applied) {
            session_set_params(rt->full, &params);
            session_set_params(rt->preview, &params);
            session_set_camera(rt->full, &cam);
            session_set_camera(rt->preview, &cam);
            applied = gen;
        }
        render_session *rs = preview ? rt->preview : rt->full;
        render_stats before = session_stats(rs);
        double t0 = cli_now();
        if (session_render_frame(rs) == 1) { /* stopped for a newer change: nothing to show */
            if (rs == rt->full) rt->full_film_partial = 1;
            pthread_mutex_lock(&sh->lock);
            continue;
        }
        if (rs == rt->full) rt->full_film_partial = 0;
        double ms = 1e3 * seconds_since(t0);
        publish(rt, rs, preview, ms, &before, resets_seen, gen);
        if (preview) adapt_preview(rt, ms, &cam, &params);
        pthread_mutex_lock(&sh->lock);
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
    clear_light_edits(&rt->lights_applied);
    sh->stats.reset_at = cli_now(); /* the first accumulation starts now, not at the clock's origin */
    if (make_sessions(rt, sh->render_w, sh->render_h, &sh->cam, &sh->params) != 0) {
        session_destroy(rt->full); /* before the scene they read, which stays the caller's */
        session_destroy(rt->preview);
        free(rt);
        return NULL;
    }
    pthread_create(&rt->thread, NULL, render_main, rt);
    return rt;
}

void render_thread_stop(render_thread *rt) {
    pthread_mutex_lock(&rt->sh->lock);
    rt->sh->quit = 1;
    pthread_mutex_unlock(&rt->sh->lock);
    pthread_join(rt->thread, NULL);
    session_destroy(rt->full);
    session_destroy(rt->preview);
    scene_destroy(rt->scene);
    free(rt->back.rgb);
    free(rt->combined);
    image_rgb_free(&rt->reference);
    free(rt);
}
