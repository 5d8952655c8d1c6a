/* glint view: what the window shows (UI thread). The newest published image, tone-mapped or as
 * its error against a reference, in a GL texture behind the panel; the error plot; screenshots
 * of the image and captures of the whole window. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image_io.h"
#include "reference.h"
#include "view.h"

/* ---- the reference image and the error plot -------------------------------------------------- */

/* Loads a reference for the error view and plot, measured from cam with lights when cam is not
 * NULL (its description's), else from any view: it must match the render size. Returns 0, or -1
 * with the message shown (the previous reference stays). */
int load_reference(ui_thread *u, const char *path, const camera *cam, const char *lights) {
    image_rgb img;
    char err[1200];
    if (image_rgb_load(path, &img, err, sizeof err) != 0) {
        snprintf(u->message, sizeof u->message, "%s", err);
        cli_error("%s", err);
        return -1;
    }
    int w, h;
    controller_size(u->vc, &w, &h);
    image_rgb copy = {img.width, img.height, NULL};
    size_t bytes = sizeof(float) * 3 * (size_t)img.width * (size_t)img.height;
    if (img.width != w || img.height != h) {
        snprintf(u->message, sizeof u->message, "%s: the reference is %dx%d but the render is %dx%d; not used", path,
                 img.width, img.height, w, h);
    } else if (!(copy.rgb = malloc(bytes))) {
        snprintf(u->message, sizeof u->message, "%s: out of memory", path);
    }
    if (!copy.rgb) {
        cli_error("%s", u->message);
        image_rgb_free(&img);
        return -1;
    }
    memcpy(copy.rgb, img.rgb, bytes);
    u->reference_cam_valid = cam != NULL;
    if (cam) u->reference_cam = *cam;
    snprintf(u->reference_lights, sizeof u->reference_lights, "%s", cam ? lights : "");
    /* the render side's own copy, for the errors of its images */
    controller_set_reference(u->vc, &copy, cam, u->reference_lights);
    image_rgb_free(&u->reference);
    u->reference = img;
    snprintf(u->reference_path, sizeof u->reference_path, "%s", path);
    /* Its own noise, when glint render described it: the error plot's floor. */
    reference_info info;
    char why[1200];
    u->reference_noise = reference_load(path, &info, why, sizeof why) == 0 && info.has_noise ? info.rel_l2_noise : -1.0;
    u->rel_error = u->shown_error = -1.0;
    u->num_curves = 0; /* errors against another image do not compare */
    u->current_curve = -1;
    u->need_tonemap = 1;
    snprintf(u->message, sizeof u->message, "reference %s", path);
    return 0;
}

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

/* Per-pixel relative error |I - R| / (|R| + eps) as colours on a log scale: blue 1%, green 10%,
 * red 100% and more. eps, a hundredth of the mean reference, keeps black pixels from glaring. */
static void false_colour_error(const float *img, const float *ref, int num_pixels, unsigned char *out) {
    size_t n = 3 * (size_t)num_pixels;
    double mean = 0.0;
    for (size_t i = 0; i < n; i++) mean += (double)ref[i];
    float eps = (float)(0.01 * mean / (double)(n ? n : 1)) + 1e-20f;
    for (int i = 0; i < num_pixels; i++) {
        const float *a = img + 3 * (size_t)i, *r = ref + 3 * (size_t)i;
        float d2 = 0.0f, r2 = 0.0f;
        for (int k = 0; k < 3; k++) {
            d2 += (a[k] - r[k]) * (a[k] - r[k]);
            r2 += r[k] * r[k];
        }
        float e = sqrtf(d2) / (sqrtf(r2) + eps);
        float t = isfinite(e) ? clampf(0.5f * (log10f(fmaxf(e, 1e-6f)) + 2.0f), 0.0f, 1.0f) : 1.0f;
        float rgb[3] = {clampf(2.0f * t - 1.0f, 0.0f, 1.0f), 1.0f - fabsf(2.0f * t - 1.0f),
                        clampf(1.0f - 2.0f * t, 0.0f, 1.0f)};
        for (int k = 0; k < 3; k++) out[3 * (size_t)i + (size_t)k] = (unsigned char)(255.0f * rgb[k] + 0.5f);
    }
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

/* The texture the image is drawn from; black until the first image (it has no storage yet).
 * Linear filtering: an image shown in a place of another size is scaled smoothly. */
static void make_texture(ui_thread *u) {
    if (u->texture) return;
    GLuint t;
    glGenTextures(1, &t);
    u->texture = t;
    glBindTexture(GL_TEXTURE_2D, t);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
}

/* The image shown, tone-mapped (or its error in false colour), into the texture drawn. */
void tonemap_and_upload(ui_thread *u) {
    int w = u->front.width, h = u->front.height;
    if (!u->front.rgb || w <= 0 || h <= 0) return;
    if (w * h > u->pixels_cap) {
        free(u->pixels);
        u->pixels = malloc(3 * (size_t)w * (size_t)h);
        u->pixels_cap = u->pixels ? w * h : 0;
        if (!u->pixels) return;
    }
    const image_rgb *ref = &u->reference;
    if (u->ctl.show == UI_SHOW_ERROR && ref->rgb && ref->width == w && ref->height == h) {
        false_colour_error(u->front.rgb, ref->rgb, w * h, u->pixels);
    } else { /* also an image of another size than the reference's */
        tonemap_params tp = {u->ctl.exposure, 0.0f, 0.0f, (tonemap_op)u->ctl.tonemap};
        tonemap_apply(u->front.rgb, w * h, &tp, u->pixels);
    }
    make_texture(u);
    glBindTexture(GL_TEXTURE_2D, u->texture);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    if (w != u->tex_w || h != u->tex_h) {
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB8, w, h, 0, GL_RGB, GL_UNSIGNED_BYTE, u->pixels);
        u->tex_w = w;
        u->tex_h = h;
    } else {
        glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, w, h, GL_RGB, GL_UNSIGNED_BYTE, u->pixels);
    }
}

/* Saves the image as shown, without the panel, as a PNG (numbered, never overwriting). */
void take_screenshot(ui_thread *u, const char *name) {
    char path[1024], err[1200];
    if (u->need_tonemap) { /* a newer image or exposure than the one drawn last: save what is current */
        tonemap_and_upload(u);
        u->need_tonemap = 0;
    }
    if (!u->front.rgb || !u->pixels) {
        snprintf(u->message, sizeof u->message, "%s: nothing rendered yet", name);
        cli_error("%s", u->message);
        return;
    }
    if (unique_path(name, path, sizeof path) != 0) {
        snprintf(u->message, sizeof u->message, "%s: no free file name", name);
        cli_error("%s", u->message);
        return;
    }
    if (png_save_rgb8(path, u->front.width, u->front.height, u->pixels, WRITE_NO_REPLACE, err, sizeof err) != 0) {
        snprintf(u->message, sizeof u->message, "%s", err);
        cli_error("%s", err);
        return;
    }
    snprintf(u->message, sizeof u->message, "wrote %s", path);
    printf("glint: wrote %s\n", path);
    fflush(stdout);
}

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
                   .tonemap_names = tonemap_names,
                   .num_tonemaps = TONEMAP_COUNT,
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
    const char *methods[METHOD_COUNT];
    for (int m = 0; m < METHOD_COUNT; m++) methods[m] = method_name((render_method)m);
    st.method_names = methods;
    st.num_methods = METHOD_COUNT;
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
