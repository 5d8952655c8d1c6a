/* The viewer's render side through its narrow interface (app/view/view_controller.h), headless: it
 * links no window and no GL. Every image is at the render's full size and finite; a camera change
 * is shown with its own generation and carries history over; pausing stops refinement between
 * frames (nothing more is rendered while it stands); an export written after two whole frames is,
 * bit for bit, the film a session makes of the same two frames (the display never touches the
 * estimate); a load that fails changes nothing and says why; quitting reports its counts; a change
 * at rest stops the part in flight, those while things move do not; the estimator's map is shown
 * in place of light when asked, as is the map of each pixel's rays. Waits are for what happens, counted, never for a time. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "camera.h"
#include "check.h"
#include "scratch.h"
#include "session.h"
#include "view_controller.h"

#define W 64
#define H 36

static void nap(void) { nanosleep(&(struct timespec){0, 20 * 1000 * 1000}, NULL); }

/* Waits until the render side has published an image of generation gen or later with at least
 * `frames` whole frames behind it; the newest image into *img. */
static void wait_for(view_controller *c, uint64_t *serial, image_buf *img, uint64_t gen, long long frames) {
    view_stats st;
    for (;;) {
        controller_take_image(c, serial, img);
        controller_stats(c, &st);
        if (img->rgb && img->generation >= gen && st.frames_generation >= gen && st.frames >= frames &&
            img->frames >= frames)
            return;
        nap();
    }
}

/* Shows the film components in mask (or SHOW_ESTIMATOR_SHARE), the filter on; the image of the
 * second update after the change (the first may have begun before it) into *img. */
static void set_look(view_controller *c, uint64_t *serial, image_buf *img, unsigned mask) {
    view_stats st;
    controller_stats(c, &st);
    uint64_t asked = st.updates;
    controller_set_look(c, mask, 1);
    do {
        nap();
        controller_stats(c, &st);
    } while (st.updates < asked + 2);
    controller_take_image(c, serial, img);
    CHECK(img->mask == mask, "the image asked to show %#x shows %#x", mask, img->mask);
}

static int finite_image(const image_buf *img) {
    for (int i = 0; i < 3 * img->width * img->height; i++)
        if (!isfinite(img->rgb[i])) return 0;
    return 1;
}

/* A change while the image is at rest stops the part in flight (its first image comes sooner), and
 * the accumulation after it runs whole frames; changes while things move (each within 20 ms of the
 * last, after the first) stop none: a drag's steps would stop every part. At rest an update renders
 * parts for most of its time, so a change lands in one in all but a few of its tries. */
static void check_preemption(void) {
    char err[1200];
    scene *s = scene_load("builtin:atelier", NULL, NULL, err, sizeof err); /* the controller's to free */
    CHECK(s != NULL, "builtin:atelier: %s", err);
    if (!s) return;
    camera cam = scene_camera(s, 0, 240.0f / 136.0f);
    render_params p = {.method = METHOD_VSL, .max_depth = 4, .seed = 6, .threads = 2};
    view_start start = {.cam = cam, .params = p, .width = 240, .height = 136, .denoise = 1};
    view_controller *c = controller_start(s, &start, err, sizeof err);
    CHECK(c != NULL, "controller_start: %s", err);
    if (!c) return;
    light_edits none;
    clear_light_edits(&none);
    uint64_t serial = 0, gen = 0;
    image_buf img = {0};
    wait_for(c, &serial, &img, 0, 0);
    view_stats st;
    camera moved = cam;
    for (int k = 0; k < 20; k++) { /* at rest: a change after more than YOUNG_SECONDS (0.5 s) */
        nanosleep(&(struct timespec){0, 700 * 1000 * 1000}, NULL);
        moved.position = add3(moved.position, v3(0.005f, 0.0f, 0.0f));
        gen = controller_change(c, &moved, &p, &none, 0);
        wait_for(c, &serial, &img, gen, 0);
        controller_stats(c, &st);
        if (st.preempted_parts > 0) break;
    }
    CHECK(st.preempted_parts > 0, "no change at rest stopped the part in flight in 20 tries");
    wait_for(c, &serial, &img, gen, 1);
    CHECK(img.generation == gen && finite_image(&img), "after a stopped part: a whole frame of the change");
    uint64_t preempted = st.preempted_parts;
    for (int k = 0; k < 20; k++) { /* moving: the first change may find the image at rest, no other */
        moved.position = add3(moved.position, v3(0.005f, 0.0f, 0.0f));
        gen = controller_change(c, &moved, &p, &none, 0);
        nap();
    }
    wait_for(c, &serial, &img, gen, 0);
    controller_stats(c, &st);
    CHECK(st.preempted_parts <= preempted + 1, "changes 20 ms apart stopped %llu parts",
          (unsigned long long)(st.preempted_parts - preempted));
    controller_stop(c, NULL);
    free(img.rgb);
}

int main(void) {
    char err[1200], path[1100];
    if (scratch_open("controller") != 0) return fprintf(stderr, "no scratch directory\n"), 1;
    scene *s = scene_load("builtin:atelier", NULL, NULL, err, sizeof err);
    CHECK(s != NULL, "builtin:atelier: %s", err);
    if (!s) return check_exit("test_controller");
    camera cam = scene_camera(s, 0, (float)W / (float)H);
    render_params p = {.method = METHOD_VSL, .max_depth = 4, .seed = 5, .threads = 2};
    view_start start = {.cam = cam, .params = p, .width = W, .height = H, .denoise = 1};
    check_preemption();
    view_controller *c = controller_start(s, &start, err, sizeof err);
    CHECK(c != NULL, "controller_start: %s", err);
    if (!c) return check_exit("test_controller");

    uint64_t serial = 0;
    image_buf img = {0};
    wait_for(c, &serial, &img, 0, 1);
    CHECK(img.width == W && img.height == H && img.full_w == W, "an image at %dx%d of %dx%d", img.width, img.height,
          img.full_w, img.full_h);
    CHECK(finite_image(&img), "the image shown is finite");

    /* the estimator's map in place of light: vsl gave every sampled pixel all its samples */
    set_look(c, &serial, &img, SHOW_ESTIMATOR_SHARE);
    int ones = 0;
    for (int i = 0; i < 3 * W * H; i++) ones += img.rgb[i] == 1.0f;
    CHECK(ones == 3 * W * H, "the estimator's map under vsl: %d of %d values 1", ones, 3 * W * H);
    /* the map of work: each pixel's rays against the most, in [0, 1], the most at 1, not all alike */
    set_look(c, &serial, &img, SHOW_WORK_MAP);
    float least = 1.0f, most = 0.0f;
    for (int i = 0; i < 3 * W * H; i++) least = fminf(least, img.rgb[i]), most = fmaxf(most, img.rgb[i]);
    CHECK(most == 1.0f && least >= 0.0f && least < 0.9f, "the map of work spans %g to %g", least, most);
    set_look(c, &serial, &img, COMP_MASK_ALL);
    view_stats st;

    /* pause: refinement stands once the frame under way is whole; nothing is rendered meanwhile */
    controller_set_refinement(c, 1, 0, 0.0);
    do {
        nap();
        controller_stats(c, &st);
    } while (!st.standing);
    CHECK(st.parts == 0, "paused mid-frame: %d parts of %d done", st.parts_done, st.parts);
    uint64_t updates = st.updates, frames = st.frames_total;
    for (int k = 0; k < 10; k++) nap();
    controller_stats(c, &st);
    CHECK(st.frames_total == frames && st.updates == updates, "rendered while paused: frames %llu -> %llu",
          (unsigned long long)frames, (unsigned long long)st.frames_total);
    controller_set_refinement(c, 0, 0, 0.0);

    /* a camera change: its own generation, history carried over */
    camera moved = cam;
    moved.position = add3(moved.position, v3(0.02f, 0.0f, 0.0f));
    light_edits none;
    clear_light_edits(&none);
    uint64_t gen = controller_change(c, &moved, &p, &none, 0);
    wait_for(c, &serial, &img, gen, 0);
    controller_stats(c, &st);
    CHECK(img.generation == gen && memcmp(&img.cam, &moved, sizeof moved) == 0, "the change's image and camera");
    CHECK(st.carried > st.lost, "a small move carries most of the history: carried %lld, lost %lld", st.carried,
          st.lost);

    /* back to the first view, two whole frames, an export: the film of a session of the same frames */
    gen = controller_change(c, &cam, &p, &none, 0);
    controller_set_refinement(c, 0, 2, 0.0);
    do {
        nap();
        controller_stats(c, &st);
    } while (!(st.standing && st.frames_generation == gen && st.frames == 2));
    path_in(path, sizeof path, "export.exr");
    controller_export(c, path);
    uint64_t msg = 0;
    char text[1200] = "";
    while (!controller_take_message(c, &msg, text, sizeof text) || !strstr(text, "export.exr")) nap();
    CHECK(strstr(text, "wrote"), "export: %s", text);
    image_rgb exported = {0};
    CHECK(image_rgb_load(path, &exported, err, sizeof err) == 0, "%s", err);
    /* each accumulation draws its own seed: the image of this view says which */
    controller_take_image(c, &serial, &img);
    CHECK(img.generation == gen, "the newest image is of the last change");
    render_params q = p;
    q.width = W, q.height = H, q.seed = img.seed;
    render_session *rs = session_create(s, &cam, &q, err, sizeof err);
    CHECK(rs != NULL, "session: %s", err);
    if (rs && exported.rgb) {
        session_render_frame(rs);
        session_render_frame(rs);
        float *mean = malloc(sizeof(float) * 3 * W * H);
        film_resolve(session_film(rs), COMP_MASK_ALL, mean);
        CHECK(memcmp(mean, exported.rgb, sizeof(float) * 3 * W * H) == 0,
              "the export is not the film of a session's two frames (seed %llu)", (unsigned long long)q.seed);
        free(mean);
    }
    session_destroy(rs);
    image_rgb_free(&exported);

    /* a load that fails: said, and nothing changes */
    uint64_t info_serial = 0;
    scene_info info;
    controller_take_info(c, &info_serial, &info);
    uint64_t resets = st.resets;
    uint64_t load = controller_load(c, LOAD_SCENE, "no-such-scene.gltf", "", 0);
    while (!controller_load_settled(c, load, info_serial)) nap();
    controller_take_message(c, &msg, text, sizeof text);
    controller_stats(c, &st);
    CHECK(strstr(text, "no-such-scene.gltf"), "the failed load is not said: %s", text);
    CHECK(st.resets == resets, "a failed load restarted the accumulation");

    view_stats last;
    controller_stop(c, &last);
    CHECK(last.frames_total >= 3 && last.late_parts <= 1, "at the end: %llu frames, %llu late parts",
          (unsigned long long)last.frames_total, (unsigned long long)last.late_parts);
    free(img.rgb);
    int status = check_exit("test_controller");
    scratch_close(status);
    return status;
}
