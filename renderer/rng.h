/* glint — random numbers: PCG32 (O'Neill 2014), seeded from (pixel, frame, seed) so runs reproduce
 * whatever the thread count. */
#ifndef GLINT_RNG_H
#define GLINT_RNG_H

#include <stdint.h>

#include "gmath.h"

typedef struct {
    uint64_t state, inc;
} rng_state;

static inline uint32_t rng_next_u32(rng_state *r) {
    uint64_t old = r->state;
    r->state = old * 6364136223846793005ULL + r->inc;
    uint32_t xorshifted = (uint32_t)(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = (uint32_t)(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((-rot) & 31u));
}

/* SplitMix64 finaliser: turns structured keys into well-spread seeds. */
static inline uint64_t rng_hash64(uint64_t x) {
    x += 0x9e3779b97f4a7c15ULL;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
    return x ^ (x >> 31);
}

static inline rng_state rng_make(uint64_t seed, uint64_t stream) {
    rng_state r;
    r.state = 0u;
    r.inc = (stream << 1u) | 1u;
    rng_next_u32(&r);
    r.state += seed;
    rng_next_u32(&r);
    return r;
}

/* One independent stream per (key, frame, user seed); key is usually the pixel index. */
static inline rng_state rng_for(uint64_t key, uint64_t frame, uint64_t seed) {
    uint64_t s = rng_hash64(seed ^ rng_hash64(frame * 0x632be59bd9b4e019ULL + key));
    return rng_make(s, rng_hash64(key + 0x1f83d9abfb41bd6bULL * (frame + 1)));
}

/* A stream of its own from r's next numbers: an estimator that takes its numbers from a fork
 * does not shift another's when either changes how many it uses. */
static inline rng_state rng_fork(rng_state *r, uint64_t stream) {
    uint64_t s = (uint64_t)rng_next_u32(r) << 32;
    s |= rng_next_u32(r);
    return rng_make(rng_hash64(s), stream);
}

/* Uniform float in [0, 1): 24 random bits, so the result is never 1. */
static inline float rng_float(rng_state *r) { return (float)(rng_next_u32(r) >> 8) * 0x1p-24f; }
static inline vec2 rng_vec2(rng_state *r) {
    float a = rng_float(r);
    return v2(a, rng_float(r));
}
/* Uniform double in [0, 1) with 53 random bits. */
static inline double rng_double(rng_state *r) {
    uint64_t hi = rng_next_u32(r), lo = rng_next_u32(r);
    return (double)(((hi << 32) | lo) >> 11) * 0x1p-53;
}

#endif
