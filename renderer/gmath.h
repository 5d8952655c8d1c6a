/* glint — the one math header: small vectors passed by value, all static inline. */
#ifndef GLINT_GMATH_H
#define GLINT_GMATH_H

#include <math.h>
#include <stdint.h>

#ifndef __cplusplus
/* fmaxf and fminf as C defines them (of a NaN and a number, the number), inline: GCC calls the C
 * library for them, and those calls, with the registers they clobber, cost the path tracer
 * several percent (docs/benchmarks.md, 2026-11-25). */
static inline float gm_fmaxf(float a, float b) { return a > b || isnan(b) ? a : b; }
static inline float gm_fminf(float a, float b) { return a < b || isnan(b) ? a : b; }
#define fmaxf gm_fmaxf
#define fminf gm_fminf
#endif

#define PI_F 3.14159265358979323846f
#define INV_PI_F 0.31830988618379067154f
#define INV_2PI_F 0.15915494309189533577f
#define INV_4PI_F 0.07957747154594766788f

typedef struct {
    float x, y;
} vec2;
typedef struct {
    float x, y, z;
} vec3;
typedef struct {
    float x, y, z, w;
} vec4;
/* Row-major affine transform: p' = m[r][0]*x + m[r][1]*y + m[r][2]*z + m[r][3]. */
typedef struct {
    float m[4][4];
} mat4;
typedef struct {
    vec3 lo, hi;
} bounds3;
/* Orthonormal frame: t (tangent, x), b (bitangent, y), n (normal, z). */
typedef struct {
    vec3 t, b, n;
} frame3;

static inline vec2 v2(float x, float y) { return (vec2){x, y}; }
static inline vec3 v3(float x, float y, float z) { return (vec3){x, y, z}; }
static inline vec3 v3s(float s) { return (vec3){s, s, s}; }
static inline vec3 add3(vec3 a, vec3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline vec3 sub3(vec3 a, vec3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline vec3 mul3(vec3 a, vec3 b) { return v3(a.x * b.x, a.y * b.y, a.z * b.z); }
static inline vec3 div3(vec3 a, vec3 b) { return v3(a.x / b.x, a.y / b.y, a.z / b.z); }
static inline vec3 scale3(vec3 a, float s) { return v3(a.x * s, a.y * s, a.z * s); }
static inline vec3 neg3(vec3 a) { return v3(-a.x, -a.y, -a.z); }
/* a + b * s */
static inline vec3 madd3(vec3 a, vec3 b, float s) { return v3(a.x + b.x * s, a.y + b.y * s, a.z + b.z * s); }
static inline float dot3(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline vec3 cross3(vec3 a, vec3 b) {
    return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline float length_sq3(vec3 a) { return dot3(a, a); }
static inline float length3(vec3 a) { return sqrtf(dot3(a, a)); }
static inline vec3 normalize3(vec3 a) {
    float l = length3(a);
    return l > 0.0f ? scale3(a, 1.0f / l) : a;
}
static inline vec3 min3(vec3 a, vec3 b) { return v3(fminf(a.x, b.x), fminf(a.y, b.y), fminf(a.z, b.z)); }
static inline vec3 max3(vec3 a, vec3 b) { return v3(fmaxf(a.x, b.x), fmaxf(a.y, b.y), fmaxf(a.z, b.z)); }
static inline vec3 lerp3(vec3 a, vec3 b, float t) { return madd3(scale3(a, 1.0f - t), b, t); }
static inline float max_comp3(vec3 a) { return fmaxf(a.x, fmaxf(a.y, a.z)); }
static inline float min_comp3(vec3 a) { return fminf(a.x, fminf(a.y, a.z)); }
static inline float avg3(vec3 a) { return (a.x + a.y + a.z) * (1.0f / 3.0f); }
static inline int is_black3(vec3 a) { return a.x == 0.0f && a.y == 0.0f && a.z == 0.0f; }
/* x - x is 0 for finite x and NaN otherwise: one branch for all three. */
static inline int is_finite3(vec3 a) { return (a.x - a.x) + (a.y - a.y) + (a.z - a.z) == 0.0f; }
/* Rec. 709 luminance of linear RGB. */
static inline float luminance3(vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }
static inline float clampf(float x, float lo, float hi) { return x < lo ? lo : (x > hi ? hi : x); }
static inline float sqr(float x) { return x * x; }
static inline float safe_sqrtf(float x) { return sqrtf(fmaxf(x, 0.0f)); }
static inline float lerpf(float a, float b, float t) { return a + (b - a) * t; }
/* Mirror of w about n (both unit, result points away from the surface like w). */
static inline vec3 reflect3(vec3 w, vec3 n) { return sub3(scale3(n, 2.0f * dot3(w, n)), w); }
static inline float comp3(vec3 a, int i) { return i == 0 ? a.x : (i == 1 ? a.y : a.z); }

/* Branchless orthonormal basis around a unit normal (Duff et al., JCGT 2017). */
static inline frame3 frame_from_normal(vec3 n) {
    float sign = copysignf(1.0f, n.z);
    float a = -1.0f / (sign + n.z);
    float b = n.x * n.y * a;
    frame3 f;
    f.t = v3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
    f.b = v3(b, sign + n.y * n.y * a, -n.y);
    f.n = n;
    return f;
}
/* Frame from a normal and an approximate tangent (Gram-Schmidt); falls back when degenerate. */
static inline frame3 frame_from_normal_tangent(vec3 n, vec3 t) {
    vec3 tt = sub3(t, scale3(n, dot3(n, t)));
    float l2 = length_sq3(tt);
    if (!(l2 > 1e-12f)) return frame_from_normal(n);
    frame3 f;
    f.n = n;
    f.t = scale3(tt, 1.0f / sqrtf(l2));
    f.b = cross3(n, f.t);
    return f;
}
static inline vec3 to_local(frame3 f, vec3 w) { return v3(dot3(w, f.t), dot3(w, f.b), dot3(w, f.n)); }
static inline vec3 to_world(frame3 f, vec3 w) {
    return add3(add3(scale3(f.t, w.x), scale3(f.b, w.y)), scale3(f.n, w.z));
}

static inline mat4 mat4_identity(void) {
    mat4 m = {{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}}};
    return m;
}
static inline mat4 mat4_mul(mat4 a, mat4 b) {
    mat4 r;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            r.m[i][j] = a.m[i][0] * b.m[0][j] + a.m[i][1] * b.m[1][j] + a.m[i][2] * b.m[2][j] + a.m[i][3] * b.m[3][j];
    return r;
}
static inline vec3 xform_point(const mat4 *m, vec3 p) {
    return v3(m->m[0][0] * p.x + m->m[0][1] * p.y + m->m[0][2] * p.z + m->m[0][3],
              m->m[1][0] * p.x + m->m[1][1] * p.y + m->m[1][2] * p.z + m->m[1][3],
              m->m[2][0] * p.x + m->m[2][1] * p.y + m->m[2][2] * p.z + m->m[2][3]);
}
static inline vec3 xform_vector(const mat4 *m, vec3 v) {
    return v3(m->m[0][0] * v.x + m->m[0][1] * v.y + m->m[0][2] * v.z,
              m->m[1][0] * v.x + m->m[1][1] * v.y + m->m[1][2] * v.z,
              m->m[2][0] * v.x + m->m[2][1] * v.y + m->m[2][2] * v.z);
}

static inline bounds3 bounds_empty(void) { return (bounds3){v3s(INFINITY), v3s(-INFINITY)}; }
static inline bounds3 bounds_add(bounds3 b, vec3 p) { return (bounds3){min3(b.lo, p), max3(b.hi, p)}; }
static inline vec3 bounds_center(bounds3 b) { return scale3(add3(b.lo, b.hi), 0.5f); }
static inline float bounds_diagonal(bounds3 b) { return length3(sub3(b.hi, b.lo)); }

#endif
