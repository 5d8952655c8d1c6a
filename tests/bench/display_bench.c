/* The display pipeline headless, as the viewer's render thread drives it: each update renders one
 * part of a frame (session_render_part) into the display's sink, the display takes the samples and
 * resolves the image shown; the camera may orbit a little before each update. Prints, per update,
 * what it cost (part, view change, resolve: wall and CPU time, the filter's wall time and passes)
 * and, given a reference of the final pose, the error of the image shown and of the film. A measurement for tuning (use a release build with tests on),
 * not a test; the viewer itself is measured by tests/bench/viewer_display.sh.
 *
 * usage: display_bench [--scene S] [--method M] [--size WxH] [--parts K] [--updates N]
 *                      [--rest R] [--orbit DEG --orbit-updates M] [--denoise 0|1] [--by-need 0|1] [--reference REF.exr]
 *                      [--threads T] [--seed S] [--save PREFIX] [--light DX,DY,DZ]
 * The orbit turns the camera by DEG about the vertical through the point in front of it as far as
 * the scene's centre (as the viewer's orbit turns) before each of the first M updates; it begins
 * DEG x M short of the scene's first camera, so that it ends there and a reference of that camera
 * (glint render) serves every orbit. With --rest R the orbit begins after R updates at rest (history
 * to carry over); --orbit 12 --orbit-updates 1 is then a jump. A start outside the room (on atelier
 * 12 degrees of a negative DEG, on doorway 8 of a positive one) is refused after the rest: it would
 * measure a cold start, not the history carried. --by-need 0 renders frames in the lattice's order, not the
 * display's need's (session_set_packet_need). --light drags the scene's light 0 by (DX, DY, DZ) in
 * M equal steps (--orbit-updates M, the camera still) after the rest, as the viewer's light drag
 * does, and makes the plan again after the last step (the viewer does 0.3 s later); the reference
 * is then one rendered with the light moved (glint render --move-light). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "camera.h"
#include "clock.h"
#include "display.h"
#include "image_io.h"
#include "metrics.h"
#include "session.h"

static double cpu_ms(void) {
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec * 1e3 + (double)t.tv_nsec * 1e-6;
}

static camera orbit(camera c, float degrees, vec3 target) {
    float t = degrees * PI_F / 180.0f, cs = cosf(t), sn = sinf(t);
    vec3 d = sub3(c.position, target);
    vec3 r = v3(cs * d.x + sn * d.z, d.y, -sn * d.x + cs * d.z);
    return camera_look_at(add3(target, r), target, v3(0, 1, 0), c.yfov);
}

static int any_light(const float *rgb, size_t n) {
    for (size_t i = 0; i < n; i++)
        if (rgb[i] > 0.0f) return 1;
    return 0;
}

#define EXTRA_REQUESTS 4096

int main(int argc, char **argv) {
    const char *scene_path = "builtin:atelier", *method = "vsl", *ref_path = NULL, *save = NULL;
    int w = 960, h = 540, parts = 64, updates = 30, rest = 0, orbit_updates = 0, denoise = 1, threads = 2, by_need = 1;
    int extra = 0;
    float orbit_deg = 0.0f;
    vec3 light_move = v3(0.0f, 0.0f, 0.0f);
    uint64_t seed = 1;
    for (int i = 1; i + 1 < argc; i += 2) {
        const char *a = argv[i], *v = argv[i + 1];
        if (!strcmp(a, "--scene"))
            scene_path = v;
        else if (!strcmp(a, "--method"))
            method = v;
        else if (!strcmp(a, "--size"))
            sscanf(v, "%dx%d", &w, &h);
        else if (!strcmp(a, "--parts"))
            parts = atoi(v);
        else if (!strcmp(a, "--updates"))
            updates = atoi(v);
        else if (!strcmp(a, "--rest"))
            rest = atoi(v);
        else if (!strcmp(a, "--orbit"))
            orbit_deg = (float)atof(v);
        else if (!strcmp(a, "--orbit-updates"))
            orbit_updates = atoi(v);
        else if (!strcmp(a, "--extra"))
            extra = atoi(v);
        else if (!strcmp(a, "--by-need"))
            by_need = atoi(v);
        else if (!strcmp(a, "--denoise"))
            denoise = atoi(v);
        else if (!strcmp(a, "--reference"))
            ref_path = v;
        else if (!strcmp(a, "--threads"))
            threads = atoi(v);
        else if (!strcmp(a, "--seed"))
            seed = strtoull(v, NULL, 10);
        else if (!strcmp(a, "--save"))
            save = v;
        else if (!strcmp(a, "--light"))
            sscanf(v, "%f,%f,%f", &light_move.x, &light_move.y, &light_move.z);
        else
            return fprintf(stderr, "display_bench: unknown option %s\n", a), 2;
    }
    char err[1200];
    scene *s = scene_load(scene_path, NULL, NULL, err, sizeof err);
    if (!s) return fprintf(stderr, "%s\n", err), 1;
    image_rgb ref = {0};
    if (ref_path && image_rgb_load(ref_path, &ref, err, sizeof err) != 0) return fprintf(stderr, "%s\n", err), 1;
    render_params p = {.width = w, .height = h, .max_depth = DEFAULT_MAX_DEPTH, .seed = seed, .threads = threads};
    int m = method_from_name(method);
    if (m < 0) return fprintf(stderr, "unknown method %s\n", method), 2;
    p.method = (render_method)m;
    camera cam = scene_camera(s, 0, (float)w / (float)h);
    vec3 pivot = madd3(cam.position, cam.forward,
                       fmaxf(dot3(sub3(bounds_center(s->bounds), cam.position), cam.forward), 0.05f * s->diag));
    if (is_black3(light_move)) cam = orbit(cam, -orbit_deg * (float)orbit_updates, pivot);
    render_session *rs = session_create(s, &cam, &p, err, sizeof err);
    display *d = rs ? display_create(w, h, threads, err, sizeof err) : NULL;
    if (!d) return fprintf(stderr, "%s\n", err), 1;
    session_set_sink(rs, display_sink(d));
    display_change_view(d, s, &cam, DISPLAY_RESTART);
    size_t n = 3 * (size_t)w * (size_t)h;
    float *shown = malloc(sizeof(float) * n), *raw = malloc(sizeof(float) * n);
    printf("update,seconds,part_ms,view_ms,gbuffer_ms,resolve_ms,resolve_cpu_ms,filter_ms,levels,mean_count,frames,"
           "shown_error,film_error\n");
    uint64_t t_start = clock_ns();
    for (int u = 0; u < updates; u++) {
        double view_ms = 0.0, gbuffer_ms = 0.0;
        int dragging = !is_black3(light_move);
        if (u >= rest && u < rest + orbit_updates) {
            if (dragging && scene_move_light(s, 0, scale3(light_move, 1.0f / (float)orbit_updates), err, sizeof err))
                return fprintf(stderr, "%s\n", err), 1;
            if (!dragging) cam = orbit(cam, orbit_deg, pivot);
            p.seed = seed + (uint64_t)u + 1; /* each accumulation its own random numbers, as the viewer */
            session_set_params(rs, &p);
            session_set_camera(rs, &cam);
            if (dragging && u + 1 == rest + orbit_updates && session_scene_changed(rs) != 0)
                return fprintf(stderr, "%s\n", session_error(rs)), 1;
            display_change_view(d, s, &cam, dragging ? DISPLAY_LIGHTS : DISPLAY_CAMERA);
            display_stats ds = display_get_stats(d);
            view_ms = ds.view_ms;
            gbuffer_ms = ds.gbuffer_ms;
        }
        if (by_need && session_frame_parts(rs) == 0) session_set_packet_need(rs, display_packet_need(d));
        uint64_t t0 = clock_ns();
        int done = 0;
        if (session_render_part(rs, parts, &done) != 0) return fprintf(stderr, "%s\n", session_error(rs)), 1;
        display_take_samples(d);
        if (extra > 0) { /* the display's own samples where they take most off its error */
            static extra_request req[EXTRA_REQUESTS];
            int asked = display_plan_extra(d, extra, req, EXTRA_REQUESTS);
            if (session_render_extra(rs, req, asked) == 0) display_take_extra(d, req, asked);
        }
        double part_ms = 1e-6 * (double)(clock_ns() - t0);
        double cpu0 = cpu_ms();
        display_resolve(d, COMP_MASK_ALL, denoise, shown);
        double resolve_cpu = cpu_ms() - cpu0;
        display_stats ds = display_get_stats(d);
        double e_shown = -1.0, e_film = -1.0;
        if (u + 1 == rest && orbit_updates > 0 && !any_light(shown, n)) {
            /* an orbit or jump whose start sees nothing would measure a cold start, not what history carries */
            fprintf(stderr, "display_bench: the view before the move shows no light (a camera outside the room?): "
                            "move the other way or less far\n");
            return 1;
        }
        int at_ref = ref.rgb && ref.width == w && ref.height == h && u >= rest + orbit_updates;
        if (at_ref) e_shown = metric_rel_l2(shown, ref.rgb, n);
        if (at_ref && session_frames(rs) > 0 && session_frame_parts(rs) == 0) {
            film_resolve(session_film(rs), COMP_MASK_ALL, raw);
            e_film = metric_rel_l2(raw, ref.rgb, n);
        }
        printf("%d,%.3f,%.1f,%.1f,%.1f,%.1f,%.1f,%.1f,%d,%.3f,%lld,%.4f,%.4f\n", u,
               1e-9 * (double)(clock_ns() - t_start), part_ms, view_ms, gbuffer_ms, ds.resolve_ms, resolve_cpu,
               ds.filter_ms, ds.levels, ds.mean_count, session_frames(rs), e_shown, e_film);
        fflush(stdout);
    }
    if (save) { /* the last image shown and the film, with their components: PREFIX-shown.exr, PREFIX-film.exr */
        char path[1100];
        float *layers[2][COMP_COUNT + 1];
        for (int k = 0; k < 2; k++)
            for (int c = 0; c <= COMP_COUNT; c++) {
                unsigned mask = c == COMP_COUNT ? COMP_MASK_ALL : 1u << c;
                layers[k][c] = malloc(sizeof(float) * n);
                if (k == 0)
                    display_resolve(d, mask, denoise, layers[k][c]);
                else
                    film_resolve(session_film(rs), mask, layers[k][c]);
            }
        const char *names[2] = {"shown", "film"};
        for (int k = 0; k < 2; k++) {
            snprintf(path, sizeof path, "%s-%s.exr", save, names[k]);
            exr_layer l[COMP_COUNT + 1] = {{"", layers[k][COMP_COUNT]}};
            for (int c = 0; c < COMP_COUNT; c++) l[c + 1] = (exr_layer){film_component_names[c], layers[k][c]};
            if (exr_save_layers(path, w, h, l, COMP_COUNT + 1, WRITE_REPLACE, err, sizeof err) != 0)
                fprintf(stderr, "%s\n", err);
            for (int c = 0; c <= COMP_COUNT; c++) free(layers[k][c]);
        }
    }
    free(shown);
    free(raw);
    image_rgb_free(&ref);
    display_destroy(d);
    session_destroy(rs);
    scene_destroy(s);
    return 0;
}
