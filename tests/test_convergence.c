/* Convergence. The path tracer, unbiased, has an error that falls like 1/sqrt(spp): mean squared
 * error against a much longer render is V/n + V/N_ref for per-sample variance V; a bias would show
 * as a floor, a wrong weighting of samples as a different slope. The VSL estimator with its
 * default, consistent schedule converges to the path tracer's answer in a closed diffuse and a
 * closed glossy room, along the edges (where a fixed radius loses light) as in the open; so does
 * auto in the diffuse room, probing both and then choosing per tile. */
#include <math.h>
#include <stdlib.h>

#include "check.h"
#include "test_scenes.h"

static double mse(const float *a, const float *b, int n) {
    double s = 0.0;
    for (int i = 0; i < 3 * n; i++) s += ((double)a[i] - b[i]) * ((double)a[i] - b[i]);
    return s / (3.0 * n);
}

static void test_path_tracer_rate(void) {
    /* A small room: Lambert walls, a large emissive ceiling panel, a glossy Phong box and a Ward
     * box, so every part of the path tracer (NEE, MIS on both lobes, Russian roulette)
     * contributes. The light is large and the lobes moderate so that the per-sample variance is
     * finite and not dominated by rare caustic paths: the squared error of a few hundred pixels
     * then estimates its expectation well. */
    scene *s = ts_new("convergence-room");
    int wall = ts_lambert(s, v3(0.7f, 0.6f, 0.5f), v3s(0), 0);
    int lamp = ts_lambert(s, v3s(0), v3s(3.0f), 0);
    material phong = material_default();
    phong.model = MATERIAL_PHONG;
    phong.kd = v3s(0.2f);
    phong.ks = v3s(0.6f);
    phong.exponent = 12.0f;
    material ward = material_default();
    ward.model = MATERIAL_WARD;
    ward.kd = v3(0.1f, 0.2f, 0.1f);
    ward.ks = v3s(0.7f);
    ward.alpha_x = 0.25f;
    ward.alpha_y = 0.4f;
    int mp = ts_material(s, phong), mw = ts_material(s, ward);
    ts_box(s, v3(-1, 0, -1), v3(1, 2, 1), 1, wall);
    ts_quad(s, v3(-0.8f, 1.99f, -0.8f), v3(0.8f, 1.99f, -0.8f), v3(0.8f, 1.99f, 0.8f), v3(-0.8f, 1.99f, 0.8f), lamp);
    ts_box(s, v3(-0.7f, 0, -0.6f), v3(-0.1f, 0.8f, 0.0f), 0, mp);
    ts_box(s, v3(0.2f, 0, -0.3f), v3(0.7f, 0.5f, 0.3f), 0, mw);
    ts_finalize(s);
    camera cam = camera_look_at(v3(0, 1.0f, 0.95f), v3(0, 0.6f, 0), v3(0, 1, 0), 1.3f);

    const int w = 32, h = 24, n = w * h, n_ref = 4096;
    float *ref = ts_render(s, &cam, w, h, n_ref, 16, 1, COMP_MASK_ALL);
    const int spp[4] = {4, 16, 64, 256};
    double m[4];
    for (int k = 0; k < 4; k++) {
        float *img = ts_render(s, &cam, w, h, spp[k], 16, 100 + (uint64_t)k, COMP_MASK_ALL);
        m[k] = mse(img, ref, n);
        printf("spp %4d  rmse %.5f\n", spp[k], sqrt(m[k]));
        free(img);
    }
    /* V from the shortest render, then the part of each error that is the render's own. */
    double v = m[0] / (1.0 / spp[0] + 1.0 / n_ref);
    double own[4];
    for (int k = 0; k < 4; k++) own[k] = m[k] - v / n_ref;
    double slope = log(own[3] / own[0]) / log((double)spp[3] / spp[0]);
    printf("mse slope %.3f (expected -1: rmse ~ spp^-0.5)\n", slope);
    CHECK(v > 0.0, "the scene has no variance: the test tests nothing");
    CHECK_NEAR(slope, -1.0, 0.12, "error does not fall like 1/sqrt(spp)");
    for (int k = 1; k < 4; k++)
        CHECK_NEAR(own[k] * spp[k] / v, 1.0, 0.25, "mse at %d spp against the 1/spp prediction", spp[k]);
    free(ref);
    scene_destroy(s);
}

/* ---- the VSL estimator's consistent schedule ---------------------------------------------------- */

enum { VW = 24, VH = 18, VN = VW * VH, SEEDS = 4, CHECKPOINTS = 3 };
static const int checkpoint_frames[CHECKPOINTS] = {16, 64, 256};

/* Which pixels see a point within 0.2 m of the box's edges (1) or not (0); -1: nothing hit. */
static void edge_mask(const scene *s, const camera *cam, int *mask) {
    for (int y = 0; y < VH; y++)
        for (int x = 0; x < VW; x++) {
            vec3 d = camera_ray_dir(cam, (float)VW / VH, (x + 0.5f) / VW, (y + 0.5f) / VH);
            surface_hit h;
            int i = y * VW + x;
            mask[i] = -1;
            if (!scene_intersect(s, cam->position, d, INFINITY, &h)) continue;
            /* distance to the nearest edge: the second smallest distance to a face */
            float a = 1 - fabsf(h.p.x), b = 1 - fabsf(h.p.y), c = 1 - fabsf(h.p.z);
            float lo = fminf(a, fminf(b, c)), hi = fmaxf(a, fmaxf(b, c)), mid = a + b + c - lo - hi;
            mask[i] = mid < 0.2f;
        }
}

/* Mean indirect radiance over the pixels with mask == region. */
static double region_mean(const float *img, const int *mask, int region) {
    double sum = 0.0;
    int n = 0;
    for (int i = 0; i < VN; i++)
        if (mask[i] == region) sum += (double)img[3 * i] + img[3 * i + 1] + img[3 * i + 2], n++;
    return n ? sum / n : 0.0;
}

/* Region means of `SEEDS` independent runs at each checkpoint, and each region's standard error
 * of their mean there, from the spread of single frames: frames are independent (fresh lights
 * and random numbers), and a glossy room's fireflies make the spread of only `SEEDS` runs too
 * uncertain to test against (0.013 and 0.028 for one room from two sets of seeds). */
static void vsl_runs(const scene *s, const camera *cam, render_params p, const int *mask,
                     double means[CHECKPOINTS][2][SEEDS], double se[CHECKPOINTS][2]) {
    enum { FRAMES = 256 };
    static double frame[2][SEEDS][FRAMES];
    float *img = malloc(sizeof(float) * 3 * VN);
    for (int k = 0; k < SEEDS; k++) {
        p.seed = 40 + (uint64_t)k;
        char err[256];
        render_session *rs = session_create(s, cam, &p, err, sizeof err);
        double before[2] = {0.0, 0.0};
        for (int c = 0, f = 0; c < CHECKPOINTS; c++) {
            for (; f < checkpoint_frames[c]; f++) {
                session_render_frame(rs);
                film_resolve(session_film(rs), 1u << COMP_INDIRECT, img);
                for (int r = 0; r < 2; r++) { /* this frame's own region mean, from the running one */
                    double now = region_mean(img, mask, r);
                    frame[r][k][f] = now * (f + 1) - before[r] * f;
                    before[r] = now;
                }
            }
            for (int r = 0; r < 2; r++) means[c][r][k] = before[r];
        }
        session_destroy(rs);
    }
    for (int c = 0; c < CHECKPOINTS; c++)
        for (int r = 0; r < 2; r++) {
            int n = checkpoint_frames[c];
            double m = 0.0, v = 0.0;
            for (int k = 0; k < SEEDS; k++)
                for (int f = 0; f < n; f++) m += frame[r][k][f] / (SEEDS * n);
            for (int k = 0; k < SEEDS; k++)
                for (int f = 0; f < n; f++) v += (frame[r][k][f] - m) * (frame[r][k][f] - m) / (SEEDS * n - 1);
            se[c][r] = sqrt(v / (SEEDS * n));
        }
    free(img);
}

/* Bias of the runs' mean against ref, and the standard error se_abs relative to ref. */
static void bias_of(const double *runs, double ref, double se_abs, double *bias, double *se) {
    double m = 0.0;
    for (int k = 0; k < SEEDS; k++) m += runs[k] / SEEDS;
    *bias = m / ref - 1.0;
    *se = se_abs / ref;
}

static void test_vsl_converges(int glossy) {
    scene *s = ts_new(glossy ? "closed glossy room" : "closed diffuse room");
    material m = ts_phong(v3s(glossy ? 0.15f : 0.6f), v3s(glossy ? 0.7f : 0.0f), 60.0f);
    ts_box(s, v3(-1, -1, -1), v3(1, 1, 1), 1, ts_material(s, m));
    light l = {.type = LIGHT_POINT, .color = v3s(1.0f), .position = v3(0.3f, 0.5f, 0.2f)};
    scene_add_light(s, &l);
    ts_finalize(s);
    camera cam = camera_look_at(v3(0.2f, 0.1f, 0.9f), v3(-1, -1, -1), v3(0, 1, 0), 1.3f);
    int mask[VN];
    edge_mask(s, &cam, mask);
    render_params pt = {.width = VW, .height = VH, .max_depth = 8, .seed = 3};
    float *ref = ts_render_with(s, &cam, &pt, glossy ? 16384 : 4096, 1u << COMP_INDIRECT);
    double ref_mean[2] = {region_mean(ref, mask, 0), region_mean(ref, mask, 1)};
    /* The defaults, with few lights a frame so that radii are large and the bias a fixed radius
     * keeps shows plainly; the glossy room gathers its lobes (the VSL kernel's own glossy case). */
    render_params p = {.width = VW, .height = VH, .method = METHOD_VSL, .max_depth = 8};
    p.vl.count = 1024;
    if (glossy) p.vl.trace_glossy = -1.0f;
    static double schedule[CHECKPOINTS][2][SEEDS], fixed[CHECKPOINTS][2][SEEDS];
    double schedule_se[CHECKPOINTS][2], fixed_se[CHECKPOINTS][2];
    vsl_runs(s, &cam, p, mask, schedule, schedule_se);
    p.vl.radius_shrink = -1.0f;
    vsl_runs(s, &cam, p, mask, fixed, fixed_se);
    const char *regions[2] = {"interior", "edges"};
    for (int r = 0; r < 2; r++) {
        double b[CHECKPOINTS], se[CHECKPOINTS], fb, fse;
        for (int c = 0; c < CHECKPOINTS; c++) bias_of(schedule[c][r], ref_mean[r], schedule_se[c][r], &b[c], &se[c]);
        bias_of(fixed[CHECKPOINTS - 1][r], ref_mean[r], fixed_se[CHECKPOINTS - 1][r], &fb, &fse);
        printf("%s, %s: bias %+.4f (%.4f), %+.4f (%.4f), %+.4f (%.4f) after %d, %d, %d frames; fixed radius %+.4f "
               "(%.4f)\n",
               s->path, regions[r], b[0], se[0], b[1], se[1], b[2], se[2], checkpoint_frames[0], checkpoint_frames[1],
               checkpoint_frames[2], fb, fse);
        /* The reference's own noise is below 0.3% over a region (measured); 1% stands for it. */
        CHECK(fabs(b[2]) < 3.0 * se[2] + 0.01,
              "%s, %s: the mean is %+.4f off path tracing after %d frames (noise %.4f)", s->path, regions[r], b[2],
              checkpoint_frames[2], se[2]);
        CHECK(fabs(b[2]) < fabs(fb) || fabs(fb) < 3.0 * fse + 0.01,
              "%s, %s: the schedule leaves %+.4f, no less than the fixed radius's %+.4f", s->path, regions[r], b[2],
              fb);
    }
    if (!glossy) { /* auto, its tiles choosing on the way, converges as its estimators do */
        p.vl.radius_shrink = 0.0f;
        p.method = METHOD_AUTO;
        vsl_runs(s, &cam, p, mask, schedule, schedule_se);
        for (int r = 0; r < 2; r++) {
            double b, se;
            bias_of(schedule[CHECKPOINTS - 1][r], ref_mean[r], schedule_se[CHECKPOINTS - 1][r], &b, &se);
            printf("%s, %s: auto's bias %+.4f (%.4f) after %d frames\n", s->path, regions[r], b, se,
                   checkpoint_frames[CHECKPOINTS - 1]);
            CHECK(fabs(b) < 3.0 * se + 0.01,
                  "%s, %s: auto's mean is %+.4f off path tracing after %d frames (noise %.4f)", s->path, regions[r], b,
                  checkpoint_frames[CHECKPOINTS - 1], se);
        }
    }
    free(ref);
    scene_destroy(s);
}

int main(void) {
    test_path_tracer_rate();
    test_vsl_converges(0);
    test_vsl_converges(1);
    return check_exit("test_convergence");
}
