/* glint view: the render side's interface (view_controller.h). Each request is written into the
 * shared state under its lock and returns; the render thread (view_render.c) takes it between
 * updates. Each result is read under the same lock. */
#define _POSIX_C_SOURCE 200809L
#include "view_controller.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "reference.h"
#include "view_render.h"

struct view_controller {
    shared_state sh;
    render_thread *rt;
};

/* ---- starting and stopping ------------------------------------------------------------------ */

view_controller *controller_start(scene *s, const view_start *start, char *err, size_t errlen) {
    view_controller *c = calloc(1, sizeof *c);
    if (!c) return snprintf(err, errlen, "out of memory"), NULL;
    shared_state *sh = &c->sh;
    pthread_mutex_init(&sh->lock, NULL);
    pthread_rwlock_init(&sh->scene_lock, NULL);
    pthread_cond_init(&sh->load_cond, NULL);
    clear_light_edits(&sh->lights);
    sh->show_mask = COMP_MASK_ALL;
    sh->denoise = start->denoise;
    sh->wake = start->wake;
    sh->cam = start->cam;
    sh->params = start->params;
    sh->render_w = start->width;
    sh->render_h = start->height;
    snprintf(sh->env_now, sizeof sh->env_now, "%s", start->env ? start->env : "");
    fill_scene_info(&sh->info, s);
    if (!(c->rt = render_thread_start(sh, s))) {
        snprintf(err, errlen, "%s", sh->message);
        controller_stop(c, NULL);
        return NULL;
    }
    return c;
}

void controller_stop(view_controller *c, view_stats *last) {
    if (!c) return;
    shared_state *sh = &c->sh;
    if (c->rt) render_thread_stop(c->rt);
    if (last) *last = sh->stats;
    image_rgb_free(&sh->reference_new);
    free(sh->image.rgb);
    pthread_rwlock_destroy(&sh->scene_lock);
    pthread_cond_destroy(&sh->load_cond);
    pthread_mutex_destroy(&sh->lock);
    free(c);
}

/* ---- requests ----------------------------------------------------------------------------- */

uint64_t controller_change(view_controller *c, const camera *cam, const render_params *p, const light_edits *lights,
                           uint64_t lights_scene) {
    shared_state *sh = &c->sh;
    pthread_mutex_lock(&sh->lock);
    sh->cam = *cam;
    sh->params.max_depth = p->max_depth;
    sh->params.method = p->method;
    sh->params.vl = p->vl;
    sh->lights = *lights;
    sh->lights_scene = lights_scene;
    uint64_t gen = ++sh->generation;
    sh->requests++;
    sh->changed_at = cli_now();
    if (sh->preemptible && !sh->export_pending) atomic_store(&sh->abort_frame, 1);
    pthread_mutex_unlock(&sh->lock);
    return gen;
}

void controller_set_look(view_controller *c, unsigned show_mask, int denoise) {
    pthread_mutex_lock(&c->sh.lock);
    c->sh.show_mask = show_mask;
    c->sh.denoise = denoise;
    pthread_mutex_unlock(&c->sh.lock);
}

void controller_set_size(view_controller *c, int width, int height) {
    pthread_mutex_lock(&c->sh.lock);
    c->sh.render_w = width;
    c->sh.render_h = height;
    pthread_mutex_unlock(&c->sh.lock);
}

void controller_size(view_controller *c, int *width, int *height) {
    pthread_mutex_lock(&c->sh.lock);
    *width = c->sh.render_w;
    *height = c->sh.render_h;
    pthread_mutex_unlock(&c->sh.lock);
}

void controller_export(view_controller *c, const char *path) {
    pthread_mutex_lock(&c->sh.lock);
    snprintf(c->sh.export_path, sizeof c->sh.export_path, "%s", path);
    c->sh.export_pending = 1;
    pthread_mutex_unlock(&c->sh.lock);
}

uint64_t controller_load(view_controller *c, int kind, const char *path, const char *variant, int keep_view) {
    shared_state *sh = &c->sh;
    pthread_mutex_lock(&sh->lock);
    snprintf(sh->load_path, sizeof sh->load_path, "%s", path);
    snprintf(sh->load_variant, sizeof sh->load_variant, "%s", variant);
    sh->load_keep_view = keep_view;
    sh->load_kind = kind;
    /* Not a change yet: the frames go on, and the accumulation too, unless the load succeeds (a
     * new scene then arrives, and with it a new view). */
    uint64_t serial = ++sh->load_requests;
    pthread_cond_signal(&sh->load_cond);
    pthread_mutex_unlock(&sh->lock);
    return serial;
}

int controller_load_settled(view_controller *c, uint64_t serial, uint64_t info_serial) {
    pthread_mutex_lock(&c->sh.lock);
    int done = c->sh.loads_done >= serial && c->sh.info_serial == info_serial;
    pthread_mutex_unlock(&c->sh.lock);
    return done;
}

void controller_set_reference(view_controller *c, image_rgb *ref, const camera *cam, const char *lights) {
    shared_state *sh = &c->sh;
    pthread_mutex_lock(&sh->lock);
    image_rgb_free(&sh->reference_new);
    sh->reference_new = *ref; /* the render thread's own copy, for the error of each frame */
    *ref = (image_rgb){0};
    sh->reference_pending = 1;
    sh->reference_cam_valid = cam != NULL;
    if (cam) sh->reference_cam = *cam;
    snprintf(sh->reference_lights, sizeof sh->reference_lights, "%s", lights ? lights : "");
    pthread_mutex_unlock(&sh->lock);
}

void controller_set_refinement(view_controller *c, int paused, long long spp, double seconds) {
    pthread_mutex_lock(&c->sh.lock);
    c->sh.paused = paused;
    c->sh.spp_limit = spp;
    c->sh.time_limit = seconds;
    pthread_mutex_unlock(&c->sh.lock);
}

/* ---- results ------------------------------------------------------------------------------ */

int controller_take_image(view_controller *c, uint64_t *serial, image_buf *front) {
    shared_state *sh = &c->sh;
    pthread_mutex_lock(&sh->lock);
    int fresh = sh->image_serial != *serial;
    if (fresh) {
        image_buf t = *front;
        *front = sh->image;
        sh->image = t;
        *serial = sh->image_serial;
    }
    pthread_mutex_unlock(&sh->lock);
    return fresh;
}

void controller_stats(view_controller *c, view_stats *out) {
    pthread_mutex_lock(&c->sh.lock);
    *out = c->sh.stats;
    pthread_mutex_unlock(&c->sh.lock);
}

int controller_take_message(view_controller *c, uint64_t *serial, char *out, size_t n) {
    pthread_mutex_lock(&c->sh.lock);
    int fresh = c->sh.message_serial != *serial;
    if (fresh) {
        snprintf(out, n, "%s", c->sh.message);
        *serial = c->sh.message_serial;
    }
    pthread_mutex_unlock(&c->sh.lock);
    return fresh;
}

int controller_take_info(view_controller *c, uint64_t *serial, scene_info *out) {
    pthread_mutex_lock(&c->sh.lock);
    int fresh = c->sh.info_serial != *serial;
    if (fresh) {
        *out = c->sh.info;
        *serial = c->sh.info_serial;
    }
    pthread_mutex_unlock(&c->sh.lock);
    return fresh;
}

void controller_env(view_controller *c, char *out, size_t n) {
    pthread_mutex_lock(&c->sh.lock);
    snprintf(out, n, "%s", c->sh.env_now);
    pthread_mutex_unlock(&c->sh.lock);
}

float controller_scene_distance(view_controller *c, vec3 o, vec3 d) {
    shared_state *sh = &c->sh;
    float t = INFINITY;
    if (pthread_rwlock_tryrdlock(&sh->scene_lock) != 0) return INFINITY; /* never wait */
    surface_hit h;
    if (sh->scene_now && scene_intersect(sh->scene_now, o, d, 1e30f, &h)) t = h.t;
    pthread_rwlock_unlock(&sh->scene_lock);
    return t;
}

/* ---- the record in a stats line ------------------------------------------------------------- */

/* The record's fields as a table: kind, place and stats-line name (VIEW_STATS, once). */
enum { KIND_U64, KIND_I64, KIND_INT, KIND_DBL };
#define VIEW_STATS_KIND_U64 KIND_U64
#define VIEW_STATS_KIND_I64 KIND_I64
#define VIEW_STATS_KIND_INT KIND_INT
#define VIEW_STATS_KIND_DBL KIND_DBL
static const struct {
    int kind;
    size_t offset;
    const char *name;
} stats_fields[] = {
#define VIEW_STATS_ROW(kind, field, name, doc) {VIEW_STATS_KIND_##kind, offsetof(view_stats, field), name},
    VIEW_STATS(VIEW_STATS_ROW)
#undef VIEW_STATS_ROW
};

void view_stats_print(const view_stats *s) {
    const char *base = (const char *)s;
    for (size_t i = 0; i < sizeof stats_fields / sizeof stats_fields[0]; i++) {
        const char *name = stats_fields[i].name, *at = base + stats_fields[i].offset;
        if (!name) continue;
        switch (stats_fields[i].kind) {
        case KIND_U64: printf(" %s=%llu", name, (unsigned long long)*(const uint64_t *)(const void *)at); break;
        case KIND_I64: printf(" %s=%lld", name, *(const long long *)(const void *)at); break;
        case KIND_INT: printf(" %s=%d", name, *(const int *)(const void *)at); break;
        default: printf(" %s=%.6g", name, *(const double *)(const void *)at); break;
        }
    }
}
