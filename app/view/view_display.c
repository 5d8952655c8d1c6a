/* glint view: what the window shows (UI thread). The newest published image (view_image.c tone-maps
 * it into the texture drawn behind the panel), the error plot, captures of the image and of the
 * whole window. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image_io.h"
#include "reference.h"
#include "view.h"

/* ---- the error plot -------------------------------------------------------------------------- */

/* The plot's name for the current method and settings. */
static void curve_label(const ui_thread *u, char *out, size_t n) {
    const render_params *c = &u->ctl.params;
    int len = snprintf(out, n, "%s, depth %d", method_name(c->method), c->max_depth);
    if (c->method != METHOD_PT && len < (int)n)
        len += snprintf(out + len, n - (size_t)len, ", %d lights, radius x%g", c->vl.count, (double)c->vl.radius_mult);
    if (c->method == METHOD_VSL_HL && len < (int)n)
        snprintf(out + len, n - (size_t)len, ", N %d, K %d", c->vl.secondary_rays, c->vl.clusters);
}

/* A new error measurement, of the estimate or (shown) of the image shown. A new accumulation starts
 * its curve afresh, replacing an earlier one of the same settings, so switching between methods
 * leaves one curve for each side by side. */
static void add_error_point(ui_thread *u, double seconds, double error, uint64_t resets, int shown) {
    if (u->current_curve < 0 || resets != u->curve_resets) {
        char label[96];
        curve_label(u, label, sizeof label);
        int c = -1;
        for (int i = 0; i < u->num_curves; i++)
            if (strcmp(u->curves[i].label, label) == 0) c = i;
        if (c < 0 && u->num_curves == MAX_CURVES) { /* forget the oldest */
            memmove(&u->curves[0], &u->curves[1], sizeof(error_curve) * (MAX_CURVES - 1));
            c = MAX_CURVES - 1;
        } else if (c < 0) {
            c = u->num_curves++;
        }
        snprintf(u->curves[c].label, sizeof u->curves[c].label, "%s", label);
        u->curves[c].n = u->curves[c].shown_n = 0;
        u->current_curve = c;
        u->curve_resets = resets;
    }
    error_curve *k = &u->curves[u->current_curve];
    int *n = shown ? &k->shown_n : &k->n;
    float *t = shown ? k->shown_seconds : k->seconds, *e = shown ? k->shown_error : k->error;
    if (*n == MAX_CURVE_POINTS) { /* keep the whole time span at half the density */
        for (int i = 0; i < MAX_CURVE_POINTS / 2; i++) {
            t[i] = t[2 * i + 1];
            e[i] = e[2 * i + 1];
        }
        *n = MAX_CURVE_POINTS / 2;
    }
    t[*n] = (float)seconds;
    e[*n] = (float)error;
    (*n)++;
    if (shown)
        u->shown_error = error;
    else
        u->rel_error = error;
}

/* Takes the newest published image and statistics. Returns 1 when the image is new. */
int fetch_published(ui_thread *u) {
    int fresh = controller_take_image(u->vc, &u->image_serial, &u->front);
    if (fresh) {
        if (u->step_ms < 0.0 && u->front.generation == u->sent_generation) /* the change's first image */
            u->step_ms = 1e3 * seconds_since(u->sent_at);
        u->images_shown++;
        u->images_full++; /* every image is at the render's full size */
        u->image_pixels += (unsigned long long)u->front.width * (unsigned long long)u->front.height;
    }
    view_stats was = u->stats;
    controller_stats(u->vc, &u->stats);
    int new_error = u->stats.rel_error_serial != was.rel_error_serial;
    int new_shown = u->stats.shown_error_serial != was.shown_error_serial;
    uint64_t message_was = u->message_serial;
    controller_take_message(u->vc, &u->message_serial, u->message, sizeof u->message);
    int new_info = controller_take_info(u->vc, &u->info_serial, &u->info);
    if (new_error && u->reference.rgb)
        add_error_point(u, u->stats.rel_error_at, u->stats.rel_error, u->stats.rel_error_resets, 0);
    if (new_shown && u->reference.rgb)
        add_error_point(u, u->stats.shown_error_at, u->stats.shown_error, u->stats.shown_error_resets, 1);
    if (new_info) { /* a new scene: its own view (not for another variant of it), lights and bookmarks */
        if (!u->info.kept_view) {
            u->ctl.camera = -1;
            u->applied_ctl.camera = -1;
            u->ctl.reset_view = 1;
        }
        u->ctl.variant = u->info.variant;
        reset_lights(u);
        bookmarks_load(u);
    }
    int news = new_error || new_shown || new_info || u->message_serial != message_was;
    return (fresh ? VIEW_NEW_IMAGE : 0) | (news ? VIEW_NEW_NEWS : 0);
}

/* ---- the image and the panel ----------------------------------------------------------------- */

/* src (w x h, RGB) magnified to out (W x H) as the window draws it: a GL_LINEAR texture with
 * clamp-to-edge, texel centres at (i + 0.5) / w, stretched over the image. */
static void magnify_bilinear(const float *src, int w, int h, float *out, int W, int H) {
    for (int Y = 0; Y < H; Y++) {
        float v = ((float)Y + 0.5f) * (float)h / (float)H - 0.5f;
        int y0 = (int)floorf(v);
        float fy = v - (float)y0;
        int ya = y0 < 0 ? 0 : y0 >= h ? h - 1 : y0, yb = y0 + 1 < 0 ? 0 : y0 + 1 >= h ? h - 1 : y0 + 1;
        for (int X = 0; X < W; X++) {
            float x = ((float)X + 0.5f) * (float)w / (float)W - 0.5f;
            int x0 = (int)floorf(x);
            float fx = x - (float)x0;
            int xa = x0 < 0 ? 0 : x0 >= w ? w - 1 : x0, xb = x0 + 1 < 0 ? 0 : x0 + 1 >= w ? w - 1 : x0 + 1;
            const float *p00 = src + 3 * ((size_t)ya * (size_t)w + (size_t)xa),
                        *p01 = src + 3 * ((size_t)ya * (size_t)w + (size_t)xb),
                        *p10 = src + 3 * ((size_t)yb * (size_t)w + (size_t)xa),
                        *p11 = src + 3 * ((size_t)yb * (size_t)w + (size_t)xb);
            float *o = out + 3 * ((size_t)Y * (size_t)W + (size_t)X);
            for (int k = 0; k < 3; k++)
                o[k] = (1.0f - fy) * ((1.0f - fx) * p00[k] + fx * p01[k]) + fy * ((1.0f - fx) * p10[k] + fx * p11[k]);
        }
    }
}

/* A capture on its way to its file: the image as taken, magnified and written by a thread of its
 * own, so that taking it costs the window (and what it measures) a copy, not a compression. */
typedef struct {
    char path[1024];
    float *rgb; /* the image shown: w x h, magnified to W x H when they differ, with json... */
    int w, h, W, H;
    char *json;
    unsigned char *png; /* ...or the window, w x h, as a PNG */
} capture_job;

static void *capture_main(void *arg) {
    capture_job *j = arg;
    char err[1200];
    if (j->png) {
        if (png_save_rgb8(j->path, j->w, j->h, j->png, WRITE_NO_REPLACE, err, sizeof err) != 0)
            cli_error("%s", err);
        else
            printf("glint: wrote %s\n", j->path), fflush(stdout);
        free(j->png);
        free(j);
        return NULL;
    }
    float *full = j->rgb;
    if (j->w != j->W || j->h != j->H) {
        full = malloc(sizeof(float) * 3 * (size_t)j->W * (size_t)j->H);
        if (full) magnify_bilinear(j->rgb, j->w, j->h, full, j->W, j->H);
    }
    exr_layer layer = {"", full};
    exr_text_attr attr = {REFERENCE_ATTR, j->json};
    if (!full)
        cli_error("%s: out of memory", j->path);
    else if (exr_save_layers_attrs(j->path, j->W, j->H, &layer, 1, &attr, 1, WRITE_NO_REPLACE, err, sizeof err) != 0)
        cli_error("%s", err);
    else
        printf("glint: wrote %s\n", j->path), fflush(stdout);
    if (full != j->rgb) free(full);
    free(j->rgb);
    free(j->json);
    free(j);
    return NULL;
}

void capture_finish(ui_thread *u) {
    for (int i = 0; i < u->num_captures; i++) pthread_join(u->captures[i], NULL);
    u->num_captures = 0;
}

/* The description of the image shown (im), taken now: its own camera and lights, when. NULL
 * with the message set. */
static char *describe_capture(ui_thread *u, const image_buf *im) {
    reference_info info;
    char err[1200];
    if (describe_view(u, &info, im->full_w, im->full_h, &im->lights, err, sizeof err) != 0) {
        snprintf(u->message, sizeof u->message, "%s", err);
        return NULL;
    }
    /* One of the scene's cameras when it is that view, else a free camera. */
    info.cam = im->cam;
    info.camera_index = -1;
    for (int i = 0; i < u->info.num_cameras && info.camera_index < 0; i++)
        if (camera_same_view(&im->cam, &u->info.cameras[i], u->info.diag)) info.camera_index = i;
    const render_params *p = &u->ctl.params;
    snprintf(info.method, sizeof info.method, "%s", method_name(p->method));
    reference_params_text(p, info.params, sizeof info.params);
    info.max_depth = p->max_depth > 0 ? p->max_depth : DEFAULT_MAX_DEPTH;
    info.seed = im->seed; /* the film's own: each accumulation draws its own random numbers */
    info.threads = p->threads;
    info.spp = im->frames;
    double now = cli_now();
    info.capture = 1;
    info.since_change = now - u->sent_at;
    info.seconds = info.since_change;
    info.since_start = now - u->started_at;
    info.image_age = now - im->published_at;
    info.preview = 0; /* every image is at the render's size */
    info.image_width = im->width;
    info.image_height = im->height;
    info.latest = im->generation == u->sent_generation;
    char *json = reference_json(&info);
    if (!json) snprintf(u->message, sizeof u->message, "out of memory");
    return json;
}

/* Before a capture named name: a file of that name on its way would be given the same free name,
 * so it is waited for; so is a backlog. */
static void make_room(ui_thread *u, const char *name) {
    for (int i = 0; i < u->num_captures; i++)
        if (strcmp(u->capture_names[i], name) == 0) capture_finish(u);
    if (u->num_captures == MAX_CAPTURES) capture_finish(u);
}

/* Starts the thread that writes j (after make_room). 0, or -1 with the message set. */
static int start_capture(ui_thread *u, capture_job *j, const char *name) {
    snprintf(u->capture_names[u->num_captures], sizeof u->capture_names[0], "%s", name);
    if (pthread_create(&u->captures[u->num_captures], NULL, capture_main, j) != 0)
        return snprintf(u->message, sizeof u->message, "%s: cannot start a thread to write it", name), -1;
    u->num_captures++;
    snprintf(u->message, sizeof u->message, "capturing %s", j->path);
    return 0;
}

void capture_image(ui_thread *u, const char *name) {
    const image_buf *im = &u->front;
    size_t bytes = sizeof(float) * 3 * (size_t)im->width * (size_t)im->height;
    make_room(u, name);
    capture_job *j = calloc(1, sizeof *j);
    if (!im->rgb || im->full_w <= 0 || im->full_h <= 0) {
        snprintf(u->message, sizeof u->message, "%s: nothing rendered yet", name);
    } else if (!j || !(j->rgb = malloc(bytes))) {
        snprintf(u->message, sizeof u->message, "%s: out of memory", name);
    } else if (unique_path(name, j->path, sizeof j->path) != 0) {
        snprintf(u->message, sizeof u->message, "%s: no free file name", name);
    } else if ((j->json = describe_capture(u, im)) != NULL) {
        memcpy(j->rgb, im->rgb, bytes);
        j->w = im->width;
        j->h = im->height;
        j->W = im->full_w;
        j->H = im->full_h;
        if (start_capture(u, j, name) == 0) return;
        free(j->json);
    }
    cli_error("%s", u->message);
    if (j) free(j->rgb);
    free(j);
}

/* Saves the window's back buffer as drawn (panel included); the PNG is written as captures are. */
void capture_window(ui_thread *u, int w, int h) {
    make_room(u, u->window_shot);
    capture_job *j = calloc(1, sizeof *j);
    unsigned char *px = malloc(3 * (size_t)w * (size_t)h), *row = malloc(3 * (size_t)w);
    if (!j || !px || !row || unique_path(u->window_shot, j->path, sizeof j->path) != 0) {
        cli_error("%s: cannot capture the window", u->window_shot);
    } else {
        glPixelStorei(GL_PACK_ALIGNMENT, 1);
        glReadPixels(0, 0, w, h, GL_RGB, GL_UNSIGNED_BYTE, px);
        for (int y = 0; y < h / 2; y++) { /* OpenGL's rows run bottom-up */
            memcpy(row, px + 3 * (size_t)w * (size_t)y, 3 * (size_t)w);
            memcpy(px + 3 * (size_t)w * (size_t)y, px + 3 * (size_t)w * (size_t)(h - 1 - y), 3 * (size_t)w);
            memcpy(px + 3 * (size_t)w * (size_t)(h - 1 - y), row, 3 * (size_t)w);
        }
        j->png = px;
        j->w = w;
        j->h = h;
        if (start_capture(u, j, u->window_shot) == 0)
            px = NULL, j = NULL; /* the thread's now */
        else
            cli_error("%s", u->message);
    }
    free(j);
    free(px);
    free(row);
    u->window_shot[0] = 0;
}

/* The image behind the panel, the light markers over it, and the panel with the statistics and
 * controls; the panel edits u->ctl in place. */
void draw_image_and_panel(ui_thread *u) {
    for (int c = 0; c < u->num_curves; c++)
        u->ui_curves[c] =
            (ui_curve){u->curves[c].label,         u->curves[c].seconds,     u->curves[c].error,  u->curves[c].n,
                       u->curves[c].shown_seconds, u->curves[c].shown_error, u->curves[c].shown_n};
    describe_bookmarks(u);
    ui_stats st = {.render = u->stats,
                   .scene_name = u->info.name,
                   .spp = (double)frames_of_current_state(u),
                   .seconds = seconds_since(u->stats.reset_at),
                   .cost_ms = view_cost_ms(u),
                   .cost_before_ms = u->cost_before_ms,
                   .width = u->front.width,
                   .height = u->front.height,
                   .num_cameras = u->info.num_cameras,
                   .many_light = u->ctl.params.method != METHOD_PT,
                   .highlights = u->ctl.params.method == METHOD_VSL_HL,
                   .light_names = u->light_label_ptrs,
                   .num_lights = u->info.num_lights,
                   .light_movable = light_movable(u, u->ctl.light),
                   .reference = u->reference.rgb ? u->reference_path : NULL,
                   .rel_error = u->rel_error,
                   .shown_error = u->shown_error,
                   .curves = u->ui_curves,
                   .num_curves = u->num_curves,
                   .bookmarks = u->bookmarks_text,
                   .message = u->message,
                   .status = u->status};
    panel_frame(u, &st);
    ui_panel(&u->ctl, &st); /* first: the image goes beside the panel as it is drawn now */
    float rect[4];
    view_image_rect(u, rect);
    make_texture(u); /* before the first image, too: the draw list takes its name now */
    ui_draw_image(u->texture, rect);
    if (u->ctl.show_panel) {
        update_light_screen(u);
        ui_draw_lights(u->light_xy, u->info.num_lights, u->ctl.light);
    }
    panel_after(u);
}
