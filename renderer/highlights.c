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
        if (t == LIGHT_POINT || t == LIGHT_SPOT || t == LIGHT_DIRECTIONAL)
            h.num_punctual = li + 1;
        else if (t == LIGHT_TRIANGLE)
            h.area_lights = 1;
    }
    vl_params r = vl_params_resolve(vp);
    h.mode = r.merge == HL_MERGE_OFF ? HL_UNMERGED : r.merge == HL_MERGE_TRACE ? HL_TRACED : HL_MERGED;
    h.choose = r.merge == HL_MERGE_AUTO;
    h.secondary_rays = r.secondary_rays;
    h.clusters = r.clusters;
    h.share = r.share == HL_SHARE_ON;
    h.dim_share = r.dim_share;
    h.check_share = r.check_share;
    h.env_filter = env_filter;
    return h;
}

/* One secondary hit's record: where it lies and its glossy lobe as vMF bands. */
typedef struct {
    vec3 p, n;                  /* position, geometric normal toward x */
    vec3 mu;                    /* the lobe's mean direction (world) */
    vec3 across;                /* unit, across the plane of incidence (along which a microfacet lobe is narrower) */
    vec3 color[VMF_LOBE_BANDS]; /* per band: x's weight / N x the lobe's albedo x the band's weight,
                                 * over the band's mass above the surface (the lobe's energy lies above it) */
    float lum[VMF_LOBE_BANDS];  /* their luminances: the members' weights in the merge */
    float rbar[VMF_LOBE_BANDS]; /* mean resultant length A(kappa) of each band (Eq. 5) */
    float var_along[VMF_LOBE_BANDS], var_across[VMF_LOBE_BANDS]; /* each band's variance per axis, 1 / kappa */
    int bands;
    float x_share[VMF_LOBE_BANDS]; /* the share of each band of x's lobe in the direction that reached it */
    /* x's lobe, whose image in this member's mirror the member stands for (docs/design.md,
     * "Merging without the sample's spread"): the sampled direction from x and its length, q's
     * shading normal, and per band of x's lobe the offset from the sampled direction to the band's
     * mean and the band's spread as two scaled tangent axes. Without a fit of x's lobe the offsets
     * and spreads are zero: the members keep the sample's spread. */
    vec3 wi, nq;
    float t;
    int x_fitted;
    vec3 x_offset[VMF_LOBE_BANDS], x_axis1[VMF_LOBE_BANDS], x_axis2[VMF_LOBE_BANDS];
} hl_hit;

/* x's glossy lobe as vMF bands in world space, when it is one round-enough lobe: each band's mean
 * and its spread as two tangent axes scaled by their standard deviations. */
typedef struct {
    int fitted, sharp;
    vec3 mu[VMF_LOBE_BANDS], axis1[VMF_LOBE_BANDS], axis2[VMF_LOBE_BANDS];
} x_lobe;

/* A cluster's lobe is a mixture of components, one per band of x's lobe and band of the members'
 * lobes. x's lobe's bands matter because the members' spread is the image of x's lobe: GGX's long
 * tails put a few members far out, and one Gaussian with the members' covariance would be far
 * broader than the core that makes the highlight's peak (peak 0.64 of path tracing's for GGX
 * alpha 0.09, K = 1). Each of x's bands is a near-Gaussian (Beckmann) lobe, so the members,
 * each shared among x's bands by the bands' densities where it was sampled, are merged per band. */
#define HL_COMPONENTS (VMF_LOBE_BANDS * VMF_LOBE_BANDS)

/* A cluster of secondary hits lit as one lobe: the members, where the shadow rays start, and per
 * band the members merged as seen from far away (Eq. 5), for the environment and lobe sampling. */
typedef struct {
    const hl_hit *hits;
    const int *members;
    int count;
    vec3 origin, n; /* above every member's tangent plane; the members' mean normal */
    vmf far[HL_COMPONENTS];
    vec3 far_color[HL_COMPONENTS];
    float comp_prob[HL_COMPONENTS]; /* lobe sampling's choice of component */
} hl_cluster;

/* The rotation by the smallest angle that takes unit a to unit b, applied to v. */
static vec3 rotate_onto(vec3 a, vec3 b, vec3 v) {
    float c = dot3(a, b);
    if (c > 0.9999999f) return v;
    if (c < -0.9999f) { /* a half turn about any axis across a */
        vec3 axis = frame_from_normal(a).t;
        return sub3(scale3(axis, 2.0f * dot3(axis, v)), v);
    }
    vec3 k = cross3(a, b);
    return add3(add3(scale3(v, c), cross3(k, v)), scale3(k, dot3(k, v) / (1.0f + c)));
}

/* Moments of one band of a cluster's members: weight, colour, the weighted sums of rbar mu (Eq. 5),
 * of mu, and of mu mu^T plus each member's own covariance (its lobe's variances across its mean). */
typedef struct {
    double w, r[3], m[3], s[6];
    vec3 color;
} band_moments;

/* Adds w v v^T to the second moments s (xx xy xz yy yz zz). */
static void outer_add(double *s, double w, vec3 v) {
    const double x = v.x, y = v.y, z = v.z;
    s[0] += w * x * x, s[1] += w * x * y, s[2] += w * x * z;
    s[3] += w * y * y, s[4] += w * y * z, s[5] += w * z * z;
}

/* Adds w times a lobe's covariance about unit mu, var_along along the plane of incidence and
 * var_across across it (unit `across`, made perpendicular to mu first), to s. */
static void cov_add(double *s, double w, vec3 mu, vec3 across, double var_along, double var_across) {
    vec3 a = sub3(across, scale3(mu, dot3(across, mu)));
    float al = length3(a);
    a = al > 1e-6f ? scale3(a, 1.0f / al) : frame_from_normal(mu).t;
    outer_add(s, w * var_along, cross3(mu, a));
    outer_add(s, w * var_across, a);
}

static void moments_add(band_moments *bm, vec3 mu, vec3 color, double w, double rbar) {
    const double x = mu.x, y = mu.y, z = mu.z;
    bm->w += w;
    bm->color = add3(bm->color, color);
    bm->r[0] += w * rbar * x, bm->r[1] += w * rbar * y, bm->r[2] += w * rbar * z;
    bm->m[0] += w * x, bm->m[1] += w * y, bm->m[2] += w * z;
    outer_add(bm->s, w, mu);
}

/* The band's mean direction and isotropic concentration (Eq. 5 and 3); 0 when it has no weight. */
static int moments_vmf(const band_moments *bm, vmf *v) {
    if (!(bm->w > 0.0)) return 0;
    double len = sqrt(bm->r[0] * bm->r[0] + bm->r[1] * bm->r[1] + bm->r[2] * bm->r[2]);
    if (!(len > 1e-12 * bm->w)) return 0; /* antipodal members: no mean direction */
    v->mu = v3((float)(bm->r[0] / len), (float)(bm->r[1] / len), (float)(bm->r[2] / len));
    v->kappa = (float)vmf_kappa_from_rbar(len / bm->w);
    return 1;
}

/* The band's density toward direction s: a Gaussian across the members' mean direction with their
 * covariance C (the spread of their means plus their own lobes' variances), K = C^-1: density
 * sqrt(det K) / (2 pi (1 - e^{-2 sqrt(det K)})) exp(-(d^T K d + sqrt(det K) dn^2) / 2), d the offset of s
 * across the mean and dn along it. For one round lobe (K = kappa I) this is that vMF exactly. Eq. 5
 * alone, one round vMF of the members' mean resultant length, fails where they spread in a line,
 * as the secondary hits of a lobe seen at a grazing angle do: it smears the highlight across that
 * line, dimming its peak. */
static double moments_density(const band_moments *bm, const vmf *v, vec3 s) {
    frame3 f = frame_from_normal(v->mu);
    const double t1[3] = {f.t.x, f.t.y, f.t.z}, t2[3] = {f.b.x, f.b.y, f.b.z};
    double w = bm->w, m1 = 0.0, m2 = 0.0, c11 = 0.0, c12 = 0.0, c22 = 0.0;
    const double *q = bm->s; /* xx xy xz yy yz zz */
    const double S[3][3] = {{q[0], q[1], q[2]}, {q[1], q[3], q[4]}, {q[2], q[4], q[5]}};
    for (int i = 0; i < 3; i++) {
        m1 += bm->m[i] * t1[i];
        m2 += bm->m[i] * t2[i];
        for (int j = 0; j < 3; j++) {
            c11 += t1[i] * S[i][j] * t1[j];
            c12 += t1[i] * S[i][j] * t2[j];
            c22 += t2[i] * S[i][j] * t2[j];
        }
    }
    m1 /= w, m2 /= w;
    c11 = c11 / w - m1 * m1;
    c22 = c22 / w - m2 * m2;
    c12 = c12 / w - m1 * m2;
    double det = c11 * c22 - c12 * c12, tr = c11 + c22;
    if (!(tr > 0.0) || !(det > 1e-12 * tr * tr)) return vmf_eval(*v, s);
    double k11 = c22 / det, k22 = c11 / det, k12 = -c12 / det, kg = 1.0 / sqrt(det);
    double dx = (double)s.x - (double)v->mu.x, dy = (double)s.y - (double)v->mu.y, dz = (double)s.z - (double)v->mu.z;
    double omc = 0.5 * (dx * dx + dy * dy + dz * dz); /* 1 - mu.s */
    double d1 = (double)s.x * t1[0] + (double)s.y * t1[1] + (double)s.z * t1[2];
    double d2 = (double)s.x * t2[0] + (double)s.y * t2[1] + (double)s.z * t2[2];
    double e = k11 * d1 * d1 + 2.0 * k12 * d1 * d2 + k22 * d2 * d2 + kg * omc * omc;
    double norm = kg < 1e-8 ? 0.25 / 3.14159265358979 : kg / (2.0 * 3.14159265358979 * -expm1(-2.0 * kg));
    return norm * exp(-0.5 * e);
}

/* x's band's image is taken (rather than the sample's spread) only while the band is narrow (its
 * variance along either axis below HL_MAX_X_VAR: a broad band straddles edges, where part of it
 * meets another surface than the member's) and its image narrow enough for the linear map to hold
 * (HL_MAX_IMAGE_VAR: beyond, GGX's tails, which no Gaussian band follows, carry visible light).
 * Measured on test_highlights' corners of GGX alpha 0.09 planes, whose bands have variances up to
 * 0.009: taking their images lost 17% of the highlights, 7% when only images below 0.01 were taken,
 * and at an edge (the paper's Fig. 6) the error rose from 0.04 to 0.20. Such x keep the sample's
 * spread; the chrome of roughness 0.12 (variances 0.0016 and 0.0002) takes its image. */
#define HL_MAX_X_VAR 0.002
#define HL_MAX_IMAGE_VAR 0.008

/* The image of an offset v of the direction from x, as the member's lobe sees the light: its
 * mirror direction turns by v reflected about q's normal, and, unless the light is far, the point q
 * slides along its plane by t v (projected along the ray) and the direction to the light, dl away
 * along unit li, turns against it. Both turns move the mirror direction relative to the light:
 * M v = R v + (t / dl) (I - li li^T) (v - wi (ng.v) / (ng.wi)) (docs/design.md). */
static vec3 image_of_offset(const hl_hit *h, vec3 v, vec3 li, double dl, int far) {
    vec3 r = sub3(v, scale3(h->nq, 2.0f * dot3(v, h->nq)));
    float wn = dot3(h->wi, h->n);
    if (far || !(fabsf(wn) > 1e-4f) || !(dl > 0.0)) return r;
    vec3 dq = sub3(v, scale3(h->wi, dot3(v, h->n) / wn));
    dq = sub3(dq, scale3(li, dot3(dq, li)));
    return madd3(r, dq, (float)((double)h->t / dl));
}

/* Whether a band of x's lobe, given by its two scaled axes, is narrow enough to take its image. */
static int axes_narrow(vec3 axis1, vec3 axis2) {
    return (double)length_sq3(axis1) <= HL_MAX_X_VAR && (double)length_sq3(axis2) <= HL_MAX_X_VAR;
}

static int x_band_narrow(const hl_hit *h, int xb) { return h->x_fitted && axes_narrow(h->x_axis1[xb], h->x_axis2[xb]); }

/* Where band xb's image puts the member's lobe, as the light along li (dl away, or far) sees it. */
static vec3 image_centre(const hl_hit *h, int xb, vec3 li, double dl, int far) {
    return normalize3(add3(h->mu, image_of_offset(h, h->x_offset[xb], li, dl, far)));
}

/* Adds member h, its weight scaled by g, to the components' moments as the light along li (dl away,
 * or far) sees it, its directions turned by the rotation that takes li onto wl: per band of x's
 * lobe, the member's lobe moved to that band's image and spread by the member's own band and the
 * image of x's (docs/design.md, "Merging without the sample's spread"). */
static void members_add(band_moments *bm, const hl_hit *h, vec3 li, vec3 wl, double dl, int far, double g) {
    int turn = dot3(li, wl) < 0.9999999f;
    vec3 across = turn ? rotate_onto(li, wl, h->across) : h->across;
    for (int xb = 0; xb < VMF_LOBE_BANDS; xb++) {
        if (!(h->x_share[xb] > 0.0f)) continue;
        double gx = g * (double)h->x_share[xb];
        vec3 c = h->mu, a1 = v3(0, 0, 0), a2 = v3(0, 0, 0);
        double x_rbar = 1.0;
        int image = 0;
        if (x_band_narrow(h, xb)) {
            a1 = image_of_offset(h, h->x_axis1[xb], li, dl, far);
            a2 = image_of_offset(h, h->x_axis2[xb], li, dl, far);
            double var = 0.5 * (double)(length_sq3(a1) + length_sq3(a2));
            image = var < HL_MAX_IMAGE_VAR;
            if (image) {
                c = image_centre(h, xb, li, dl, far);
                x_rbar = vmf_rbar_from_kappa(1.0 / fmax(var, 1e-12));
                if (turn) a1 = rotate_onto(li, wl, a1), a2 = rotate_onto(li, wl, a2);
            }
        }
        if (turn) c = rotate_onto(li, wl, c);
        for (int b = 0; b < h->bands; b++) {
            band_moments *m = &bm[xb * VMF_LOBE_BANDS + b];
            double w = (double)h->lum[b] * gx;
            moments_add(m, c, scale3(h->color[b], (float)gx), w, (double)h->rbar[b] * x_rbar);
            cov_add(m->s, w, c, across, h->var_along[b], h->var_across[b]);
            if (image) {
                outer_add(m->s, w, a1);
                outer_add(m->s, w, a2);
            }
        }
    }
}

/* The cluster's lobe toward a light seen from its origin along unit wl, at point y unless `far`
 * (directional light, environment): what it reflects per unit of the light's radiance at the
 * origin. Each member sees the light from its own position: its lobe is turned by the rotation
 * that takes its own direction to the light onto wl, its weight scaled by (distance from the
 * origin / its own distance)^2, and a member the light lies below contributes nothing. Lighting
 * every member from the origin instead (the paper's assumption of distant light) shifts each lobe by
 * the parallax between the two: lobes sampled from a glossy x converge on x's mirror image, and
 * for a light closer than that image the merged lobe came out narrower than the lobes it stood for
 * and the highlight too bright at its peak (1.45 times path tracing's on a corner of three Phong-100
 * planes, K = 1) and too dim around it. */
static vec3 cluster_toward(const hl_cluster *c, vec3 wl, vec3 y, int far) {
    band_moments bm[HL_COMPONENTS] = {{0}};
    double d2o = far ? 1.0 : (double)length_sq3(sub3(y, c->origin));
    for (int m = 0; m < c->count; m++) {
        const hl_hit *h = &c->hits[c->members[m]];
        vec3 li = wl;
        double g = 1.0, dist = 0.0;
        if (!far) {
            vec3 dl = sub3(y, h->p);
            float d2 = length_sq3(dl);
            if (!(d2 > 0.0f)) continue;
            dist = sqrt((double)d2);
            li = scale3(dl, (float)(1.0 / dist));
            g = d2o / (double)d2;
        }
        if (!(dot3(li, h->n) > 0.0f)) continue;
        members_add(bm, h, li, wl, dist, far, g);
    }
    vec3 sum = v3(0, 0, 0);
    for (int b = 0; b < HL_COMPONENTS; b++) {
        vmf v;
        if (!moments_vmf(&bm[b], &v)) continue;
        sum = add3(sum, scale3(bm[b].color, (float)moments_density(&bm[b], &v, wl)));
    }
    return sum;
}

/* Lobe sampling's pdf of direction wi from the origin: the far lobes by their bands' choice. */
static float cluster_pdf(const hl_cluster *c, vec3 wi) {
    double pdf = 0.0;
    for (int b = 0; b < HL_COMPONENTS; b++)
        if (c->comp_prob[b] > 0.0f) pdf += (double)c->comp_prob[b] * vmf_eval(c->far[b], wi);
    return (float)pdf;
}

/* Sets up cluster c from its members: origin, normal, far lobes. Where the shadow rays start: the
 * members' mean position (weighted like the merge), raised along their mean normal until it lies
 * above every member's tangent plane, so the rays never start under a curved surface (the paper's
 * per-ray epsilon, made explicit). */
static void cluster_make(hl_cluster *c, const hl_hit *hits, const int *members, int count) {
    c->hits = hits;
    c->members = members;
    c->count = count;
    vec3 p = v3(0, 0, 0), n = v3(0, 0, 0);
    double w = 0.0;
    int heaviest = members[0];
    float heaviest_a = -1.0f;
    band_moments bm[HL_COMPONENTS] = {{0}};
    for (int m = 0; m < count; m++) {
        const hl_hit *h = &hits[members[m]];
        float a = 0.0f;
        for (int b = 0; b < h->bands; b++) a += h->lum[b];
        members_add(bm, h, h->mu, h->mu, 0.0, 1, 1.0);
        p = madd3(p, h->p, a);
        n = madd3(n, h->n, a);
        w += (double)a;
        if (a > heaviest_a) heaviest_a = a, heaviest = members[m];
    }
    double total = 0.0;
    for (int b = 0; b < HL_COMPONENTS; b++) {
        c->far_color[b] = bm[b].color;
        if (!moments_vmf(&bm[b], &c->far[b])) bm[b].w = 0.0;
        total += bm[b].w;
    }
    for (int b = 0; b < HL_COMPONENTS; b++) c->comp_prob[b] = total > 0.0 ? (float)(bm[b].w / total) : 0.0f;
    float len = length3(n);
    p = scale3(p, (float)(1.0 / w));
    if (!(len > 1e-3f * (float)w)) { /* opposed normals: no mean side to stand on */
        c->origin = hits[heaviest].p;
        c->n = hits[heaviest].n;
        return;
    }
    n = scale3(n, 1.0f / len);
    float raise = 0.0f;
    for (int m = 0; m < count; m++) {
        const hl_hit *h = &hits[members[m]];
        float cs = dot3(n, h->n);
        if (cs > 0.1f) raise = fmaxf(raise, dot3(sub3(h->p, p), h->n) / cs);
    }
    c->origin = madd3(p, n, raise);
    c->n = n;
}

/* A lobe to light: a cluster of vMF lobes, or (traced) one secondary hit's own BSDF lobe. */
typedef struct {
    vec3 origin, n; /* where shadow rays start; no light from below n */
    const hl_cluster *c;
    const shading_point *q; /* traced: the secondary hit */
    vec3 weight;            /* traced: x's sample weight (over N) */
} lit_lobe;

/* The lobe's value toward a light along wi (at point y unless far) and the pdf with which
 * lobe_sample produces wi. */
static vec3 lobe_eval(const lit_lobe *l, vec3 wi, vec3 y, int far, float *pdf) {
    if (l->q) {
        vec3 w = to_local(l->q->frame, wi);
        *pdf = bsdf_pdf(&l->q->b, l->q->wo, w, BSDF_GLOSSY);
        if (!(w.z > 0.0f) || !(dot3(wi, l->n) > 0.0f)) return v3(0, 0, 0);
        return mul3(l->weight, scale3(bsdf_eval(&l->q->b, l->q->wo, w, BSDF_GLOSSY), w.z));
    }
    *pdf = cluster_pdf(l->c, wi);
    return dot3(wi, l->n) > 0.0f ? cluster_toward(l->c, wi, y, far) : v3(0, 0, 0);
}

/* The lobe toward a light sample for next-event estimation: punctual lights are not sampled here
 * (each has its own shadow ray), nor the environment unless traced. */
typedef struct {
    const lit_lobe *l;
    const scene *s;
    int env_by_sampling;
} lobe_nee;

static vec3 lobe_toward(const void *ctx, const light_sample *ls, float *pdf) {
    const lobe_nee *n = ctx;
    if (ls->delta || (n->s->lights[ls->light].type != LIGHT_TRIANGLE && !n->env_by_sampling)) return v3(0, 0, 0);
    return lobe_eval(n->l, ls->wi, ls->p_light, !isfinite(ls->dist), pdf);
}

/* A direction from the lobe (BSDF sampling, or the far vMF bands); 0 when none. */
static int lobe_sample(const lit_lobe *l, rng_state *rng, vec3 *wi) {
    float u_band = rng_float(rng);
    vec2 u = rng_vec2(rng);
    if (!l->q) {
        int b = 0;
        while (b < HL_COMPONENTS - 1 && u_band >= l->c->comp_prob[b]) u_band -= l->c->comp_prob[b++];
        if (!(l->c->comp_prob[b] > 0.0f)) return 0;
        *wi = vmf_sample(l->c->far[b], u);
        return 1;
    }
    bsdf_sample_result bs;
    if (!bsdf_sample(&l->q->b, l->q->wo, BSDF_GLOSSY, 0.0f, u, &bs) || !(bs.pdf > 0.0f)) return 0;
    *wi = to_world(l->q->frame, bs.wi);
    return 1;
}

/* The emission the lobe's sample wi finds, weighted against next-event estimation's light sample:
 * at its hit and, as shadow rays do, beyond glass they pass (scene_glass_pass). */
static vec3 lobe_emission(const scene *s, const lit_lobe *l, vec3 wi, int env_by_sampling, render_stats *st) {
    vec3 sum = v3(0, 0, 0), tr = v3s(1.0f), sigma = v3s(0.0f), o = offset_origin(s, l->origin, l->n, wi);
    for (int k = 0; k <= SCENE_MAX_GLASS && !is_black3(tr); k++) {
        surface_hit e;
        float pdf;
        st->rays[RAY_BOUNCE]++;
        if (!scene_intersect(s, o, wi, INFINITY, &e)) {
            vec3 f = env_by_sampling ? lobe_eval(l, wi, wi, 1, &pdf) : v3(0, 0, 0);
            tr = mul3(tr, medium_transmittance(sigma, INFINITY));
            if (!is_black3(f) && pdf > 0.0f)
                sum = add3(sum, scale3(mul3(mul3(f, tr), env_eval(s, wi)),
                                       nee_emission_weight(s, l->origin, NULL, wi, pdf) / pdf));
            break;
        }
        tr = mul3(tr, medium_transmittance(sigma, e.t));
        vec3 le = s->tri_light[e.tri] >= 0 ? material_emission(s, &e) : v3(0, 0, 0);
        vec3 f = is_black3(le) ? le : lobe_eval(l, wi, e.p, 0, &pdf);
        if (!is_black3(f) && pdf > 0.0f)
            sum = add3(sum, scale3(mul3(mul3(f, tr), le), nee_emission_weight(s, l->origin, &e, wi, pdf) / pdf));
        tr = mul3(tr, scene_glass_pass(s, &e, wi, &sigma));
        o = offset_origin(s, e.p, e.ng, wi);
    }
    return sum;
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
        vec3 f = lobe_eval(l, ls.wi, ls.p_light, !isfinite(ls.dist), &pdf);
        if (is_black3(f)) continue; /* outside the lobe: no shadow ray */
        vec3 tr = light_sample_visible(s, l->origin, l->n, &ls, v3s(0.0f), &st->rays[RAY_SHADOW]);
        sum = add3(sum, mul3(mul3(f, ls.radiance), tr));
    }
    int env_by_sampling = traced && s->env_light >= 0;
    if (h->area_lights || env_by_sampling) {
        float u_sel = rng_float(rng);
        vec2 u = rng_vec2(rng);
        lobe_nee ctx = {l, s, env_by_sampling};
        vec3 f_light, arrival = nee_direct(s, l->origin, l->n, v3s(0.0f), u_sel, u, rng, lobe_toward, &ctx,
                                           &st->rays[RAY_SHADOW], &f_light, NULL);
        sum = add3(sum, mul3(f_light, arrival));
        vec3 wi;
        if (lobe_sample(l, rng, &wi)) sum = add3(sum, lobe_emission(s, l, wi, env_by_sampling, st));
    }
    if (!traced && h->env_filter) {
        /* One occlusion ray along the heaviest band's mean decides for the lobe (paper, Sec. 6.4). */
        int main_band = 0;
        for (int b = 1; b < HL_COMPONENTS; b++)
            if (l->c->comp_prob[b] > l->c->comp_prob[main_band]) main_band = b;
        vec3 dir = l->c->far[main_band].mu;
        vec3 e = v3(0, 0, 0);
        if (dot3(dir, l->n) > 0.0f)
            for (int b = 0; b < HL_COMPONENTS; b++)
                if (l->c->comp_prob[b] > 0.0f)
                    e = add3(e, mul3(l->c->far_color[b], env_vmf_filter_lookup(h->env_filter, l->c->far[b])));
        if (!is_black3(e)) {
            st->rays[RAY_SHADOW]++;
            if (!scene_occluded(s, offset_origin(s, l->origin, l->n, dir), dir, INFINITY)) sum = add3(sum, e);
        }
    }
    return sum;
}

/* Lobes more anisotropic than this (larger roughness over smaller) are not fitted by a vMF: no
 * isotropic vMF follows their streak (the default scene's brushed metals: over half the vMF
 * modes' error). Nor are two lobes of two widths (a clear coat over a glossy base). */
#define HL_MAX_VMF_ASPECT 1.5f
/* Nor are lobes whose broadest band has less of its mass above the surface than this: a broad lobe
 * seen at a grazing angle, cut by the horizon and bent toward the normal by the cosine, is no
 * vMF about the mirror direction (GGX alpha 0.36 in a corner of three planes: 0.83 of path
 * tracing's highlights as vMFs). Broad lobes gain little from merging anyway: a light is rarely
 * outside them. */
#define HL_MIN_MASS_ABOVE 0.9

enum { HIT_NONE = 0, HIT_VMF, HIT_TRACE };

/* x's lobe as bands in world space; not fitted (the members keep the sample's spread) when it is
 * no single round-enough lobe. */
static x_lobe x_lobe_fit(const shading_point *x) {
    x_lobe xl = {0};
    vmf_lobe lobe;
    vec3 albedo;
    if (!bsdf_glossy_is_single(&x->b) || bsdf_glossy_aspect(&x->b) > HL_MAX_VMF_ASPECT ||
        !vmf_fit_glossy_bands(&x->b, x->wo, &lobe, &albedo))
        return xl;
    double sq = fmax((double)lobe.squeeze, 1e-3);
    vec3 across = cross3(x->frame.n, to_world(x->frame, x->wo));
    float al = length3(across);
    xl.sharp = 1;
    for (int b = 0; b < VMF_LOBE_BANDS; b++) {
        int band = b < lobe.bands ? b : 0;
        double k = fmax((double)lobe.band[band].kappa, 1e-6);
        vec3 mu = normalize3(to_world(x->frame, lobe.band[band].mu));
        vec3 a = al > 1e-6f ? scale3(across, 1.0f / al) : frame_from_normal(mu).t;
        a = normalize3(sub3(a, scale3(mu, dot3(a, mu))));
        xl.mu[b] = mu;
        xl.axis1[b] = scale3(cross3(mu, a), (float)sqrt(1.0 / (k * sq))); /* along the plane of incidence */
        xl.axis2[b] = scale3(a, (float)sqrt(sq / k));
        if (!axes_narrow(xl.axis1[b], xl.axis2[b])) xl.sharp = 0;
    }
    xl.fitted = 1;
    return xl;
}

/* Records in hit what it needs to take x's lobe's image (members_add): the sampled direction wi,
 * its length t to q, q's shading normal nq, and per band of x's lobe the offset to the band's mean
 * and its axes. */
static void hit_record_x(hl_hit *hit, const x_lobe *xl, vec3 wi, float t, vec3 nq) {
    hit->wi = wi;
    hit->t = t;
    hit->nq = nq;
    hit->x_fitted = xl->fitted;
    for (int xb = 0; xb < VMF_LOBE_BANDS; xb++) {
        hit->x_offset[xb] = xl->fitted ? sub3(xl->mu[xb], wi) : v3(0, 0, 0);
        hit->x_axis1[xb] = xl->axis1[xb];
        hit->x_axis2[xb] = xl->axis2[xb];
    }
}

/* Fills hit's record from the secondary hit q reached with x's sample weight and x's bands'
 * shares there. Returns HIT_VMF, HIT_TRACE when the lobe is to be lit through its own BSDF, or
 * HIT_NONE when it carries nothing. */
static int hit_record(hl_hit *hit, const shading_point *q, vec3 weight, const float *x_share) {
    vmf_lobe lobe;
    vec3 albedo;
    if (!bsdf_glossy_is_single(&q->b) || bsdf_glossy_aspect(&q->b) > HL_MAX_VMF_ASPECT) return HIT_TRACE;
    if (!vmf_fit_glossy_bands(&q->b, q->wo, &lobe, &albedo)) return HIT_NONE;
    /* The normal lies in the plane of incidence: what the horizon cuts is the spread along it. */
    double sq = fmax((double)lobe.squeeze, 1e-3), broadest = (double)lobe.band[0].kappa;
    for (int b = 1; b < lobe.bands; b++) broadest = fmin(broadest, (double)lobe.band[b].kappa);
    vec3 mu = normalize3(to_world(q->frame, lobe.band[0].mu));
    float cos_n = dot3(mu, q->ng), total = 0.0f;
    if (vmf_mass_above(broadest * sq, (double)cos_n) < HL_MIN_MASS_ABOVE) return HIT_TRACE;
    hit->p = q->p;
    hit->n = q->ng;
    hit->mu = mu;
    vec3 across = cross3(q->frame.n, to_world(q->frame, q->wo));
    float al = length3(across);
    hit->across = al > 1e-6f ? scale3(across, 1.0f / al) : frame_from_normal(hit->mu).t;
    hit->bands = lobe.bands;
    for (int b = 0; b < VMF_LOBE_BANDS; b++) hit->x_share[b] = x_share[b];
    vec3 color = mul3(weight, albedo);
    for (int b = 0; b < VMF_LOBE_BANDS; b++) {
        hit->color[b] = v3(0, 0, 0);
        hit->lum[b] = hit->rbar[b] = hit->var_along[b] = hit->var_across[b] = 0.0f;
    }
    for (int b = 0; b < lobe.bands; b++) {
        double k = fmax((double)lobe.band[b].kappa, 1e-6), above = vmf_mass_above(k * sq, (double)cos_n);
        hit->color[b] = scale3(color, (float)((double)lobe.weight[b] / fmax(above, 0.05)));
        hit->lum[b] = luminance3(hit->color[b]);
        hit->rbar[b] = (float)vmf_rbar_from_kappa(k);
        hit->var_along[b] = (float)(1.0 / (k * sq));
        hit->var_across[b] = (float)(sq / k);
        total += hit->lum[b];
    }
    for (int b = 0; b < lobe.bands; b++)
        if (!is_finite3(hit->color[b])) return HIT_NONE;
    return total > 0.0f && isfinite(total) ? HIT_VMF : HIT_NONE;
}

/* The lobes merged at one point: EM on the members' image directions, each cluster lit once. */
static vec3 merge_and_light(const hl_setup *h, const scene *s, const hl_hit *hits, const int *index, int m,
                            rng_state *rng, render_stats *st) {
    vec3 sum = v3(0, 0, 0), dirs[HL_MAX_SECONDARY_RAYS];
    float alpha[HL_MAX_SECONDARY_RAYS];
    int assign[HL_MAX_SECONDARY_RAYS], members[HL_MAX_SECONDARY_RAYS];
    uint64_t t0 = clock_ns();
    for (int i = 0; i < m; i++) {
        const hl_hit *hit = &hits[index[i]];
        /* Clustered by where x's lobe's image lies, where it is taken: members of one smooth
         * surface coincide. */
        dirs[i] = x_band_narrow(hit, 0) ? image_centre(hit, 0, hit->mu, 0.0, 1) : hit->mu;
        alpha[i] = 0.0f;
        for (int b = 0; b < hit->bands; b++) alpha[i] += hit->lum[b];
    }
    int k = vmf_em(dirs, alpha, m, h->clusters, assign);
    hl_cluster clusters[HL_MAX_CLUSTERS];
    int used = 0;
    for (int c = 0; c < k; c++) {
        int n_c = 0;
        for (int i = 0; i < m; i++)
            if (assign[i] == c) members[used + n_c++] = index[i];
        cluster_make(&clusters[c], hits, &members[used], n_c);
        used += n_c;
    }
    if (h->mode == HL_MERGED) st->hl_merge_ns += clock_ns() - t0; /* unmerged: clusters of one, no merging */
    for (int c = 0; c < k; c++) {
        lit_lobe l = {clusters[c].origin, clusters[c].n, &clusters[c], NULL, v3(0, 0, 0)};
        sum = add3(sum, light_lobe(h, s, &l, rng, st));
    }
    st->hl_lobes += (uint64_t)k;
    return sum;
}

/* Camera hit x's lobe as the estimator takes it: fitted = -1 when x has no highlight lobe facing
 * the camera; unmerged, unfitted (each member is its own sampled lobe, the paper's Fig. 4 top). */
static x_lobe point_lobe(const hl_setup *h, const shading_point *x) {
    if (!bsdf_highlight_lobe(&x->b) || !(x->wo.z > 0.0f)) return (x_lobe){.fitted = -1};
    return h->mode == HL_MERGED ? x_lobe_fit(x) : (x_lobe){0};
}

int hl_point_sharp(const hl_setup *h, const shading_point *x) { return point_lobe(h, x).sharp; }

/* Secondary hit q, reached from x along world direction wi (local wl, t away) with x's sample
 * weight, as one of x's members: recorded in *hit (returns 1), or lit at once through its own
 * BSDF and added to *sum, or nothing (returns 0). */
static int member_record(const hl_setup *h, const scene *s, const shading_point *x, const x_lobe *xl,
                         const shading_point *q, vec3 wi, vec3 wl, float t, vec3 weight, hl_hit *hit, rng_state *rng,
                         render_stats *st, vec3 *sum) {
    float x_share[VMF_LOBE_BANDS];
    vmf_glossy_band_shares(&x->b, x->wo, wl, x_share);
    int rec = h->mode == HL_TRACED ? HIT_TRACE : hit_record(hit, q, weight, x_share);
    if (rec == HIT_TRACE) {
        lit_lobe l = {q->p, q->ng, NULL, q, weight};
        *sum = add3(*sum, light_lobe(h, s, &l, rng, st));
        st->hl_lobes++;
        return 0;
    }
    if (rec == HIT_NONE) return 0;
    hit_record_x(hit, xl, wi, t, q->frame.n);
    if (h->mode == HL_UNMERGED) { /* a cluster of one */
        int one = 0;
        *sum = add3(*sum, merge_and_light(h, s, hit, &one, 1, rng, st));
        return 0;
    }
    return 1;
}

/* One secondary ray from x along its lobe's sample u: the hit q when it has a highlight lobe
 * (shaded as seen from x), with x's sample weight (before dividing by the rays) and the world
 * direction. */
static int secondary_hit(const scene *s, const shading_point *x, vec2 u, render_stats *st, surface_hit *hq,
                         shading_point *q, bsdf_sample_result *bs, vec3 *wi) {
    if (!bsdf_sample(&x->b, x->wo, BSDF_GLOSSY, 0.0f, u, bs) || !(bs->pdf > 0.0f)) return 0;
    *wi = to_world(x->frame, bs->wi);
    if (dot3(*wi, x->ng) <= 0.0f) return 0;
    st->rays[RAY_BOUNCE]++;
    st->hl_secondary_rays++;
    if (!scene_intersect(s, offset_origin(s, x->p, x->ng, *wi), *wi, INFINITY, hq)) return 0;
    *q = shading_point_at(s, hq, *wi);
    return bsdf_highlight_lobe(&q->b) != 0; /* a rough lobe: the VSLs keep these paths */
}

vec3 hl_estimate(const hl_setup *h, const scene *s, const shading_point *xs, int points, const qmc_run *runs,
                 rng_state *rng, render_stats *st, int *sharp, vec3 *traced_out) {
    vec3 sum = v3(0, 0, 0);
    if (traced_out) *traced_out = sum;
    int n = h->secondary_rays;
    if (points < 1) return sum;
    if (points > n) points = n;
    hl_hit hits[HL_MAX_SECONDARY_RAYS];
    int hit_point[HL_MAX_SECONDARY_RAYS], count = 0;
    x_lobe xl[HL_MAX_SECONDARY_RAYS];
    int lit = 0;
    for (int j = 0; j < points; j++) {
        xl[j] = point_lobe(h, &xs[j]);
        if (xl[j].fitted < 0) continue;
        lit++;
        *sharp |= xl[j].sharp;
    }
    if (!lit) return sum;
    st->hl_points += (uint64_t)lit;
    /* In a share of the frames the merged lobes are checked: the same hits lit through their own
     * lobes (the trace, the path tracer's answer for these paths), and (traced - merged) / share
     * added, so the estimate's expectation is the trace's (docs/design.md, "The highlight
     * estimator"). */
    int check = h->mode == HL_MERGED && h->check_share > 0.0f && rng_float(rng) < h->check_share;
    int trace_too = check || (traced_out && h->mode == HL_MERGED);
    vec3 traced = v3(0, 0, 0);
    /* The N directions stratified over the lobes and over frames (each point's run), ray k from
     * point k mod points, each point's rays weighted 1 / (points x its rays): the mean over the
     * points. */
    for (int k = 0; k < n; k++) {
        int j = k % points;
        if (xl[j].fitted < 0) continue;
        surface_hit hq;
        shading_point q;
        bsdf_sample_result bs;
        vec3 wi;
        if (!secondary_hit(s, &xs[j], qmc_run_point(runs[j], (uint32_t)(k / points)), st, &hq, &q, &bs, &wi)) continue;
        vec3 weight = scale3(bs.f, bs.wi.z / (bs.pdf * (float)(hl_rays_of_point(n, points, j) * points)));
        if (member_record(h, s, &xs[j], &xl[j], &q, wi, bs.wi, hq.t, weight, &hits[count], rng, st, &sum)) {
            hit_point[count++] = j;
            if (trace_too) {
                lit_lobe l = {q.p, q.ng, NULL, &q, weight};
                traced = add3(traced, light_lobe(h, s, &l, rng, st));
            }
        }
    }
    vec3 merged = v3(0, 0, 0);
    /* Each point's lobes are merged among themselves: rays from points spread over a curved mirror
     * part ways, and lobes merged across them made the highlights 18% off on atelier. */
    for (int j = 0; j < points; j++) {
        int index[HL_MAX_SECONDARY_RAYS], m = 0;
        for (int i = 0; i < count; i++)
            if (hit_point[i] == j) index[m++] = i;
        if (m > 0) merged = add3(merged, merge_and_light(h, s, hits, index, m, rng, st));
    }
    /* sum holds so far what both estimates share (lobes lit through their own BSDF) */
    if (traced_out) *traced_out = add3(sum, traced);
    sum = add3(sum, merged);
    if (check) sum = madd3(sum, sub3(traced, merged), 1.0f / h->check_share);
    return sum;
}

/* ---- hits shared among neighbouring pixels ----------------------------------------------------- */

/* A secondary hit in a block's pool: q as shaded from the point whose ray found it, and each point's
 * direction to it, distance and density of finding it. */
typedef struct {
    shading_point q;
    int from;
    vec3 dir[HL_SHARE_POINTS];
    float dist[HL_SHARE_POINTS];
    float pdf_area[HL_SHARE_POINTS]; /* per unit area at q; 0 where the point cannot find q */
    double rays_pdf;                 /* N times their sum: the block's density at q */
} pool_hit;

/* Where q (on the side its normal ng faces) lies from x: unit *dir, *dist away, and x's density of
 * finding it by sampling its glossy lobe, per unit area at q (the solid angle's pdf times
 * cos at q / dist^2); 0 where x's sampling cannot reach it. Visibility is the caller's. */
static float area_pdf(const shading_point *x, vec3 qp, vec3 qng, vec3 *dir, float *dist) {
    vec3 d = sub3(qp, x->p);
    float len = length3(d);
    if (!(len > 0.0f)) return 0.0f;
    *dir = scale3(d, 1.0f / len);
    *dist = len;
    float cq = -dot3(*dir, qng);
    vec3 wl = to_local(x->frame, *dir);
    if (!(dot3(*dir, x->ng) > 0.0f) || !(cq > 0.0f) || !(wl.z > 0.0f)) return 0.0f;
    float p = bsdf_pdf(&x->b, x->wo, wl, BSDF_GLOSSY);
    return p > 0.0f ? p * cq / (len * len) : 0.0f;
}

/* Whether x sees q along unit dir (a shadow ray between the offset points). */
static int sees(const scene *s, const shading_point *x, const shading_point *q, vec3 dir, render_stats *st) {
    vec3 org = offset_origin(s, x->p, x->ng, dir), target = offset_origin(s, q->p, q->ng, neg3(dir));
    vec3 span = sub3(target, org);
    float len = length3(span);
    st->rays[RAY_SHADOW]++;
    return len > 0.0f && dot3(span, dir) > 0.0f && !scene_occluded(s, org, scale3(span, 1.0f / len), len);
}

unsigned hl_estimate_shared(const hl_setup *h, const scene *s, const shading_point *xs, int m, qmc_run run,
                            const int *slot, rng_state *rngs, render_stats *st, vec3 *out) {
    int n = h->secondary_rays < HL_SHARE_MAX_RAYS ? h->secondary_rays : HL_SHARE_MAX_RAYS;
    pool_hit pool[HL_SHARE_POINTS * HL_SHARE_MAX_RAYS];
    int count = 0;
    x_lobe xl[HL_SHARE_POINTS];
    /* A point merges up to 4N members, and the merge's expectation moves with the members per
     * cluster (atelier's floor: 1.000 of the reference at N = 8, K = 4; 1.124 at N = 32, K = 4;
     * 1.006 at N = 32, K = 8): twice the clusters. */
    hl_setup merge = *h;
    merge.clusters = 2 * h->clusters < HL_MAX_CLUSTERS ? 2 * h->clusters : HL_MAX_CLUSTERS;
    unsigned estimated = 0;
    for (int j = 0; j < m; j++) {
        out[j] = v3(0, 0, 0);
        xl[j] = point_lobe(h, &xs[j]);
        if (xl[j].sharp) { /* its own estimator's: no rays, no density, no estimate here */
            xl[j].fitted = -1;
            continue;
        }
        estimated |= 1u << j;
        if (xl[j].fitted >= 0) st->hl_points++;
    }
    /* The point in slot j takes the block's points j N .. j N + N - 1: its own run of N is
     * stratified (every fourth point would hold some of the sample's bits fixed, and the point would
     * sample one part of its lobe), and so are the block's 4N together. */
    for (int j = 0; j < m; j++) {
        for (int k = 0; xl[j].fitted >= 0 && k < n; k++) {
            surface_hit hq;
            bsdf_sample_result bs;
            vec3 wi;
            uint32_t index = (uint32_t)(slot[j] * n + k);
            if (!secondary_hit(s, &xs[j], qmc_run_point(run, index), st, &hq, &pool[count].q, &bs, &wi)) continue;
            pool[count++].from = j;
        }
    }
    /* Every point's density at every hit, zero where it does not see the hit (a shadow ray, but
     * for the point that found it): the balance heuristic over the points' samplings is then
     * unbiased for each point. */
    for (int i = 0; i < count; i++) {
        pool_hit *ph = &pool[i];
        ph->rays_pdf = 0.0;
        for (int j = 0; j < m; j++) {
            float *p = &ph->pdf_area[j];
            *p = xl[j].fitted >= 0 ? area_pdf(&xs[j], ph->q.p, ph->q.ng, &ph->dir[j], &ph->dist[j]) : 0.0f;
            if (*p > 0.0f && j != ph->from && !sees(s, &xs[j], &ph->q, ph->dir[j], st)) *p = 0.0f;
            ph->rays_pdf += (double)n * (double)*p;
        }
    }
    for (int a = 0; a < m; a++) {
        const shading_point *x = &xs[a];
        hl_hit hits[HL_SHARE_POINTS * HL_SHARE_MAX_RAYS];
        int index[HL_SHARE_POINTS * HL_SHARE_MAX_RAYS], members = 0;
        vec3 sum = v3(0, 0, 0);
        for (int i = 0; xl[a].fitted >= 0 && i < count; i++) {
            const pool_hit *ph = &pool[i];
            if (!(ph->pdf_area[a] > 0.0f)) continue;
            vec3 d = ph->dir[a], wl = to_local(x->frame, d);
            float dist = ph->dist[a];
            /* The pooled density in x's solid angle: per unit area x dist^2 / cos at q. */
            double pdf = ph->rays_pdf * (double)dist * (double)dist / (double)-dot3(d, ph->q.ng);
            vec3 weight = scale3(bsdf_eval(&x->b, x->wo, wl, BSDF_GLOSSY), (float)((double)wl.z / pdf));
            shading_point q = ph->q;
            q.wo = to_local(q.frame, neg3(d));
            if (!(q.wo.z > 0.0f) || !is_finite3(weight) || is_black3(weight)) continue;
            if (member_record(h, s, x, &xl[a], &q, d, wl, dist, weight, &hits[members], &rngs[a], st, &sum))
                index[members] = members, members++;
        }
        if (members > 0) sum = add3(sum, merge_and_light(&merge, s, hits, index, members, &rngs[a], st));
        out[a] = sum;
    }
    return estimated;
}
