/* The vMF-prefiltered environment: a ladder of equirect levels, each the map convolved with a vMF
 * lobe. The sharpest level is a direct summation of the lobe over the map's texels; each other
 * level a direct summation over a sharper level box-resampled to its grid (see plan_input). */
#include "envfilter.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "threadpool.h"

#define PI_D 3.14159265358979323846

/* Texels per lobe standard deviation 1/sqrt(kappa) in the level grids: bilinear lookup then
 * rebuilds a blurred point within about 1.5%, and the summation samples the lobe finely. */
#define TEXELS_PER_SIGMA 3.0
/* The summation window: kappa (1 - mu.s) < CUTOFF, where gamma is e^-12 of its peak. */
#define CUTOFF 12.0
/* The first level. Below it E = mean + O(kappa), so the blend toward kappa 0 is linear in kappa. */
#define FIRST_KAPPA 0.25
/* Levels at least this sharp are summed over the next sharper level (see plan_input). */
#define CHAIN_KAPPA 256.0
/* Smallest level grid: fine enough (texel 0.065 rad) that the low-kappa levels can be summed
 * over a level as sharp as kappa ~ 200 (see plan_input). */
#define MIN_WIDTH 96
#define MIN_HEIGHT 48
/* Near the poles a row's texels are narrower than the lobe by 1 / sin(theta): only every few
 * are summed (at least this many per row) and the rest interpolated, so cost per row is even. */
#define MIN_COLUMNS 8
#define MAX_LEVELS 64
/* Output columns summed together: one kernel tap feeds a block of columns, so the inner loop runs
 * over vector lanes with independent sums. */
#define BLOCK 32

typedef struct {
    double kappa;
    int w, h;
    float *rgb;   /* interleaved linear RGB, rows top (+Y) first like the map */
    vec3 pole[2]; /* E at +Y and -Y, which the first and last rows' centres miss by half a texel */
} filter_level;

struct env_vmf_filter {
    const env_map *env; /* borrowed: the sharpest lobes read its image, lookups its rotation */
    vec3 mean;          /* kappa 0: the solid-angle mean */
    int num_levels;
    filter_level levels[MAX_LEVELS]; /* ascending kappa */
    /* log kappa of each level, then of kappa_source, past which the map itself is used */
    double log_kappa[MAX_LEVELS + 1];
    double kappa_source;
};

/* ---- lookups ------------------------------------------------------------------------------ */

/* Held to finite floats: two huge texels must not blend into Inf (and then NaN). */
static float finite_clamp(float v) { return v < FLT_MAX ? (v > -FLT_MAX ? v : -FLT_MAX) : FLT_MAX; }
static float mixf(float a, float b, float t) { return finite_clamp(a + (b - a) * t); }
static vec3 mix3(vec3 a, vec3 b, float t) { return v3(mixf(a.x, b.x, t), mixf(a.y, b.y, t), mixf(a.z, b.z, t)); }

static vec3 texel(const float *rgb, int w, int x, int y) {
    const float *p = rgb + 3 * ((size_t)y * (size_t)w + (size_t)x);
    return v3(p[0], p[1], p[2]);
}

/* Bilinear with the renderer's conventions: texel centres at (i + 0.5) / size, u wraps across the
 * seam, v clamps at the poles, or with pole values (levels), blends from the first or last row
 * to the pole's own value over the last half texel: a coarse level's first row lies well off the
 * pole, and clamping to it would be off by its gradient times half a texel. */
static vec3 bilinear(const float *rgb, int w, int h, const vec3 *pole, vec2 uv) {
    float x = uv.x * (float)w - 0.5f, y = uv.y * (float)h - 0.5f;
    if (!(x >= -1.0f && x <= (float)w)) x = 0.0f; /* NaN from a NaN direction */
    if (!(y >= -1.0f && y <= (float)h)) y = 0.0f;
    float fx = floorf(x), fy = floorf(y);
    float ax = x - fx, ay = y - fy;
    int x0 = (int)fx, y0 = (int)fy;
    int x1 = x0 + 1, y1 = y0 + 1;
    x0 = (x0 % w + w) % w;
    x1 = (x1 % w + w) % w;
    if (pole && y < 0.0f) {
        vec3 row = mix3(texel(rgb, w, x0, 0), texel(rgb, w, x1, 0), ax);
        return mix3(pole[0], row, 2.0f * (y + 0.5f));
    }
    if (pole && y > (float)(h - 1)) {
        vec3 row = mix3(texel(rgb, w, x0, h - 1), texel(rgb, w, x1, h - 1), ax);
        return mix3(pole[1], row, 2.0f * ((float)h - 0.5f - y));
    }
    y0 = y0 < 0 ? 0 : (y0 >= h ? h - 1 : y0);
    y1 = y1 < 0 ? 0 : (y1 >= h ? h - 1 : y1);
    vec3 a = mix3(texel(rgb, w, x0, y0), texel(rgb, w, x1, y0), ax);
    vec3 b = mix3(texel(rgb, w, x0, y1), texel(rgb, w, x1, y1), ax);
    return mix3(a, b, ay);
}

static vec3 level_sample(const env_vmf_filter *f, int i, vec2 uv) {
    if (i == f->num_levels) {
        const image_rgb *img = &f->env->image;
        return bilinear(img->rgb, img->width, img->height, NULL, uv);
    }
    const filter_level *l = &f->levels[i];
    return bilinear(l->rgb, l->w, l->h, l->pole, uv);
}

vec3 env_vmf_filter_lookup(const env_vmf_filter *f, vmf lobe) {
    double kappa = (double)lobe.kappa;
    if (!(kappa > 0.0)) return f->mean;
    vec2 uv = env_uv(f->env, lobe.mu);
    if (kappa <= f->levels[0].kappa) return mix3(f->mean, level_sample(f, 0, uv), (float)(kappa / f->levels[0].kappa));
    if (kappa >= f->kappa_source) return level_sample(f, f->num_levels, uv);
    /* the bracketing pair: log_kappa[lo] <= log kappa < log_kappa[hi], hi = num_levels the map */
    double lk = log(kappa);
    int lo = 0, hi = f->num_levels;
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (f->log_kappa[mid] <= lk)
            lo = mid;
        else
            hi = mid;
    }
    float t = (float)((lk - f->log_kappa[lo]) / (f->log_kappa[hi] - f->log_kappa[lo]));
    return mix3(level_sample(f, lo, uv), level_sample(f, hi, uv), t);
}

size_t env_vmf_filter_bytes(const env_vmf_filter *f) {
    if (!f) return 0;
    size_t bytes = sizeof *f;
    for (int i = 0; i < f->num_levels; i++)
        bytes += sizeof(float) * 3 * (size_t)f->levels[i].w * (size_t)f->levels[i].h;
    return bytes;
}

void env_vmf_filter_destroy(env_vmf_filter *f) {
    if (!f) return;
    for (int i = 0; i < f->num_levels; i++) free(f->levels[i].rgb);
    free(f);
}

/* ---- the level ladder ----------------------------------------------------------------------- */

/* lo first: a map smaller than the minimum grid caps it */
static int clampi(int v, int lo, int hi) { return (v < lo ? lo : v) > hi ? hi : (v < lo ? lo : v); }
static double sqr_d(double x) { return x * x; }

/* Levels from FIRST_KAPPA up to the first whose lobe (1/sqrt(kappa)) is no wider than a source
 * texel. Past it the blend goes on, in log kappa, to the map's own bilinear lookup at four times
 * that kappa, about where a lobe sees a single bright texel as it is (kappa dOmega / 2pi ~ 1),
 * and the map alone beyond: no jump in kappa. Steps of sqrt 2 while levels are small (cheap, and
 * the blend in log kappa is then within about 1.5% even for a point light), octaves once they
 * near the map's size (each of those costs memory and time like the map itself). */
static void plan_levels(env_vmf_filter *f, int W, int H) {
    double texel_side = fmax(PI_D / H, 2.0 * PI_D / W);
    double kappa = FIRST_KAPPA;
    int n = 0;
    for (;;) {
        double s = TEXELS_PER_SIGMA * PI_D * sqrt(kappa); /* texels over pi radians */
        int h = clampi((int)ceil(s), MIN_HEIGHT, H), w = clampi((int)ceil(2.0 * s), MIN_WIDTH, W);
        f->levels[n] = (filter_level){.kappa = kappa, .w = w, .h = h};
        f->log_kappa[n] = log(kappa);
        n++;
        if (kappa * texel_side * texel_side >= 1.0 || kappa >= VMF_MAX_KAPPA || n == MAX_LEVELS) break;
        kappa *= (size_t)w * (size_t)h * 16 <= (size_t)W * (size_t)H ? sqrt(2.0) : 2.0;
    }
    f->num_levels = n;
    f->kappa_source = 4.0 * kappa;
    f->log_kappa[n] = log(f->kappa_source);
}

/* Each level is summed over a sharper one, box-resampled to its grid, rather than over the map
 * box-downsampled: the sharper level is already smooth on the coarser grid, so nothing is lost of
 * where in a coarse texel a small bright source lay (on a grid of a third of the lobe width the
 * downsampled map moves a point light by up to a sixth of a lobe, 15% on the lobe's flank), and
 * the extra kernel is narrower than the level's own lobe, so the sums are shorter. Convolving
 * vMFs multiplies their mean resultant lengths A exactly for the first harmonic and, for the
 * rest, within about 0.25 / kappa per octave: so a level above CHAIN_KAPPA uses the next sharper
 * level, and one below the sharpest level that is still a texel wide on its grid (composition
 * error about 1 / kappa of that level: 0.5% for the smallest grids). The sharpest level is summed
 * over the map's own texels. Returns the input level (num_levels: the map) and sets the kernel
 * concentration: A(kernel) = A(kappa) / (A(input kappa) A_box), the box resampling being a blur
 * of variance (cell^2 + input cell^2) / 12 per axis, A_box ~ 1 - variance / 2. */
static int plan_input(const env_vmf_filter *f, int l, double *kernel) {
    const filter_level *c = &f->levels[l];
    int n = f->num_levels;
    if (l == n - 1) {
        *kernel = c->kappa;
        return n;
    }
    int in = l + 1;
    if (c->kappa < CHAIN_KAPPA) {
        double texel = fmax(PI_D / c->h, 2.0 * PI_D / c->w);
        for (int j = n - 1; j > l; j--)
            if (f->levels[j].kappa * texel * texel <= 1.0) {
                in = j;
                break;
            }
    }
    const filter_level *src = &f->levels[in];
    double var = 0.0;
    if (c->h != src->h) var += (sqr_d(PI_D / c->h) + sqr_d(PI_D / src->h)) / 12.0;
    if (c->w != src->w) var += (sqr_d(2.0 * PI_D / c->w) + sqr_d(2.0 * PI_D / src->w)) / 12.0;
    double ratio = vmf_rbar_from_kappa(c->kappa) / (vmf_rbar_from_kappa(src->kappa) * (1.0 - 0.5 * var));
    *kernel = vmf_kappa_from_rbar(ratio);
    return in;
}

/* kappa 0: sum of L dOmega / 4 pi with the texel solid angle (2pi/W)(pi/H) sin(theta). */
static vec3 map_mean(const image_rgb *img) {
    double sum[3] = {0.0, 0.0, 0.0}, weight = 0.0;
    for (int y = 0; y < img->height; y++) {
        double row[3] = {0.0, 0.0, 0.0}, st = sin(PI_D * (y + 0.5) / img->height);
        const float *p = img->rgb + 3 * (size_t)y * (size_t)img->width;
        for (int x = 0; x < img->width; x++)
            for (int c = 0; c < 3; c++) row[c] += (double)p[3 * x + c];
        for (int c = 0; c < 3; c++) sum[c] += row[c] * st;
        weight += st * img->width;
    }
    return v3((float)(sum[0] / weight), (float)(sum[1] / weight), (float)(sum[2] / weight));
}

/* ---- box downsampling ----------------------------------------------------------------------- */

typedef struct {
    int first, count; /* source cells, weights at the same offset in the weight array */
    int offset;
} span;

/* Area weights of the n_src source cells under each of n_dst equal cells of the same interval,
 * normalised to sum 1 (so a huge texel cannot overflow a sum). For rows (theta in [0, pi]) a
 * cell's share is its solid angle, cos(a) - cos(b), so the map's integral is kept. Writes at most
 * n_src + n_dst weights. */
static void make_spans(int n_src, int n_dst, int rows, span *spans, float *weights) {
    int offset = 0;
    for (int i = 0; i < n_dst; i++) {
        double a = (double)i * n_src / n_dst, b = (double)(i + 1) * n_src / n_dst;
        int first = clampi((int)floor(a), 0, n_src - 1), last = clampi((int)ceil(b) - 1, first, n_src - 1);
        double sum = 0.0;
        for (int s = first; s <= last; s++) {
            double lo = fmax(a, s), hi = fmin(b, s + 1.0), wgt = fmax(hi - lo, 0.0);
            if (rows) wgt = 2.0 * sin(0.5 * PI_D * (lo + hi) / n_src) * sin(0.5 * PI_D * wgt / n_src);
            weights[offset + s - first] = (float)wgt;
            sum += wgt;
        }
        for (int s = first; s <= last; s++) {
            float *wt = &weights[offset + s - first];
            *wt = sum > 0.0 ? (float)((double)*wt / sum) : 1.0f / (float)(last - first + 1);
        }
        spans[i] = (span){first, last - first + 1, offset};
        offset += last - first + 1;
    }
}

/* ---- the summation window ------------------------------------------------------------------- */

/* Rows of the window around theta0: |theta - theta0| <= theta_w, 1 - cos theta_w = CUTOFF / kappa
 * (the nearest texel centre may lie a little outside: one row of margin). */
static void window_rows(double kappa, int h, double theta0, int *first, int *last) {
    double q = CUTOFF / (2.0 * kappa), dth = PI_D / h;
    double thw = q >= 1.0 ? PI_D : 2.0 * asin(sqrt(q));
    *first = clampi((int)floor((theta0 - thw) / dth - 0.5), 0, h - 1);
    *last = clampi((int)ceil((theta0 + thw) / dth - 0.5), 0, h - 1);
}

/* Writing mu.s - 1 = (cos(theta0 - theta) - 1) + sin theta0 sin theta (cos dphi - 1) splits gamma
 * into a row factor e^b and one kernel e^{-a (1 - cos dphi)} per pair of rows, shared by every
 * column. Returns 0 when row y lies outside output row y0's window, else b, a and the column
 * offsets -nl..nr with a (1 - cos dphi) <= CUTOFF + b (the whole row when that reaches round). */
static int row_extent(double kappa, int w, int h, int y0, int y, double *b, double *a, int *nl, int *nr) {
    double dth = PI_D / h, th0 = (y0 + 0.5) * dth, th = (y + 0.5) * dth;
    double hd = sin(0.5 * (th0 - th)); /* 1 - cos x = 2 sin^2(x/2): no cancellation */
    *b = -2.0 * kappa * hd * hd;
    *a = kappa * sin(th0) * sin(th);
    double rem = CUTOFF + *b, z = rem / (2.0 * *a);
    if (rem < 0.0) return 0;
    *nl = (w - 1) / 2;
    *nr = w / 2;
    if (z < 1.0) {
        int n = (int)(2.0 * asin(sqrt(z)) / (2.0 * PI_D / w));
        if (2 * n + 1 < w) *nl = *nr = n;
    }
    return 1;
}

/* ---- the summation grid --------------------------------------------------------------------- */

/* The input of one level's summation, planar (3 planes of plane floats), each row padded on both
 * sides with copies wrapped across the seam, so that every kernel reads one contiguous run:
 * column x of row y at base[y] + x, for x in [-margin[y], w + margin[y] + BLOCK) (a block of
 * columns, or a kernel padded with zeros to a multiple of 8, may overrun the row's end). */
typedef struct {
    float *data;
    size_t plane;
    size_t *base;
    int *margin;
} padded_grid;

/* Margins for a level (kernel concentration kappa): the widest kernel each row takes part in. */
static size_t grid_layout(double kappa, int w, int h, size_t *base, int *margin) {
    for (int y = 0; y < h; y++) margin[y] = 0;
    for (int y0 = 0; y0 < h; y0++) {
        int ya, yb, nl, nr;
        double a, b;
        window_rows(kappa, h, PI_D * (y0 + 0.5) / h, &ya, &yb);
        for (int y = ya; y <= yb; y++)
            if (row_extent(kappa, w, h, y0, y, &b, &a, &nl, &nr) && nr > margin[y]) margin[y] = nr;
    }
    size_t at = 0;
    for (int y = 0; y < h; y++) {
        base[y] = at + (size_t)margin[y];
        at += (size_t)w + 2 * (size_t)margin[y] + BLOCK;
    }
    return at;
}

typedef struct {
    const float *src; /* interleaved input: the map or the next sharper level */
    int src_w, src_h;
    float *tmp; /* planar, 3 planes of src_h x w: columns resampled */
    int w, h;
    const span *xs, *ys;
    const float *xw, *yw;
    padded_grid grid;
} resample_job;

static void resample_columns(void *ctx, int y, int worker) {
    const resample_job *job = ctx;
    const float *row = job->src + 3 * (size_t)y * (size_t)job->src_w;
    size_t plane = (size_t)job->src_h * (size_t)job->w;
    float *out = job->tmp + (size_t)y * (size_t)job->w;
    for (int x = 0; x < job->w; x++) {
        span sp = job->xs[x];
        const float *wt = job->xw + sp.offset, *p = row + 3 * sp.first;
        float r = 0.0f, g = 0.0f, b = 0.0f;
        for (int i = 0; i < sp.count; i++) {
            r += wt[i] * p[3 * i];
            g += wt[i] * p[3 * i + 1];
            b += wt[i] * p[3 * i + 2];
        }
        out[x] = r;
        out[plane + x] = g;
        out[2 * plane + x] = b;
    }
}

static void resample_rows(void *ctx, int y, int worker) {
    const resample_job *job = ctx;
    int w = job->w, m = job->grid.margin[y];
    size_t tmp_plane = (size_t)job->src_h * (size_t)w;
    span sp = job->ys[y];
    for (int c = 0; c < 3; c++) {
        float *out = job->grid.data + c * job->grid.plane + job->grid.base[y];
        for (int x = 0; x < w; x++) out[x] = 0.0f;
        for (int i = 0; i < sp.count; i++) {
            const float *in = job->tmp + c * tmp_plane + (size_t)(sp.first + i) * (size_t)w;
            float wt = job->yw[sp.offset + i];
            for (int x = 0; x < w; x++) out[x] += wt * in[x];
        }
        for (int x = -m; x < 0; x++) out[x] = out[(x % w + w) % w];
        for (int x = w; x < w + m + BLOCK; x++) out[x] = out[x % w];
    }
}

/* ---- direct summation ----------------------------------------------------------------------- */

typedef struct {
    int row, nl, len, len8; /* source row, first column offset -nl, kernel length (padded to 8) */
    size_t offset;          /* into the worker's kernel buffer */
} kernel_row;

typedef struct {
    padded_grid grid;
    float *out; /* the level, interleaved */
    int w, h;
    double kappa;       /* of the kernel */
    double level_kappa; /* of the level: its output is smooth on the scale 1/sqrt(level_kappa) */
    const double *omc;  /* 1 - cos(j 2pi / w), j = 0..w/2 */
    float **kernels;    /* per worker */
    kernel_row **rows;  /* per worker */
} filter_job;

/* One output row: gamma summed over the window's texels with the texel solid angle (prop. to
 * sin theta), divided by the sum of those weights, so a constant input comes out exactly constant
 * even on coarse grids and at the poles. The normalisation c(kappa) cancels: no sinh, no overflow
 * at any kappa. Near the poles a row's texels are narrower than the lobe by 1/sin(theta): only
 * every few columns are summed and the rest interpolated, so every row costs about the same. */
static void filter_row(void *ctx, int y0, int worker) {
    const filter_job *job = ctx;
    int w = job->w, h = job->h;
    double kappa = job->kappa, s0 = sin((y0 + 0.5) * PI_D / h);
    float *kbuf = job->kernels[worker];
    kernel_row *rows = job->rows[worker];
    int ya, yb, nrows = 0;
    window_rows(kappa, h, (y0 + 0.5) * PI_D / h, &ya, &yb);
    size_t used = 0;
    double total = 0.0;
    for (int y = ya; y <= yb; y++) {
        double a, b;
        int nl, nr;
        if (!row_extent(kappa, w, h, y0, y, &b, &a, &nl, &nr)) continue;
        double s = sin((y + 0.5) * PI_D / h);
        int len = nl + nr + 1, len8 = (len + 7) & ~7;
        float *k = kbuf + used;
        for (int d = -nl; d <= nr; d++) {
            float v = (float)(exp(b - a * job->omc[d < 0 ? -d : d]) * s);
            k[d + nl] = v;
            total += (double)v;
        }
        for (int i = len; i < len8; i++) k[i] = 0.0f;
        rows[nrows++] = (kernel_row){y, nl, len, len8, used};
        used += (size_t)len8;
    }
    /* weights summing to 1: the sums below stay within the input's range (no overflow) */
    float inv = total > 0.0 ? (float)(1.0 / total) : 0.0f;
    for (size_t i = 0; i < used; i++) kbuf[i] *= inv;

    const float *R = job->grid.data, *G = R + job->grid.plane, *B = G + job->grid.plane;
    float *out = job->out + 3 * (size_t)y0 * (size_t)w;
    /* summed columns at most a fifth of the level's lobe apart along the row (linear
     * interpolation then within 0.5% at a peak), and no farther apart than at the equator */
    int most = w / MIN_COLUMNS > 1 ? w / MIN_COLUMNS : 1;
    double spacing = fmin(1.0, 0.2 / (sqrt(job->level_kappa) * 2.0 * PI_D / w)) / s0;
    int step = spacing < (double)most ? (spacing > 1.0 ? (int)spacing : 1) : most;
    if (step == 1) {
        /* every column: each tap scaled onto a block of neighbouring columns */
        for (int j0 = 0; j0 < w; j0 += BLOCK) {
            float ar[BLOCK] = {0}, ag[BLOCK] = {0}, ab[BLOCK] = {0};
            for (int i = 0; i < nrows; i++) {
                const float *k = kbuf + rows[i].offset;
                size_t o = job->grid.base[rows[i].row] + (size_t)j0 - (size_t)rows[i].nl;
                const float *r = R + o, *g = G + o, *b = B + o;
                for (int n = 0; n < rows[i].len; n++) {
                    float kv = k[n];
                    for (int l = 0; l < BLOCK; l++) {
                        ar[l] += kv * r[n + l];
                        ag[l] += kv * g[n + l];
                        ab[l] += kv * b[n + l];
                    }
                }
            }
            for (int l = 0; l < BLOCK && j0 + l < w; l++) {
                out[3 * (j0 + l)] = finite_clamp(ar[l]);
                out[3 * (j0 + l) + 1] = finite_clamp(ag[l]);
                out[3 * (j0 + l) + 2] = finite_clamp(ab[l]);
            }
        }
        return;
    }
    for (int j = 0; j < w; j += step) {
        /* a few columns of a wide row: one dot product per kernel row, in eight lanes */
        float ar[8] = {0}, ag[8] = {0}, ab[8] = {0};
        for (int i = 0; i < nrows; i++) {
            const float *k = kbuf + rows[i].offset;
            size_t o = job->grid.base[rows[i].row] + (size_t)j - (size_t)rows[i].nl;
            const float *r = R + o, *g = G + o, *b = B + o;
            for (int n = 0; n < rows[i].len8; n += 8)
                for (int l = 0; l < 8; l++) {
                    ar[l] += k[n + l] * r[n + l];
                    ag[l] += k[n + l] * g[n + l];
                    ab[l] += k[n + l] * b[n + l];
                }
        }
        float sr = 0.0f, sg = 0.0f, sb = 0.0f;
        for (int l = 0; l < 8; l++) {
            sr += ar[l];
            sg += ag[l];
            sb += ab[l];
        }
        out[3 * j] = finite_clamp(sr);
        out[3 * j + 1] = finite_clamp(sg);
        out[3 * j + 2] = finite_clamp(sb);
    }
    /* columns between the summed ones, linear in phi (wrapping to column 0) */
    for (int j = 0; j < w; j += step) {
        int next = j + step < w ? j + step : w;
        const float *a = out + 3 * j, *b = out + 3 * (next % w);
        for (int m = j + 1; m < next; m++) {
            float t = (float)(m - j) / (float)(next - j);
            for (int c = 0; c < 3; c++) out[3 * m + c] = mixf(a[c], b[c], t);
        }
    }
}

/* E at a pole: there the lobe is constant along each row, so each row enters with its mean. */
static vec3 pole_value(const padded_grid *g, int w, int h, double kappa, int south) {
    double q = CUTOFF / (2.0 * kappa), thw = q >= 1.0 ? PI_D : 2.0 * asin(sqrt(q));
    double sum[3] = {0.0, 0.0, 0.0}, total = 0.0;
    for (int i = 0; i < h; i++) {
        double th = PI_D * (i + 0.5) / h; /* from this pole */
        if (th > thw + PI_D / h) break;
        double hs = sin(0.5 * th), wgt = exp(-2.0 * kappa * hs * hs) * sin(th);
        for (int c = 0; c < 3; c++) {
            const float *row = g->data + c * g->plane + g->base[south ? h - 1 - i : i];
            double rs = 0.0;
            for (int x = 0; x < w; x++) rs += (double)row[x];
            sum[c] += wgt * rs / w;
        }
        total += wgt;
    }
    return v3((float)(sum[0] / total), (float)(sum[1] / total), (float)(sum[2] / total));
}

/* ---- create --------------------------------------------------------------------------------- */

static void run(threadpool *pool, task_fn fn, void *ctx, int n) {
    if (pool)
        threadpool_run(pool, fn, ctx, n);
    else
        for (int i = 0; i < n; i++) fn(ctx, i, 0);
}

/* The most window rows any output row of a level can have. */
static int max_window_rows(double kappa, int h) {
    int most = 0;
    for (int y = 0; y < h; y++) {
        int a, b;
        window_rows(kappa, h, PI_D * (y + 0.5) / h, &a, &b);
        if (b - a + 1 > most) most = b - a + 1;
    }
    return most;
}

env_vmf_filter *env_vmf_filter_create(const env_map *env, char *err, size_t errlen) {
    if (!env || env->image.width <= 0 || env->image.height <= 0 || !env->image.rgb) {
        snprintf(err, errlen, "vMF environment filter: no environment image");
        return NULL;
    }
    int W = env->image.width, H = env->image.height;
    env_vmf_filter *f = calloc(1, sizeof *f);
    if (!f) {
        snprintf(err, errlen, "vMF environment filter: out of memory");
        return NULL;
    }
    f->env = env;
    f->mean = map_mean(&env->image);
    plan_levels(f, W, H);

    /* sizes: every level's image, the largest column pass, kernel buffer and padded grid */
    threadpool *pool = threadpool_create(0);
    int workers = pool ? threadpool_size(pool) : 1;
    double kernel_kappa[MAX_LEVELS];
    int input[MAX_LEVELS];
    size_t max_kernel = 0, max_rows = 0, max_tmp = 0;
    int ok = 1;
    for (int l = 0; l < f->num_levels; l++) {
        filter_level *lv = &f->levels[l];
        input[l] = plan_input(f, l, &kernel_kappa[l]);
        size_t rows = (size_t)max_window_rows(kernel_kappa[l], lv->h);
        size_t src_h = input[l] < f->num_levels ? (size_t)f->levels[input[l]].h : (size_t)H;
        lv->rgb = malloc(sizeof(float) * 3 * (size_t)lv->w * (size_t)lv->h);
        ok = ok && lv->rgb;
        if (rows > max_rows) max_rows = rows;
        if (rows * ((size_t)lv->w + 8) > max_kernel) max_kernel = rows * ((size_t)lv->w + 8);
        if (src_h * (size_t)lv->w > max_tmp) max_tmp = src_h * (size_t)lv->w;
    }
    padded_grid grid = {NULL, 0, malloc(sizeof(size_t) * (size_t)H), malloc(sizeof(int) * (size_t)H)};
    size_t grid_cap = 0;
    float *tmp = malloc(sizeof(float) * 3 * max_tmp);
    span *spans = malloc(sizeof(span) * (size_t)(W + H));
    float *weights = malloc(sizeof(float) * 2 * (size_t)(W + H));
    double *omc = malloc(sizeof(double) * (size_t)(W / 2 + 1));
    float **kernels = calloc((size_t)workers, sizeof(float *));
    kernel_row **krows = calloc((size_t)workers, sizeof(kernel_row *));
    ok = ok && grid.base && grid.margin && tmp && spans && weights && omc && kernels && krows;
    for (int i = 0; ok && i < workers; i++) {
        kernels[i] = malloc(sizeof(float) * max_kernel);
        krows[i] = malloc(sizeof(kernel_row) * max_rows);
        ok = kernels[i] && krows[i];
    }

    /* sharpest first: each level is the next sharper one blurred a little more */
    for (int l = f->num_levels - 1; ok && l >= 0; l--) {
        filter_level *lv = &f->levels[l];
        int in = input[l];
        const float *src = in < f->num_levels ? f->levels[in].rgb : env->image.rgb;
        int src_w = in < f->num_levels ? f->levels[in].w : W, src_h = in < f->num_levels ? f->levels[in].h : H;
        grid.plane = grid_layout(kernel_kappa[l], lv->w, lv->h, grid.base, grid.margin);
        if (grid.plane > grid_cap) {
            free(grid.data);
            grid.data = malloc(sizeof(float) * 3 * grid.plane);
            grid_cap = grid.plane;
            if (!grid.data) {
                ok = 0;
                break;
            }
        }
        span *xs = spans, *ys = spans + lv->w;
        float *xw = weights, *yw = weights + src_w + lv->w;
        make_spans(src_w, lv->w, 0, xs, xw);
        make_spans(src_h, lv->h, 1, ys, yw);
        resample_job rj = {src, src_w, src_h, tmp, lv->w, lv->h, xs, ys, xw, yw, grid};
        run(pool, resample_columns, &rj, src_h);
        run(pool, resample_rows, &rj, lv->h);
        for (int j = 0; j <= lv->w / 2; j++) {
            double sh = sin(PI_D * j / lv->w);
            omc[j] = 2.0 * sh * sh;
        }
        filter_job fj = {grid, lv->rgb, lv->w, lv->h, kernel_kappa[l], lv->kappa, omc, kernels, krows};
        run(pool, filter_row, &fj, lv->h);
        lv->pole[0] = pole_value(&grid, lv->w, lv->h, kernel_kappa[l], 0);
        lv->pole[1] = pole_value(&grid, lv->w, lv->h, kernel_kappa[l], 1);
    }

    for (int i = 0; kernels && krows && i < workers; i++) {
        free(kernels[i]);
        free(krows[i]);
    }
    free(kernels);
    free(krows);
    free(omc);
    free(weights);
    free(spans);
    free(tmp);
    free(grid.data);
    free(grid.base);
    free(grid.margin);
    threadpool_destroy(pool);
    if (!ok) {
        env_vmf_filter_destroy(f);
        snprintf(err, errlen, "vMF environment filter: out of memory");
        return NULL;
    }
    return f;
}
