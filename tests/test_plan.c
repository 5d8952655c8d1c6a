/* The effect plan: the analysis finds what each scene has (glossy or not, glossy surfaces that see
 * each other, indirect light at all), the passes follow, a skipped pass costs nothing (its
 * counters and timers stay zero), and the answer is the one every pass forced on gives, up to
 * noise: compared per image quadrant with the standard error measured from the frames. */
#include <math.h>

#include "check.h"
#include "envfilter.h"
#include "plan.h"
#include "test_scenes.h"

#define W 24
#define H 24

enum { ROOM_DIFFUSE, ROOM_GLOSSY_WALLS, ROOM_GLOSSY_BLOCK };

/* A closed room [-1,1]^2 x [0,2] with a panel under the ceiling and a block on the floor. Glossy
 * walls: the floor and the back wall are Phong mirrors that see each other. Glossy block: only the
 * (convex) block is glossy, and no glossy surface sees another. */
static scene *room(int kind) {
    scene *s = ts_new("room");
    int wall = ts_lambert(s, v3(0.6f, 0.55f, 0.5f), v3s(0.0f), 0);
    int glossy = ts_material(s, ts_phong(v3s(0.1f), v3s(0.7f), 300.0f));
    int lamp = ts_lambert(s, v3s(0.0f), v3(8.0f, 7.5f, 7.0f), 0);
    ts_box(s, v3(-1, 0, -1), v3(1, 2, 1), 1, wall);
    if (kind == ROOM_GLOSSY_WALLS) {
        ts_quad(s, v3(-0.99f, 0.001f, 0.99f), v3(0.99f, 0.001f, 0.99f), v3(0.99f, 0.001f, -0.99f),
                v3(-0.99f, 0.001f, -0.99f), glossy);
        ts_quad(s, v3(-0.99f, 0.01f, -0.999f), v3(0.99f, 0.01f, -0.999f), v3(0.99f, 1.99f, -0.999f),
                v3(-0.99f, 1.99f, -0.999f), glossy);
    }
    ts_box(s, v3(-0.3f, 0.0f, -0.4f), v3(0.2f, 0.5f, 0.1f), 0, kind == ROOM_GLOSSY_BLOCK ? glossy : wall);
    ts_quad(s, v3(-0.3f, 1.98f, -0.3f), v3(0.3f, 1.98f, -0.3f), v3(0.3f, 1.98f, 0.3f), v3(-0.3f, 1.98f, 0.3f), lamp);
    ts_finalize(s);
    return s;
}

static camera room_camera(void) { return camera_look_at(v3(0, 1, 0.95f), v3(0, 0.5f, -1), v3(0, 1, 0), 1.2f); }

static scene_analysis analyse(const scene *s) {
    scene_analysis a;
    char err[256];
    if (scene_analyse(s, &a, err, sizeof err) != 0) {
        fprintf(stderr, "scene_analyse: %s\n", err);
        abort();
    }
    return a;
}

/* Renders `frames` frames; per quadrant, the mean over frames of the quadrant's mean radiance
 * (components in mask) and its standard error from the frame-to-frame spread. */
typedef struct {
    double mean[4], sem[4];
    render_stats stats;
    effect_plan plan;
} run_result;

static run_result run(const scene *s, const camera *cam, render_params p, int frames, unsigned mask) {
    run_result r;
    memset(&r, 0, sizeof r);
    char err[256];
    render_session *rs = session_create(s, cam, &p, err, sizeof err);
    if (!rs) {
        fprintf(stderr, "session: %s\n", err);
        abort();
    }
    float *img = malloc(sizeof(float) * 3 * W * H);
    double prev[4] = {0, 0, 0, 0}, sum[4] = {0, 0, 0, 0}, sum2[4] = {0, 0, 0, 0};
    for (int f = 1; f <= frames; f++) {
        if (session_render_frame(rs) != 0) {
            fprintf(stderr, "frame: %s\n", session_error(rs));
            abort();
        }
        film_resolve(session_film(rs), mask, img);
        double q[4] = {0, 0, 0, 0};
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) {
                const float *px = &img[3 * (y * W + x)];
                q[(y >= H / 2) * 2 + (x >= W / 2)] += (px[0] + px[1] + px[2]) / (3.0 * W * H / 4);
            }
        for (int k = 0; k < 4; k++) { /* this frame's own value from the running means */
            double v = f * q[k] - (f - 1) * prev[k];
            prev[k] = q[k];
            sum[k] += v;
            sum2[k] += v * v;
        }
    }
    for (int k = 0; k < 4; k++) {
        r.mean[k] = sum[k] / frames;
        r.sem[k] = sqrt(fmax(sum2[k] / frames - r.mean[k] * r.mean[k], 0.0) / (frames - 1));
    }
    r.stats = session_stats(rs);
    r.plan = *session_plan(rs);
    free(img);
    session_destroy(rs);
    return r;
}

static void agree(const char *what, const run_result *a, const run_result *b) {
    for (int k = 0; k < 4; k++) {
        double tol = 4.5 * sqrt(a->sem[k] * a->sem[k] + b->sem[k] * b->sem[k]) + 1e-6;
        CHECK(fabs(a->mean[k] - b->mean[k]) <= tol, "%s, quadrant %d: plan %.5f vs every pass %.5f (tolerance %.5f)",
              what, k, a->mean[k], b->mean[k], tol);
    }
    printf("%s: plan %.4f %.4f %.4f %.4f, every pass %.4f %.4f %.4f %.4f\n", what, a->mean[0], a->mean[1], a->mean[2],
           a->mean[3], b->mean[0], b->mean[1], b->mean[2], b->mean[3]);
}

static render_params params(render_method method, int plan) {
    render_params p = {.width = W, .height = H, .method = method, .max_depth = 5, .seed = 11, .plan = plan};
    p.vl.count = 256;
    p.vl.secondary_rays = 8;
    return p;
}

#define ALL ((1u << COMP_DIRECT) | (1u << COMP_INDIRECT) | (1u << COMP_HIGHLIGHTS))

/* Diffuse walls: no glossy material, no highlight pass, the diffuse VSL kernel, and the answer of
 * the forced-full plan. Then the same room with glossy walls switches the glossy passes on. */
static void test_diffuse_then_glossy(void) {
    scene *s = room(ROOM_DIFFUSE);
    camera cam = room_camera();
    scene_analysis a = analyse(s);
    CHECK(a.glossy == 0 && a.diffuse >= 1 && !a.glossy_to_glossy,
          "diffuse room: %d glossy, %d diffuse materials, g2g %d", a.glossy, a.diffuse, a.glossy_to_glossy);
    CHECK(a.indirect && a.reflective && a.area == 2 && a.punctual == 0 && !a.env,
          "diffuse room: indirect %d, reflective %d, %d emissive triangles", a.indirect, a.reflective, a.area);
    effect_plan p = plan_make(&a, METHOD_VSL_HL, 5, PLAN_AUTO);
    CHECK(!p.highlights && p.virtual_lights && !p.vsl_all_strategies && !p.env_prefilter && p.max_depth == 5,
          "diffuse room plan: highlights %d, virtual lights %d, all strategies %d", p.highlights, p.virtual_lights,
          p.vsl_all_strategies);
    run_result plan = run(s, &cam, params(METHOD_VSL_HL, PLAN_AUTO), 48, ALL);
    run_result full = run(s, &cam, params(METHOD_VSL_HL, PLAN_FULL), 48, ALL);
    CHECK(plan.stats.hl_secondary_rays == 0 && plan.stats.hl_points == 0 && plan.stats.pass_ns[PASS_HIGHLIGHTS] == 0,
          "diffuse room: the skipped highlight pass did work (%llu rays)",
          (unsigned long long)plan.stats.hl_secondary_rays);
    CHECK(full.plan.highlights && full.plan.vsl_all_strategies, "forced full: every pass must be on");
    CHECK(plan.stats.vsl_samples > 0 && plan.stats.pass_ns[PASS_GATHER] > 0, "diffuse room: VSLs must still gather");
    agree("diffuse room, vsl+hl", &plan, &full);
    scene_analysis_free(&a);
    scene_destroy(s);

    s = room(ROOM_GLOSSY_WALLS);
    a = analyse(s);
    CHECK(a.glossy == 1 && a.glossy_to_glossy && a.alpha_min > 0.0f && a.alpha_min < BSDF_HIGHLIGHT_ALPHA,
          "glossy walls: %d glossy materials (alpha %g), g2g %d", a.glossy, (double)a.alpha_min, a.glossy_to_glossy);
    p = plan_make(&a, METHOD_VSL_HL, 5, PLAN_AUTO);
    CHECK(p.highlights && p.virtual_lights, "glossy walls: the plan must switch the highlight pass on");
    plan = run(s, &cam, params(METHOD_VSL_HL, PLAN_AUTO), 32, ALL);
    CHECK(plan.stats.hl_secondary_rays > 0 && plan.stats.hl_lobes > 0 && plan.stats.pass_ns[PASS_HIGHLIGHTS] > 0,
          "glossy walls: the highlight pass must work (%llu rays, %llu lobes)",
          (unsigned long long)plan.stats.hl_secondary_rays, (unsigned long long)plan.stats.hl_lobes);
    full = run(s, &cam, params(METHOD_VSL_HL, PLAN_FULL), 32, ALL);
    agree("glossy walls, vsl+hl", &plan, &full);
    /* camera - glossy - glossy - light is two scattering events: highlights at max depth 2 too */
    render_params two = params(METHOD_VSL_HL, PLAN_AUTO);
    two.max_depth = 2;
    run_result r2 = run(s, &cam, two, 2, ALL);
    CHECK(r2.plan.highlights && r2.stats.hl_secondary_rays > 0, "max depth 2: the highlight pass must run");
    scene_analysis_free(&a);
    scene_destroy(s);
}

/* A glossy block alone among diffuse walls: glossy, but no glossy surface sees another, so no
 * highlight pass and the VSLs keep those paths; forced on, the highlight pass takes them over:
 * both must give the same image. */
static void test_glossy_without_glossy_transport(void) {
    scene *s = room(ROOM_GLOSSY_BLOCK);
    camera cam = room_camera();
    scene_analysis a = analyse(s);
    CHECK(a.glossy == 1 && !a.glossy_to_glossy,
          "glossy block: %d glossy, g2g %d (the inside of the block must not count)", a.glossy, a.glossy_to_glossy);
    run_result plan = run(s, &cam, params(METHOD_VSL_HL, PLAN_AUTO), 48, ALL);
    run_result full = run(s, &cam, params(METHOD_VSL_HL, PLAN_FULL), 48, ALL);
    CHECK(!plan.plan.highlights && plan.stats.hl_secondary_rays == 0, "glossy block: no highlight pass expected");
    agree("glossy block, vsl+hl", &plan, &full);
    scene_analysis_free(&a);
    scene_destroy(s);
}

/* A camera that sees only a diffuse wall of the glossy room: no highlight ray that frame. */
static void test_view_without_glossy_pixels(void) {
    scene *s = room(ROOM_GLOSSY_WALLS);
    camera cam = camera_look_at(v3(0, 1, -0.5f), v3(1, 1, -0.5f), v3(0, 1, 0), 0.5f);
    run_result r = run(s, &cam, params(METHOD_VSL_HL, PLAN_AUTO), 2, ALL);
    CHECK(r.plan.highlights, "the scene calls for highlights");
    CHECK(r.stats.hl_points == 0 && r.stats.hl_secondary_rays == 0,
          "a view of a diffuse wall traced %llu highlight rays", (unsigned long long)r.stats.hl_secondary_rays);
    CHECK(r.stats.vsl_samples > 0, "the wall must still gather from the VSLs");
    scene_destroy(s);
}

/* A constant sky over a convex block: nothing reflects onto anything, so direct light only and
 * no virtual lights; the path tracer at full depth agrees. The same sky over the glossy room:
 * virtual lights from the sky alone, and the environment prefiltered once for every session. */
static void test_environment_only(void) {
    scene *s = ts_new("block under the sky");
    ts_box(s, v3(-0.5f, 0, -0.5f), v3(0.5f, 1, 0.5f), 0, ts_material(s, ts_phong(v3s(0.5f), v3s(0.3f), 40.0f)));
    enum { EW = 32, EH = 16 };
    image_rgb img = {EW, EH, malloc(sizeof(float) * 3 * EW * EH)};
    for (int i = 0; i < 3 * EW * EH; i++) img.rgb[i] = 0.8f;
    char err[256];
    CHECK(scene_set_env_image(s, &img, 0.0f, err, sizeof err) == 0, "env: %s", err);
    ts_finalize(s);
    camera cam = camera_look_at(v3(1.5f, 1.5f, 2.0f), v3(0, 0.4f, 0), v3(0, 1, 0), 0.9f);
    scene_analysis a = analyse(s);
    CHECK(a.env && a.punctual == 0 && a.area == 0 && !a.indirect, "block under the sky: env %d, indirect %d", a.env,
          a.indirect);
    run_result plan = run(s, &cam, params(METHOD_VSL, PLAN_AUTO), 24, ALL);
    CHECK(plan.plan.max_depth == 1 && !plan.plan.virtual_lights && plan.stats.light_paths == 0 &&
              plan.stats.pass_ns[PASS_VIRTUAL_LIGHTS] == 0,
          "block under the sky: depth %d, %llu light paths", plan.plan.max_depth,
          (unsigned long long)plan.stats.light_paths);
    run_result pt = run(s, &cam, params(METHOD_PT, PLAN_FULL), 24, ALL);
    agree("block under the sky, vsl (plan) vs pt", &plan, &pt);
    scene_analysis_free(&a);
    scene_destroy(s);

    s = ts_new("glossy floor and wall under the sky");
    int glossy = ts_material(s, ts_phong(v3s(0.1f), v3s(0.7f), 300.0f));
    ts_quad(s, v3(-2, 0, 2), v3(2, 0, 2), v3(2, 0, -2), v3(-2, 0, -2), glossy);
    ts_quad(s, v3(-2, 0, -1), v3(2, 0, -1), v3(2, 2, -1), v3(-2, 2, -1), glossy);
    img = (image_rgb){EW, EH, malloc(sizeof(float) * 3 * EW * EH)};
    for (int i = 0; i < 3 * EW * EH; i++) img.rgb[i] = 0.5f + 0.5f * (float)(i / (3 * EW)) / EH;
    CHECK(scene_set_env_image(s, &img, 0.0f, err, sizeof err) == 0, "env: %s", err);
    ts_finalize(s);
    cam = camera_look_at(v3(0, 0.6f, 2.2f), v3(0, 0.05f, 0), v3(0, 1, 0), 0.9f);
    run_result vsl = run(s, &cam, params(METHOD_VSL, PLAN_AUTO), 2, ALL);
    CHECK(vsl.stats.env_filter_bytes == 0 && !vsl.plan.env_prefilter, "vsl must not prefilter the environment");
    CHECK(vsl.stats.light_paths > 0 && vsl.plan.virtual_lights, "virtual lights from the sky alone");
    run_result hl = run(s, &cam, params(METHOD_VSL_HL, PLAN_AUTO), 2, ALL);
    CHECK(hl.plan.env_prefilter && hl.stats.env_filter_bytes > 0, "vsl+hl under a sky must prefilter it");
    /* The session's filter follows the scene's map: made again from another map (a larger one
     * here, so a larger filter). */
    render_params hp = params(METHOD_VSL_HL, PLAN_AUTO);
    render_session *rs = session_create(s, &cam, &hp, err, sizeof err);
    CHECK(rs && session_render_frame(rs) == 0, "session: %s", rs ? session_error(rs) : err);
    uint64_t before = session_stats(rs).env_filter_bytes;
    img = (image_rgb){4 * EW, 4 * EH, malloc(sizeof(float) * 3 * 16 * EW * EH)};
    for (int i = 0; i < 3 * 16 * EW * EH; i++) img.rgb[i] = 0.5f;
    CHECK(scene_set_env_image(s, &img, 0.0f, err, sizeof err) == 0, "env: %s", err);
    CHECK(session_scene_changed(rs) == 0 && session_render_frame(rs) == 0, "frame: %s", session_error(rs));
    CHECK(session_stats(rs).env_filter_bytes > before, "another map must be prefiltered again: %llu bytes, before %llu",
          (unsigned long long)session_stats(rs).env_filter_bytes, (unsigned long long)before);
    session_destroy(rs);
    scene_destroy(s);
}

/* A probe cut short by its time budget (here none at all) says so, and its plan turns every pass
 * on: the diffuse room, whose full probe switches the highlight pass off, gets it. */
static void test_cut_probe(void) {
    scene *s = room(ROOM_DIFFUSE);
    scene_analysis a, whole = analyse(s);
    char err[256];
    CHECK(scene_analyse_within(s, &a, 0.0, err, sizeof err) == 0, "%s", err);
    CHECK(a.cut && a.probe_rays == 0 && !whole.cut && whole.probe_rays > 0, "cut %d after %ld rays; whole %d, %ld",
          a.cut, a.probe_rays, whole.cut, whole.probe_rays);
    effect_plan p = plan_make(&a, METHOD_VSL_HL, 5, PLAN_AUTO), q = plan_make(&whole, METHOD_VSL_HL, 5, PLAN_AUTO);
    CHECK(p.full && p.highlights && p.virtual_lights && p.vsl_all_strategies && !q.highlights,
          "a cut probe's plan: full %d, highlights %d (the whole probe's %d)", p.full, p.highlights, q.highlights);
    CHECK(strstr(p.why_highlights, "time budget") != NULL, "the plan does not say why: %s", p.why_highlights);
    scene_analysis_free(&a);
    scene_analysis_free(&whole);
    scene_destroy(s);
}

int main(void) {
    test_cut_probe();
    test_diffuse_then_glossy();
    test_glossy_without_glossy_transport();
    test_view_without_glossy_pixels();
    test_environment_only();
    return check_exit("test_plan");
}
