/* Ray queries against the scene's BVH (alpha.c builds it): the closest hit, one or a packet, with
 * its shading frame; occlusion; and the transmittance of shadow rays through glass. */
#include <math.h>

#include "scene_parts.h"

static void init_ray(struct RTCRay *r, vec3 o, vec3 d, float tmax) {
    r->org_x = o.x;
    r->org_y = o.y;
    r->org_z = o.z;
    r->tnear = 0.0f;
    r->dir_x = d.x;
    r->dir_y = d.y;
    r->dir_z = d.z;
    r->time = 0.0f;
    r->tfar = tmax;
    r->mask = 0xFFFFFFFFu;
    r->id = 0;
    r->flags = 0;
}

/* Fills h from Embree's hit (triangle t, barycentrics b1 b2, distance tfar) of the ray along d. */
static void complete_hit(const scene *s, vec3 d, int t, float b1, float b2, float tfar, surface_hit *h) {
    const uint32_t *v = &s->indices[3 * t];
    /* A ray in the triangle's plane through one of its corners can come back with NaN
     * barycentrics: the hit is that triangle, so keep the point on it. */
    if (!isfinite(b1) || !isfinite(b2)) b1 = b2 = 0.0f;
    float b0 = 1.0f - b1 - b2;
    vec3 p0 = s->positions[v[0]], p1 = s->positions[v[1]], p2 = s->positions[v[2]];
    h->t = tfar;
    h->tri = t;
    h->material = s->tri_material[t];
    /* Barycentric interpolation is more accurate than o + t d far from the origin. */
    h->p = add3(add3(scale3(p0, b0), scale3(p1, b1)), scale3(p2, b2));
    vec3 ng = s->tri_normal[t];
    h->backface = dot3(ng, d) > 0.0f;
    if (h->backface) ng = neg3(ng);
    h->ng = ng;
    h->uv0 = triangle_uv(s, s->uv0, t, b1, b2);
    h->uv1 = triangle_uv(s, s->uv1, t, b1, b2);

    shading_frame_at_hit(s, h, b1, b2, d);
}

int scene_intersect(const scene *s, vec3 o, vec3 d, float tmax, surface_hit *h) {
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    struct RTCRayHit rh;
    init_ray(&rh.ray, o, d, tmax);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(s->rtc, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return 0;
    complete_hit(s, d, scene_hit_triangle(s, rh.hit.geomID, rh.hit.primID), rh.hit.u, rh.hit.v, rh.ray.tfar, h);
    return 1;
}

_Static_assert(SCENE_PACKET == 16, "scene_intersect_packet traces one RTCRayHit16");

unsigned scene_intersect_packet(const scene *s, vec3 o, const vec3 *d, int n, surface_hit *h) {
    /* One 16-wide packet: Embree traverses the BVH once for rays that go the same way. */
    RTC_ALIGN(64) int valid[SCENE_PACKET]; /* Embree reads the mask and packet as aligned vectors */
    RTC_ALIGN(64) struct RTCRayHit16 rh;
    for (int i = 0; i < SCENE_PACKET; i++) {
        int live = i < n;
        valid[i] = live ? -1 : 0;
        vec3 di = live ? d[i] : v3(0, 0, 1);
        rh.ray.org_x[i] = o.x;
        rh.ray.org_y[i] = o.y;
        rh.ray.org_z[i] = o.z;
        rh.ray.tnear[i] = 0.0f;
        rh.ray.dir_x[i] = di.x;
        rh.ray.dir_y[i] = di.y;
        rh.ray.dir_z[i] = di.z;
        rh.ray.time[i] = 0.0f;
        rh.ray.tfar[i] = INFINITY;
        rh.ray.mask[i] = 0xFFFFFFFFu;
        rh.ray.id[i] = (unsigned)i;
        rh.ray.flags[i] = 0;
        rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
    }
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    rtcIntersect16(valid, s->rtc, &ctx, &rh);
    unsigned hits = 0;
    for (int i = 0; i < n; i++) {
        if (rh.hit.geomID[i] == RTC_INVALID_GEOMETRY_ID) continue;
        complete_hit(s, d[i], scene_hit_triangle(s, rh.hit.geomID[i], rh.hit.primID[i]), rh.hit.u[i], rh.hit.v[i],
                     rh.ray.tfar[i], &h[i]);
        hits |= 1u << i;
    }
    return hits;
}

/* One occlusion query; with record, the glass passed is in ctx. */
static int occluded(const scene *s, vec3 o, vec3 d, float tmax, int record, shadow_context *ctx) {
    rtcInitIntersectContext(&ctx->rtc);
    ctx->record = record;
    ctx->count = 0;
    struct RTCRay r;
    init_ray(&r, o, d, tmax);
    rtcOccluded1(s->rtc, &ctx->rtc, &r);
    return r.tfar < 0.0f; /* Embree sets tfar to -inf on a hit */
}

int scene_occluded(const scene *s, vec3 o, vec3 d, float tmax) {
    shadow_context ctx;
    return occluded(s, o, d, tmax, 0, &ctx);
}

/* The glass a shadow ray recorded (ctx), in order along the ray (the filter saw it in the BVH's
 * order): each surface's pass and Beer-Lambert between. Apart, so that shadow rays meeting no
 * glass keep a small frame. */
static vec3 glass_transmittance(const scene *s, const shadow_context *ctx, vec3 o, vec3 d, float tmax, vec3 sigma) {
    surface_hit h[SCENE_MAX_GLASS];
    for (int k = 0; k < ctx->count; k++) {
        complete_hit(s, d, ctx->hit[k].tri, ctx->hit[k].b1, ctx->hit[k].b2, 0.0f, &h[k]);
        h[k].t = dot3(sub3(h[k].p, o), d);
        for (int j = k; j > 0 && h[j].t < h[j - 1].t; j--) {
            surface_hit tmp = h[j];
            h[j] = h[j - 1], h[j - 1] = tmp;
        }
    }
    vec3 tr = v3s(1.0f);
    float t0 = 0.0f;
    for (int k = 0; k < ctx->count && !is_black3(tr); k++) {
        /* A ray through an edge or a corner meets each triangle there: one crossing. */
        if (k > 0 && h[k].material == h[k - 1].material && h[k].t - h[k - 1].t <= scene_offset_eps(s, h[k].p)) continue;
        tr = mul3(tr, medium_transmittance(sigma, h[k].t - t0));
        tr = mul3(tr, scene_glass_pass(s, &h[k], d, &sigma));
        t0 = h[k].t;
    }
    return mul3(tr, medium_transmittance(sigma, tmax - t0));
}

vec3 scene_transmittance(const scene *s, vec3 o, vec3 d, float tmax, vec3 sigma) {
    shadow_context ctx;
    if (occluded(s, o, d, tmax, 1, &ctx)) return v3s(0.0f);
    return ctx.count ? glass_transmittance(s, &ctx, o, d, tmax, sigma) : medium_transmittance(sigma, tmax);
}

vec3 scene_glass_pass(const scene *s, const surface_hit *h, vec3 d, vec3 *sigma) {
    if (!scene_material_passes_shadows(s, h->material)) return v3s(0.0f);
    frame3 fr;
    bsdf b = material_bsdf(s, h, &fr);
    *sigma = material_medium_after(&s->materials[h->material], h->backface, BSDF_TRANSMIT, *sigma);
    return material_pass_through(s, h, &b, to_local(fr, neg3(d)));
}
