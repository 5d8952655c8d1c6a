/* glint view: the render thread. It owns the scene and the render sessions; between frames it takes
 * the UI's requests from the shared state, and after each frame publishes the image and its
 * statistics there (see view.h). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "envmap.h"
#include "lights.h"
#include "metrics.h"
#include "view.h"

#define PREVIEW_DIVISOR 3      /* preview resolution = full / 3 on each axis, or coarser... */
#define PREVIEW_TARGET_MS 70.0 /* ...so that a preview frame takes about this long... */
#define PREVIEW_MAX_DIVISOR 12 /* ...down to 80x45 at 960x540: blurred, but 10 a second on a busy machine */
#define PREVIEW_HOLD_SECONDS 0.3

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
    render_session *full, *preview;
    image_buf back;             /* the next image, swapped with the shared one when published */
    light_edits lights_applied; /* the edits the scene has */
    image_rgb reference;        /* for the error of each frame */
    float *combined;            /* the whole image when another part is shown */
    size_t combined_len;
    int preview_divisor;
    int scene_edited; /* lights changed since the plan was made */
    pthread_t loader;
    int loader_running;
    load_job job;
    int full_film_partial; /* a stopped frame left samples in the full film; cleared
                                         * by the next full frame that completes */
};

void shared_state_init(shared_state *sh) {
    memset(sh, 0, sizeof *sh);
    pthread_mutex_init(&sh->lock, NULL);
    pthread_rwlock_init(&sh->scene_lock, NULL);
    pthread_cond_init(&sh->load_cond, NULL);
    clear_light_edits(&sh->lights);
    sh->show_mask = COMP_MASK_ALL;
    sh->changed_at = -1e9;
}

void shared_state_deinit(shared_state *sh) {
    image_rgb_free(&sh->reference_new);
    free(sh->image.rgb);
    pthread_rwlock_destroy(&sh->scene_lock);
    pthread_cond_destroy(&sh->load_cond);
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
    info->unlit = s->num_lights - (s->env_light >= 0 ? 1 : 0) == 0;
    info->num_variants = scene_num_variants(s) < MAX_VIEW_VARIANTS ? scene_num_variants(s) : MAX_VIEW_VARIANTS;
    for (int i = 0; i < info->num_variants; i++)
        snprintf(info->variant_names[i], sizeof info->variant_names[i], "%s", scene_variant_name(s, i));
    info->variant = scene_variant(s) < info->num_variants ? scene_variant(s) : -1;
    info->kept_view = 0;
}

void clear_light_edits(light_edits *e) {
    for (int g = 0; g < MAX_LIGHT_GROUPS; g++) {
        e->offset[g] = v3(0, 0, 0);
        e->gain[g] = 1.0f;
    }
}

void light_edits_text(const light_edits *e, char *out, size_t n) {
    light_edit list[MAX_LIGHT_GROUPS];
    for (int g = 0; g < MAX_LIGHT_GROUPS; g++) list[g] = (light_edit){g, e->offset[g], e->gain[g]};
    if (reference_lights_text(list, MAX_LIGHT_GROUPS, out, n) != 0 && n) out[0] = 0; /* n too small: none said */
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
    /* Only quitting stops a preview frame: while things move every one must finish, or none would
     * be shown. */
    render_session *rs = session_create(rt->scene, cam, &p, err, errlen);
    if (rs) session_set_abort_flag(rs, &rt->sh->abort_preview);
    return rs;
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

/* The preview session at full size / d, replacing the one there is (kept when that fails). */
static void set_preview_divisor(render_thread *rt, int d, const camera *cam, const render_params *params) {
    if (d == rt->preview_divisor) return;
    char err[512];
    render_session *p = create_preview(rt, d, cam, params, err, sizeof err);
    if (!p) return;
    session_destroy(rt->preview);
    rt->preview = p;
    rt->preview_divisor = d;
}

/* The divisor whose preview frames take about PREVIEW_TARGET_MS, from a frame of frame_ms at
 * divisor d (a frame's time goes about as its pixels, 1 / d^2), within the divisors' limits. */
static int divisor_for(int d, double frame_ms) {
    int fit = (int)ceil((double)d * sqrt(frame_ms / PREVIEW_TARGET_MS));
    return fit < PREVIEW_DIVISOR ? PREVIEW_DIVISOR : fit > PREVIEW_MAX_DIVISOR ? PREVIEW_MAX_DIVISOR : fit;
}

/* Coarser previews when their frames are slow (a large window, a costly method, a busy
 * machine), at once to the size that should be quick enough; finer again, a step at a time,
 * when they are quick, so the image follows motion at about 10 frames a second or more. A step
 * finer makes a frame at most 1.78 times slower (from divisor 4 to 3): 0.45 of the target
 * becomes 0.8, still under the 1.3 that coarsens. */
static void adapt_preview(render_thread *rt, double frame_ms, const camera *cam, const render_params *params) {
    int d = rt->preview_divisor;
    if (frame_ms > 1.3 * PREVIEW_TARGET_MS)
        d = divisor_for(d, frame_ms);
    else if (frame_ms < 0.45 * PREVIEW_TARGET_MS && d > PREVIEW_DIVISOR)
        d--;
    set_preview_divisor(rt, d, cam, params);
}

/* After the first full frame of a state: a preview size fitted to that frame's time, so that
 * the first preview after a change comes quickly instead of after adapt_preview's steps. Only
 * coarser: previews measured at the size there is know the costs a frame has whatever its size
 * (the virtual lights' pass) better than the full frame does. */
static void fit_preview(render_thread *rt, double frame_ms, const camera *cam, const render_params *params) {
    int d = divisor_for(1, frame_ms);
    if (d > rt->preview_divisor) set_preview_divisor(rt, d, cam, params);
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
        if (ok && !sh->export_pending) atomic_store(&sh->abort_frame, 1); /* a change: stop the frame */
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
    /* The sessions read the old scene: replace them with it. */
    int w = session_params(rt->full)->width, h = session_params(rt->full)->height;
    session_destroy(rt->full);
    session_destroy(rt->preview);
    rt->full = rt->preview = NULL;
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
    /* The plan depends on the map (its prefiltering, its light) */
    if (session_scene_changed(rt->full) != 0 || session_scene_changed(rt->preview) != 0)
        load_failed(rt, session_error(rt->full));
    session_set_camera(rt->full, cam);
    session_set_camera(rt->preview, cam);
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
static void publish(render_thread *rt, render_session *rs, int preview, int measure, double frame_ms,
                    const render_stats *before, uint64_t resets_seen, uint64_t gen) {
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
    rt->back.full_w = session_film(rt->full)->width;
    rt->back.full_h = session_film(rt->full)->height;
    rt->back.generation = gen;
    rt->back.cam = *session_camera(rs); /* what its frames were rendered from, whatever asked since */
    rt->back.lights = rt->lights_applied;
    rt->back.frames = preview ? 0 : session_frames(rs);
    rt->back.published_at = cli_now();
    double rel_error = preview || !measure ? -1.0 : frame_error(rt, f, mask, rt->back.rgb);
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
            sh->stats.full_frame_ms = frame_ms;
            plan_summary(session_plan(rs), sh->stats.plan, sizeof sh->stats.plan);
            sh->stats.plan_highlights = session_plan(rs)->highlights;
            sh->stats.virtual_lights = st.virtual_lights;
            sh->stats.hl_points = st.hl_points - before->hl_points;
            sh->stats.hl_lobes = st.hl_lobes - before->hl_lobes;
            sh->stats.hl_merge_share = merge_share;
            sh->stats.error_paused = !measure;
        }
    }
    pthread_mutex_unlock(&sh->lock);
    glfwPostEmptyEvent(); /* the UI thread, waiting for events, takes the image now */
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
        load_job *job = &rt->job;
        if (job->active && job->done) { /* a load read (or failed): apply it between frames */
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
        const film *ff = session_film(rt->full);
        int resize = ff->width != sh->render_w || ff->height != sh->render_h;
        uint64_t gen = sh->generation;
        atomic_store(&sh->abort_frame, 0); /* this change is taken: frames of it run to the end */
        camera cam = sh->cam;
        render_params params = sh->params;
        int preview = seconds_since(sh->changed_at) < PREVIEW_HOLD_SECONDS;
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
        uint64_t resets_seen = sh->stats.resets;
        int held = !preview && gen == applied && !resize && refinement_held(sh, session_frames(rt->full));
        sh->stats.standing = held;
        pthread_mutex_unlock(&sh->lock);
        if (held) { /* paused, or at the spp or time limit */
            refinement_hold(sh);
            continue;
        }

        if (edit_lights) apply_light_edits(rt, &lights);
        /* ...and with the lights it was rendered with */
        if (measure && lights_measured) {
            char now[sizeof reference_lights];
            light_edits_text(&rt->lights_applied, now, sizeof now);
            measure = reference_lights_same(now, reference_lights);
        }
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
        publish(rt, rs, preview, measure, ms, &before, resets_seen, gen);
        if (preview)
            adapt_preview(rt, ms, &cam, &params);
        else if (session_frames(rt->full) == 1)
            fit_preview(rt, ms, &cam, &params);
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
    sh->scene_now = s;
    clear_light_edits(&rt->lights_applied);
    sh->stats.reset_at = cli_now(); /* the first accumulation starts now, not at the clock's origin */
    /* Previews first, as after a change: the window shows the scene at once (a full frame can take
     * seconds), and their times size the previews before the first move. */
    sh->changed_at = sh->stats.reset_at;
    if (make_sessions(rt, sh->render_w, sh->render_h, &sh->cam, &sh->params) != 0) {
        session_destroy(rt->full); /* before the scene they read, which stays the caller's */
        session_destroy(rt->preview);
        free(rt);
        return NULL;
    }
    if (pthread_create(&rt->loader, NULL, loader_main, rt) != 0) {
        snprintf(sh->message, sizeof sh->message, "cannot start the loading thread");
        session_destroy(rt->full);
        session_destroy(rt->preview);
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
    pthread_cond_broadcast(&rt->sh->load_cond);
    /* The frame in flight stops at its next tile (unless an export waits for it). */
    if (!rt->sh->export_pending) atomic_store(&rt->sh->abort_frame, 1);
    atomic_store(&rt->sh->abort_preview, 1);
    pthread_mutex_unlock(&rt->sh->lock);
    pthread_join(rt->thread, NULL);
    if (rt->loader_running) pthread_join(rt->loader, NULL); /* a load under way is waited for */
    load_job_free(&rt->job);
    session_destroy(rt->full);
    session_destroy(rt->preview);
    scene_destroy(rt->scene);
    free(rt->back.rgb);
    free(rt->combined);
    image_rgb_free(&rt->reference);
    free(rt);
}
