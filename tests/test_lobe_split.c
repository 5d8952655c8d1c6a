/* The glossy part of a sample (the sink's glossy, session.h): the light that left the camera hit
 * through its view-dependent lobes, which the display keeps apart from the rest. Checked against
 * renders that have only that lobe at the camera hit: with direct light from a point light alone
 * (max depth 1) a sample's glossy part is the sample a render with the diffuse lobe taken out gives
 * (the same random numbers, the same arithmetic but for rounding), and its rest the one with the
 * glossy lobe taken out, for pt and for vsl's direct estimator; with indirect light (pt, depth 2)
 * their means agree within their noise, and not once the glossy part is scaled by 1.2 (the test can
 * fail). A diffuse scene has no glossy part at all; where the camera sees only a sharp glossy
 * lobe all of a sample is glossy, vsl's traced lobes and what its path gathers beyond them
 * included. */
#include <math.h>
#include <stdlib.h>

#include "check.h"
#include "session.h"
#include "test_scenes.h"

enum { W = 20, H = 14, N = W * H };

/* A floor (Phong kd, ks, exponent 40: alpha 0.22, traced by vsl) seen from above, walls
 * of Lambert wall_kd (or of the floor's material with wall_kd < 0) on three sides, a point light. */
static scene *room(float kd, float ks, float wall_kd) {
    scene *s = ts_new("lobes");
    int floor = ts_material(s, ts_phong(v3s(kd), v3s(ks), 40.0f));
    int wall = wall_kd < 0.0f ? floor : ts_lambert(s, v3(wall_kd, wall_kd * 0.8f, wall_kd * 0.6f), v3s(0.0f), 0);
    ts_quad(s, v3(-2, 0, -2), v3(-2, 0, 2), v3(2, 0, 2), v3(2, 0, -2), floor);
    ts_quad(s, v3(-2, 0, -2), v3(2, 0, -2), v3(2, 3, -2), v3(-2, 3, -2), wall);
    ts_quad(s, v3(-2, 0, 2), v3(-2, 0, -2), v3(-2, 3, -2), v3(-2, 3, 2), wall);
    ts_quad(s, v3(2, 0, -2), v3(2, 0, 2), v3(2, 3, 2), v3(2, 3, -2), wall);
    ts_point_light(s, v3(0.3f, 2.2f, 0.4f));
    ts_finalize(s);
    return s;
}

/* Every pixel sees the floor: its lobes are all the camera hits have. */
static camera view(void) { return camera_look_at(v3(0, 1.5f, 0.8f), v3(0, 0, -0.2f), v3(0, 1, 0), 0.6f); }

/* frames frames of scene s; per pixel the mean over them of the film's samples (film), and of the
 * sink's glossy part and its rest (glossy, rest), all components summed; *worst the largest glossy
 * part above its sample (relative), *least the smallest below zero. */
typedef struct {
    double film[N], glossy[N], rest[N];
    double worst, least;
} split_means;

static void render_split(const scene *s, render_method method, int depth, int frames, split_means *m) {
    char err[256];
    camera cam = view();
    render_params p = {.width = W, .height = H, .max_depth = depth, .seed = 5, .threads = 2, .method = method};
    p.vl.count = 32;
    p.vl.adapt = VL_ADAPT_OFF; /* the same samples whatever the film holds */
    render_session *rs = session_create(s, &cam, &p, err, sizeof err);
    CHECK(rs != NULL, "session: %s", err);
    if (!rs) return;
    static float rgb[COMP_COUNT][3 * N], glossy[COMP_COUNT][3 * N];
    static uint32_t stamp[N];
    sample_sink sink = {.serial = 1, .stamp = stamp};
    for (int c = 0; c < COMP_COUNT; c++) sink.rgb[c] = rgb[c], sink.glossy[c] = glossy[c];
    session_set_sink(rs, &sink);
    *m = (split_means){.worst = 0.0, .least = 0.0};
    for (int f = 0; f < frames; f++) {
        CHECK(session_render_frame(rs) == 0, "frame: %s", session_error(rs));
        for (int i = 0; i < N; i++) {
            if (stamp[i] != sink.serial) continue;
            for (int c = 0; c < COMP_COUNT; c++)
                for (int e = 0; e < 3; e++) {
                    double x = rgb[c][3 * i + e], g = glossy[c][3 * i + e];
                    m->glossy[i] += g / frames, m->rest[i] += (x - g) / frames;
                    if (g - x > m->worst * (fabs(x) + 1e-6)) m->worst = (g - x) / (fabs(x) + 1e-6);
                    if (g < m->least) m->least = g;
                }
        }
        sink.serial++;
    }
    static float img[3 * N];
    film_resolve(session_film(rs), COMP_MASK_ALL, img);
    for (int i = 0; i < N; i++) m->film[i] = (double)img[3 * i] + img[3 * i + 1] + img[3 * i + 2];
    session_destroy(rs);
}

/* Largest difference between a and b over the pixels, relative to b's largest value. */
static double max_gap(const double *a, const double *b) {
    double gap = 0.0, top = 1e-12;
    for (int i = 0; i < N; i++) gap = fmax(gap, fabs(a[i] - b[i])), top = fmax(top, fabs(b[i]));
    return gap / top;
}

/* Direct light from a point light: the parts are the lobe-only renders, sample for sample. */
static void check_direct(render_method method) {
    static split_means both, glossy_only, diffuse_only;
    scene *s = room(0.4f, 0.3f, 0.5f), *g = room(0.0f, 0.3f, 0.5f), *d = room(0.4f, 0.0f, 0.5f);
    /* (depth 1: the walls' light is nowhere in the image) */
    render_split(s, method, 1, 8, &both);
    render_split(g, method, 1, 8, &glossy_only);
    render_split(d, method, 1, 8, &diffuse_only);
    const char *name = method == METHOD_PT ? "pt" : "vsl";
    double eg = max_gap(both.glossy, glossy_only.film), ed = max_gap(both.rest, diffuse_only.film);
    CHECK(eg < 1e-4, "%s direct: the glossy part is the glossy lobe's light: off by %g", name, eg);
    CHECK(ed < 1e-4, "%s direct: the rest is the diffuse lobe's light: off by %g", name, ed);
    double lit = 0.0;
    for (int i = 0; i < N; i++) lit += glossy_only.film[i];
    CHECK(lit > 1e-3, "%s direct: the floor's glossy lobe reflects the light (%g)", name, lit);
    CHECK(both.worst < 1e-5 && both.least >= 0.0, "%s direct: no glossy part above its sample (%g) or below 0 (%g)",
          name, both.worst, both.least);
    scene_destroy(s), scene_destroy(g), scene_destroy(d);
}

/* Indirect light (pt, depth 2): the glossy part's mean is the glossy-lobe floor's film, within the
 * noise of both (the walls stay Lambert, so the lobe is taken out at the camera hit alone). */
static void check_indirect(void) {
    static split_means both, glossy_only;
    enum { FRAMES = 384 };
    scene *s = room(0.4f, 0.3f, 0.6f), *g = room(0.0f, 0.3f, 0.6f);
    render_split(s, METHOD_PT, 2, FRAMES, &both);
    render_split(g, METHOD_PT, 2, FRAMES, &glossy_only);
    /* the image's mean, and its spread from pixel to pixel of the two renders' difference: blocks
     * of pixels are independent estimates */
    double z[2];
    for (int k = 0; k < 2; k++) {
        double scale = k ? 1.2 : 1.0, sum = 0.0, sq = 0.0;
        for (int i = 0; i < N; i++) {
            double diff = scale * both.glossy[i] - glossy_only.film[i];
            sum += diff, sq += diff * diff;
        }
        double mean = sum / N, var = fmax(sq / N - mean * mean, 1e-30);
        z[k] = fabs(mean) / sqrt(var / N);
    }
    CHECK(z[0] < 4.0, "pt indirect: the glossy part's mean is the glossy lobe's light (z %.2f)", z[0]);
    CHECK(z[1] > 4.0, "pt indirect: and the test tells 1.2 times it apart (z %.2f)", z[1]);
    scene_destroy(s), scene_destroy(g);
}

/* No glossy lobe: no glossy part. Only a sharp glossy lobe at the camera hits (the floor): all of
 * it glossy, whatever the path meets after it (sharp walls, or Lambert walls, where vsl's path ends
 * in a gather). */
static void check_extremes(render_method method, float wall_kd) {
    static split_means m;
    const char *name = method == METHOD_PT ? "pt" : "vsl";
    scene *diffuse = room(0.5f, 0.0f, 0.6f), *sharp = room(0.0f, 0.6f, wall_kd);
    render_split(diffuse, method, 4, 4, &m);
    double most = 0.0, lit = 0.0;
    for (int i = 0; i < N; i++) most = fmax(most, fabs(m.glossy[i])), lit += m.film[i];
    CHECK(most == 0.0 && lit > 0.0, "%s: a diffuse room has no glossy part (%g)", name, most);
    render_split(sharp, method, 4, 4, &m);
    double off = 0.0, top = 0.0;
    for (int i = 0; i < N; i++) top = fmax(top, m.film[i]), off = fmax(off, fabs(m.rest[i]));
    CHECK(top > 0.0 && off <= 1e-4 * top, "%s: a sharp glossy floor's light is all glossy (walls %g; rest %g of %g)",
          name, wall_kd, off, top);
    scene_destroy(diffuse), scene_destroy(sharp);
}

int main(void) {
    check_direct(METHOD_PT);
    check_direct(METHOD_VSL);
    check_indirect();
    check_extremes(METHOD_PT, -1.0f);
    check_extremes(METHOD_VSL, -1.0f);
    check_extremes(METHOD_PT, 0.6f);
    check_extremes(METHOD_VSL, 0.6f);
    return check_exit("test_lobe_split");
}
