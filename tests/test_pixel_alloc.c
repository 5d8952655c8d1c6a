/* Where a many-light frame's samples go, per pixel (pixel_alloc.h): the traced directions'
 * allocation by one direction's spread, and which pixels' highlights are judged dim, checked
 * against hand-made records and brute force over the neighbourhood. */
#include <stdlib.h>

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

int main(void) {
    test_pixel_alloc_plan();
    test_judge_dim();
    return check_exit("test_pixel_alloc");
}
