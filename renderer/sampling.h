/* glint — sampling routines, each with its pdf. Directions are in a local frame around +z.
 * Every routine here lives once; estimators call these, never their own copies. */
#ifndef GLINT_SAMPLING_H
#define GLINT_SAMPLING_H

#include "gmath.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Cosine-weighted hemisphere around +z; pdf = cos(theta) / pi. */
vec3 sample_cosine_hemisphere(vec2 u);
static inline float pdf_cosine_hemisphere(vec3 w) { return w.z > 0.0f ? w.z * INV_PI_F : 0.0f; }

/* Uniform sphere; pdf = 1 / (4 pi). */
vec3 sample_uniform_sphere(vec2 u);
static inline float pdf_uniform_sphere(void) { return INV_4PI_F; }

/* Uniform cone around +z given 1 - cos(theta_max) in (0, 2]; pdf = 1 / (2 pi (1 - cos theta_max)).
 * Taking 1 - cos rather than cos keeps tiny cones (distant lights) exact. */
vec3 sample_uniform_cone(vec2 u, float one_minus_cos_max);
static inline float pdf_uniform_cone(float one_minus_cos_max) { return INV_2PI_F / one_minus_cos_max; }

/* 1 - cos(theta_max) for a sphere of radius r seen from distance d, s = r/d < 1, without
 * cancellation: s^2 / (1 + sqrt(1 - s^2)). Returns 1 (a hemisphere) when s >= 1: the point is inside. */
float cone_one_minus_cos(float sin_theta_max);

/* Power-cosine lobe around +z: pdf = (n + 1) / (2 pi) cos^n(theta) over the sphere's upper half.
 * Angles enter as 1 - cos(theta): sharp lobes (n ~ 1e6) live where cos(theta) rounds to 1 in float. */
vec3 sample_power_cosine(vec2 u, float exponent);
float pdf_power_cosine(float one_minus_cos, float exponent);
/* cos^n(theta) from 1 - cos(theta); 0 beyond 90 degrees. */
float power_cosine(float one_minus_cos, float exponent);

/* Uniform point on a triangle as barycentrics (b1, b2); b0 = 1 - b1 - b2. */
vec2 sample_uniform_triangle(vec2 u);

/* Concentric map of the unit square onto the unit disk (Shirley-Chiu). */
vec2 sample_concentric_disk(vec2 u);

/* Point k of the R2 sequence (Roberts 2018: additive recurrence on the plastic number) shifted by
 * u mod 1: N of them cover [0,1)^2 evenly for any N, and the shift keeps each unbiased. */
static inline vec2 sample_r2(int k, vec2 u) {
    double x = (double)u.x + 0.7548776662466927 * (double)k, y = (double)u.y + 0.5698402909980532 * (double)k;
    vec2 r = v2((float)(x - floor(x)), (float)(y - floor(y)));
    /* float rounding can land on 1 */
    if (r.x >= 1.0f) r.x = 0.0f;
    if (r.y >= 1.0f) r.y = 0.0f;
    return r;
}

/* A pixel's run of a 2D low-discrepancy sequence over frames: points index, index + 1, ... of
 * the Sobol (0,2)-sequence (van der Corput and Sobol's second dimension), each coordinate's bits
 * XORed with the pixel's own random scramble. A pixel that keeps its scramble and starts each
 * frame where the last one stopped covers [0,1)^2 evenly over any run of frames, not only within
 * each frame, and every point is still uniform. Not R2: pixel positions follow R2 over frames, and
 * two R2 runs indexed by the frame tie each direction to the position (the pixel would converge
 * to an average over a slice of its domain); base-2 digits and the plastic number do not. */
typedef struct {
    uint32_t index;
    uint32_t scramble_x, scramble_y;
} qmc_run;
static inline vec2 qmc_run_point(qmc_run r, uint32_t k) {
    uint32_t i = r.index + k, x = 0, y = 0;
    for (uint32_t b = 1u << 31, v = 1u << 31; i; i >>= 1, b >>= 1, v ^= v >> 1)
        if (i & 1u) x |= b, y ^= v;
    /* 24 bits: a float in [0,1) without rounding up to 1 */
    return v2((float)((x ^ r.scramble_x) >> 8) * 0x1p-24f, (float)((y ^ r.scramble_y) >> 8) * 0x1p-24f);
}

/* Point k of a pixel's run of positions: R2 (sample_r2) from the run's index, shifted by its
 * scramble. For positions beside a Sobol run of directions counted alike (several paths a frame):
 * points of two Sobol runs at related indices tie a direction's digits to the position's (the j-th
 * path of every frame would pair one quarter of the pixel with one quarter of the directions). */
static inline vec2 qmc_run_r2(qmc_run r, uint32_t k) {
    vec2 shift = v2((float)(r.scramble_x >> 8) * 0x1p-24f, (float)(r.scramble_y >> 8) * 0x1p-24f);
    return sample_r2((int)((r.index + k) & 0x3fffffffu), shift);
}

/* Multiple importance sampling weights for strategy a against b (one sample each). */
static inline float mis_balance(float pdf_a, float pdf_b) {
    /* As a ratio: the sum of two pdfs near FLT_MAX would overflow. */
    if (pdf_a <= 0.0f) return 0.0f;
    if (!(pdf_b > 0.0f)) return 1.0f;
    return 1.0f / (1.0f + pdf_b / pdf_a);
}
static inline float mis_power(float pdf_a, float pdf_b) {
    /* Divide first: squaring a pdf of 1e20 would overflow float. */
    if (pdf_a <= 0.0f) return 0.0f;
    if (!(pdf_b > 0.0f)) return 1.0f;
    float r = pdf_b / pdf_a;
    return 1.0f / (1.0f + r * r);
}

/* Russian roulette, the one rule every path follows: a path whose weight w (its throughput, or a
 * light path's gain) has fallen goes on with probability q = min(0.95, max component of w), its
 * weight divided by q, so its expectation is unchanged. u is uniform in [0,1); returns 0 when
 * the path stops. Camera paths play it when they leave vertex RR_FIRST_VERTEX or a later one (the
 * camera hit is vertex 0). */
#define RR_FIRST_VERTEX 3
static inline int russian_roulette(vec3 *w, float u) {
    float q = fminf(0.95f, max_comp3(*w));
    if (!(u < q)) return 0;
    *w = scale3(*w, 1.0f / q);
    return 1;
}

/* Piecewise-constant 1D distribution over [0,1) with n bins. Owns its arrays (init/deinit). */
typedef struct {
    int n;
    float *func;     /* n non-negative values (copied; non-finite or negative input counted as 0) */
    double *cdf;     /* n + 1 values, cdf[0] = 0, cdf[n] = 1 */
    double integral; /* sum(func) / n; 0 means the input was all zero and sampling is uniform */
} dist1d;

/* Returns 0 on success, -1 when out of memory or n < 1. */
int dist1d_init(dist1d *d, const float *func, int n);
void dist1d_deinit(dist1d *d);
/* Discrete sample: bin index with probability pmf; *u_remapped (optional) reuses u inside the bin. */
int dist1d_sample_discrete(const dist1d *d, float u, float *pmf, float *u_remapped);
float dist1d_pmf(const dist1d *d, int index);
/* Continuous sample in [0,1) with density pdf (relative to [0,1)); *bin (optional) receives the bin. */
float dist1d_sample_continuous(const dist1d *d, float u, float *pdf, int *bin);
float dist1d_pdf(const dist1d *d, float x);

/* A discrete distribution drawn in constant time (Walker's alias method, Vose's construction):
 * n bins, each split between itself and one alias. Owns its arrays (init/deinit). */
typedef struct {
    int n;
    float *pmf;  /* n probabilities (non-finite or negative weights count as 0; all zero: uniform) */
    float *keep; /* the share of bin i's slot that draws i itself */
    int *alias;  /* what the rest of the slot draws */
} alias_table;

/* Returns 0, or -1 when out of memory or n < 1. */
int alias_init(alias_table *a, const float *weights, int n);
void alias_deinit(alias_table *a);
/* Index with probability pmf[index], from u in [0,1); *pmf (optional) receives it. */
static inline int alias_sample(const alias_table *a, float u, float *pmf) {
    float x = u * (float)a->n;
    int i = (int)x;
    if (i >= a->n) i = a->n - 1;
    if (x - (float)i >= a->keep[i]) i = a->alias[i];
    if (pmf) *pmf = a->pmf[i];
    return i;
}

/* Piecewise-constant 2D distribution over [0,1)^2 from nu x nv values (row-major, v rows). */
typedef struct {
    int nu, nv;
    dist1d *rows;    /* nv conditionals p(u | v) */
    dist1d marginal; /* p(v) */
} dist2d;

int dist2d_init(dist2d *d, const float *func, int nu, int nv);
void dist2d_deinit(dist2d *d);
/* Sample (u, v) in [0,1)^2 with density *pdf relative to the unit square. */
vec2 dist2d_sample(const dist2d *d, vec2 u, float *pdf);
float dist2d_pdf(const dist2d *d, vec2 uv);

#ifdef __cplusplus
}
#endif

#endif
