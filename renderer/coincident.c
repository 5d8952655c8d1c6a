/* Triangles that repeat another's three corners: a scene of a million copies of one triangle
 * renders as one, and makes every ray through it test them all (a BVH cannot split coincident
 * triangles). Counted once when a scene is finished, for a warning and glint info. */
#include <stdlib.h>
#include <string.h>

#include "scene.h"

/* A triangle's corners in one order (lexicographic), whatever its winding and first vertex. */
static void corners(const scene *s, int t, vec3 c[3]) {
    const uint32_t *v = &s->indices[3 * (size_t)t];
    for (int k = 0; k < 3; k++) c[k] = s->positions[v[k]];
    for (int i = 1; i < 3; i++)
        for (int j = i; j > 0; j--) {
            const vec3 a = c[j - 1], b = c[j];
            int after = a.x > b.x || (a.x == b.x && (a.y > b.y || (a.y == b.y && a.z > b.z)));
            if (!after) break;
            c[j - 1] = b, c[j] = a;
        }
}

static uint64_t hash_corners(const vec3 c[3]) {
    uint64_t h = 0xcbf29ce484222325ull;
    uint32_t bits[9];
    memcpy(bits, c, sizeof bits);
    for (int k = 0; k < 9; k++) {
        h ^= bits[k] + (bits[k] == 0x80000000u ? 0x80000000u : 0u); /* -0 as 0 */
        h *= 0x100000001b3ull;
    }
    return h ^ (h >> 29);
}

long scene_count_coincident(const scene *s) {
    size_t cap = 64;
    while (cap < 2 * (size_t)s->num_triangles) cap *= 2;
    /* each slot: a triangle's hash (its high half) and index; corners compared only when those agree */
    typedef struct {
        uint32_t hash;
        int32_t t; /* -1: empty */
    } entry;
    entry *slot = malloc(sizeof(entry) * cap);
    if (!slot) return -1;
    memset(slot, 0xff, sizeof(entry) * cap);
    long repeats = 0;
    /* in batches whose slots are fetched ahead: one random access a triangle is the cost */
    enum { BATCH = 32 };
    for (int t0 = 0; t0 < s->num_triangles; t0 += BATCH) {
        int n = s->num_triangles - t0 < BATCH ? s->num_triangles - t0 : BATCH;
        vec3 c[BATCH][3];
        uint64_t h[BATCH];
        for (int k = 0; k < n; k++) {
            corners(s, t0 + k, c[k]);
            h[k] = hash_corners(c[k]);
            __builtin_prefetch(&slot[h[k] & (cap - 1)]);
        }
        for (int k = 0; k < n; k++) {
            uint32_t high = (uint32_t)(h[k] >> 32);
            for (size_t i = h[k] & (cap - 1);; i = (i + 1) & (cap - 1)) {
                if (slot[i].t < 0) {
                    slot[i] = (entry){high, t0 + k};
                    break;
                }
                if (slot[i].hash != high) continue;
                vec3 o[3];
                corners(s, slot[i].t, o);
                int same = 1;
                for (int j = 0; j < 3 && same; j++)
                    same = c[k][j].x == o[j].x && c[k][j].y == o[j].y && c[k][j].z == o[j].z;
                if (same) {
                    repeats++;
                    break;
                }
            }
        }
    }
    free(slot);
    return repeats;
}
