/* k-nearest-neighbour distances (the VSL radius rule) against brute force. */
#include <stdlib.h>

#include "check.h"
#include "knn.h"
#include "rng.h"

/* The k-th smallest distance to the other points, keeping the k smallest squared distances in a
 * sorted array: O(n k), and obviously right. */
static float brute(const vec3 *p, int n, int i, int k) {
    float best[16];
    int m = 0;
    for (int j = 0; j < n; j++) {
        if (j == i || !is_finite3(p[j])) continue;
        vec3 e = sub3(p[j], p[i]);
        float d = e.x * e.x + e.y * e.y + e.z * e.z;
        if (m == k && !(d < best[k - 1])) continue;
        int b = m < k ? m++ : k - 1;
        for (; b > 0 && best[b - 1] > d; b--) best[b] = best[b - 1];
        best[b] = d;
    }
    return m == 0 ? 0.0f : sqrtf(best[m - 1]);
}

static void check_against_brute(const char *name, const vec3 *p, int n, int k) {
    float *out = malloc(sizeof(float) * (size_t)n);
    CHECK(knn_distances(p, sizeof(vec3), n, k, out) == 0, "%s: failed", name);
    int bad = 0;
    for (int i = 0; i < n; i++) {
        float want = is_finite3(p[i]) ? brute(p, n, i, k) : INFINITY;
        if (!(out[i] == want)) {
            if (bad++ < 3)
                fprintf(stderr, "%s k=%d: point %d got %.9g want %.9g\n", name, k, i, (double)out[i], (double)want);
        }
    }
    CHECK(bad == 0, "%s, n=%d, k=%d: %d distances differ from brute force", name, n, k, bad);
    free(out);
}

static vec3 *make_points(int n, int kind, uint64_t seed) {
    vec3 *p = malloc(sizeof(vec3) * (size_t)n);
    rng_state r = rng_make(seed, 1);
    for (int i = 0; i < n; i++) {
        float a = rng_float(&r), b = rng_float(&r), c = rng_float(&r);
        switch (kind) {
        case 0: p[i] = v3(a, b, c); break;                              /* uniform cube */
        case 1: p[i] = v3((float)(i % 5), 0.01f * a, 0.01f * b); break; /* tight blobs */
        case 2: p[i] = v3(a * 100.0f, b * 100.0f, 3.0f); break;         /* a plane, large */
        case 3: p[i] = v3((float)(i % 3), 1.0f, 2.0f); break;           /* exact duplicates */
        default: p[i] = v3(a, b, i % 17 == 0 ? NAN : c); break;         /* some non-finite */
        }
    }
    return p;
}

int main(void) {
    const char *names[5] = {"uniform", "blobs", "plane", "duplicates", "non-finite"};
    int sizes[6] = {1, 2, 5, 11, 300, 2000};
    for (int kind = 0; kind < 5; kind++)
        for (int s = 0; s < 6; s++)
            for (int k = 1; k <= 10; k += 9) {
                vec3 *p = make_points(sizes[s], kind, (uint64_t)(kind * 100 + s));
                check_against_brute(names[kind], p, sizes[s], k);
                free(p);
            }

    /* A struct stride, as the virtual lights pass theirs. */
    struct item {
        int pad;
        vec3 p;
        float more[5];
    } items[500];
    vec3 flat[500];
    rng_state r = rng_make(3, 3);
    for (int i = 0; i < 500; i++) flat[i] = items[i].p = v3(rng_float(&r), rng_float(&r), rng_float(&r));
    float a[500], b[500];
    knn_distances(&items[0].p, sizeof(struct item), 500, 10, a);
    knn_distances(flat, sizeof(vec3), 500, 10, b);
    int same = 1;
    for (int i = 0; i < 500; i++) same &= a[i] == b[i];
    CHECK(same, "a strided array gives different distances");

    /* A quarter million points (more than any frame traces) completes; spot checks against brute
     * force. And 200000 identical points: no quadratic blow-up, all distances 0. */
    int n = 250000;
    vec3 *p = make_points(n, 0, 42);
    float *out = malloc(sizeof(float) * (size_t)n);
    CHECK(knn_distances(p, sizeof(vec3), n, 10, out) == 0, "250000 points failed");
    int bad = 0;
    for (int i = 0; i < n; i += 2503) bad += out[i] != brute(p, n, i, 10);
    CHECK(bad == 0, "250000 points: %d spot checks differ", bad);
    for (int i = 0; i < 200000; i++) p[i] = v3(1, 2, 3);
    CHECK(knn_distances(p, sizeof(vec3), 200000, 10, out) == 0, "duplicates failed");
    int nonzero = 0;
    for (int i = 0; i < 200000; i++) nonzero += out[i] != 0.0f;
    CHECK(nonzero == 0, "identical points: %d non-zero distances", nonzero);
    free(p);
    free(out);
    return check_exit("test_knn");
}
