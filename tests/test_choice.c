/* --method auto's choice of estimator (choice.h), against hand-made records and against renders.
 * A tile takes the estimator whose samples' variance times work is the smaller, the variance
 * pooled over its pixels about each pixel's own mean (a tile whose light changes across it but
 * whose samples do not vary has none); a path-traced tile traces as many paths as a virtual-light
 * sample costs, within [1, CHOICE_MAX_PATHS]; a tile turns to the estimator it has not taken only
 * if that one measures better around it too. Judgements come before an accumulation's first frame
 * and at each power of two; the probe takes one pixel in each 4x4 block, the frames measure the
 * other estimator at each pixel of an 8x8 block once in 64 frames. The records' moments equal a
 * two-pass computation's. A render of an indirect-lit room (doorway) gives most tiles to the
 * virtual lights, its probe samples every tile and its map of shares stays in [0, 1]. (test_convergence checks auto's image against
 * path tracing, test_parts that its frames are the same whole and in parts.) */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "choice.h"
#include "test_scenes.h"

/* Tile t's pixels given samples of estimator e: a pixel's luminance alternates lum -/+ spread
 * around its own level (level + the pixel's x: the light changes across the tile), each sample
 * costing `work`. */
static void fill(estimator_choice *c, int tile_x, int e, int samples, double spread, double work) {
    for (int y = 0; y < CHOICE_TILE && y < c->height; y++)
        for (int x = tile_x * CHOICE_TILE; x < (tile_x + 1) * CHOICE_TILE && x < c->width; x++) {
            est_moments *m = &c->rec[y * c->width + x].e[e];
            for (int k = 0; k < samples; k++)
                est_moments_add(m, (float)(1.0 + 0.1 * x + (k % 2 ? spread : -spread)), work);
        }
}

static void test_judgement(void) {
    estimator_choice c;
    CHECK(choice_init(&c, 10 * CHOICE_TILE, CHOICE_TILE - 3) == 0, "choice_init");
    CHECK(c.tiles_x == 10 && c.tiles_y == 1, "tiles %dx%d", c.tiles_x, c.tiles_y);
    /* tiles 0, 3, 6 and 9; those between have no samples and trace one path */
    /* 0: vl's variance a tenth of pt's for 5 times the work: vl (0.5 < 1) */
    fill(&c, 0, EST_PT, 4, 1.0, 2.0), fill(&c, 0, EST_VL, 4, sqrt(0.1), 10.0);
    /* 3: half the variance for 4 times the work: pt (2 > 1), tracing 4 paths a frame */
    fill(&c, 3, EST_PT, 4, 1.0, 3.0), fill(&c, 3, EST_VL, 4, sqrt(0.5), 12.0);
    /* 6: no spread at all (the light changes across the tile, not between samples): one path */
    fill(&c, 6, EST_PT, 4, 0.0, 3.0), fill(&c, 6, EST_VL, 4, 0.0, 12.0);
    /* 9: vl 100 times the work and no less variance: pt, at most CHOICE_MAX_PATHS paths */
    fill(&c, 9, EST_PT, 4, 1.0, 1.0), fill(&c, 9, EST_VL, 4, 1.0, 100.0);
    choice_judge(&c);
    CHECK(c.mode[0] == CHOICE_VL, "tile 0 must take the virtual lights");
    CHECK(c.mode[1] == CHOICE_PT && c.paths[1] == 1, "a tile without samples must trace one path");
    CHECK(c.mode[3] == CHOICE_PT && c.paths[3] == 4, "tile 3 must trace 4 paths (mode %d, %d paths)", c.mode[3],
          c.paths[3]);
    CHECK(c.mode[6] == CHOICE_PT && c.paths[6] == 1, "tile 6 must trace one path (mode %d, %d paths)", c.mode[6],
          c.paths[6]);
    CHECK(c.mode[9] == CHOICE_PT && c.paths[9] == CHOICE_MAX_PATHS, "tile 9 must trace %d paths (mode %d, %d)",
          CHOICE_MAX_PATHS, c.mode[9], c.paths[9]);
    CHECK(c.vl_tiles == 1, "tile 0 alone takes the virtual lights (%d)", c.vl_tiles);
    /* tile 0's path tracing turns out quieter: it turns at the next judgement */
    fill(&c, 0, EST_PT, 400, 0.01, 2.0);
    choice_judge(&c);
    CHECK(c.mode[0] == CHOICE_PT && c.vl_tiles == 0, "tile 0 must turn to path tracing (mode %d)", c.mode[0]);
    CHECK(choice_vl_share(&c, 0, 4.0) == 0.0f, "no sample was recorded as a virtual light's in the map");
    choice_reset(&c);
    for (int t = 0; t < 10; t++) CHECK(c.paths[t] == 1, "a reset forgets the paths (tile %d)", t);
    CHECK(c.rec[5].e[EST_PT].n == 0.0f && c.rec[5].e[EST_VL].work == 0.0f, "a reset forgets the records");
    choice_free(&c);
    for (long long f = 0; f < 70; f++)
        CHECK(choice_judge_due(f) == (f == 0 || f == 1 || f == 2 || f == 4 || f == 8 || f == 16 || f == 32 || f == 64),
              "a judgement before frame %lld: %d", f, choice_judge_due(f));
}

/* A tile turns to the estimator it has not taken only on evidence that holds around it: that
 * estimator's variance is the larger of the tile's and its 3x3 tiles'. Three tiles take the
 * virtual lights; then the middle one's path tracing measures quiet (400 samples). With its
 * neighbours' few path-traced samples as quiet as its first ones, it turns; with theirs wild (a
 * variance 100 times, which its own few would have missed), it stays. */
static void test_turn_needs_neighbours(void) {
    for (int wild = 0; wild < 2; wild++) {
        estimator_choice c;
        CHECK(choice_init(&c, 3 * CHOICE_TILE, CHOICE_TILE) == 0, "choice_init");
        for (int t = 0; t < 3; t++)
            fill(&c, t, EST_PT, 4, t != 1 && wild ? 10.0 : 1.0, 2.0), fill(&c, t, EST_VL, 4, sqrt(0.1), 10.0);
        choice_judge(&c);
        CHECK(c.vl_tiles == 3, "all three tiles first take the virtual lights (%d)", c.vl_tiles);
        fill(&c, 1, EST_PT, 400, 0.01, 2.0);
        choice_judge(&c);
        CHECK(c.mode[1] == (wild ? CHOICE_VL : CHOICE_PT), "neighbours %s: the middle tile must %s (mode %d)",
              wild ? "wild" : "quiet", wild ? "stay with the virtual lights" : "turn to path tracing", c.mode[1]);
        choice_free(&c);
    }
}

/* The probe's and the frames' measuring patterns: one probed pixel in each 4x4 block; each pixel of
 * an 8x8 block measured once in 64 frames, one a frame. */
static void test_patterns(void) {
    estimator_choice c;
    CHECK(choice_init(&c, 40, 24) == 0, "choice_init");
    int bad = 0;
    for (int by = 0; by < 24; by += CHOICE_PROBE_STEP)
        for (int bx = 0; bx < 40; bx += CHOICE_PROBE_STEP) {
            int n = 0;
            for (int y = by; y < by + CHOICE_PROBE_STEP; y++)
                for (int x = bx; x < bx + CHOICE_PROBE_STEP; x++) n += choice_probe_pixel(&c, y * 40 + x);
            bad += n != 1;
        }
    CHECK(bad == 0, "%d blocks of 4x4 without exactly one probed pixel", bad);
    for (int y = 0; y < 24; y++)
        for (int x = 0; x < 40; x++) {
            int n = 0;
            for (long long f = 0; f < 64; f++) n += choice_measures(&c, y * 40 + x, f + 1000);
            bad += n != 1;
        }
    for (long long f = 0; f < 64; f++) {
        int n = 0;
        for (int y = 0; y < 8; y++)
            for (int x = 0; x < 8; x++) n += choice_measures(&c, y * 40 + x, f);
        bad += n != 1;
    }
    CHECK(bad == 0, "%d pixels or frames off the measuring pattern", bad);
    choice_free(&c);
}

/* Welford's running moments against a two-pass mean and variance. */
static void test_moments(void) {
    est_moments m = {0};
    double x[64], sum = 0.0, ss = 0.0;
    for (int k = 0; k < 64; k++) {
        x[k] = 3.0 + sin(1.7 * k) * (k % 5 == 0 ? 40.0 : 1.0); /* a few large ones, as fireflies */
        est_moments_add(&m, (float)x[k], 0.5 * k);
        sum += x[k];
    }
    double mean = sum / 64.0;
    for (int k = 0; k < 64; k++) ss += (x[k] - mean) * (x[k] - mean);
    CHECK(m.n == 64.0f && fabs((double)m.mean - mean) < 1e-5 * fabs(mean) + 1e-5 &&
              fabs((double)m.m2 - ss) < 1e-4 * ss && fabs((double)m.work - 0.5 * 63 * 64 / 2) < 1e-3,
          "moments: n %g mean %g (%g) m2 %g (%g) work %g", (double)m.n, (double)m.mean, mean, (double)m.m2, ss,
          (double)m.work);
}

/* Tiles given to the virtual lights after 8 frames of auto on scene s at w x h, and the pixels
 * probed in every tile (the least of them over the tiles). */
static double vl_share_of_tiles(const scene *s, const camera *cam, int w, int h, int *least_probed) {
    render_params p = {.width = w, .height = h, .method = METHOD_AUTO, .max_depth = 8, .seed = 2, .threads = 2};
    char err[256];
    render_session *rs = session_create(s, cam, &p, err, sizeof err);
    CHECK(rs != NULL, "session: %s", err);
    if (!rs) return -1.0;
    CHECK(session_render_frame(rs) == 0, "a frame: %s", session_error(rs));
    render_stats first = session_stats(rs);
    CHECK(first.auto_pt_paths > 0 && first.auto_vl_samples > 0, "the first frame must probe both estimators");
    for (int f = 1; f < 8; f++) session_render_frame(rs);
    render_stats st = session_stats(rs);
    /* the map: each pixel's share of film samples from the virtual lights, in [0, 1], whole */
    float *share = malloc(sizeof(float) * 3 * (size_t)w * (size_t)h);
    session_vl_share(rs, share);
    int off = 0, whole = 0;
    for (int i = 0; i < w * h; i++) {
        off += !(share[3 * i] >= 0.0f && share[3 * i] <= 1.0f) || share[3 * i + 1] != share[3 * i];
        whole += share[3 * i] == 1.0f;
    }
    CHECK(off == 0 && whole > 0, "the share map: %d pixels off [0, 1] or grey, %d wholly the virtual lights'", off,
          whole);
    free(share);
    int tiles = ((w + CHOICE_TILE - 1) / CHOICE_TILE) * ((h + CHOICE_TILE - 1) / CHOICE_TILE);
    session_destroy(rs);
    estimator_choice c;
    CHECK(choice_init(&c, w, h) == 0, "choice_init");
    *least_probed = CHOICE_TILE * CHOICE_TILE;
    for (int t = 0; t < tiles; t++) {
        int n = 0, tx = t % c.tiles_x, ty = t / c.tiles_x;
        for (int y = ty * CHOICE_TILE; y < (ty + 1) * CHOICE_TILE && y < h; y++)
            for (int x = tx * CHOICE_TILE; x < (tx + 1) * CHOICE_TILE && x < w; x++)
                n += choice_probe_pixel(&c, y * w + x);
        if (n < *least_probed) *least_probed = n;
    }
    choice_free(&c);
    return (double)st.auto_vl_tiles / tiles;
}

static void test_direction(void) {
    char err[256];
    scene *doorway = scene_load("builtin:doorway", NULL, NULL, err, sizeof err);
    CHECK(doorway != NULL, "doorway: %s", err);
    if (doorway) {
        camera cam = scene_camera(doorway, 0, 16.0f / 9.0f);
        int probed;
        double share = vl_share_of_tiles(doorway, &cam, 128, 72, &probed);
        CHECK(share >= 0.7, "doorway, lit through a door: %.2f of the tiles take the virtual lights", share);
        CHECK(probed >= 8, "a tile (an edge's, 8 rows) with %d probed pixels", probed);
        scene_destroy(doorway);
    }
}

int main(void) {
    test_judgement();
    test_turn_needs_neighbours();
    test_patterns();
    test_moments();
    test_direction();
    return check_exit("test_choice");
}
