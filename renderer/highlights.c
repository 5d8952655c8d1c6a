#define _POSIX_C_SOURCE 200809L
#include "highlights.h"

#include "clock.h"
#include "envfilter.h"
#include "lights.h"
#include "manylight.h"
#include "sampling.h"
#include "vmf.h"

hl_setup hl_setup_from(const scene *s, const vl_params *vp, const struct env_vmf_filter *env_filter) {
    hl_setup h;
    h.num_punctual = 0;
    h.area_lights = 0;
    for (int li = 0; li < s->num_lights; li++) {
        light_type t = s->lights[li].type;
        if (t == LIGHT_POINT || t == LIGHT_SPOT || t == LIGHT_DIRECTIONAL) h.num_punctual = li + 1;
        else if (t == LIGHT_TRIANGLE) h.area_lights = 1;
    }
    h.mode = vp->merge == HL_MERGE_OFF ? HL_UNMERGED : vp->merge == HL_MERGE_TRACE ? HL_TRACED : HL_MERGED;
    h.secondary_rays = vp->secondary_rays > 0 ? vp->secondary_rays : HL_DEFAULT_SECONDARY_RAYS;
    if (h.secondary_rays > HL_MAX_SECONDARY_RAYS) h.secondary_rays = HL_MAX_SECONDARY_RAYS;
    h.clusters = vp->clusters > 0 ? vp->clusters : HL_DEFAULT_CLUSTERS;
    if (h.clusters > HL_MAX_CLUSTERS) h.clusters = HL_MAX_CLUSTERS;
    h.env_filter = env_filter;
    return h;
}

/* A lobe to light: what it carries and where its shadow rays start. The vMF modes approximate the
 * cosine-weighted glossy lobe at q by color x vMF; the traced mode evaluates the BSDF at q. */
typedef struct {
    vec3 color;  /* x's sample weight (over N) times, for vMF lobes, the glossy albedo at q */
    vec3 origin; /* on or just above the surface(s) the lobe came from */
    vec3 n;      /* geometric normal there, toward x: no light from below it */
    float spread2; /* mean squared distance of the members from their mean position */
    vmf v;       /* world space */
    const shading_point *q; /* HL_TRACED: the secondary hit */
} lit_lobe;

/* The lobe's value toward world direction wi and the pdf with which lobe_sample produces wi. */
static vec3 lobe_eval(const lit_lobe *l, vec3 wi, float *pdf) {
    if (l->q) {
        vec3 w = to_local(l->q->frame, wi);
        *pdf = bsdf_pdf(&l->q->b, l->q->wo, w, BSDF_GLOSSY);
        if (!(w.z > 0.0f) || !(dot3(wi, l->n) > 0.0f)) return v3(0, 0, 0);
        return mul3(l->color, scale3(bsdf_eval(&l->q->b, l->q->wo, w, BSDF_GLOSSY), w.z));
    }
    float g = (float)vmf_eval(l->v, wi);
    *pdf = g;
    return dot3(wi, l->n) > 0.0f ? scale3(l->color, g) : v3(0, 0, 0);
}

/* A direction from the lobe (BSDF sampling, or the vMF); 0 when none. */
static int lobe_sample(const lit_lobe *l, rng_state *rng, vec3 *wi) {
    vec2 u = rng_vec2(rng);
    if (!l->q) {
        *wi = vmf_sample(l->v, u);
        return 1;
    }
    bsdf_sample_result bs;
    if (!bsdf_sample(&l->q->b, l->q->wo, BSDF_GLOSSY, 0.0f, u, &bs) || !(bs.pdf > 0.0f)) return 0;
    *wi = to_world(l->q->frame, bs.wi);
    return 1;
}

/* Light reflected by the lobe: punctual lights one shadow ray each; area lights (and, traced, the
 * environment) by one light sample and one lobe sample with the power heuristic; in the vMF modes
 * the environment by the prefiltered map and a ray along the lobe's mean. */
static vec3 light_lobe(const hl_setup *h, const scene *s, const lit_lobe *l, rng_state *rng, render_stats *st) {
    vec3 sum = v3(0, 0, 0);
    int traced = l->q != NULL;
    for (int li = 0; li < h->num_punctual; li++) {
        light_sample ls;
        float pdf;
        if (s->lights[li].type == LIGHT_TRIANGLE || s->lights[li].type == LIGHT_ENV) continue;
        if (!light_sample_one(s, li, l->origin, v2(0.5f, 0.5f), &ls)) continue;
        vec3 f = lobe_eval(l, ls.wi, &pdf);
        if (is_black3(f)) continue; /* outside the lobe: no shadow ray */
        /* A merged lobe stands for a patch of surface: a light closer than the patch's extent lights
         * it as a whole, not with the 1/d^2 peak at its centre (lights touching a reflector). */
        float falloff = isfinite(ls.dist) ? ls.dist * ls.dist / (ls.dist * ls.dist + l->spread2) : 1.0f;
        if (light_sample_visible(s, l->origin, l->n, &ls, &st->rays[RAY_SHADOW]))
            sum = add3(sum, scale3(mul3(f, ls.radiance), falloff));
    }
    int env_by_sampling = traced && s->env_light >= 0;
    if (h->area_lights || env_by_sampling) {
        light_sample ls;
        float u_sel = rng_float(rng);
        vec2 u = rng_vec2(rng);
        if (light_sample_direct(s, l->origin, u_sel, u, &ls) && !ls.delta &&
            (s->lights[ls.light].type == LIGHT_TRIANGLE || env_by_sampling)) {
            float pdf;
            vec3 f = lobe_eval(l, ls.wi, &pdf);
            if (!is_black3(f) && light_sample_visible(s, l->origin, l->n, &ls, &st->rays[RAY_SHADOW]))
                sum = add3(sum, scale3(mul3(f, ls.radiance), mis_power(ls.pdf, pdf) / ls.pdf));
        }
        vec3 wi;
        float pdf;
        if (lobe_sample(l, rng, &wi)) {
            vec3 f = lobe_eval(l, wi, &pdf);
            if (!is_black3(f) && pdf > 0.0f) {
                surface_hit e;
                st->rays[RAY_BOUNCE]++;
                if (scene_intersect(s, offset_origin(s, l->origin, l->n, wi), wi, INFINITY, &e)) {
                    int li = s->tri_light[e.tri];
                    vec3 le = li >= 0 ? material_emission(s, &e) : v3(0, 0, 0);
                    if (!is_black3(le))
                        sum = add3(sum, scale3(mul3(f, le), mis_power(pdf, light_pdf_triangle(s, li, l->origin, &e)) / pdf));
                } else if (env_by_sampling) {
                    sum = add3(sum, scale3(mul3(f, env_eval(s, wi)), mis_power(pdf, light_pdf_env(s, wi)) / pdf));
                }
            }
        }
    }
    if (!traced && h->env_filter && dot3(l->v.mu, l->n) > 0.0f) {
        vec3 e = env_vmf_filter_lookup(h->env_filter, l->v);
        if (!is_black3(e)) {
            st->rays[RAY_SHADOW]++;
            if (!scene_occluded(s, offset_origin(s, l->origin, l->n, l->v.mu), l->v.mu, INFINITY))
                sum = add3(sum, mul3(l->color, e));
        }
    }
    return sum;
}

/* Lobes more anisotropic than this (larger roughness over smaller) are not fitted by a vMF. */
#define HL_MAX_VMF_ASPECT 1.5f

/* One secondary hit's record. */
typedef struct {
    vec3 p, n;   /* position, geometric normal toward x */
    vec3 color;  /* x's weight / N times the lobe's albedo */
} hl_hit;

/* Where a cluster's shadow rays start: the members' mean position (weighted like the merge),
 * raised along their mean normal until it lies above every member's tangent plane, so the rays
 * never start under a curved surface (the paper's per-ray epsilon, made explicit). */
static void cluster_origin(const hl_hit *hits, const float *alpha, const int *members, int count, vec3 *origin,
                           vec3 *normal, float *spread2) {
    vec3 p = v3(0, 0, 0), n = v3(0, 0, 0);
    double w = 0.0;
    int heaviest = members[0];
    for (int m = 0; m < count; m++) {
        int i = members[m];
        p = madd3(p, hits[i].p, alpha[i]);
        n = madd3(n, hits[i].n, alpha[i]);
        w += (double)alpha[i];
        if (alpha[i] > alpha[heaviest]) heaviest = i;
    }
    float len = length3(n);
    p = scale3(p, (float)(1.0 / w));
    double s2 = 0.0;
    for (int m = 0; m < count; m++) s2 += (double)alpha[members[m]] * (double)length_sq3(sub3(hits[members[m]].p, p));
    *spread2 = (float)(s2 / w);
    if (!(len > 1e-3f * (float)w)) { /* opposed normals: no mean side to stand on */
        *origin = hits[heaviest].p;
        *normal = hits[heaviest].n;
        return;
    }
    n = scale3(n, 1.0f / len);
    float raise = 0.0f;
    for (int m = 0; m < count; m++) {
        const hl_hit *hi = &hits[members[m]];
        float c = dot3(n, hi->n);
        if (c > 0.1f) raise = fmaxf(raise, dot3(sub3(hi->p, p), hi->n) / c);
    }
    *origin = madd3(p, n, raise);
    *normal = n;
}

vec3 hl_estimate(const hl_setup *h, const scene *s, const shading_point *x, rng_state *rng, render_stats *st) {
    vec3 sum = v3(0, 0, 0);
    if (!bsdf_highlight_lobe(&x->b) || !(x->wo.z > 0.0f)) return sum;
    int n = h->secondary_rays;
    hl_hit hits[HL_MAX_SECONDARY_RAYS];
    vmf lobes[HL_MAX_SECONDARY_RAYS];
    vec3 dirs[HL_MAX_SECONDARY_RAYS];
    float alpha[HL_MAX_SECONDARY_RAYS];
    int count = 0;
    st->hl_points++;
    /* The N directions stratified over the lobe: a randomly shifted R2 sequence. */
    vec2 shift = rng_vec2(rng);
    for (int k = 0; k < n; k++) {
        bsdf_sample_result bs;
        if (!bsdf_sample(&x->b, x->wo, BSDF_GLOSSY, 0.0f, sample_r2(k, shift), &bs) || !(bs.pdf > 0.0f)) continue;
        vec3 wi = to_world(x->frame, bs.wi);
        if (dot3(wi, x->ng) <= 0.0f) continue;
        vec3 weight = scale3(bs.f, bs.wi.z / (bs.pdf * (float)n));
        surface_hit hq;
        st->rays[RAY_BOUNCE]++;
        st->hl_secondary_rays++;
        if (!scene_intersect(s, offset_origin(s, x->p, x->ng, wi), wi, INFINITY, &hq)) continue;
        shading_point q = shading_point_at(s, &hq, wi);
        if (!bsdf_highlight_lobe(&q.b)) continue; /* a rough lobe: the VSLs keep these paths */
        /* An isotropic vMF cannot follow an anisotropic lobe's streak (the default scene's brushed
         * metals: over half the vMF modes' error); such a lobe is lit through its own BSDF. */
        if (h->mode == HL_TRACED || bsdf_glossy_aspect(&q.b) > HL_MAX_VMF_ASPECT) {
            lit_lobe l = {weight, q.p, q.ng, 0.0f, {v3(0, 0, 1), 0.0f}, &q};
            sum = add3(sum, light_lobe(h, s, &l, rng, st));
            st->hl_lobes++;
            continue;
        }
        vmf lobe;
        vec3 albedo;
        if (!vmf_fit_glossy(&q.b, q.wo, &lobe, &albedo)) continue;
        lobe.mu = normalize3(to_world(q.frame, lobe.mu));
        hl_hit *hit = &hits[count];
        hit->p = q.p;
        hit->n = q.ng;
        hit->color = mul3(weight, albedo);
        if (!is_finite3(hit->color) || !(max_comp3(hit->color) > 0.0f)) continue;
        if (h->mode == HL_UNMERGED) {
            lit_lobe l = {hit->color, q.p, q.ng, 0.0f, lobe, NULL};
            sum = add3(sum, light_lobe(h, s, &l, rng, st));
            st->hl_lobes++;
            continue;
        }
        lobes[count] = lobe;
        dirs[count] = lobe.mu;
        alpha[count] = fmaxf(luminance3(hit->color), 1e-30f);
        count++;
    }
    if (count == 0) return sum;

    uint64_t t0 = clock_ns();
    int assign[HL_MAX_SECONDARY_RAYS];
    int k = vmf_em(dirs, alpha, count, h->clusters, assign);
    lit_lobe merged[HL_MAX_CLUSTERS];
    for (int c = 0; c < k; c++) {
        int members[HL_MAX_SECONDARY_RAYS], m = 0;
        vec3 color = v3(0, 0, 0);
        for (int i = 0; i < count; i++) {
            if (assign[i] != c) continue;
            members[m++] = i;
            color = add3(color, hits[i].color); /* Eq. 10: the clusters' energies sum to the members' */
        }
        merged[c].color = color;
        merged[c].v = vmf_merge(lobes, alpha, members, m);
        merged[c].q = NULL;
        cluster_origin(hits, alpha, members, m, &merged[c].origin, &merged[c].n, &merged[c].spread2);
    }
    st->hl_merge_ns += clock_ns() - t0;
    for (int c = 0; c < k; c++) sum = add3(sum, light_lobe(h, s, &merged[c], rng, st));
    st->hl_lobes += (uint64_t)k;
    return sum;
}
