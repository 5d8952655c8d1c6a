/* The vMF-prefiltered environment against answers that do not come from envfilter.c: a constant
 * map stays that constant, kappa 0 is the solid-angle mean summed here, a map linear in the
 * direction gives a + A(kappa) b.mu exactly (A = coth kappa - 1/kappa in long double), a map with
 * bright spots matches brute-force quadrature of gamma L over every texel in double, and maps
 * with zeros and huge texels stay finite for kappa up to 1e6. Directions include the poles and
 * the u = 0/1 seam; maps are rotated, so lookups must go through the map's rotation. */
#define _POSIX_C_SOURCE 200809L
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "check.h"
#include "envfilter.h"
#include "lights.h"
#include "rng.h"

#define PI_D 3.14159265358979323846

/* The direction at map coordinates (u, v) of a map rotated by rot about +Y, in double, from the
 * convention in scene.h: u = 0.5 is +X, u = 0.75 is +Z, the top row +Y. */
static void dir_at(double u, double v, double rot, double d[3]) {
    double phi = 2.0 * PI_D * (u - 0.5) + rot, th = PI_D * v;
    d[0] = sin(th) * cos(phi);
    d[1] = cos(th);
    d[2] = sin(th) * sin(phi);
}

typedef void (*radiance_fn)(const double d[3], const void *param, float out[3]);

/* A w x h map whose texels are fn at their centres' directions. */
static env_map *make_env(int w, int h, float rot, radiance_fn fn, const void *param) {
    image_rgb img = {w, h, malloc(sizeof(float) * 3 * (size_t)w * (size_t)h)};
    if (!img.rgb) abort();
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double d[3];
            dir_at((x + 0.5) / w, (y + 0.5) / h, rot, d);
            fn(d, param, img.rgb + 3 * ((size_t)y * (size_t)w + (size_t)x));
        }
    char err[256];
    env_map *env = env_map_create(&img, rot, err, sizeof err);
    if (!env) {
        fprintf(stderr, "make_env: %s\n", err);
        abort();
    }
    return env;
}

static env_vmf_filter *make_filter(const env_map *env, double *seconds) {
    char err[256] = "";
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    env_vmf_filter *f = env_vmf_filter_create(env, err, sizeof err);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    if (seconds) *seconds = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    if (!f) {
        fprintf(stderr, "env_vmf_filter_create: %s\n", err);
        abort();
    }
    return f;
}

/* Directions that stress the parameterisation: both poles and just off them, the seam (u = 0/1)
 * at several latitudes and either side of it, then uniformly random ones. Returns the count. */
static int test_directions(float rot, vec3 *dirs, int max) {
    vec3 fixed[4 + 15];
    int n = 0;
    fixed[n++] = v3(0, 1, 0);
    fixed[n++] = v3(0, -1, 0);
    fixed[n++] = normalize3(v3(1e-4f, 1.0f, 0.0f));
    fixed[n++] = normalize3(v3(0.0f, -1.0f, -2e-4f));
    const double vs[] = {0.001, 0.1, 0.5, 0.77, 0.999};
    for (int i = 0; i < 5; i++)
        for (int side = -1; side <= 1; side++) {
            double d[3];
            dir_at(side * 1e-6, vs[i], rot, d); /* u slightly below 0 is the far edge, u ~ 1 */
            fixed[n++] = v3((float)d[0], (float)d[1], (float)d[2]);
        }
    if (n > max) n = max;
    for (int i = 0; i < n; i++) dirs[i] = fixed[i];
    rng_state r = rng_make(7, 11);
    while (n < max) {
        double z = 1.0 - 2.0 * rng_double(&r), phi = 2.0 * PI_D * rng_double(&r), s = sqrt(fmax(0.0, 1.0 - z * z));
        dirs[n++] = v3((float)(s * cos(phi)), (float)z, (float)(s * sin(phi)));
    }
    return n;
}

/* The convention dir_at encodes must be the renderer's. */
static void test_convention(void) {
    env_map env = {.rotation = 0.9f};
    const float uvs[][2] = {{0.5f, 0.5f}, {0.75f, 0.5f}, {0.0f, 0.3f}, {0.123f, 0.9f}, {0.9f, 0.01f}};
    for (int i = 0; i < 5; i++) {
        double d[3];
        dir_at(uvs[i][0], uvs[i][1], env.rotation, d);
        vec3 e = env_direction(&env, v2(uvs[i][0], uvs[i][1]));
        CHECK(fabs(d[0] - e.x) < 1e-5 && fabs(d[1] - e.y) < 1e-5 && fabs(d[2] - e.z) < 1e-5,
              "dir_at(%g, %g) = (%g %g %g), env_direction (%g %g %g)", uvs[i][0], uvs[i][1], d[0], d[1], d[2], e.x, e.y,
              e.z);
    }
}

static const double kappas_wide[] = {0.0,   1e-30, 1e-6,  1e-3,   0.1, 0.25, 0.3, 1.0, 7.0, 50.0,
                                     700.0, 710.0, 800.0, 3000.0, 1e4, 3e4,  1e5, 3e5, 1e6};
enum { NKW = sizeof kappas_wide / sizeof kappas_wide[0] };

static void constant_fn(const double d[3], const void *param, float out[3]) {
    const float *c = param;
    for (int i = 0; i < 3; i++) out[i] = c[i];
}

static void test_constant(void) {
    const float c[3] = {0.25f, 1.5f, 3.0f};
    const int sizes[][2] = {{1, 1}, {3, 2}, {64, 32}, {301, 150}, {512, 256}};
    vec3 dirs[64];
    for (int s = 0; s < 5; s++) {
        float rot = 0.37f * (float)s;
        env_map *env = make_env(sizes[s][0], sizes[s][1], rot, constant_fn, c);
        env_vmf_filter *f = make_filter(env, NULL);
        int nd = test_directions(rot, dirs, 64);
        double worst = 0.0;
        for (int k = 0; k < NKW; k++)
            for (int i = 0; i < nd; i++) {
                vec3 e = env_vmf_filter_lookup(f, (vmf){dirs[i], (float)kappas_wide[k]});
                for (int ch = 0; ch < 3; ch++) {
                    double rel = fabs(comp3(e, ch) - c[ch]) / c[ch];
                    if (!(rel <= worst)) worst = rel; /* NaN sticks */
                }
            }
        CHECK(worst <= 1e-5, "constant %dx%d map: worst relative deviation %g", sizes[s][0], sizes[s][1], worst);
        printf("constant %dx%d: worst relative deviation %.2g over %d kappas x %d directions\n", sizes[s][0],
               sizes[s][1], worst, NKW, nd);
        env_vmf_filter_destroy(f);
        env_map_destroy(env);
    }
}

/* Smooth random-looking colours, so the mean is not a symmetric accident. */
static void wavy_fn(const double d[3], const void *param, float out[3]) {
    out[0] = (float)(1.0 + 0.9 * sin(3.0 * d[0] + 1.0) * cos(2.0 * d[1]));
    out[1] = (float)(2.0 + d[1] + 0.5 * d[2] * d[0]);
    out[2] = (float)(0.5 + 0.4 * cos(5.0 * d[2] - d[1]));
}

static void test_mean(void) {
    const int w = 97, h = 48;
    env_map *env = make_env(w, h, 1.1f, wavy_fn, NULL);
    env_vmf_filter *f = make_filter(env, NULL);
    /* sum of L dOmega over the sphere / 4 pi, dOmega = (2pi/w)(pi/h) sin theta per texel */
    double sum[3] = {0, 0, 0}, area = 0.0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double dom = (2.0 * PI_D / w) * (PI_D / h) * sin(PI_D * (y + 0.5) / h);
            const float *p = env->image.rgb + 3 * (y * w + x);
            for (int c = 0; c < 3; c++) sum[c] += p[c] * dom;
            area += dom;
        }
    CHECK_NEAR(area, 4.0 * PI_D, 1e-3 * 4.0 * PI_D, "texel solid angles sum to the sphere");
    vec3 dirs[16];
    int nd = test_directions(1.1f, dirs, 16);
    for (int i = 0; i < nd; i++) {
        vec3 e = env_vmf_filter_lookup(f, (vmf){dirs[i], 0.0f});
        for (int c = 0; c < 3; c++)
            CHECK_NEAR(comp3(e, c), sum[c] / area, 1e-6 * sum[c] / area, "kappa 0 mean, channel %d", c);
        /* and the limit kappa -> 0 meets it */
        vec3 e2 = env_vmf_filter_lookup(f, (vmf){dirs[i], 1e-7f});
        for (int c = 0; c < 3; c++)
            CHECK_NEAR(comp3(e2, c), sum[c] / area, 1e-5 * sum[c] / area, "kappa 1e-7 ~ mean, channel %d", c);
    }
    env_vmf_filter_destroy(f);
    env_map_destroy(env);
}

/* L_c(s) = a_c + b_c.s: E_c(mu, kappa) = a_c + A(kappa) b_c.mu, since the vMF's mean is A mu. */
static const double lin_a[3] = {2.0, 1.0, 1.5};
static const double lin_b[3][3] = {{0.5, -0.7, 0.3}, {0.1, 0.6, -0.5}, {-0.8, 0.2, 0.9}};

static void linear_fn(const double d[3], const void *param, float out[3]) {
    for (int c = 0; c < 3; c++)
        out[c] = (float)(lin_a[c] + lin_b[c][0] * d[0] + lin_b[c][1] * d[1] + lin_b[c][2] * d[2]);
}

static long double ref_rbar(long double k) {
    if (k == 0.0L) return 0.0L;
    if (k < 1e-2L) return k / 3.0L - k * k * k / 45.0L + 2.0L * k * k * k * k * k / 945.0L;
    return (1.0L + expl(-2.0L * k)) / (-expm1l(-2.0L * k)) - 1.0L / k; /* coth k - 1/k */
}

static void test_linear(void) {
    const float rot = 0.7f;
    env_map *env = make_env(512, 256, rot, linear_fn, NULL);
    env_vmf_filter *f = make_filter(env, NULL);
    vec3 dirs[80];
    int nd = test_directions(rot, dirs, 80);
    enum { NK = 46 };
    /* worst per range of kappa: below 1, to 100, to 1e4 (levels), to 1e6 (the map's own texels) */
    double worst[4] = {0.0, 0.0, 0.0, 0.0};
    for (int k = 0; k < NK; k++) {
        double kappa = k == 0 ? 0.0 : pow(10.0, -3.0 + 9.0 * (k - 1) / (NK - 2));
        double A = (double)ref_rbar((long double)(float)kappa);
        double level_worst = 0.0;
        for (int i = 0; i < nd; i++) {
            vec3 e = env_vmf_filter_lookup(f, (vmf){dirs[i], (float)kappa});
            for (int c = 0; c < 3; c++) {
                double bm = lin_b[c][0] * dirs[i].x + lin_b[c][1] * dirs[i].y + lin_b[c][2] * dirs[i].z;
                double want = lin_a[c] + A * bm, rel = fabs(comp3(e, c) - want) / want;
                if (!(rel <= level_worst)) level_worst = rel;
            }
        }
        CHECK(level_worst <= 0.01, "linear map, kappa %g: worst relative error %g", kappa, level_worst);
        int range = kappa < 1.0 ? 0 : (kappa < 100.0 ? 1 : (kappa < 1e4 ? 2 : 3));
        if (!(level_worst <= worst[range])) worst[range] = level_worst;
    }
    printf("linear map 512x256, %d kappas x %d directions: worst relative error %.2g%% (kappa < 1), %.2g%% (1..100), "
           "%.2g%% (100..1e4), %.2g%% (1e4..1e6)\n",
           NK, nd, 100.0 * worst[0], 100.0 * worst[1], 100.0 * worst[2], 100.0 * worst[3]);
    env_vmf_filter_destroy(f);
    env_map_destroy(env);
}

/* Gaussian spots (angular width sigma) on a dim coloured background: a generic one, one next to
 * the north pole and one on the seam (u = 0, so at phi = rot - pi). */
typedef struct {
    double dir[3], sigma, peak[3];
} spot;

typedef struct {
    spot spots[3];
    double bg[3];
} spot_map;

static void spot_fn(const double d[3], const void *param, float out[3]) {
    const spot_map *m = param;
    for (int c = 0; c < 3; c++) {
        double v = m->bg[c];
        for (int i = 0; i < 3; i++) {
            const spot *s = &m->spots[i];
            double dx = d[0] - s->dir[0], dy = d[1] - s->dir[1], dz = d[2] - s->dir[2];
            double omc = 0.5 * (dx * dx + dy * dy + dz * dz); /* 1 - cos */
            v += s->peak[c] * exp(-omc / (s->sigma * s->sigma));
        }
        out[c] = (float)v;
    }
}

/* gamma(s) L(s) summed over every texel, dOmega = (2pi/W)(pi/H) sin theta, gamma in the stable
 * form kappa / (2 pi (1 - e^{-2 kappa})) e^{-kappa (1 - mu.s)}, all in double; divided by the sum
 * of gamma dOmega (returned in *mass), which differs from 1 by the quadrature's own error: up to
 * ~1% next to a pole for a lobe a few texels wide, where sin theta has a kink. */
static void brute_force(const env_map *env, const double *dirs3, const double *dom, double kappa, const double mu[3],
                        double out[3], double *mass) {
    int n = env->image.width * env->image.height;
    double norm = kappa / (2.0 * PI_D * -expm1(-2.0 * kappa));
    double sum[3] = {0, 0, 0}, total = 0.0;
    for (int i = 0; i < n; i++) {
        const double *s = dirs3 + 3 * i;
        double dx = mu[0] - s[0], dy = mu[1] - s[1], dz = mu[2] - s[2];
        double g = norm * exp(-kappa * 0.5 * (dx * dx + dy * dy + dz * dz)) * dom[i / env->image.width];
        const float *p = env->image.rgb + 3 * i;
        for (int c = 0; c < 3; c++) sum[c] += g * p[c];
        total += g;
    }
    for (int c = 0; c < 3; c++) out[c] = sum[c] / total;
    *mass = total;
}

static void unit_from(double th, double phi, double d[3]) {
    d[0] = sin(th) * cos(phi);
    d[1] = cos(th);
    d[2] = sin(th) * sin(phi);
}

static void test_spots(void) {
    const int w = 1024, h = 512;
    const float rot = 0.3f;
    spot_map m = {.bg = {0.1, 0.2, 0.3}};
    unit_from(1.1, 0.4, m.spots[0].dir);
    m.spots[0].sigma = 0.02;
    m.spots[0].peak[0] = 1000.0, m.spots[0].peak[1] = 800.0, m.spots[0].peak[2] = 300.0;
    unit_from(0.03, 2.0, m.spots[1].dir);
    m.spots[1].sigma = 0.02;
    m.spots[1].peak[0] = 200.0, m.spots[1].peak[1] = 500.0, m.spots[1].peak[2] = 100.0;
    unit_from(2.0, rot - PI_D, m.spots[2].dir);
    m.spots[2].sigma = 0.03;
    m.spots[2].peak[0] = 300.0, m.spots[2].peak[1] = 300.0, m.spots[2].peak[2] = 600.0;
    env_map *env = make_env(w, h, rot, spot_fn, &m);
    double seconds;
    env_vmf_filter *f = make_filter(env, &seconds);
    printf("spot map %dx%d: prefiltered in %.3f s, %.1f MB (the map %.1f MB)\n", w, h, seconds,
           (double)env_vmf_filter_bytes(f) / 1048576.0, 12.0 * w * h / 1048576.0);

    double *dirs3 = malloc(sizeof(double) * 3 * (size_t)w * (size_t)h), *dom = malloc(sizeof(double) * (size_t)h);
    if (!dirs3 || !dom) abort();
    for (int y = 0; y < h; y++) {
        dom[y] = (2.0 * PI_D / w) * (PI_D / h) * sin(PI_D * (y + 0.5) / h);
        for (int x = 0; x < w; x++) dir_at((x + 0.5) / w, (y + 0.5) / h, rot, dirs3 + 3 * ((size_t)y * w + x));
    }
    const double kappas[] = {4.0, 50.0, 500.0, 5000.0};
    for (int k = 0; k < 4; k++) {
        double kappa = kappas[k], sigma = 1.0 / sqrt(kappa);
        /* each spot's centre and points 0.5, 1 and 2 lobe widths away from it, and a few others */
        double probes[40][3];
        int np = 0;
        for (int s = 0; s < 3; s++) {
            double t1[3], t2[3], *c = m.spots[s].dir;
            double ref[3] = {fabs(c[1]) < 0.9 ? 0.0 : 1.0, fabs(c[1]) < 0.9 ? 1.0 : 0.0, 0.0};
            t1[0] = ref[1] * c[2] - ref[2] * c[1], t1[1] = ref[2] * c[0] - ref[0] * c[2],
            t1[2] = ref[0] * c[1] - ref[1] * c[0];
            double l = sqrt(t1[0] * t1[0] + t1[1] * t1[1] + t1[2] * t1[2]);
            for (int i = 0; i < 3; i++) t1[i] /= l;
            t2[0] = c[1] * t1[2] - c[2] * t1[1], t2[1] = c[2] * t1[0] - c[0] * t1[2],
            t2[2] = c[0] * t1[1] - c[1] * t1[0];
            const double offs[] = {0.0, 0.5, 1.0, 2.0};
            for (int o = 0; o < 4; o++)
                for (int side = 0; side < (o == 0 ? 1 : 2); side++) {
                    double a = offs[o] * sigma, *t = side ? t2 : t1, *p = probes[np++];
                    for (int i = 0; i < 3; i++) p[i] = cos(a) * c[i] + sin(a) * t[i];
                }
        }
        vec3 extra[8];
        int ne = test_directions(rot, extra, 8); /* the poles, the seam */
        for (int i = 0; i < ne && np < 40; i++)
            probes[np][0] = extra[i].x, probes[np][1] = extra[i].y, probes[np++][2] = extra[i].z;
        double worst = 0.0, mass_lo = 1.0, mass_hi = 1.0;
        for (int i = 0; i < np; i++) {
            double want[3], mass;
            brute_force(env, dirs3, dom, kappa, probes[i], want, &mass);
            mass_lo = fmin(mass_lo, mass);
            mass_hi = fmax(mass_hi, mass);
            vec3 mu = v3((float)probes[i][0], (float)probes[i][1], (float)probes[i][2]);
            vec3 e = env_vmf_filter_lookup(f, (vmf){mu, (float)kappa});
            for (int c = 0; c < 3; c++) {
                double rel = fabs(comp3(e, c) - want[c]) / want[c];
                if (!(rel <= worst)) worst = rel;
                if (getenv("ENVF_VERBOSE"))
                    printf("  kappa %g probe %d ch %d: %g vs %g (%.2f%%)\n", kappa, i, c, comp3(e, c), want[c],
                           100.0 * (comp3(e, c) - want[c]) / want[c]);
                CHECK(rel <= 0.025, "spots, kappa %g, probe %d, channel %d: %g, brute force %g (%.2g%%)", kappa, i, c,
                      comp3(e, c), want[c], 100.0 * rel);
            }
        }
        printf("spot map: kappa %g, worst relative error %.3g%% over %d probes (spot centres, 0.5/1/2 lobe widths off, "
               "poles, seam); quadrature mass %.4f..%.4f\n",
               kappa, 100.0 * worst, np, mass_lo, mass_hi);
    }
    free(dirs3);
    free(dom);
    env_vmf_filter_destroy(f);
    env_map_destroy(env);
}

/* Zeros, ordinary values and texels near FLT_MAX side by side; and a map of FLT_MAX only. Every
 * lookup is finite and within the map's range (E is an average of the map). */
static void extreme_fn(const double d[3], const void *param, float out[3]) {
    const int *all_max = param;
    if (*all_max) {
        out[0] = out[1] = out[2] = FLT_MAX;
        return;
    }
    /* a hash of the direction picks the kind of texel */
    unsigned bits = (unsigned)(fabs(d[0] * 7919.0 + d[1] * 104729.0 + d[2] * 1299709.0)) * 2654435761u;
    for (int c = 0; c < 3; c++) {
        unsigned kind = (bits >> (3 * c)) % 5;
        out[c] = kind < 2 ? 0.0f : (kind == 2 ? 0.5f * FLT_MAX : (float)(kind)*0.7f);
    }
}

static void test_extremes(void) {
    for (int all_max = 0; all_max < 2; all_max++) {
        int w = all_max ? 16 : 128, h = all_max ? 8 : 64;
        env_map *env = make_env(w, h, 0.2f, extreme_fn, &all_max);
        float hi = 0.0f;
        for (int i = 0; i < 3 * w * h; i++) hi = fmaxf(hi, env->image.rgb[i]);
        env_vmf_filter *f = make_filter(env, NULL);
        vec3 dirs[200];
        int nd = test_directions(0.2f, dirs, 200);
        int bad = 0, outside = 0;
        const float more[] = {INFINITY, NAN, -1.0f, 2e6f};
        for (int k = 0; k < NKW + 4; k++)
            for (int i = 0; i < nd; i++) {
                float kappa = k < NKW ? (float)kappas_wide[k] : more[k - NKW];
                vec3 e = env_vmf_filter_lookup(f, (vmf){dirs[i], kappa});
                if (!is_finite3(e))
                    bad++;
                else if (min_comp3(e) < 0.0f || max_comp3(e) > hi * 1.00001f)
                    outside++;
            }
        /* a degenerate direction must not poison the lookup either */
        vec3 nan_dir = env_vmf_filter_lookup(f, (vmf){v3(NAN, 0, 0), 100.0f});
        CHECK(is_finite3(nan_dir), "NaN direction gives a non-finite result");
        CHECK(bad == 0, "%s map: %d non-finite lookups", all_max ? "FLT_MAX" : "zeros and huge", bad);
        CHECK(outside == 0, "%s map: %d lookups outside the map's range", all_max ? "FLT_MAX" : "zeros and huge",
              outside);
        env_vmf_filter_destroy(f);
        env_map_destroy(env);
    }
    env_vmf_filter_destroy(NULL);
    CHECK(env_vmf_filter_bytes(NULL) == 0, "bytes of NULL");
    char err[128] = "";
    CHECK(env_vmf_filter_create(NULL, err, sizeof err) == NULL && err[0], "NULL map refused with a message");
}

int main(void) {
    test_convention();
    test_constant();
    test_mean();
    test_linear();
    test_spots();
    test_extremes();
    return check_exit("test_envfilter");
}
