/* The display's denoiser (denoise.h) on G-buffers filled by hand: identity where nothing is to be
 * done, noise reduced as the filter's linear model predicts without bias, no leak across geometric
 * edges, holes filled from their own side, the count-weighted filter against a brute-force model
 * of it, a pixel of many samples counted as no more than the cap, and finite output for hostile
 * input. `test_denoise --bench [THREADS]` times 960x540 instead
 * (a release build of the tests; nothing is asserted on the clock). */
#define _POSIX_C_SOURCE 200809L
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "check.h"
#include "clock.h"
#include "denoise.h"
#include "rng.h"

typedef struct {
    int w, h, comps;
    gbuffer g;
    float *light[COMP_COUNT], *count[COMP_COUNT], *var[COMP_COUNT];
    float *out[COMP_COUNT], *out_count[COMP_COUNT];
} img;

/* A w x h image of comps components on one plane facing the camera (normal +z, depth 10), every
 * pixel a hole until set. */
static void img_make(img *im, int w, int h, int comps) {
    memset(im, 0, sizeof *im);
    im->w = w;
    im->h = h;
    im->comps = comps;
    size_t n = (size_t)w * (size_t)h;
    if (gbuffer_init(&im->g, w, h) != 0) abort();
    for (size_t i = 0; i < n; i++) {
        im->g.pos[3 * i] = (float)(i % (size_t)w);
        im->g.pos[3 * i + 1] = (float)(i / (size_t)w);
        im->g.pos[3 * i + 2] = 0.0f;
        im->g.normal[3 * i] = im->g.normal[3 * i + 1] = 0.0f;
        im->g.normal[3 * i + 2] = 1.0f;
        im->g.depth[i] = 10.0f;
        im->g.albedo[3 * i] = im->g.albedo[3 * i + 1] = im->g.albedo[3 * i + 2] = 1.0f;
        im->g.gloss[i] = 0.0f;
        im->g.alpha[i] = 1.0f;
        im->g.material[i] = 0;
    }
    for (int c = 0; c < comps; c++) {
        im->light[c] = calloc(3 * n, sizeof(float));
        im->count[c] = calloc(n, sizeof(float));
        im->var[c] = calloc(n, sizeof(float));
        im->out[c] = calloc(3 * n, sizeof(float));
        im->out_count[c] = calloc(n, sizeof(float));
        if (!im->light[c] || !im->count[c] || !im->var[c] || !im->out[c] || !im->out_count[c]) abort();
    }
}

static void img_free(img *im) {
    gbuffer_deinit(&im->g);
    for (int c = 0; c < im->comps; c++) {
        free(im->light[c]);
        free(im->count[c]);
        free(im->var[c]);
        free(im->out[c]);
        free(im->out_count[c]);
    }
}

static void set(img *im, int c, size_t i, float r, float g, float b, float n, float v) {
    im->light[c][3 * i] = r;
    im->light[c][3 * i + 1] = g;
    im->light[c][3 * i + 2] = b;
    im->count[c][i] = n;
    im->var[c][i] = v;
}

static void set_normal(img *im, size_t i, float x, float y, float z) {
    im->g.normal[3 * i] = x;
    im->g.normal[3 * i + 1] = y;
    im->g.normal[3 * i + 2] = z;
}

static int run_with(img *im, denoiser *d, const denoise_params *p, threadpool *pool) {
    denoise_input in = {.components = im->comps, .g = &im->g};
    denoise_output out = {0};
    for (int c = 0; c < im->comps; c++) {
        in.light[c] = im->light[c];
        in.count[c] = im->count[c];
        in.variance[c] = im->var[c];
        out.light[c] = im->out[c];
        out.count[c] = im->out_count[c];
    }
    return denoise_run(d, &in, p, &out, pool);
}

static int run(img *im, int levels, float sigma_l) {
    denoiser *d = denoiser_create(im->w, im->h);
    if (!d) abort();
    denoise_params p = {.levels = levels, .sigma_l = sigma_l};
    int status = run_with(im, d, &p, NULL);
    denoiser_destroy(d);
    return status;
}

static double lum(const float *rgb) {
    return 0.2126 * (double)rgb[0] + 0.7152 * (double)rgb[1] + 0.0722 * (double)rgb[2];
}

static double gauss(rng_state *r) {
    double u = rng_double(r), v = rng_double(r);
    return sqrt(-2.0 * log(1.0 - u)) * cos(6.283185307179586 * v);
}

/* ---- the filter's linear model, by brute force ---- */

/* With every stop open on one plane the filter is linear in the values, and its counts follow the
 * counts (docs/design.md): the full image's 3x3 pass (B1 x B1), the half grid's pooling (K4 x K4
 * over the 4x4 around each 2x2 block), the half grid's passes (B3 x B3, holes 1, 2, ... of its
 * pixels), and the way back up: a pixel's 3x3 value at weight UP_OWN and its four nearest half
 * pixels' (bilinear, 3/4 and 1/4 a side), each weighted by its samples. */
static const double B3D[5] = {1.0 / 16, 1.0 / 4, 3.0 / 8, 1.0 / 4, 1.0 / 16};
static const double B1D[3] = {0.25, 0.5, 0.25};
static const double K4D[4] = {0.125, 0.375, 0.375, 0.125};
static const double BILD[2] = {0.75, 0.25};
#define UP_OWN_D (9.0 / 64.0)
#define KR 72 /* beyond the reach of five levels: 1 + 2 + 2 (2 + 4 + 8 + 16) + 3 */
#define KN (2 * KR + 1)

static double sum_sq(const double *k, int n) {
    double s = 0.0;
    for (int i = 0; i < n; i++) s += k[i] * k[i];
    return s;
}

/* dst(u) += w src(u - (dx, dy)) on the KN x KN grid */
static void add_shifted(double *dst, const double *src, double w, int dx, int dy) {
    for (int y = 0; y < KN; y++)
        for (int x = 0; x < KN; x++) {
            int xs = x - dx, ys = y - dy;
            if (xs >= 0 && xs < KN && ys >= 0 && ys < KN) dst[y * KN + x] += w * src[ys * KN + xs];
        }
}

/* The model's composite kernels in 2D, over the input's pixels around (KR, KR): the 3x3 pass's of
 * full pixel 0, the half grid's of its pixel 0 (its block's top left at full pixel 0), the
 * output's of full pixel 0; and kappa, each step's real growth of the count 1 / sum K^2 over what
 * its rule (sum a)^2 / sum (a^2 / n) promises independent taps. */
typedef struct {
    double kappa_fine, kappa_pool, kappa_coarse[4], kappa_up;
    double nf, nc, sum_k2; /* the 3x3 pass's and the half grid's counts, the output's sum K^2 */
    double *out;           /* the output's kernel, KN x KN (free) */
} model;

static model model_of(int levels) {
    model m = {0};
    double *kf = calloc(KN * KN, sizeof(double)), *kc = calloc(KN * KN, sizeof(double));
    double *t = calloc(KN * KN, sizeof(double));
    m.out = calloc(KN * KN, sizeof(double));
    double b1 = 0.0, k4 = 0.0, b3 = 0.0;
    for (int i = 0; i < 3; i++) b1 += B1D[i] * B1D[i];
    for (int i = 0; i < 4; i++) k4 += K4D[i] * K4D[i];
    for (int i = 0; i < 5; i++) b3 += B3D[i] * B3D[i];
    for (int b = 0; b < 3; b++)
        for (int a = 0; a < 3; a++) kf[(KR + b - 1) * KN + KR + a - 1] = B1D[a] * B1D[b];
    m.nf = 1.0 / sum_sq(kf, KN * KN);
    m.kappa_fine = m.nf * b1 * b1;
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++) kc[(KR + r - 1) * KN + KR + c - 1] = K4D[r] * K4D[c];
    m.nc = 1.0 / sum_sq(kc, KN * KN);
    m.kappa_pool = m.nc * k4 * k4;
    for (int i = 0; i + 1 < levels; i++) {
        int s = 2 << i; /* full pixels */
        memset(t, 0, sizeof(double) * KN * KN);
        for (int b = 0; b < 5; b++)
            for (int a = 0; a < 5; a++) add_shifted(t, kc, B3D[a] * B3D[b], (a - 2) * s, (b - 2) * s);
        memcpy(kc, t, sizeof(double) * KN * KN);
        double n2 = 1.0 / sum_sq(kc, KN * KN);
        m.kappa_coarse[i] = n2 / m.nc * b3 * b3;
        m.nc = n2;
    }
    /* full pixel 0: half pixels 0 (near) and -1 (far, the kernel 2 full pixels left or up) */
    double own = UP_OWN_D * m.nf, total = own + m.nc;
    add_shifted(m.out, kf, own / total, 0, 0);
    for (int ty = 0; ty < 2; ty++)
        for (int tx = 0; tx < 2; tx++) add_shifted(m.out, kc, m.nc / total * BILD[tx] * BILD[ty], -2 * tx, -2 * ty);
    m.sum_k2 = sum_sq(m.out, KN * KN);
    double bil2 = (BILD[0] * BILD[0] + BILD[1] * BILD[1]) * (BILD[0] * BILD[0] + BILD[1] * BILD[1]);
    m.kappa_up = (1.0 / m.sum_k2) / (total * total / (UP_OWN_D * UP_OWN_D * m.nf + m.nc * bil2));
    free(kf);
    free(kc);
    free(t);
    return m;
}

/* The model on a w x h image of values v and counts n (0: a hole; the image's outside is holes),
 * in double: each step's value is sum a v / sum a, a = h n, its count kappa (sum a)^2 / sum h^2 n.
 * v and n are replaced by the output's. */
static void brute_filter(int w, int h, int levels, const model *m, double *v, double *n) {
    int w2 = (w + 1) / 2, h2 = (h + 1) / 2;
    size_t np = (size_t)w * (size_t)h, nh = (size_t)w2 * (size_t)h2;
    double *fv = calloc(np, sizeof(double)), *fn = calloc(np, sizeof(double));
    double *cv = calloc(nh, sizeof(double)), *cn = calloc(nh, sizeof(double));
    double *tv = calloc(nh, sizeof(double)), *tn = calloc(nh, sizeof(double));
#define ADD(hw, vq, nq) (sa += (hw) * (nq), sv += (hw) * (nq) * (vq), sb += (hw) * (hw) * (nq))
    for (int y = 0; y < h; y++) /* the 3x3 pass */
        for (int x = 0; x < w; x++) {
            double sa = 0.0, sv = 0.0, sb = 0.0;
            for (int b = -1; b <= 1; b++)
                for (int a = -1; a <= 1; a++)
                    if (x + a >= 0 && x + a < w && y + b >= 0 && y + b < h)
                        ADD(B1D[a + 1] * B1D[b + 1], v[(y + b) * w + x + a], n[(y + b) * w + x + a]);
            fv[y * w + x] = sa > 0.0 ? sv / sa : 0.0;
            fn[y * w + x] = sa > 0.0 ? m->kappa_fine * sa * sa / sb : 0.0;
        }
    for (int y = 0; y < h2; y++) /* pooled */
        for (int x = 0; x < w2; x++) {
            double sa = 0.0, sv = 0.0, sb = 0.0;
            for (int r = 0; r < 4; r++)
                for (int c = 0; c < 4; c++) {
                    int xx = 2 * x - 1 + c, yy = 2 * y - 1 + r;
                    if (xx >= 0 && xx < w && yy >= 0 && yy < h) ADD(K4D[r] * K4D[c], v[yy * w + xx], n[yy * w + xx]);
                }
            cv[y * w2 + x] = sa > 0.0 ? sv / sa : 0.0;
            cn[y * w2 + x] = sa > 0.0 ? m->kappa_pool * sa * sa / sb : 0.0;
        }
    for (int i = 0; i + 1 < levels; i++) { /* the half grid's passes */
        int s = 1 << i;
        for (int y = 0; y < h2; y++)
            for (int x = 0; x < w2; x++) {
                double sa = 0.0, sv = 0.0, sb = 0.0;
                for (int b = 0; b < 5; b++)
                    for (int a = 0; a < 5; a++) {
                        int xx = x + (a - 2) * s, yy = y + (b - 2) * s;
                        if (xx >= 0 && xx < w2 && yy >= 0 && yy < h2)
                            ADD(B3D[a] * B3D[b], cv[yy * w2 + xx], cn[yy * w2 + xx]);
                    }
                tv[y * w2 + x] = sa > 0.0 ? sv / sa : 0.0;
                tn[y * w2 + x] = sa > 0.0 ? m->kappa_coarse[i] * sa * sa / sb : 0.0;
            }
        memcpy(cv, tv, sizeof(double) * nh);
        memcpy(cn, tn, sizeof(double) * nh);
    }
    for (int y = 0; y < h; y++) /* back up: a = UP_OWN n_f and bilinear N */
        for (int x = 0; x < w; x++) {
            double sa = 0.0, sv = 0.0, sb = 0.0;
            ADD(UP_OWN_D, fv[y * w + x], fn[y * w + x]);
            int cx[2] = {x >> 1, (x & 1) ? (x >> 1) + 1 : (x >> 1) - 1},
                cy[2] = {y >> 1, (y & 1) ? (y >> 1) + 1 : (y >> 1) - 1};
            for (int ty = 0; ty < 2; ty++)
                for (int tx = 0; tx < 2; tx++)
                    if (cx[tx] >= 0 && cx[tx] < w2 && cy[ty] >= 0 && cy[ty] < h2)
                        ADD(BILD[tx] * BILD[ty], cv[cy[ty] * w2 + cx[tx]], cn[cy[ty] * w2 + cx[tx]]);
            v[y * w + x] = sa > 0.0 ? sv / sa : 0.0;
            n[y * w + x] = sa > 0.0 ? m->kappa_up * sa * sa / sb : 0.0;
        }
#undef ADD
    free(fv);
    free(fn);
    free(cv);
    free(cn);
    free(tv);
    free(tn);
}

/* ---- 1. identity ---- */

static void test_identity(void) {
    img im;
    int w = 96, h = 64;
    img_make(&im, w, h, 2);
    rng_state r = rng_make(7, 1);
    /* no pass: the input back, holes 0 */
    for (int c = 0; c < 2; c++)
        for (size_t i = 0; i < (size_t)w * (size_t)h; i++) {
            float n = i % 7 == 0 ? 0.0f : 1.0f + (float)(i % 13);
            set(&im, c, i, rng_float(&r), 3.0f * rng_float(&r), rng_float(&r), n, rng_float(&r));
        }
    CHECK(run(&im, 0, 0.0f) == 0, "levels 0 failed");
    int bad = 0;
    for (int c = 0; c < 2; c++)
        for (size_t i = 0; i < (size_t)w * (size_t)h; i++) {
            int hole = im.count[c][i] == 0.0f;
            for (int k = 0; k < 3; k++) bad += im.out[c][3 * i + k] != (hole ? 0.0f : im.light[c][3 * i + k]);
            bad += im.out_count[c][i] != im.count[c][i];
        }
    CHECK(bad == 0, "levels 0: %d values differ from the input", bad);

    /* converged (variance 0, a million samples): sharp edges and smooth gradients come back, also
     * an edge of colour at equal luminance, which the half grid's stops (luminance alone) do not see */
    for (int c = 0; c < 2; c++)
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                size_t i = (size_t)y * (size_t)w + (size_t)x;
                float t = (float)x / (float)(w - 1), u = (float)y / (float)(h - 1);
                if (y < h / 4) /* luminance 0.6063 either side */
                    set(&im, c, i, x < w / 2 ? 1.0f : 0.2f, x < w / 2 ? 0.5f : 0.7378076f, 0.5f, 1e6f, 0.0f);
                else if (y < h / 2) /* a sharp luminance edge in colour */
                    set(&im, c, i, x < w / 2 ? 0.2f : 1.7f, x < w / 2 ? 0.5f : 0.9f, 0.3f, 1e6f, 0.0f);
                else /* smooth gradients, one per channel */
                    set(&im, c, i, 0.1f + 2.0f * t, 1.0f + 0.5f * u * u, 0.5f + 0.4f * sinf(3.0f * t + (float)c), 1e6f,
                        0.0f);
            }
    CHECK(run(&im, 5, 0.0f) == 0, "converged run failed");
    double worst = 0.0;
    for (int c = 0; c < 2; c++)
        for (size_t i = 0; i < 3 * (size_t)w * (size_t)h; i++) {
            double e = fabs((double)im.out[c][i] - (double)im.light[c][i]) / fabs((double)im.light[c][i]);
            if (!(e <= worst)) worst = e;
        }
    CHECK(worst <= 1e-5, "converged input changed by %.3g (relative)", worst);

    /* a young pixel among converged ones (a million samples of variance 1 each: the mean's standard
     * deviation 1e-3) beside an edge of 0.05 (50 of those): its variance must not loosen its
     * converged neighbours' stops (the variance is smoothed per sample, over each pixel's own
     * count), and it takes its neighbours' value, as they have a million samples to its one. */
    size_t young = (size_t)(h / 4) * (size_t)w + (size_t)(w / 2 - 1);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            size_t i = (size_t)y * (size_t)w + (size_t)x;
            float v = x < w / 2 ? 1.0f : 1.05f;
            set(&im, 0, i, v, v, v, 1e6f, 1.0f);
            set(&im, 1, i, v, v, v, 1e6f, 1.0f);
        }
    set(&im, 0, young, 2.0f, 2.0f, 2.0f, 1.0f, 1.0f);
    CHECK(run(&im, 5, 0.0f) == 0, "young-pixel run failed");
    worst = 0.0;
    for (size_t i = 0; i < (size_t)w * (size_t)h; i++) {
        if (i == young) continue;
        double e = fabs((double)im.out[0][3 * i] - (double)im.light[0][3 * i]);
        if (!(e <= worst)) worst = e;
    }
    CHECK(worst <= 5e-4, "converged pixels beside a young one moved by %.3g", worst);
    CHECK(fabs((double)im.out[0][3 * young] - 1.025) <= 0.03, "the young pixel gave %g, its neighbours 1 and 1.05",
          (double)im.out[0][3 * young]);
    img_free(&im);
}

/* ---- 2. noise on a flat plane ---- */

/* Luminance noise of standard deviation sigma on a flat plane, one sample a pixel, filtered over
 * `runs` images: the interior's mean error and mean squared error against mu. */
static void noise_runs(int n, int runs, float sigma_l, double sigma, double *bias, double *mse, long long *m) {
    const double mu[3] = {0.5, 1.0, 0.25};
    double mu_l = 0.2126 * mu[0] + 0.7152 * mu[1] + 0.0722 * mu[2];
    double s1 = 0.0, s2 = 0.0;
    *m = 0;
    img im;
    img_make(&im, n, n, 1);
    for (int run_i = 0; run_i < runs; run_i++) {
        rng_state r = rng_make(1000 + (uint64_t)run_i, 3);
        for (size_t i = 0; i < (size_t)n * (size_t)n; i++) {
            double e = sigma * gauss(&r); /* grey noise: the luminance's is sigma too */
            set(&im, 0, i, (float)(mu[0] + e), (float)(mu[1] + e), (float)(mu[2] + e), 1.0f, (float)(sigma * sigma));
        }
        CHECK(run(&im, 5, sigma_l) == 0, "noise run failed");
        for (int y = KR; y < n - KR; y++)
            for (int x = KR; x < n - KR; x++) {
                double e = lum(im.out[0] + 3 * ((size_t)y * (size_t)n + (size_t)x)) - mu_l;
                s1 += e;
                s2 += e * e;
                ++*m;
            }
    }
    *bias = s1 / (double)*m;
    *mse = s2 / (double)*m;
    img_free(&im);
}

static void test_noise(void) {
    /* The open filter's output is sum K x: its variance is sigma^2 sum K^2. Its interior mean
     * sums each input with weight at most 1/M (K sums to 1), so its standard deviation is at most
     * sigma / sqrt(M). The variance estimate (a Gaussian field's mean square over M pixels) has
     * relative standard deviation sqrt(2 sum_d rho(d)^2 / M), rho the field's autocorrelation
     * (K * K) / sum K^2. K is a sum of two separable terms, alpha f x f (the 3x3 pass) and
     * beta g x g (the half grid's, bilinear), so sum_d (K * K)^2 is a sum of products of 1D
     * autocorrelations' inner products. */
    model md = model_of(5);
    double sum_k2 = md.sum_k2;
    enum { L1 = KN, A1 = 2 * KN - 1 };
    double f[L1] = {0}, kc[L1] = {0}, t[L1], g[L1] = {0};
    for (int i = 0; i < 3; i++) f[KR + i - 1] = B1D[i];
    for (int i = 0; i < 4; i++) kc[KR + i - 1] = K4D[i];
    for (int p = 0; p < 4; p++) {
        memset(t, 0, sizeof t);
        for (int u = 0; u < L1; u++)
            for (int a = 0; a < 5; a++) {
                int v = u - (a - 2) * (2 << p);
                if (v >= 0 && v < L1) t[u] += B3D[a] * kc[v];
            }
        memcpy(kc, t, sizeof t);
    }
    for (int u = 0; u < L1; u++) g[u] = BILD[0] * kc[u] + (u + 2 < L1 ? BILD[1] * kc[u + 2] : 0.0);
    double alpha = UP_OWN_D * md.nf / (UP_OWN_D * md.nf + md.nc), beta = 1.0 - alpha;
    double ff = 0.0, fg = 0.0, gg = 0.0;
    for (int u = 0; u < L1; u++) ff += f[u] * f[u], fg += f[u] * g[u], gg += g[u] * g[u];
    CHECK(fabs((alpha * alpha * ff * ff + 2.0 * alpha * beta * fg * fg + beta * beta * gg * gg) / sum_k2 - 1.0) < 1e-9,
          "the 1D and 2D models disagree");
    /* the four terms' 1D autocorrelations: f*f, f*g, g*f, g*g, weighted alpha^2, alpha beta (twice), beta^2 */
    static double ac[4][A1];
    const double *pa[4] = {f, f, g, g}, *pb[4] = {f, g, f, g},
                 cw[4] = {alpha * alpha, alpha * beta, alpha * beta, beta * beta};
    memset(ac, 0, sizeof ac);
    for (int k = 0; k < 4; k++)
        for (int i = 0; i < L1; i++)
            for (int j = 0; j < L1; j++) ac[k][i - j + L1 - 1] += pa[k][i] * pb[k][j];
    double sum_a2 = 0.0;
    for (int k = 0; k < 4; k++)
        for (int l = 0; l < 4; l++) {
            double d = 0.0;
            for (int u = 0; u < A1; u++) d += ac[k][u] * ac[l][u];
            sum_a2 += cw[k] * cw[l] * d * d;
        }
    double rho2 = sum_a2 / (sum_k2 * sum_k2);
    free(md.out);

    const double sigma = 0.2;
    int n = 448, runs = 6;
    double bias, mse;
    long long m;
    /* every stop open (sigma_l huge): the linear model exactly */
    noise_runs(n, runs, 1e30f, sigma, &bias, &mse, &m);
    double ratio = mse / (sigma * sigma), se = sqrt(2.0 * rho2 / (double)m);
    printf("noise, stops open: variance x %.4g, the model predicts %.4g (+-%.1f%%); bias %.2g sigma\n", ratio, sum_k2,
           100.0 * se, bias / sigma);
    CHECK(fabs(ratio / sum_k2 - 1.0) <= 4.0 * se, "open: variance ratio %.4g, predicted %.4g (+-%.3g)", ratio, sum_k2,
          se);
    CHECK(fabs(bias) <= 5.0 * sigma / sqrt((double)m), "open: bias %.3g, bound %.3g", bias,
          5.0 * sigma / sqrt((double)m));
    /* the real stops: no bias (the weights are symmetric in the noise), and the variance within a
     * factor 2 of the open filter's. A neighbour within the noise (a difference of N(0, 2 var))
     * keeps E[exp(-|d| / 4 sd)] = 0.77 of its weight, which raises sum w^2 / (sum w)^2 by 1.09 a
     * step; the weights' own randomness adds some. That holds only while the stop sees the noise's
     * true size after each step (kappa, docs/design.md) and the variance estimate is right. */
    noise_runs(n, runs, 0.0f, sigma, &bias, &mse, &m);
    ratio = mse / (sigma * sigma);
    printf("noise, default stops: variance x %.4g (%.2f of the open filter's); bias %.2g sigma\n", ratio,
           ratio / sum_k2, bias / sigma);
    CHECK(ratio <= 2.0 * sum_k2 * (1.0 + 4.0 * se), "default: variance ratio %.4g, the open filter's %.4g", ratio,
          sum_k2);
    CHECK(fabs(bias) <= 5.0 * sigma / sqrt((double)m), "default: bias %.3g, bound %.3g", bias,
          5.0 * sigma / sqrt((double)m));
}

/* ---- 3. edges ---- */

/* Two halves at x = w/2 (kind 0: normals 90 degrees... kind 1: depths apart; kind 2: one plane,
 * the control) lit 1 and 1.5 with noise: the worst relative error of a column's mean luminance
 * one and two pixels either side of the edge. */
static double edge_leak(int kind) {
    int w = 128, h = 256;
    img im;
    img_make(&im, w, h, 1);
    double sigma = 0.3, worst = 0.0, col[4] = {0};
    int xs[4] = {w / 2 - 2, w / 2 - 1, w / 2, w / 2 + 1};
    for (int run_i = 0; run_i < 2; run_i++) {
        rng_state r = rng_make(77 + (uint64_t)run_i, 5);
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                size_t i = (size_t)y * (size_t)w + (size_t)x;
                int right = x >= w / 2;
                float v = (float)((right ? 1.5 : 1.0) + sigma * gauss(&r));
                set(&im, 0, i, v, v, v, 1.0f, (float)(sigma * sigma));
                if (kind == 0 && right) set_normal(&im, i, 0.6f, 0.0f, 0.8f);
                if (kind == 1) im.g.depth[i] = right ? 12.0f : 10.0f;
            }
        CHECK(run(&im, 5, 0.0f) == 0, "edge run failed");
        for (int t = 0; t < 4; t++)
            for (int y = 0; y < h; y++) col[t] += lum(im.out[0] + 3 * ((size_t)y * (size_t)w + (size_t)xs[t]));
    }
    for (int t = 0; t < 4; t++) {
        double want = t < 2 ? 1.0 : 1.5, e = fabs(col[t] / (2.0 * h) - want) / want;
        if (e > worst) worst = e;
    }
    img_free(&im);
    return worst;
}

static void test_edges(void) {
    double normal = edge_leak(0), depth = edge_leak(1), none = edge_leak(2);
    printf("edges: leak %.2f%% across normals, %.2f%% across depths, %.2f%% on one plane\n", 100.0 * normal,
           100.0 * depth, 100.0 * none);
    CHECK(normal <= 0.03, "normal edge: a side's level off by %.1f%% beside it", 100.0 * normal);
    CHECK(depth <= 0.03, "depth edge: a side's level off by %.1f%% beside it", 100.0 * depth);
    CHECK(none > 0.05, "without a geometric edge the light edge should blur (%.1f%%): the measure sees leaks",
          100.0 * none);
}

/* ---- 4. holes ---- */

static int sampled_lattice(int x, int y, int step) { return x % step == 0 && y % step == 0; }

static void test_holes(void) {
    int w = 100, h = 70;
    size_t n = (size_t)w * (size_t)h;
    img im;
    img_make(&im, w, h, 1);
    const float cr = 0.3f, cg = 0.5f, cb = 0.7f;
    /* 1 in 16, on a lattice and at random: every pixel gets the constant */
    for (int pattern = 0; pattern < 2; pattern++) {
        rng_state r = rng_make(5, 9);
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                int s = pattern == 0 ? sampled_lattice(x, y, 4) : rng_float(&r) < 1.0f / 16.0f;
                set(&im, 0, (size_t)y * (size_t)w + (size_t)x, s ? cr : 0.0f, s ? cg : 0.0f, s ? cb : 0.0f,
                    s ? 1.0f : 0.0f, 0.0f);
            }
        CHECK(run(&im, 5, 0.0f) == 0, "holes run failed");
        int bad = 0;
        for (size_t i = 0; i < n; i++)
            bad += !(fabsf(im.out[0][3 * i] - cr) <= 1e-5f && fabsf(im.out[0][3 * i + 1] - cg) <= 1e-5f &&
                     fabsf(im.out[0][3 * i + 2] - cb) <= 1e-5f && im.out_count[0][i] > 0.0f);
        CHECK(bad == 0, "1 in 16 (%s): %d pixels not the constant", pattern ? "random" : "lattice", bad);
    }
    /* a depth edge (and, below it, escaped rays): holes take their own side's value */
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            size_t i = (size_t)y * (size_t)w + (size_t)x;
            int s = sampled_lattice(x, y, 4), right = x >= 42, sky = y >= 50;
            float v = sky ? 5.0f : (right ? 2.0f : 1.0f);
            im.g.depth[i] = sky ? 0.0f : (right ? 20.0f : 10.0f);
            set(&im, 0, i, s ? v : 0.0f, s ? v : 0.0f, s ? v : 0.0f, s ? 1.0f : 0.0f, 0.0f);
        }
    CHECK(run(&im, 5, 0.0f) == 0, "depth-edge holes run failed");
    int bad = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            size_t i = (size_t)y * (size_t)w + (size_t)x;
            float want = y >= 50 ? 5.0f : (x >= 42 ? 2.0f : 1.0f);
            bad += !(fabsf(im.out[0][3 * i + 1] - want) <= 1e-5f * want);
        }
    CHECK(bad == 0, "holes across a depth edge and escaped rays: %d pixels took the other side", bad);
    /* a strip one pixel wide, facing another way than the plane it lies on, sampled every fifth
     * row: too thin for the half grid to show, so its holes are filled along it, from its own
     * samples, never the plane's */
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            size_t i = (size_t)y * (size_t)w + (size_t)x;
            int strip = x == 41, s = strip ? y % 5 == 0 : 1;
            float v = strip ? 3.0f : 1.0f;
            im.g.depth[i] = 10.0f;
            if (strip)
                set_normal(&im, i, 0.6f, 0.0f, 0.8f);
            else
                set_normal(&im, i, 0.0f, 0.0f, 1.0f);
            set(&im, 0, i, s ? v : 0.0f, s ? v : 0.0f, s ? v : 0.0f, s ? 1.0f : 0.0f, 0.0f);
        }
    CHECK(run(&im, 3, 0.0f) == 0, "strip run failed");
    bad = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            size_t i = (size_t)y * (size_t)w + (size_t)x;
            float want = x == 41 ? 3.0f : 1.0f;
            bad += !(fabsf(im.out[0][3 * i + 1] - want) <= 1e-4f * want && im.out_count[0][i] > 0.0f);
        }
    CHECK(bad == 0, "a strip one pixel wide: %d pixels not their own surface's light", bad);
    /* 1 in 256 and one level (the 3x3 pass, the half grid's pooling and the way back up, no pass
     * on the half grid, and a hole left after them filled from up to 6 pixels away): a hole no tap
     * reaches stays a hole, and says so */
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            size_t i = (size_t)y * (size_t)w + (size_t)x;
            int s = sampled_lattice(x, y, 16);
            im.g.depth[i] = 10.0f;
            set(&im, 0, i, s ? cr : 0.0f, s ? cg : 0.0f, s ? cb : 0.0f, s ? 1.0f : 0.0f, 0.0f);
        }
    CHECK(run(&im, 1, 0.0f) == 0, "sparse run failed");
    bad = 0;
    int unreached = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            size_t i = (size_t)y * (size_t)w + (size_t)x;
            int reached = 0; /* within 6 pixels (the half pixels' 4x4 around the block reach 3) */
            for (int b = y - 6; b <= y + 6; b++)
                for (int a = x - 6; a <= x + 6; a++)
                    reached |= a >= 0 && a < w && b >= 0 && b < h && sampled_lattice(a, b, 16);
            unreached += !reached;
            if (reached)
                bad += !(fabsf(im.out[0][3 * i] - cr) <= 1e-5f && im.out_count[0][i] > 0.0f);
            else
                bad += !(im.out[0][3 * i] == 0.0f && im.out[0][3 * i + 2] == 0.0f && im.out_count[0][i] == 0.0f);
        }
    CHECK(bad == 0, "1 in 256, one level: %d pixels wrong (reached: the constant; unreached: 0, count 0)", bad);
    CHECK(unreached > 100, "1 in 256, one level: only %d pixels out of reach, the test sees little", unreached);
    img_free(&im);
}

/* ---- the count-weighted filter against brute force ---- */

static void test_brute(void) {
    int w = 41, h = 29;
    size_t np = (size_t)w * (size_t)h;
    img im;
    img_make(&im, w, h, 1);
    double *v = malloc(sizeof(double) * np), *n = malloc(sizeof(double) * np);
    const float counts[4] = {0.0f, 1.0f, 3.0f, 50.0f};
    for (int levels = 1; levels <= 5; levels += 2) {
        rng_state r = rng_make(11, 2);
        for (size_t i = 0; i < np; i++) {
            float c = counts[rng_next_u32(&r) % 4], g = 0.2f + 2.0f * rng_float(&r);
            set(&im, 0, i, 0.5f * g, g, 2.0f * g, c, 0.3f);
            v[i] = (double)g;
            n[i] = (double)c;
        }
        CHECK(run(&im, levels, 1e30f) == 0, "brute run failed");
        model md = model_of(levels);
        brute_filter(w, h, levels, &md, v, n);
        free(md.out);
        double worst_v = 0.0, worst_n = 0.0;
        for (size_t i = 0; i < np; i++) {
            double ev = fabs((double)im.out[0][3 * i + 1] - v[i]);
            double en = n[i] > 0.0 ? fabs((double)im.out_count[0][i] / n[i] - 1.0) : (double)im.out_count[0][i];
            if (!(ev <= worst_v)) worst_v = ev;
            if (!(en <= worst_n)) worst_n = en;
        }
        /* weights carry the fast exp2's 1e-4: values within 2.2 (their spread) times that, a few steps */
        CHECK(worst_v <= 1e-3, "%d levels: count-weighted values off brute force by %.3g", levels, worst_v);
        CHECK(worst_n <= 2e-3, "%d levels: effective counts off brute force by %.3g (relative)", levels, worst_n);
    }
    free(v);
    free(n);
    img_free(&im);
}

/* ---- 5. hostile input ---- */

static int all_finite(const img *im) {
    for (int c = 0; c < im->comps; c++)
        for (size_t i = 0; i < (size_t)im->w * (size_t)im->h; i++) {
            if (!isfinite(im->out_count[c][i]) || im->out_count[c][i] < 0.0f) return 0;
            for (int k = 0; k < 3; k++)
                if (!isfinite(im->out[c][3 * i + k])) return 0;
        }
    return 1;
}

static void test_hostile(void) {
    const float bad_values[] = {0.0f, -0.0f, 1e-45f, FLT_MAX, -FLT_MAX, INFINITY, -INFINITY, NAN, 1e30f, -1.0f};
    const int nb = (int)(sizeof bad_values / sizeof bad_values[0]);
    const int sizes[][2] = {{1, 1}, {1, 37}, {37, 1}, {130, 3}, {70, 45}};
    for (int si = 0; si < 5; si++) {
        int w = sizes[si][0], h = sizes[si][1];
        size_t n = (size_t)w * (size_t)h;
        img im;
        img_make(&im, w, h, COMP_COUNT);
        for (int kind = 0; kind < 7; kind++) {
            rng_state r = rng_make(99 + (uint64_t)kind, (uint64_t)si);
            for (size_t i = 0; i < n; i++) {
                float x = bad_values[rng_next_u32(&r) % (uint32_t)nb];
                for (int c = 0; c < COMP_COUNT; c++) {
                    switch (kind) {
                    case 0: set(&im, c, i, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f); break;              /* all holes */
                    case 1: set(&im, c, i, FLT_MAX, FLT_MAX, -FLT_MAX, 1.0f, FLT_MAX); break; /* huge */
                    case 2: set(&im, c, i, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f); break;              /* zeros */
                    case 3:
                        set(&im, c, i, x, -x, x, bad_values[rng_next_u32(&r) % (uint32_t)nb], x); /* chaos */
                        break;
                    case 4: set(&im, c, i, 50.0f * x, 1.0f / 0.02f, 0.0f, 1e6f, 0.0f); break; /* albedo floor */
                    default: set(&im, c, i, rng_float(&r), 1.0f, 2.0f, FLT_MAX, 1e-30f); break;
                    }
                }
                if (kind == 5) { /* every ray escaped */
                    im.g.depth[i] = 0.0f;
                    set_normal(&im, i, 0.0f, 0.0f, -1.0f);
                } else if (kind >= 3) { /* hostile geometry, and lobes (the sharp lobe's normal stop) */
                    im.g.depth[i] = bad_values[rng_next_u32(&r) % (uint32_t)nb];
                    set_normal(&im, i, x, bad_values[rng_next_u32(&r) % (uint32_t)nb], 1.0f);
                    im.g.gloss[i] = bad_values[rng_next_u32(&r) % (uint32_t)nb];
                    im.g.alpha[i] = bad_values[rng_next_u32(&r) % (uint32_t)nb];
                } else {
                    im.g.depth[i] = 10.0f;
                    set_normal(&im, i, 0.0f, 0.0f, 1.0f);
                }
            }
            const denoise_params params[4] = {{0, 0, 0, 5, 0},
                                              {NAN, -1.0f, INFINITY, 99, NAN},
                                              {FLT_MAX, FLT_MAX, 1e-30f, 3, -1.0f},
                                              {1e-30f, 1e-30f, FLT_MAX, -3, 1e-30f}};
            for (int pi = 0; pi < 4; pi++) {
                denoiser *d = denoiser_create(w, h);
                CHECK(d != NULL, "create %dx%d failed", w, h);
                if (!d) continue;
                CHECK(run_with(&im, d, &params[pi], NULL) == 0, "%dx%d kind %d params %d failed", w, h, kind, pi);
                CHECK(all_finite(&im), "%dx%d, input kind %d, params %d: output not finite", w, h, kind, pi);
                denoiser_destroy(d);
            }
        }
        img_free(&im);
    }
    /* bad calls are refused: a size that is not the denoiser's, no components, no counts */
    img im;
    img_make(&im, 8, 8, 1);
    denoiser *d = denoiser_create(9, 8);
    denoise_params p = {.levels = 2};
    CHECK(run_with(&im, d, &p, NULL) == -1, "a G-buffer of another size was accepted");
    denoiser_destroy(d);
    d = denoiser_create(8, 8);
    im.comps = 0;
    CHECK(run_with(&im, d, &p, NULL) == -1, "no components was accepted");
    im.comps = 1;
    float *keep = im.count[0];
    im.count[0] = NULL;
    CHECK(run_with(&im, d, &p, NULL) == -1, "no counts was accepted");
    im.count[0] = keep;
    denoiser_destroy(d);
    img_free(&im);
    CHECK(denoiser_create(0, 5) == NULL && denoiser_create(5, -1) == NULL, "an empty size was accepted");
}

/* Rows run on the pool give the same image as on the calling thread. */
static void test_threads(void) {
    img im;
    int w = 150, h = 90;
    img_make(&im, w, h, 2);
    rng_state r = rng_make(3, 3);
    for (int c = 0; c < 2; c++)
        for (size_t i = 0; i < (size_t)w * (size_t)h; i++)
            set(&im, c, i, rng_float(&r), rng_float(&r), rng_float(&r), (float)(rng_next_u32(&r) % 5), 0.1f);
    denoiser *d = denoiser_create(w, h);
    threadpool *pool = threadpool_create(3);
    denoise_params p = {.levels = 4};
    CHECK(d && pool && run_with(&im, d, &p, NULL) == 0, "single-threaded run failed");
    float *first = malloc(sizeof(float) * 3 * (size_t)w * (size_t)h);
    memcpy(first, im.out[1], sizeof(float) * 3 * (size_t)w * (size_t)h);
    CHECK(run_with(&im, d, &p, pool) == 0, "pool run failed");
    CHECK(memcmp(first, im.out[1], sizeof(float) * 3 * (size_t)w * (size_t)h) == 0, "the pool changed the image");
    free(first);
    threadpool_destroy(pool);
    denoiser_destroy(d);
    img_free(&im);
}

/* ---- the viewer's case, timed ---- */

static double cpu_ms(void) {
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec * 1e3 + (double)t.tv_nsec * 1e-6;
}

static int bench(int threads) {
    int w = 960, h = 540;
    img im;
    img_make(&im, w, h, 2);
    rng_state r = rng_make(1, 1);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            size_t i = (size_t)y * (size_t)w + (size_t)x;
            im.g.depth[i] = x < w / 2 ? 5.0f + 0.01f * (float)y : 8.0f;
            if (x < w / 3) set_normal(&im, i, 0.0f, 1.0f, 0.0f);
        }
    threadpool *pool = threadpool_create(threads);
    denoiser *d = denoiser_create(w, h);
    if (!pool || !d) return 1;
    printf("denoise 960x540, 2 components, %d threads:\n", threads);
    const float counts[3] = {100.0f, 1.0f, 0.0f};
    const char *names[3] = {"converging (count 100)", "young (count 1)", "sparse (1 in 16, the rest holes)"};
    for (int kind = 0; kind < 3; kind++) {
        for (int c = 0; c < 2; c++)
            for (size_t i = 0; i < (size_t)w * (size_t)h; i++) {
                float n = kind < 2 ? counts[kind] : (i % 4 == 0 && (i / (size_t)w) % 4 == 0 ? 1.0f : 0.0f);
                set(&im, c, i, rng_float(&r), rng_float(&r), rng_float(&r), n, 0.1f);
            }
        for (int levels = 3; levels <= 5; levels++) {
            denoise_params p = {.levels = levels};
            double best = 1e30, best_cpu = 1e30;
            for (int rep = 0; rep < 15; rep++) {
                double c0 = cpu_ms();
                uint64_t t0 = clock_ns();
                run_with(&im, d, &p, pool);
                double ms = (double)(clock_ns() - t0) * 1e-6, cpu = cpu_ms() - c0;
                if (ms < best) best = ms;
                if (cpu < best_cpu) best_cpu = cpu;
            }
            printf("  %-34s %d levels: best %.1f ms wall, %.1f ms cpu\n", names[kind], levels, best, best_cpu);
            fflush(stdout);
        }
    }
    denoiser_destroy(d);
    threadpool_destroy(pool);
    img_free(&im);
    return 0;
}

/* The count cap: one pixel of many samples (the display's extra ones: a bright speck, sure of its
 * own light) beside a hole and young pixels of a dim surface. Uncapped, its count outweighs all
 * theirs and the hole beside it takes its light; capped at 4 it counts as four of them, and the
 * hole stays nearer the surface's light (the display keeps the speck's own mean: take_of). */
static void test_count_cap(void) {
    double hole[2];
    for (int k = 0; k < 2; k++) {
        img im;
        img_make(&im, 32, 32, 1);
        for (size_t i = 0; i < 32 * 32; i++) set(&im, 0, i, 1.0f, 1.0f, 1.0f, 1.0f, 1.0f);
        size_t speck = 16 * 32 + 16, gap = 16 * 32 + 17;
        set(&im, 0, speck, 100.0f, 100.0f, 100.0f, 10000.0f, 1e4f);
        set(&im, 0, gap, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f);
        denoiser *d = denoiser_create(32, 32);
        if (!d) abort();
        denoise_params p = {.levels = 3, .count_cap = k ? 4.0f : 0.0f};
        CHECK(run_with(&im, d, &p, NULL) == 0, "count cap: the filter must run");
        denoiser_destroy(d);
        hole[k] = lum(im.out[0] + 3 * gap);
        img_free(&im);
    }
    CHECK(hole[0] > 50.0 && hole[1] < 0.5 * hole[0] && hole[1] >= 1.0,
          "count cap: the hole beside the speck takes %.1f uncapped, %.1f capped at 4 (want under half)", hole[0],
          hole[1]);
}

/* A sharp lobe's normal stop: a curved mirror (normals of a sphere 20 pixels in radius, GGX alpha
 * 0.02), young and noisy everywhere (one sample a pixel, a wide spread, so the luminance stop is
 * open), with a light's speck at its centre. The speck's neighbours reflect something else: they
 * take a fraction of what they take on a rough surface of the same shape, and the speck keeps more
 * of its own light. A flat mirror (one normal) is filtered as a rough surface is: the stop goes by
 * how far the reflected lobe turns, not by the material. */
static void speck_filtered(float gloss, float alpha, int curved, double *beside, double *own) {
    enum { W = 33 };
    img im;
    img_make(&im, W, W, 1);
    for (int y = 0; y < W; y++)
        for (int x = 0; x < W; x++) {
            size_t i = (size_t)y * W + (size_t)x;
            float dx = curved ? (float)(x - W / 2) / 20.0f : 0.0f, dy = curved ? (float)(y - W / 2) / 20.0f : 0.0f;
            set_normal(&im, i, dx, dy, sqrtf(1.0f - dx * dx - dy * dy));
            im.g.gloss[i] = gloss;
            im.g.alpha[i] = alpha;
            set(&im, 0, i, 1.0f, 1.0f, 1.0f, 1.0f, 1e4f);
        }
    size_t c = (size_t)(W / 2) * W + W / 2;
    set(&im, 0, c, 100.0f, 100.0f, 100.0f, 1.0f, 1e4f);
    CHECK(run(&im, 3, 0.0f) == 0, "speck run failed");
    *beside = 0.0;
    for (int k = 0; k < 4; k++) { /* the four pixels two away */
        int x = W / 2 + (k == 0 ? 2 : k == 1 ? -2 : 0), y = W / 2 + (k == 2 ? 2 : k == 3 ? -2 : 0);
        *beside += 0.25 * (lum(im.out[0] + 3 * ((size_t)y * W + (size_t)x)) - 1.0);
    }
    *own = lum(im.out[0] + 3 * c);
    img_free(&im);
}

static void test_sharp_lobe(void) {
    double rough_beside, rough_own, mirror_beside, mirror_own, flat_beside, flat_own, rflat_beside, rflat_own;
    speck_filtered(0.0f, 1.0f, 1, &rough_beside, &rough_own);
    speck_filtered(1.0f, 0.02f, 1, &mirror_beside, &mirror_own);
    speck_filtered(1.0f, 0.02f, 0, &flat_beside, &flat_own);
    speck_filtered(0.0f, 1.0f, 0, &rflat_beside, &rflat_own);
    printf("sharp lobe: beside the speck +%.2f rough, +%.2f curved mirror; the speck %.1f, %.1f; flat %.2f, %.2f\n",
           rough_beside, mirror_beside, rough_own, mirror_own, rflat_beside, flat_beside);
    CHECK(rough_beside > 0.3, "a rough surface's noisy speck should spread (+%.2f beside it): the measure sees it",
          rough_beside);
    CHECK(mirror_beside < 0.2 * rough_beside, "a curved mirror's pixels beside the speck take +%.2f (rough: +%.2f)",
          mirror_beside, rough_beside);
    CHECK(mirror_own > 1.5 * rough_own, "the mirror's speck keeps %.1f (rough: %.1f)", mirror_own, rough_own);
    CHECK(fabs(flat_beside - rflat_beside) <= 1e-6 * rflat_beside && fabs(flat_own - rflat_own) <= 1e-6 * rflat_own,
          "a flat mirror is filtered as a flat rough surface: beside %.4f vs %.4f", flat_beside, rflat_beside);
}

int main(int argc, char **argv) {
    if (argc > 1 && strcmp(argv[1], "--bench") == 0) return bench(argc > 2 ? atoi(argv[2]) : 2);
    test_count_cap();
    test_sharp_lobe();
    test_identity();
    test_brute();
    test_holes();
    test_edges();
    test_noise();
    test_hostile();
    test_threads();
    return check_exit("test_denoise");
}
