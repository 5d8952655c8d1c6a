/* glint — arithmetic for loops that gcc vectorises (the display's filter and carry): no conversion
 * between int and float and no nested ?: in them, since either keeps gcc from vectorising a loop.
 * An integer k, |k| < 2^22, is held as the low bits of the float k + ROUNDER. */
#ifndef GLINT_VECMATH_H
#define GLINT_VECMATH_H

#include <stdint.h>
#include <string.h>

#define ROUNDER 0x1.8p23f
#define ROUNDER_BITS 0x4b400000u
/* The least power of two exp2_neg returns (2e-35): below it a weight counts for nothing. */
#define EXP2_FLOOR (-115.0f)
#define LOG2E 1.44269504f

static inline uint32_t bits_of(float f) {
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u;
}
static inline float float_of(uint32_t u) {
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

/* 2^x for x <= 0: 2^k from the exponent bits times 2^f, |f| <= 1/2, by a degree-3 fit exact at
 * f = 0 (so 2^0 is 1). Relative error under 1.0e-4 + 1e-7 |x| (the fit; the rounding of x): ample
 * for a weight. Below EXP2_FLOOR, and for NaN, it is 2^EXP2_FLOOR. */
static inline float exp2_neg(float x) {
    x = x > EXP2_FLOOR ? x : EXP2_FLOOR;
    float kr = x + ROUNDER; /* x rounded to an integer k, held as k + ROUNDER */
    float f = x - (kr - ROUNDER);
    float p = 1.0f + f * (0.69328293f + f * (0.242210964f + f * 0.0550089153f));
    return float_of(bits_of(p) + ((bits_of(kr) - ROUNDER_BITS) << 23));
}

#endif
