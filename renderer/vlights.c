#include "vlights.h"

#include <stdlib.h>
#include <string.h>

#include "knn.h"
#include "lights.h"
#include "pt.h"

void vlight_set_free(vlight_set *set) {
    free(set->v);
    memset(set, 0, sizeof *set);
}

static int push(vlight_set *set, const virtual_light *vl) {
    if (set->count == set->cap) {
        int cap = set->cap ? 2 * set->cap : 1024;
        virtual_light *v = realloc(set->v, sizeof(virtual_light) * (size_t)cap);
        if (!v) return -1;
        set->v = v;
        set->cap = cap;
    }
    set->v[set->count++] = *vl;
    return 0;
}

int vlights_trace(const scene *s, int target, int max_depth, uint64_t seed, uint64_t frame, vlight_set *set,
                  uint64_t *bounce_rays) {
    set->count = 0;
    set->paths = 0;
    if (s->num_lights == 0 || target <= 0 || max_depth < 2) return 0;
    /* One stream for the whole frame: the set is the same whatever the thread count. */
    rng_state rng = rng_for(0x766c69676874ULL, frame, seed);
    /* Stop when enough lights are in, but finish the path being traced. A cap on paths keeps a
     * scene whose light escapes (an open sky) from looping for ever. */
    long long max_paths = 64LL * target + 1024;
    while (set->count < target && set->paths < max_paths) {
        set->paths++;
        light_emission e;
        float u_sel = rng_float(&rng);
        vec2 u_pos = rng_vec2(&rng), u_dir = rng_vec2(&rng);
        if (!light_sample_emission(s, u_sel, u_pos, u_dir, &e)) continue;
        vec3 beta = e.power, sigma = v3s(0.0f);
        vec3 o = e.on_surface ? offset_origin(s, e.o, e.n, e.d) : e.o;
        vec3 d = e.d;
        /* events: scattering events so far, transmissions not counted (pt.c counts depth so); depth:
         * every surface met; bounce: the lights' bounce, every surface met but glass that shadow
         * rays pass (the highlight estimator sees the light through it, so the first surface
         * beyond it is bounce 1, as for the path tracer's split: docs/design.md). */
        for (int depth = 1, events = 1, bounce = 1; events < max_depth && depth < max_depth + PT_MAX_TRANSMISSIONS;
             depth++) {
            surface_hit h;
            (*bounce_rays)++;
            if (!scene_intersect(s, o, d, INFINITY, &h)) break;
            beta = mul3(beta, medium_transmittance(sigma, h.t));
            virtual_light vl;
            memset(&vl, 0, sizeof vl);
            bsdf b = material_bsdf(s, &h, &vl.frame);
            if (!bsdf_lobes(&b)) break; /* black: absorbs everything */
            /* No virtual light is seen through a transmission (the gather's visibility stops at
             * glass): the virtual light keeps the reflecting lobes, and the path carries on
             * through the transmission. */
            vl.b = bsdf_only(&b, BSDF_ALL & ~BSDF_TRANSMIT);
            vl.p = h.p;
            vl.ng = h.ng;
            vl.wi = to_local(vl.frame, neg3(d));
            /* Shading normals are not symmetric (Veach 1997, sec. 5.3): the light arrives through
             * the geometric surface but the BSDF weighs it by the shading normal's cosine, so the
             * light here carries |wi.ns| / |wi.ng| and leaves by the geometric cosine (below, and
             * at the gather in vsl.c): the path tracer's answer with any normal map. */
            vec3 beta_in = scale3(beta, fmaxf(vl.wi.z, 0.0f) / dot3(neg3(d), h.ng));
            vl.power = beta_in;
            vl.depth = bounce;
            if (vl.wi.z > 0.0f && bsdf_lobes(&vl.b) && push(set, &vl) != 0) return -1;
            int capped = events + 1 >= max_depth;
            if (capped && !(bsdf_lobes(&b) & BSDF_TRANSMIT)) break;

            bsdf_sample_result bs;
            float u_lobe = rng_float(&rng);
            vec2 u = rng_vec2(&rng);
            if (!bsdf_sample(&b, vl.wi, capped ? BSDF_TRANSMIT : BSDF_ALL, u_lobe, u, &bs) || !(bs.pdf > 0.0f)) break;
            vec3 wi = to_world(vl.frame, bs.wi);
            if (!bsdf_side_ok(bs.wi, dot3(wi, h.ng))) break;
            /* Light flows from vl.wi to wi: the adjoint BSDF (refraction's eta^2). */
            vec3 gain = scale3(bs.f, fabsf(dot3(wi, h.ng)) / bs.pdf * bsdf_adjoint_scale(&b, vl.wi, bs.wi));
            /* By the bounce's gain (the path's weight is the light's power), after a couple of
             * bounces. */
            if (depth >= 2 && !russian_roulette(&gain, rng_float(&rng))) break;
            beta = mul3(beta_in, gain);
            if (is_black3(beta) || !is_finite3(beta)) break;
            sigma = material_medium_after(&s->materials[h.material], h.backface, bs.lobe, sigma);
            events += bs.lobe != BSDF_TRANSMIT;
            bounce += bs.lobe != BSDF_TRANSMIT || is_black3(material_pass_through(s, &h, &b, vl.wi));
            o = offset_origin(s, h.p, h.ng, wi);
            d = wi;
        }
    }
    float inv = set->paths > 0 ? 1.0f / (float)set->paths : 0.0f;
    for (int i = 0; i < set->count; i++) set->v[i].power = scale3(set->v[i].power, inv);
    return 0;
}

int vlights_set_radii(vlight_set *set, float mult, float scene_diag) {
    if (set->count == 0) return 0;
    float *dist = malloc(sizeof(float) * (size_t)set->count);
    if (!dist) return -1;
    if (knn_distances(&set->v[0].p, sizeof(virtual_light), set->count, VSL_NEIGHBOURS, dist) != 0) {
        free(dist);
        return -1;
    }
    float floor_r = 1e-5f * scene_diag;
    for (int i = 0; i < set->count; i++) set->v[i].radius = fmaxf(mult * dist[i], floor_r);
    free(dist);
    return 0;
}
