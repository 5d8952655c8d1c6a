/* Where a many-light frame's samples go, per pixel (pixel_alloc.h): the traced directions'
 * allocation by one direction's spread, which pixels' highlights are judged dim, and which take the
 * trace rather than the merge, checked against hand-made records and brute force over the
 * neighbourhood. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "params.h"
#include "pixel_alloc.h"
#include "rng.h"

/* The traced directions' allocation: a pixel whose record is too short keeps the budget; the others
 * get the budget in proportion to the spread of one direction's light there (stochastic rounding
 * keeps fractional shares on average), clamped to [1, max]. */
static void test_pixel_alloc_plan(void) {
    pixel_alloc a;
    CHECK(pixel_alloc_init(&a, 5) == 0, "allocation");
    /* pixel 0: constant light (spread 0); 1: spread 1; 2: spread 3; 3: unrecorded; 4: two samples */
    for (int k = 0; k < 40; k++) {
        pixel_record_add(&a.rec[0], 2.0f);
        pixel_record_add(&a.rec[1], k % 2 ? 1.0f : -1.0f);
        pixel_record_add(&a.rec[2], k % 2 ? 5.0f : -1.0f);
    }
    pixel_record_add(&a.rec[4], 0.0f);
    pixel_record_add(&a.rec[4], 100.0f);
    /* The sample spreads of +-1 and 2 +- 3 over 40 values: sqrt(40/39) and 3 sqrt(40/39); the mean
     * over the three recorded pixels is 4/3 sqrt(40/39), so budget 4 wants 0, 3 and 9 directions. */
    double sum[5] = {0};
    int frames = 4000, over = 0;
    for (int f = 0; f < frames; f++) {
        pixel_alloc_plan(&a, 4, 8, (uint64_t)f, 7);
        for (int i = 0; i < 5; i++) sum[i] += a.samples[i];
        over |= a.samples[2] > 8;
    }
    CHECK(sum[0] == frames, "constant light: %.3f directions, expected 1 (the floor)", sum[0] / frames);
    CHECK_NEAR(sum[1] / frames, 3.0, 0.05, "spread 1");
    CHECK(sum[2] == 8.0 * frames && !over, "spread 3: %.3f directions, expected the cap 8", sum[2] / frames);
    CHECK(sum[3] == 4.0 * frames && sum[4] == 4.0 * frames, "unknown spreads: %.3f and %.3f, expected the budget",
          sum[3] / frames, sum[4] / frames);
    /* A fractional share: budget 3 wants 2.25 directions at pixel 1, on average. */
    sum[1] = 0.0;
    for (int f = 0; f < frames; f++) {
        pixel_alloc_plan(&a, 3, 8, (uint64_t)f, 7);
        sum[1] += a.samples[1];
    }
    CHECK_NEAR(sum[1] / frames, 2.25, 0.03, "stochastic rounding");
    pixel_alloc_reset(&a);
    pixel_alloc_plan(&a, 4, 8, 0, 7);
    CHECK(a.samples[1] == 4 && a.samples[2] == 4, "after a reset every pixel takes the budget");
    pixel_alloc_free(&a);
}

/* Brute force: whether any pixel within HL_DIM_RADIUS of (x, y), itself included, is bright. */
static int bright_near(const uint8_t *bright, int w, int h, int x, int y) {
    for (int qy = 0; qy < h; qy++)
        for (int qx = 0; qx < w; qx++)
            if (bright[qy * w + qx] && abs(qx - x) <= HL_DIM_RADIUS && abs(qy - y) <= HL_DIM_RADIUS) return 1;
    return 0;
}

/* The dim judgement: first, every probed pixel with no bright pixel within the radius turns dim,
 * the others and the unprobed ones keep their state; judged again, only dim pixels change, to broad
 * where a bright one is near (a kept pixel never turns dim). Random states and marks on a small
 * image against brute force, edges and corners included; the marks are cleared. */
static void test_judge_dim(void) {
    enum { W = 13, H = 9, ROUNDS = 200 };
    uint8_t state[W * H], before[W * H], bright[W * H];
    int wrong = 0, marks = 0, dims = 0, kept = 0, turned = 0;
    rng_state r = rng_for(1, 2, 3);
    for (int round = 0; round < ROUNDS; round++) {
        int again = round % 2;
        float p_bright = round % 4 < 2 ? 0.02f : 0.1f;
        for (int i = 0; i < W * H; i++) {
            before[i] = (uint8_t)(again ? (rng_float(&r) < 0.6f ? HL_PIXEL_DIM : 1 + (int)(rng_float(&r) * 2.0f))
                                        : (int)(rng_float(&r) * 3.0f)); /* unprobed, broad or sharp */
            bright[i] = before[i] != HL_PIXEL_DIM && rng_float(&r) < p_bright;
            state[i] = (uint8_t)(before[i] | (bright[i] ? HL_PIXEL_BRIGHT : 0));
        }
        hl_judge_dim(state, W, H, again);
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) {
                int i = y * W + x, near = bright_near(bright, W, H, x, y);
                uint8_t want = before[i];
                if (!again && before[i] != HL_PIXEL_UNPROBED && !near) want = HL_PIXEL_DIM;
                if (again && before[i] == HL_PIXEL_DIM && near) want = HL_PIXEL_BROAD, turned++;
                wrong += state[i] != want;
                marks += (state[i] & HL_PIXEL_BRIGHT) != 0;
                dims += state[i] == HL_PIXEL_DIM;
                kept += !again && near && before[i] != HL_PIXEL_UNPROBED;
            }
    }
    CHECK(wrong == 0, "%d pixels judged otherwise than brute force", wrong);
    CHECK(marks == 0, "%d bright marks left", marks);
    CHECK(dims > 0 && kept > 0 && turned > 0, "the cases were not all met: %d dim, %d kept, %d turned broad", dims,
          kept, turned);
    int due[] = {2, 4, 8, 16, 1024}, not_due[] = {0, 1, 3, 5, 6, 12, 1000};
    for (size_t k = 0; k < sizeof due / sizeof due[0]; k++)
        CHECK(hl_judge_due(due[k]), "the pixels must be judged after %d frames", due[k]);
    for (size_t k = 0; k < sizeof not_due / sizeof not_due[0]; k++)
        CHECK(!hl_judge_due(not_due[k]), "the pixels must not be judged after %d frames", not_due[k]);
}

/* Sample variance of v[0..n), two passes. */
static double sample_var(const double *v, int n) {
    double mean = 0.0, ss = 0.0;
    for (int i = 0; i < n; i++) mean += v[i] / n;
    for (int i = 0; i < n; i++) ss += (v[i] - mean) * (v[i] - mean);
    return ss / (n - 1);
}

enum { TW = 11, TH = 7, TMAX = 24 };

/* Fills records from per-pixel samples: the merge m = base + bias + its noise, the trace t = base +
 * its noise, the two sharing `base` (the same hits); returns in gain[] brute force's merge bias^2 -
 * var(d) / n - (var(t) - var(m)) / n per pixel (0 below two frames). */
static void judge_trace_case(hl_merge_record *rec, double *gain, rng_state *r, float bias, float sd_m, float sd_t,
                             int random_n) {
    for (int i = 0; i < TW * TH; i++) {
        double m[TMAX], t[TMAX], d[TMAX];
        int n = random_n ? (int)(rng_float(r) * TMAX) : TMAX;
        float b = random_n ? bias * (rng_float(r) < 0.5f ? 0.0f : rng_float(r)) : bias;
        memset(&rec[i], 0, sizeof rec[i]);
        for (int k = 0; k < n; k++) {
            float base = 1.0f + rng_float(r);
            m[k] = base + b + sd_m * (2.0f * rng_float(r) - 1.0f);
            t[k] = base + sd_t * (2.0f * rng_float(r) - 1.0f);
            d[k] = t[k] - m[k];
            hl_merge_record_add(&rec[i], (float)m[k], (float)t[k]);
        }
        double md = 0.0;
        for (int k = 0; k < n; k++) md += d[k] / n;
        gain[i] = n < 2 ? 0.0 : md * md - sample_var(d, n) / n - (sample_var(t, n) - sample_var(m, n)) / n;
    }
}

/* The choice of the trace: against brute force over the neighbourhood (two-pass variances from the
 * samples themselves, not the running sums), pixels judged before keeping the trace; and on uniform
 * images, the merge kept where it is unbiased and less noisy, the trace taken where the merge is
 * biased or where the trace is the less noisy (at nine pixels in ten). */
static void test_judge_trace(void) {
    hl_merge_record rec[TW * TH];
    double gain[TW * TH];
    rng_state r = rng_for(4, 5, 6);
    int wrong = 0, traced = 0, merged = 0, close = 0;
    for (int round = 0; round < 100; round++) {
        judge_trace_case(rec, gain, &r, 0.3f, 0.2f, 0.6f, 1);
        int before[TW * TH];
        for (int i = 0; i < TW * TH; i++) rec[i].traced = before[i] = rng_float(&r) < 0.1f;
        int count = hl_judge_trace(rec, TW, TH), counted = 0;
        for (int i = 0; i < TW * TH; i++) counted += rec[i].traced;
        CHECK(count == counted, "%d pixels counted as taking the trace, %d take it", count, counted);
        for (int y = 0; y < TH; y++)
            for (int x = 0; x < TW; x++) {
                double sum = 0.0;
                for (int qy = 0; qy < TH; qy++)
                    for (int qx = 0; qx < TW; qx++)
                        if (abs(qx - x) <= HL_DIM_RADIUS && abs(qy - y) <= HL_DIM_RADIUS) sum += gain[qy * TW + qx];
                int i = y * TW + x, want = before[i] || (rec[i].n >= 2.0f && sum > 0.0);
                if (fabs(sum) < 1e-4)
                    close++; /* float sums may tip a tie either way */
                else
                    wrong += rec[i].traced != want;
                traced += want && !before[i];
                merged += !want;
            }
    }
    CHECK(wrong == 0, "%d pixels chose otherwise than brute force (%d ties skipped)", wrong, close);
    CHECK(traced > 100 && merged > 100, "the cases were not all met: %d turned to the trace, %d merged", traced,
          merged);
    struct {
        float bias, sd_m, sd_t;
        int want;
        const char *what;
    } uniform[] = {{0.0f, 0.1f, 0.5f, 0, "an unbiased merge, less noisy than the trace"},
                   {0.5f, 0.1f, 0.5f, 1, "a merge biased by the trace's noise"},
                   {0.0f, 0.5f, 0.1f, 1, "a merge noisier than the trace"}};
    for (size_t c = 0; c < sizeof uniform / sizeof uniform[0]; c++) {
        judge_trace_case(rec, gain, &r, uniform[c].bias, uniform[c].sd_m, uniform[c].sd_t, 0);
        hl_judge_trace(rec, TW, TH);
        int agree = 0;
        for (int i = 0; i < TW * TH; i++) agree += rec[i].traced == uniform[c].want;
        /* the estimated bias's own noise tips a few pixels (most at the edges, with fewer neighbours) */
        CHECK(agree >= TW * TH * 9 / 10, "%s: %d of %d pixels %s", uniform[c].what, agree, TW * TH,
              uniform[c].want ? "took the trace" : "kept the merge");
    }
}

int main(void) {
    test_pixel_alloc_plan();
    test_judge_dim();
    test_judge_trace();
    return check_exit("test_pixel_alloc");
}
