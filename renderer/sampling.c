#include "sampling.h"

#include <stdlib.h>

vec3 sample_cosine_hemisphere(vec2 u) {
    vec2 d = sample_concentric_disk(u);
    float z = safe_sqrtf(1.0f - d.x * d.x - d.y * d.y);
    return v3(d.x, d.y, z);
}

vec3 sample_uniform_sphere(vec2 u) {
    float z = 1.0f - 2.0f * u.x;
    float r = safe_sqrtf(1.0f - z * z);
    float phi = 2.0f * PI_F * u.y;
    return v3(r * cosf(phi), r * sinf(phi), z);
}

vec3 sample_uniform_cone(vec2 u, float one_minus_cos_max) {
    /* 1 - cos(theta) uniform in [0, 1 - cos_max]; sin from (1-cos)(1+cos) keeps tiny cones exact. */
    float omc = u.x * one_minus_cos_max;
    float cos_t = 1.0f - omc;
    float sin_t = safe_sqrtf(omc * (2.0f - omc));
    float phi = 2.0f * PI_F * u.y;
    return v3(sin_t * cosf(phi), sin_t * sinf(phi), cos_t);
}

float cone_one_minus_cos(float s) {
    if (!(s < 1.0f)) return 1.0f;
    float s2 = s * s;
    return s2 / (1.0f + sqrtf(1.0f - s2));
}

vec3 sample_power_cosine(vec2 u, float exponent) {
    /* cos(theta) = (1 - u)^(1/(n+1)). Sharp lobes live where cos is within float epsilon of 1, so
     * 1 - cos comes from expm1 and sin from (1 - cos)(1 + cos), as for tiny cones. */
    float omc = -expm1f(logf(fmaxf(1.0f - u.x, 1e-30f)) / (exponent + 1.0f));
    float cos_t = 1.0f - omc;
    float sin_t = safe_sqrtf(omc * (2.0f - omc));
    float phi = 2.0f * PI_F * u.y;
    return v3(sin_t * cosf(phi), sin_t * sinf(phi), cos_t);
}

float power_cosine(float one_minus_cos, float exponent) {
    if (!(one_minus_cos < 1.0f)) return 0.0f;
    if (one_minus_cos <= 0.0f) return 1.0f;
    return expf(exponent * log1pf(-one_minus_cos));
}

float pdf_power_cosine(float one_minus_cos, float exponent) {
    return (exponent + 1.0f) * INV_2PI_F * power_cosine(one_minus_cos, exponent);
}

vec2 sample_uniform_triangle(vec2 u) {
    /* Heitz's low-distortion square-to-triangle map (2019). */
    float b0, b1;
    if (u.x < u.y) {
        b0 = u.x * 0.5f;
        b1 = u.y - b0;
    } else {
        b1 = u.y * 0.5f;
        b0 = u.x - b1;
    }
    return v2(b0, b1);
}

vec2 sample_concentric_disk(vec2 u) {
    float ox = 2.0f * u.x - 1.0f, oy = 2.0f * u.y - 1.0f;
    if (ox == 0.0f && oy == 0.0f) return v2(0.0f, 0.0f);
    float r, theta;
    if (fabsf(ox) > fabsf(oy)) {
        r = ox;
        theta = (PI_F / 4.0f) * (oy / ox);
    } else {
        r = oy;
        theta = (PI_F / 2.0f) - (PI_F / 4.0f) * (ox / oy);
    }
    return v2(r * cosf(theta), r * sinf(theta));
}

/* ---- piecewise-constant distributions ---------------------------------------------------- */

int dist1d_init(dist1d *d, const float *func, int n) {
    *d = (dist1d){0};
    if (n < 1) return -1;
    d->func = malloc(sizeof(float) * (size_t)n);
    d->cdf = malloc(sizeof(double) * ((size_t)n + 1));
    if (!d->func || !d->cdf) {
        dist1d_deinit(d);
        return -1;
    }
    d->n = n;
    d->cdf[0] = 0.0;
    for (int i = 0; i < n; i++) {
        float f = func[i];
        d->func[i] = (isfinite(f) && f > 0.0f) ? f : 0.0f;
        d->cdf[i + 1] = d->cdf[i] + (double)d->func[i] / n;
    }
    d->integral = d->cdf[n];
    if (d->integral > 0.0) {
        for (int i = 1; i <= n; i++) d->cdf[i] /= d->integral;
    } else {
        for (int i = 1; i <= n; i++) d->cdf[i] = (double)i / n;
    }
    d->cdf[n] = 1.0;
    return 0;
}

int alias_init(alias_table *a, const float *weights, int n) {
    *a = (alias_table){0};
    if (n < 1) return -1;
    a->pmf = malloc(sizeof(float) * (size_t)n);
    a->keep = malloc(sizeof(float) * (size_t)n);
    a->alias = malloc(sizeof(int) * (size_t)n);
    int *work = malloc(sizeof(int) * (size_t)n);
    double *scaled = malloc(sizeof(double) * (size_t)n);
    if (!a->pmf || !a->keep || !a->alias || !work || !scaled) {
        free(work);
        free(scaled);
        alias_deinit(a);
        return -1;
    }
    a->n = n;
    double total = 0.0;
    for (int i = 0; i < n; i++) total += isfinite(weights[i]) && weights[i] > 0.0f ? (double)weights[i] : 0.0;
    for (int i = 0; i < n; i++) {
        double w = isfinite(weights[i]) && weights[i] > 0.0f ? (double)weights[i] : 0.0;
        double p = total > 0.0 ? w / total : 1.0 / n;
        a->pmf[i] = (float)p;
        scaled[i] = p * n;
    }
    /* Small bins (scaled below 1) from the front of work, large ones from the back: each small
     * bin takes its alias from a large one, which gives up what the small one lacks. */
    int small = 0, large = n;
    for (int i = 0; i < n; i++) {
        if (scaled[i] < 1.0)
            work[small++] = i;
        else
            work[--large] = i;
    }
    int s = 0;
    while (s < small && large < n) {
        int lo = work[s++], hi = work[large];
        a->keep[lo] = (float)scaled[lo];
        a->alias[lo] = hi;
        scaled[hi] -= 1.0 - scaled[lo];
        if (scaled[hi] < 1.0) { /* it became small: it moves to the small end */
            large++;
            work[small++] = hi;
        }
    }
    /* What remains is 1 up to rounding. */
    for (; s < small; s++) a->keep[work[s]] = 1.0f, a->alias[work[s]] = work[s];
    for (; large < n; large++) a->keep[work[large]] = 1.0f, a->alias[work[large]] = work[large];
    free(work);
    free(scaled);
    return 0;
}

void alias_deinit(alias_table *a) {
    free(a->pmf);
    free(a->keep);
    free(a->alias);
    *a = (alias_table){0};
}

void dist1d_deinit(dist1d *d) {
    free(d->func);
    free(d->cdf);
    *d = (dist1d){0};
}

/* Largest i with cdf[i] <= u, restricted to bins of non-zero width when possible. */
static int find_bin(const dist1d *d, double u) {
    int lo = 0, hi = d->n; /* invariant: cdf[lo] <= u < cdf[hi] (cdf[n] = 1 > u) */
    while (hi - lo > 1) {
        int mid = (lo + hi) >> 1;
        if (d->cdf[mid] <= u)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

float dist1d_pmf(const dist1d *d, int i) {
    if (i < 0 || i >= d->n) return 0.0f;
    return (float)(d->cdf[i + 1] - d->cdf[i]);
}

int dist1d_sample_discrete(const dist1d *d, float u, float *pmf, float *u_remapped) {
    int i = find_bin(d, (double)u);
    double w = d->cdf[i + 1] - d->cdf[i];
    if (pmf) *pmf = (float)w;
    if (u_remapped) {
        float r = w > 0.0 ? (float)(((double)u - d->cdf[i]) / w) : 0.0f;
        *u_remapped = fminf(fmaxf(r, 0.0f), 0x1.fffffep-1f);
    }
    return i;
}

float dist1d_sample_continuous(const dist1d *d, float u, float *pdf, int *bin) {
    int i = find_bin(d, (double)u);
    double w = d->cdf[i + 1] - d->cdf[i];
    double du = w > 0.0 ? ((double)u - d->cdf[i]) / w : 0.0;
    if (pdf) *pdf = (float)(w * d->n);
    if (bin) *bin = i;
    float x = (float)((i + du) / d->n);
    return fminf(x, 0x1.fffffep-1f);
}

float dist1d_pdf(const dist1d *d, float x) {
    int i = (int)(x * (float)d->n);
    if (i < 0 || i >= d->n) return 0.0f;
    return (float)((d->cdf[i + 1] - d->cdf[i]) * d->n);
}

int dist2d_init(dist2d *d, const float *func, int nu, int nv) {
    *d = (dist2d){0};
    if (nu < 1 || nv < 1) return -1;
    d->rows = calloc((size_t)nv, sizeof(dist1d));
    float *marg = malloc(sizeof(float) * (size_t)nv);
    if (!d->rows || !marg) {
        free(marg);
        free(d->rows);
        d->rows = NULL;
        return -1;
    }
    d->nu = nu;
    d->nv = nv;
    int status = 0;
    for (int v = 0; v < nv && status == 0; v++) {
        status = dist1d_init(&d->rows[v], func + (size_t)v * nu, nu);
        marg[v] = (float)d->rows[v].integral;
    }
    if (status == 0) status = dist1d_init(&d->marginal, marg, nv);
    free(marg);
    if (status != 0) dist2d_deinit(d);
    return status;
}

void dist2d_deinit(dist2d *d) {
    if (d->rows)
        for (int v = 0; v < d->nv; v++) dist1d_deinit(&d->rows[v]);
    free(d->rows);
    dist1d_deinit(&d->marginal);
    *d = (dist2d){0};
}

vec2 dist2d_sample(const dist2d *d, vec2 u, float *pdf) {
    float pv, pu;
    int row;
    float y = dist1d_sample_continuous(&d->marginal, u.y, &pv, &row);
    float x = dist1d_sample_continuous(&d->rows[row], u.x, &pu, NULL);
    if (pdf) *pdf = pv * pu;
    return v2(x, y);
}

float dist2d_pdf(const dist2d *d, vec2 uv) {
    int row = (int)(uv.y * (float)d->nv);
    if (row < 0 || row >= d->nv) return 0.0f;
    return dist1d_pdf(&d->marginal, uv.y) * dist1d_pdf(&d->rows[row], uv.x);
}
