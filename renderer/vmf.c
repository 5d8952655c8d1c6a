#include "vmf.h"

#include <math.h>
#include <stdlib.h>

#define PI_D 3.14159265358979323846

/* log(c(kappa) e^kappa) = log(kappa / (2 pi (1 - e^{-2 kappa}))), without sinh. */
static double log_norm_plus_kappa(double kappa) {
    if (kappa < 1e-4) return log(0.25 / PI_D) + kappa - kappa * kappa / 6.0; /* c ~ (1 - k^2/6) / 4pi */
    return log(kappa) - log(2.0 * PI_D) - log(-expm1(-2.0 * kappa));
}

double vmf_log_norm(double kappa) { return log_norm_plus_kappa(kappa) - kappa; }

/* kappa (mu.s - 1) written with 1 - mu.s given, so sharp lobes keep their precision. */
static double eval_one_minus_cos(double kappa, double one_minus_cos) {
    return exp(log_norm_plus_kappa(kappa) - kappa * one_minus_cos);
}

double vmf_eval_cos(double kappa, double cos_theta) { return eval_one_minus_cos(kappa, 1.0 - cos_theta); }

double vmf_eval(vmf v, vec3 s) {
    /* 1 - mu.s = |mu - s|^2 / 2 for unit vectors: no cancellation near the peak. */
    double dx = (double)v.mu.x - (double)s.x, dy = (double)v.mu.y - (double)s.y, dz = (double)v.mu.z - (double)s.z;
    return eval_one_minus_cos(v.kappa, 0.5 * (dx * dx + dy * dy + dz * dz));
}

/* 1 - cos theta below which a fraction u of a vMF's mass lies: its inverse cdf. */
static double quantile_one_minus_cos(double kappa, double u) {
    return kappa < 1e-8 ? 2.0 * u : -log1p(u * expm1(-2.0 * kappa)) / kappa;
}

vec3 vmf_sample(vmf v, vec2 u) {
    double omw = quantile_one_minus_cos(v.kappa, (double)u.x); /* 1 - cos theta */
    if (!(omw >= 0.0)) omw = 0.0;
    if (omw > 2.0) omw = 2.0;
    double sin_t = sqrt(omw * (2.0 - omw)), phi = 2.0 * PI_D * (double)u.y;
    vec3 local = v3((float)(sin_t * cos(phi)), (float)(sin_t * sin(phi)), (float)(1.0 - omw));
    return to_world(frame_from_normal(v.mu), local);
}

double vmf_rbar_from_kappa(double kappa) {
    if (!(kappa > 0.0)) return 0.0;
    if (kappa < 0.05) { /* the series of coth - 1/kappa, which cancels at small kappa */
        double k2 = kappa * kappa;
        return kappa * (1.0 / 3.0 - k2 * (1.0 / 45.0 - k2 * (2.0 / 945.0 - k2 / 4725.0)));
    }
    if (kappa > 20.0) return 1.0 - 1.0 / kappa; /* coth kappa = 1 within 1e-17 */
    return 1.0 / tanh(kappa) - 1.0 / kappa;
}

double vmf_kappa_estimate(double rbar) {
    if (!(rbar > 0.0)) return 0.0;
    if (rbar >= 1.0) return VMF_MAX_KAPPA;
    double k = rbar * (3.0 - rbar * rbar) / ((1.0 - rbar) * (1.0 + rbar));
    return k < VMF_MAX_KAPPA ? k : VMF_MAX_KAPPA;
}

double vmf_kappa_from_rbar(double rbar) {
    if (!(rbar > 0.0)) return 0.0;
    if (rbar >= 1.0) return VMF_MAX_KAPPA;
    if (rbar >= vmf_rbar_from_kappa(20.0)) { /* A = 1 - 1/kappa exactly here */
        double k = 1.0 / (1.0 - rbar);
        return k < VMF_MAX_KAPPA ? k : VMF_MAX_KAPPA;
    }
    if (rbar < 1e-3 / 3.0) return 3.0 * rbar; /* A = kappa/3 to 1e-7 */
    double k = vmf_kappa_estimate(rbar);
    for (int i = 0; i < 20; i++) {
        double a = vmf_rbar_from_kappa(k), da = 1.0 - a * a - 2.0 * a / k; /* A'(kappa) */
        double next = k - (a - rbar) / da;
        if (!(next > 0.0)) next = 0.5 * k;
        if (fabs(next - k) <= 1e-14 * k) return next;
        k = next;
    }
    return k;
}

vmf vmf_product(vmf a, vmf b, double *scale) {
    double px = (double)a.kappa * (double)a.mu.x + (double)b.kappa * (double)b.mu.x;
    double py = (double)a.kappa * (double)a.mu.y + (double)b.kappa * (double)b.mu.y;
    double pz = (double)a.kappa * (double)a.mu.z + (double)b.kappa * (double)b.mu.z;
    double k = sqrt(px * px + py * py + pz * pz);
    vmf r = {a.mu, 0.0f};
    if (k > 1e-12 * ((double)a.kappa + (double)b.kappa)) {
        r.mu = v3((float)(px / k), (float)(py / k), (float)(pz / k));
        r.kappa = (float)k;
    }
    /* The scale from a(mu) b(mu) / r(mu) at the stored (float) mean: products of absolute dot
     * products would lose kappa x float epsilon, several percent at kappa 1e6. */
    if (scale) *scale = exp(log(vmf_eval(a, r.mu)) + log(vmf_eval(b, r.mu)) - log_norm_plus_kappa(r.kappa));
    return r;
}

double vmf_convolve_kappa(double ka, double kb) {
    return vmf_kappa_from_rbar(vmf_rbar_from_kappa(ka) * vmf_rbar_from_kappa(kb));
}

/* The kappa whose median 1 - cos theta is t: m(kappa) = -log1p(expm1(-2 kappa) / 2) / kappa = t,
 * by Newton's method kept inside a bracket. m falls from 1 (kappa = 0) and m(kappa) <= ln 2 / kappa,
 * so the root lies in [0, ln 2 / t]. This runs for every secondary hit of the highlight estimator:
 * a handful of iterations, not a bisection's fifty. */
static double kappa_of_median(double t) {
    if (t >= 1.0) return 0.0;
    double lo = 0.0, hi = log(2.0) / t, k = hi;
    for (int i = 0; i < 30; i++) {
        double e = exp(-2.0 * k), m = -log1p(0.5 * (e - 1.0)) / k;
        double dm = (2.0 / (1.0 / e + 1.0) - m) / k; /* (L' k - L) / k^2 with L = m k, L' = 2 / (e^{2k} + 1) */
        if (m > t)
            lo = k; /* m decreases: the root is above k */
        else
            hi = k;
        double next = dm < 0.0 ? k - (m - t) / dm : 0.5 * (lo + hi);
        if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
        if (fabs(next - k) <= 1e-10 * k) return next;
        k = next;
    }
    return k;
}

/* The vMF whose median 1 - cos theta is t: ln 2 / t once e^{-2 kappa} is negligible, broader lobes
 * by Newton's method (kappa_of_median). */
static double kappa_with_median(double t) {
    if (t <= 0.0) return VMF_MAX_KAPPA;
    if (t < 0.25) return fmin(log(2.0) / t, VMF_MAX_KAPPA);
    return kappa_of_median(t);
}

/* 1 - cos of the median reflected angle of a microfacet lobe whose median half angle has tan^2 =
 * tan2: 1 - cos(2 atan(tan)); off normal incidence the reflected lobe is squeezed across by
 * cos theta_o (the Jacobian 4 wo.h of the half-vector map), its solid angle with it. */
static double microfacet_median(double tan2, double cos_o) { return 2.0 * tan2 / (1.0 + tan2) * cos_o; }

int vmf_fit_glossy(const bsdf *b, vec3 wo, vmf *lobe, vec3 *albedo) {
    if (!(bsdf_lobes(b) & BSDF_GLOSSY) || !(wo.z > 0.0f)) return 0;
    /* Width matched by the median angle to the mirror direction, not the mean cosine: GGX's long
     * tails would dominate the mean and give a lobe far wider than the highlight it makes. At the
     * median half angle tan(theta_h) is alpha for GGX and alpha sqrt(ln 2) for Ward; Phong's
     * cos^n has cos^{n+1} = 1/2 there; the reflected angle is twice the half angle. */
    double t; /* 1 - cos of the median reflected angle */
    if (b->model == GLOSSY_PHONG) {
        t = -expm1(-log(2.0) / ((double)b->exponent + 1.0));
    } else {
        double a2 = (double)bsdf_glossy_alpha(b) * (double)bsdf_glossy_alpha(b);
        if (b->model == GLOSSY_WARD) a2 *= log(2.0);
        t = microfacet_median(a2, (double)wo.z);
    }
    lobe->mu = v3(-wo.x, -wo.y, wo.z);
    lobe->kappa = (float)kappa_with_median(t);
    *albedo = bsdf_glossy_albedo(b, wo);
    return 1;
}

/* GGX as Beckmann bands: nodes t and weights w minimising the squared difference, integrated over
 * u = tan^2(theta_h) / alpha^2, between GGX's (1 + u)^-2 and sum w t e^{-t u} (relative L2 0.045;
 * one band of GGX's median width: 0.25). Band t is Beckmann of alpha^2 / t, whose median tan^2
 * is ln 2 alpha^2 / t. */
static const double ggx_band_t[VMF_LOBE_BANDS] = {0.265157, 1.772163};
static const double ggx_band_w[VMF_LOBE_BANDS] = {0.539876, 0.460124};

int vmf_fit_glossy_bands(const bsdf *b, vec3 wo, vmf_lobe *lobe, vec3 *albedo) {
    if (!vmf_fit_glossy(b, wo, &lobe->band[0], albedo)) return 0;
    lobe->weight[0] = 1.0f;
    lobe->bands = 1;
    lobe->squeeze = b->model == GLOSSY_PHONG ? 1.0f : wo.z;
    if (b->model != GLOSSY_GGX) return 1;
    double a2 = (double)bsdf_glossy_alpha(b) * (double)bsdf_glossy_alpha(b);
    for (int k = 0; k < VMF_LOBE_BANDS; k++) {
        lobe->band[k].mu = lobe->band[0].mu;
        lobe->band[k].kappa = (float)kappa_with_median(microfacet_median(log(2.0) * a2 / ggx_band_t[k], (double)wo.z));
        lobe->weight[k] = (float)ggx_band_w[k];
    }
    lobe->bands = VMF_LOBE_BANDS;
    return lobe->bands;
}

int vmf_glossy_band_shares(const bsdf *b, vec3 wo, vec3 wi, float share[VMF_LOBE_BANDS]) {
    for (int k = 0; k < VMF_LOBE_BANDS; k++) share[k] = k == 0 ? 1.0f : 0.0f;
    if (b->model != GLOSSY_GGX) return 1;
    vec3 h = add3(wo, wi);
    if (!(h.z > 0.0f)) return VMF_LOBE_BANDS;
    /* Band t's Beckmann density is proportional to t e^{-t u}, u = tan^2(theta_h) / alpha^2 (per axis) */
    double hz2 = (double)h.z * (double)h.z, ax = fmax((double)b->alpha_x, 1e-4), ay = fmax((double)b->alpha_y, 1e-4);
    double hx = (double)h.x, hy = (double)h.y, u = (hx * hx / (ax * ax) + hy * hy / (ay * ay)) / hz2, d[VMF_LOBE_BANDS],
           sum = 0.0;
    for (int k = 0; k < VMF_LOBE_BANDS; k++) {
        d[k] = ggx_band_w[k] * ggx_band_t[k] * exp(-ggx_band_t[k] * u);
        sum += d[k];
    }
    for (int k = 0; k < VMF_LOBE_BANDS; k++) share[k] = sum > 0.0 ? (float)(d[k] / sum) : (k == 0 ? 1.0f : 0.0f);
    return VMF_LOBE_BANDS;
}

double vmf_mass_above(double kappa, double cos_mu_n) {
    double c = fmax(-1.0, fmin(1.0, cos_mu_n));
    if (!(kappa > 1e-8)) return 0.5;
    /* s.n = c cos(theta) + sqrt(1 - c^2) sin(theta) cos(phi): mean c A, variance from E[cos^2] =
     * 1 - 2 A / kappa. */
    double a = vmf_rbar_from_kappa(kappa), e2 = 1.0 - 2.0 * a / kappa;
    double var = c * c * fmax(0.0, e2 - a * a) + (1.0 - c * c) * 0.5 * (1.0 - e2);
    if (!(var > 0.0)) return c > 0.0 ? 1.0 : c < 0.0 ? 0.0 : 0.5;
    return 0.5 * erfc(-c * a / sqrt(2.0 * var));
}

vmf vmf_merge(const vmf *lobes, const float *weights, const int *members, int num_members) {
    double rx = 0.0, ry = 0.0, rz = 0.0, w_sum = 0.0;
    vmf out = {v3(0, 0, 1), 0.0f};
    for (int m = 0; m < num_members; m++) {
        int i = members ? members[m] : m;
        double w = weights ? (double)weights[i] : 1.0;
        if (!(w > 0.0)) continue;
        if (w_sum == 0.0) out.mu = lobes[i].mu; /* kept when the mean vanishes */
        double r = w * vmf_rbar_from_kappa(lobes[i].kappa);
        rx += r * (double)lobes[i].mu.x;
        ry += r * (double)lobes[i].mu.y;
        rz += r * (double)lobes[i].mu.z;
        w_sum += w;
    }
    if (!(w_sum > 0.0)) return out;
    double len = sqrt(rx * rx + ry * ry + rz * rz);
    if (len > 1e-12 * w_sum) out.mu = v3((float)(rx / len), (float)(ry / len), (float)(rz / len));
    out.kappa = (float)vmf_kappa_estimate(len / w_sum);
    return out;
}

/* One cluster of the EM: its weight share, mean direction and concentration. */
typedef struct {
    double alpha;
    vmf lobe;
    double log_scale; /* log alpha + log c(kappa) + kappa: the score's part that is the same for every direction */
} em_cluster;

static void em_set(em_cluster *c, double alpha, float kappa) {
    c->alpha = alpha;
    c->lobe.kappa = kappa;
    c->log_scale = log(alpha) + log_norm_plus_kappa(kappa);
}

static double em_score(const em_cluster *c, vec3 s) {
    double dx = (double)c->lobe.mu.x - (double)s.x, dy = (double)c->lobe.mu.y - (double)s.y,
           dz = (double)c->lobe.mu.z - (double)s.z;
    return c->log_scale - (double)c->lobe.kappa * 0.5 * (dx * dx + dy * dy + dz * dz);
}

int vmf_em(const vec3 *dirs, const float *weights, int n, int k, int *assign) {
    if (n <= 0) return 0;
    if (k > n) k = n;
    if (k < 1) k = 1;
    /* The highlight estimator calls this per camera hit with k <= 8: no allocation for small k. */
    em_cluster c_small[16];
    double sum_small[4 * 16];
    int small = k <= 16;
    em_cluster *c = small ? c_small : malloc(sizeof(em_cluster) * (size_t)k);
    double *sum = small ? sum_small : malloc(sizeof(double) * 4 * (size_t)k);
    if (!c || !sum) { /* no memory: one cluster */
        if (!small) free(c), free(sum);
        for (int i = 0; i < n; i++) assign[i] = 0;
        return 1;
    }
    double w_total = 0.0;
    for (int i = 0; i < n; i++) w_total += weights && weights[i] > 0.0f ? (double)weights[i] : (weights ? 0.0 : 1.0);
    int equal = !(w_total > 0.0); /* all weights zero: count directions instead */
#define WEIGHT(i) (equal || !weights ? 1.0 : (weights[i] > 0.0f ? (double)weights[i] : 0.0))

    /* Centres: the heaviest direction, then repeatedly the one least aligned with those chosen,
     * until k or until every direction coincides with a centre. */
    int first = 0;
    for (int i = 1; i < n; i++)
        if (WEIGHT(i) > WEIGHT(first)) first = i;
    int m = 0;
    c[m++].lobe.mu = dirs[first];
    while (m < k) {
        int best = -1;
        double best_align = 1.0 - 1e-7;
        for (int i = 0; i < n; i++) {
            double align = -2.0;
            for (int j = 0; j < m; j++) {
                double d = dot3(dirs[i], c[j].lobe.mu);
                if (d > align) align = d;
            }
            if (align < best_align) best_align = align, best = i;
        }
        if (best < 0) break;
        c[m++].lobe.mu = dirs[best];
    }
    for (int j = 0; j < m; j++) em_set(&c[j], 1.0 / m, 1.0f); /* first E-step: nearest centre */

    for (int iter = 0; iter < 50; iter++) {
        int changed = 0;
        for (int i = 0; i < n; i++) { /* E-step */
            int best = 0;
            double best_score = -INFINITY;
            for (int j = 0; j < m; j++) {
                if (!(c[j].alpha > 0.0)) continue;
                double sc = em_score(&c[j], dirs[i]);
                if (sc > best_score) best_score = sc, best = j;
            }
            if (iter == 0 || assign[i] != best) changed = 1;
            assign[i] = best;
        }
        if (!changed) break;
        for (int j = 0; j < 4 * m; j++) sum[j] = 0.0; /* M-step */
        for (int i = 0; i < n; i++) {
            double w = WEIGHT(i), *s = &sum[4 * assign[i]];
            s[0] += w * (double)dirs[i].x;
            s[1] += w * (double)dirs[i].y;
            s[2] += w * (double)dirs[i].z;
            s[3] += w;
        }
        double all = 0.0;
        for (int j = 0; j < m; j++) all += sum[4 * j + 3];
        for (int j = 0; j < m; j++) {
            const double *s = &sum[4 * j];
            if (!(s[3] > 0.0)) { /* empty (or weightless) cluster: it takes no part any more */
                c[j].alpha = 0.0;
                continue;
            }
            double len = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
            if (len > 1e-12 * s[3]) c[j].lobe.mu = v3((float)(s[0] / len), (float)(s[1] / len), (float)(s[2] / len));
            em_set(&c[j], s[3] / all, (float)vmf_kappa_estimate(len / s[3]));
        }
    }
#undef WEIGHT
    /* Number the clusters that kept members 0..used-1. */
    int *remap = (int *)sum, used = 0; /* sum has room for m ints */
    for (int j = 0; j < m; j++) remap[j] = -1;
    for (int i = 0; i < n; i++) {
        if (remap[assign[i]] < 0) remap[assign[i]] = used++;
        assign[i] = remap[assign[i]];
    }
    if (!small) free(c), free(sum);
    return used;
}
