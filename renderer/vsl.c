#include "vsl.h"

#include "sampling.h"

#define PI_D 3.14159265358979323846

/* f_x(wo, lx) f_j(wi_j, lj) with the path-space split applied (both directions local, above):
 * the highlights' part is the product of both ends' highlight lobes. */
static vec3 bsdf_pair(const virtual_light *vl, const shading_point *x, vec3 lx, vec3 lj, int lobes_j, vl_terms terms) {
    int split = terms != VL_TERMS_ALL && vl->depth == 1;
    int hx = split ? bsdf_highlight_lobe(&x->b) : 0, hj = split ? lobes_j & bsdf_highlight_lobe(&vl->b) : 0;
    if (!hx || !hj) /* no product of highlight lobes (where x's sharp lobes are traced, the common case) */
        return terms == VL_TERMS_HIGHLIGHTS
                   ? v3(0, 0, 0)
                   : mul3(bsdf_eval(&x->b, x->wo, lx, BSDF_ALL), bsdf_eval(&vl->b, vl->wi, lj, lobes_j));
    /* Each lobe evaluated once (bsdf_eval adds its lobes): all - gg = fx_rest fj + fx_hl fj_rest. */
    vec3 fx_hl = bsdf_eval(&x->b, x->wo, lx, hx), fj_hl = bsdf_eval(&vl->b, vl->wi, lj, hj);
    if (terms == VL_TERMS_HIGHLIGHTS) return mul3(fx_hl, fj_hl);
    vec3 fx_rest = bsdf_eval(&x->b, x->wo, lx, BSDF_ALL & ~hx), fj_rest = bsdf_eval(&vl->b, vl->wi, lj, lobes_j & ~hj);
    return add3(mul3(fx_rest, add3(fj_hl, fj_rest)), mul3(fx_hl, fj_rest));
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

/* The light's disk: the sphere's cross-section in the light's tangent plane (docs/design.md,
 * "Virtual spherical lights"). x lies in front of that plane at height h. */
typedef struct {
    float h;        /* x's height above the light's plane, > 0 where anything arrives */
    float omc;      /* 1 - cos of the cone from x around the sphere (1: x inside it) */
    float inv_area; /* 1 / (pi r^2) */
    frame3 plane;   /* about the geometric normal: the disk lies in the surface, whatever the shading */
} light_disk;

static light_disk disk_of(const virtual_light *vl, const shading_point *x) {
    light_disk o = {0};
    vec3 d = sub3(vl->p, x->p);
    float dist = length3(d);
    o.h = -dot3(d, vl->ng);
    o.inv_area = 1.0f / (PI_F * vl->radius * vl->radius);
    o.omc = dist > vl->radius ? cone_one_minus_cos(vl->radius / dist) : 1.0f;
    o.plane = frame_from_normal(vl->ng);
    return o;
}

/* Where the ray from x along l meets the light's plane, if within the disk: the solid-angle pdf
 * of sampling that point uniformly over the disk (t^2 / (cos_j pi r^2)); 0 off the disk. */
static float disk_pdf(const light_disk *o, const virtual_light *vl, const shading_point *x, vec3 l) {
    float cos_j = -dot3(l, vl->ng);
    if (!(cos_j > 0.0f) || !(o->h > 0.0f)) return 0.0f;
    float t = o->h / cos_j;
    vec3 off = sub3(madd3(x->p, l, t), vl->p);
    if (!(length_sq3(off) <= vl->radius * vl->radius)) return 0.0f;
    return t * t * o->inv_area / cos_j;
}

/* f_x cos_x f_j over the disk's solid angle: the light leaving the disk with the light's BSDF,
 * its cosine carried by the solid angle the disk's area spans. */
static vec3 integrand(const virtual_light *vl, const shading_point *x, vl_terms terms, vec3 l, vec3 *lx, vec3 *lj) {
    *lx = to_local(x->frame, l);
    *lj = to_local(vl->frame, neg3(l));
    if (lx->z <= 0.0f || lj->z <= 0.0f) return v3(0, 0, 0);
    return scale3(bsdf_pair(vl, x, *lx, *lj, BSDF_ALL, terms), lx->z);
}

vec3 vsl_integrand(const virtual_light *vl, const shading_point *x, vl_terms terms, vec3 l) {
    light_disk o = disk_of(vl, x);
    vec3 lx, lj;
    return disk_pdf(&o, vl, x, l) > 0.0f ? integrand(vl, x, terms, l, &lx, &lj) : v3(0, 0, 0);
}

vec3 vsl_integral(const virtual_light *vl, const shading_point *x, vl_terms terms, int all_strategies, rng_state *rng,
                  int *samples) {
    light_disk o = disk_of(vl, x);
    /* Proportional to the sphere's cone |Omega| = 2 pi (1 - cos theta_max), which holds the disk:
     * 100 at the hemisphere, at least 1. */
    int n = (int)ceilf((float)VSL_MAX_SAMPLES * o.omc);
    /* Points spread over the disk; where either lobe is glossy, both BSDFs too; where x is inside
     * the sphere, close to the disk, x's BSDF too, which finds the disk where the area's pdf is
     * poor. They take turns from a random start, so each sample's strategy is uniform (the
     * one-sample model, weights (1/S) p_t), and each takes at least one: a far light's one sample
     * from x's BSDF would miss the disk most of the time and make the rest count S times. */
    int inside = o.omc >= 1.0f;
    int strategies = all_strategies || bsdf_highlight_lobe(&x->b) || bsdf_highlight_lobe(&vl->b) ? 3 : 1 + inside;
    n = n < strategies ? strategies : (n > VSL_MAX_SAMPLES ? VSL_MAX_SAMPLES : n);
    if (samples) *samples = n;
    if (!(o.h > 0.0f)) return v3(0, 0, 0);
    unsigned strategy = (unsigned)(rng_float(rng) * (float)strategies);
    if (strategy >= (unsigned)strategies) strategy = 0;
    double sum[3] = {0.0, 0.0, 0.0}; /* double: a razor-sharp lobe over a tiny pdf must not overflow */
    for (int k = 0; k < n; k++, strategy = (strategy + 1) % (unsigned)strategies) {
        vec2 u = rng_vec2(rng);
        float u_lobe = rng_float(rng);
        vec3 l;
        float p_disk;
        if (strategy == 0) { /* on the disk by construction: its pdf t^2 / (cos_j pi r^2), cos_j = h / t */
            vec2 q = sample_concentric_disk(u);
            vec3 y = to_world(o.plane, v3(q.x * vl->radius, q.y * vl->radius, 0.0f));
            vec3 d = sub3(add3(vl->p, y), x->p);
            float len = length3(d);
            if (!(len > 0.0f)) continue;
            l = scale3(d, 1.0f / len);
            p_disk = len * len * len * o.inv_area / o.h;
        } else {
            const bsdf *b = strategy == 1 ? &x->b : &vl->b;
            vec3 wo = strategy == 1 ? x->wo : vl->wi;
            frame3 f = strategy == 1 ? x->frame : vl->frame;
            bsdf_sample_result bs;
            if (!bsdf_sample(b, wo, BSDF_ALL, u_lobe, u, &bs) || !(bs.pdf > 0.0f)) continue;
            l = to_world(f, bs.wi);
            if (strategy == 2) l = neg3(l);
            p_disk = disk_pdf(&o, vl, x, l);
        }
        if (!(p_disk > 0.0f) || !isfinite(p_disk)) continue;
        vec3 lx, lj;
        vec3 g = integrand(vl, x, terms, l, &lx, &lj);
        if (is_black3(g)) continue;
        float p_sum = p_disk;
        if (strategies >= 2) p_sum += bsdf_pdf(&x->b, x->wo, lx, BSDF_ALL);
        if (strategies == 3) p_sum += bsdf_pdf(&vl->b, vl->wi, lj, BSDF_ALL);
        if (!(p_sum > 0.0f) || !isfinite(p_sum)) continue;
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
    /* x's plane meets the light's along a line at distance delta / sin(psi) from the disk's
     * centre (delta: the centre's height above x's plane, psi: the angle between the planes). */
    double delta = (double)dot3(sub3(vl->p, x->p), x->ng);
    double sin_psi = (double)length3(cross3(x->ng, vl->ng)), r = (double)vl->radius;
    if (delta >= r * sin_psi) return 1.0;
    return disk_share(delta / (r * sin_psi));
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
