#include "vsl.h"

#include "sampling.h"

#define PI_D 3.14159265358979323846

/* f_x(wo, lx) f_j(wi_j, lj) with the path-space split applied (both directions local, above):
 * the highlights' part is the product of both ends' highlight lobes. */
static vec3 bsdf_pair(const virtual_light *vl, const shading_point *x, vec3 lx, vec3 lj, int lobes_j, vl_terms terms) {
    if (terms == VL_TERMS_ALL || vl->depth != 1)
        return terms == VL_TERMS_HIGHLIGHTS
                   ? v3(0, 0, 0)
                   : mul3(bsdf_eval(&x->b, x->wo, lx, BSDF_ALL), bsdf_eval(&vl->b, vl->wi, lj, lobes_j));
    vec3 gg = mul3(bsdf_eval(&x->b, x->wo, lx, bsdf_highlight_lobe(&x->b)),
                   bsdf_eval(&vl->b, vl->wi, lj, lobes_j & bsdf_highlight_lobe(&vl->b)));
    if (terms == VL_TERMS_HIGHLIGHTS) return gg;
    vec3 all = mul3(bsdf_eval(&x->b, x->wo, lx, BSDF_ALL), bsdf_eval(&vl->b, vl->wi, lj, lobes_j));
    return max3(sub3(all, gg), v3(0, 0, 0)); /* exact up to rounding; never below zero */
}

/* A cap on one light's contribution: far above any real radiance, far below FLT_MAX, so sums and
 * products downstream stay finite even for absurd radii or distances. */
#define VL_MAX_CONTRIBUTION 1e30

static vec3 saturate(vec3 power, vec3 f, double scale) {
    double c[3] = {(double)power.x * (double)f.x * scale, (double)power.y * (double)f.y * scale,
                   (double)power.z * (double)f.z * scale};
    for (int k = 0; k < 3; k++)
        c[k] = c[k] < VL_MAX_CONTRIBUTION ? c[k] : VL_MAX_CONTRIBUTION; /* NaN-free: inputs are finite */
    return v3((float)c[0], (float)c[1], (float)c[2]);
}

vec3 vpl_contribution(const virtual_light *vl, const shading_point *x, int glossy_at_light, vl_terms terms) {
    vec3 d = sub3(vl->p, x->p);
    float d2 = length_sq3(d);
    if (!(d2 > 0.0f)) return v3(0, 0, 0);
    vec3 l = scale3(d, 1.0f / sqrtf(d2));
    if (dot3(l, x->ng) <= 0.0f || dot3(l, vl->ng) >= 0.0f) return v3(0, 0, 0);
    vec3 lx = to_local(x->frame, l), lj = to_local(vl->frame, neg3(l));
    if (lx.z <= 0.0f || lj.z <= 0.0f) return v3(0, 0, 0);
    vec3 f = bsdf_pair(vl, x, lx, lj, glossy_at_light ? BSDF_ALL : BSDF_DIFFUSE, terms);
    if (is_black3(f)) return f;
    /* The light leaves by its geometric cosine (vlights.c: shading normals' adjoint). */
    return saturate(vl->power, f, (double)lx.z * -(double)dot3(l, vl->ng) / (double)d2);
}

/* Omega_j: the cone from x around the sphere (p_j, r_j), or x's hemisphere when x is inside. */
typedef struct {
    int inside;
    vec3 axis;      /* unit, x -> p_j (outside only) */
    float omc;      /* 1 - cos(theta_max) */
    float sin2_max; /* sin^2(theta_max) = (r/d)^2: the membership test, exact for tiny cones */
    frame3 cone;    /* around axis */
} solid_angle;

static solid_angle omega_of(const virtual_light *vl, const shading_point *x) {
    solid_angle o = {0};
    vec3 d = sub3(vl->p, x->p);
    float dist = length3(d);
    if (!(dist > vl->radius)) {
        o.inside = 1;
        o.omc = 1.0f;
        return o;
    }
    float s = vl->radius / dist;
    o.axis = scale3(d, 1.0f / dist);
    o.omc = cone_one_minus_cos(s);
    o.sin2_max = s * s;
    o.cone = frame_from_normal(o.axis);
    return o;
}

static int in_omega(const solid_angle *o, const shading_point *x, vec3 l) {
    if (o->inside) return dot3(l, x->frame.n) > 0.0f;
    float c = dot3(l, o->axis);
    return c > 0.0f && length_sq3(cross3(l, o->axis)) <= o->sin2_max;
}

static vec3 integrand(const virtual_light *vl, const shading_point *x, vl_terms terms, vec3 l, vec3 *lx, vec3 *lj) {
    *lx = to_local(x->frame, l);
    *lj = to_local(vl->frame, neg3(l));
    float cos_j = -dot3(l, vl->ng); /* geometric: shading normals' adjoint (vlights.c) */
    if (lx->z <= 0.0f || lj->z <= 0.0f || !(cos_j > 0.0f)) return v3(0, 0, 0);
    return scale3(bsdf_pair(vl, x, *lx, *lj, BSDF_ALL, terms), lx->z * cos_j);
}

vec3 vsl_integrand(const virtual_light *vl, const shading_point *x, vl_terms terms, vec3 l) {
    solid_angle o = omega_of(vl, x);
    vec3 lx, lj;
    return in_omega(&o, x, l) ? integrand(vl, x, terms, l, &lx, &lj) : v3(0, 0, 0);
}

vec3 vsl_integral(const virtual_light *vl, const shading_point *x, vl_terms terms, int all_strategies, rng_state *rng,
                  int *samples) {
    solid_angle o = omega_of(vl, x);
    /* Proportional to |Omega| = 2 pi (1 - cos theta_max): 100 at the hemisphere, at least 1. */
    int n = o.inside ? VSL_MAX_SAMPLES : (int)ceilf((float)VSL_MAX_SAMPLES * o.omc);
    n = n < 1 ? 1 : (n > VSL_MAX_SAMPLES ? VSL_MAX_SAMPLES : n);
    if (samples) *samples = n;
    float pdf_cone_uniform = o.inside ? 0.0f : pdf_uniform_cone(o.omc);
    /* The strategies take turns from a random start, so each sample's strategy is uniform: the
     * one-sample model, weights (1/3) p_t. Where neither lobe is glossy the integrand is smooth
     * over the cone and cone sampling alone does (the effect plan's diffuse kernel). */
    int strategies = all_strategies || bsdf_highlight_lobe(&x->b) || bsdf_highlight_lobe(&vl->b) ? 3 : 1;
    unsigned strategy = strategies == 3 ? (unsigned)(rng_float(rng) * 3.0f) : 0u;
    double sum[3] = {0.0, 0.0, 0.0}; /* double: a razor-sharp lobe over a tiny pdf must not overflow */
    for (int k = 0; k < n; k++, strategy = (strategy + 1) % (unsigned)strategies) {
        vec2 u = rng_vec2(rng);
        float u_lobe = rng_float(rng);
        vec3 l;
        if (strategy == 0) {
            l = o.inside ? to_world(x->frame, sample_cosine_hemisphere(u))
                         : to_world(o.cone, sample_uniform_cone(u, o.omc));
        } else {
            const bsdf *b = strategy == 1 ? &x->b : &vl->b;
            vec3 wo = strategy == 1 ? x->wo : vl->wi;
            frame3 f = strategy == 1 ? x->frame : vl->frame;
            bsdf_sample_result bs;
            if (!bsdf_sample(b, wo, BSDF_ALL, u_lobe, u, &bs) || !(bs.pdf > 0.0f)) continue;
            l = to_world(f, bs.wi);
            if (strategy == 2) l = neg3(l);
        }
        if (!in_omega(&o, x, l)) continue;
        vec3 lx, lj;
        vec3 g = integrand(vl, x, terms, l, &lx, &lj);
        if (is_black3(g)) continue;
        float p_cone = o.inside ? pdf_cosine_hemisphere(lx) : pdf_cone_uniform;
        float p_sum = strategies == 1
                          ? p_cone
                          : p_cone + bsdf_pdf(&x->b, x->wo, lx, BSDF_ALL) + bsdf_pdf(&vl->b, vl->wi, lj, BSDF_ALL);
        if (!(p_sum > 0.0f)) continue;
        double w = (double)strategies / (double)p_sum;
        sum[0] += (double)g.x * w;
        sum[1] += (double)g.y * w;
        sum[2] += (double)g.z * w;
    }
    return saturate(v3s(1.0f),
                    v3((float)fmin(sum[0], VL_MAX_CONTRIBUTION), (float)fmin(sum[1], VL_MAX_CONTRIBUTION),
                       (float)fmin(sum[2], VL_MAX_CONTRIBUTION)),
                    1.0 / n);
}

/* The share of a disk of radius 1 on the near side of a chord at signed distance h beyond its
 * centre (1 for h >= 1, 1/2 for h = 0). */
static double disk_share(double h) {
    if (h >= 1.0) return 1.0;
    if (h <= -1.0) return 0.0;
    return 1.0 - (acos(h) - h * sqrt(1.0 - h * h)) / PI_D;
}

double vsl_front_share(const virtual_light *vl, const shading_point *x) {
    vec3 d = sub3(vl->p, x->p);
    double r = (double)vl->radius;
    double a = disk_share((double)dot3(d, x->ng) / r), b = disk_share(-(double)dot3(d, vl->ng) / r);
    return fmin(a, b) * sqrt(fmax(a, b));
}

vec3 vsl_contribution(const virtual_light *vl, const shading_point *x, vl_terms terms, int all_strategies,
                      rng_state *rng, int *samples) {
    if (!(vl->radius > 0.0f)) return vpl_contribution(vl, x, 1, terms); /* the limit r -> 0 */
    vec3 i = vsl_integral(vl, x, terms, all_strategies, rng, samples);
    if (is_black3(i)) return i;
    double share = vsl_front_share(vl, x);
    if (!(share > 0.0)) return v3(0, 0, 0);
    return saturate(vl->power, i, 1.0 / (PI_D * (double)vl->radius * (double)vl->radius * share));
}
