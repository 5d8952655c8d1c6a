#include "pt.h"

#include "lights.h"

/* The component a path belongs to, by the scattering events before the vertex where it reaches
 * an emitter, transmissions not counted (0: the camera hit itself, 1: one bounce, i.e. direct
 * lighting, also through glass). */
static inline film_component component_of(int emitter_vertex) {
    return emitter_vertex <= 1 ? COMP_DIRECT : COMP_INDIRECT;
}

/* A contribution c of a path that reaches the light at its third vertex, whose part through the
 * highlight lobes (bsdf_highlight_lobe) of both scattering vertices is hl: that part to the
 * highlights, the rest indirect. */
static void add_split(vec3 out[COMP_COUNT], vec3 c, vec3 hl) {
    out[COMP_HIGHLIGHTS] = add3(out[COMP_HIGHLIGHTS], hl);
    vec3 rest = sub3(c, hl); /* >= 0 up to rounding: f >= its glossy lobe */
    out[COMP_INDIRECT] = add3(out[COMP_INDIRECT], v3(fmaxf(rest.x, 0.0f), fmaxf(rest.y, 0.0f), fmaxf(rest.z, 0.0f)));
}

/* Where a path's light goes: out per component, and with glossy (not NULL) the part of it that left
 * the camera hit through a view-dependent lobe (BSDF_VIEW_DEPENDENT) there too, for a display. Each
 * contribution c comes with that part g. */
typedef struct {
    vec3 *out, *glossy;
} path_sink;

static void put(path_sink o, int comp, vec3 c, vec3 g) {
    o.out[comp] = add3(o.out[comp], c);
    if (o.glossy) o.glossy[comp] = add3(o.glossy[comp], g);
}

/* add_split for a path_sink: the highlights' part hl left the camera hit through a glossy lobe. */
static void put_split(path_sink o, vec3 c, vec3 g, vec3 hl) {
    add_split(o.out, c, hl);
    if (o.glossy) add_split(o.glossy, g, hl);
}

/* Emission le reached at vertex `depth` (glass that shadow rays pass after the second scattering
 * event not counted) with MIS weight w: to its component, split into highlights for the paths
 * that reach the light at their third vertex (`before`: the scattering events before the ray's
 * origin, 1 for a continuation, which the split counts). */
static void add_emission(path_sink out, int depth, int events, int before, int split_highlights, vec3 beta, vec3 beta_g,
                         vec3 beta_hl, vec3 le, float w) {
    vec3 c = scale3(mul3(beta, le), w), g = scale3(mul3(beta_g, le), w);
    if (split_highlights && depth + before == 2 && events + before == 2)
        put_split(out, c, g, scale3(mul3(beta_hl, le), w));
    else
        put(out, component_of(events), c, g);
}

/* A BSDF's lobes as next-event estimation sees them: their value, and the pdf of the lobes the
 * vertex samples its continuation from (pdf_lobes); for lights above the surface, or with below
 * those beyond it (its transmission). With image_alpha > 0 the vertex is a regularised one
 * (docs/design.md, "Regularised images"): a point or spot light at distance d sees its glossy
 * lobes widened to image_alpha (1 + near_t / d), near_t the distance the ray came. */
typedef struct {
    const bsdf *b;
    frame3 fr;
    vec3 wo;
    int lobes, pdf_lobes, below;
    float image_alpha, near_t;
} bsdf_lobe;

/* The BSDF that light sample ls sees at l: l's own, or for a delta light at a regularised vertex
 * a copy in *store widened to image_alpha (1 + near_t / d). */
static const bsdf *bsdf_lobe_for(const bsdf_lobe *l, const light_sample *ls, bsdf *store) {
    if (!(l->image_alpha > 0.0f) || !ls->delta) return l->b;
    float near = ls->dist > 0.0f ? l->near_t / ls->dist : INFINITY; /* 0 for a directional light */
    *store = *l->b;
    bsdf_regularize(store, fminf(l->image_alpha * (1.0f + near), BSDF_HIGHLIGHT_ALPHA));
    return store;
}

static vec3 bsdf_lobe_toward(const void *ctx, const light_sample *ls, float *lobe_pdf) {
    const bsdf_lobe *l = ctx;
    vec3 wi = to_local(l->fr, ls->wi);
    if (!(l->below ? wi.z < 0.0f : wi.z > 0.0f)) return v3(0, 0, 0);
    bsdf store;
    vec3 f = bsdf_eval(bsdf_lobe_for(l, ls, &store), l->wo, wi, l->lobes);
    /* A delta light's weight needs no lobe pdf: skip evaluating it (point and spot lights are
     * common, and this runs at every vertex). */
    if (!ls->delta && !is_black3(f)) *lobe_pdf = bsdf_pdf(l->b, l->wo, wi, l->pdf_lobes);
    return scale3(f, fabsf(wi.z));
}

/* What a caller fixes at a path's first vertex: the lobes it may leave by (BSDF_NOT_HIGHLIGHT: see
 * trace_path), the run whose point 0 its bounce takes (NULL: drawn), and the number that selects the
 * light of its next-event estimation (< 0: drawn). */
typedef struct {
    int lobes;
    const qmc_run *run;
    float u_select;
} first_vertex;

/* The path tracer, for a ray (o, d) whose closest hit the caller has traced: *first, or NULL when
 * the ray escaped; the ray travels in a medium of absorption sigma. A continuation ray is a bounce
 * of a path begun elsewhere: the emission it finds first belongs to that path's direct light and
 * is not counted. With split_highlights the paths camera - glossy - glossy - light go to
 * COMP_HIGHLIGHTS: the product of the two vertices' highlight lobes, out of the same samples (the
 * lobes add up to the BSDF); a continuation then left the camera hit through its highlight lobe,
 * and its first hit is the second vertex (its light's rest goes to COMP_INDIRECT). max_depth
 * counts scattering events; transmissions are free (beyond the depth only transmission carries
 * on), up to PT_MAX_TRANSMISSIONS more vertices. reg widens glossy lobes (pt_regularize; zero:
 * none); fv fixes what first_vertex says. */
static void trace_path(const scene *s, int max_depth, vec3 o, vec3 d, vec3 sigma, const surface_hit *first,
                       rng_state *rng, path_sink out, uint64_t rays[RAY_KIND_COUNT], int continuation,
                       int split_highlights, first_vertex fv, pt_regularize reg) {
    for (int c = 0; c < COMP_COUNT; c++) {
        out.out[c] = v3(0, 0, 0);
        if (out.glossy) out.glossy[c] = v3(0, 0, 0);
    }
    vec3 beta = v3s(1.0f);
    /* beta's part that left the first vertex through its view-dependent lobes (only with out.glossy;
     * a continuation has none: its caller splits) */
    vec3 beta_g = v3s(0.0f);
    /* the throughput through highlight lobes only (of the first two scattering events) */
    vec3 beta_hl = v3s(split_highlights && continuation ? 1.0f : 0.0f);
    /* The last scattering vertex (prev_p): the pdf of the BSDF sample that left it and whether
     * next-event estimation there could have found what the ray finds, also beyond glass that
     * shadow rays pass (material_pass_through), which leaves these as they are. */
    float prev_pdf = 0.0f;
    int prev_nee = 0;
    vec3 prev_p = o;
    int passes = 0; /* such glass passed after the second scattering event (the highlight split) */
    /* With fv.lobes BSDF_NOT_HIGHLIGHT: the share of the path that left the first vertex by its
     * highlight lobe. Its light is the highlight estimator's while only glass that shadow rays
     * pass lies between; at the first other vertex it joins the path (docs/design.md). Only in
     * scenes with glass: without, it could only be lost. */
    vec3 held = v3s(0.0f);
    for (int depth = 0, events = 0;; depth++) {
        surface_hit h;
        rays[depth == 0 && !continuation ? RAY_CAMERA : RAY_BOUNCE]++;
        int hit;
        if (depth > 0)
            hit = scene_intersect(s, o, d, INFINITY, &h);
        else if ((hit = first != NULL))
            h = *first;
        if (!hit) {
            vec3 le = env_eval(s, d);
            if (!is_black3(le) && (events > 0 || !continuation)) {
                float w = prev_nee ? nee_emission_weight(s, prev_p, NULL, d, prev_pdf) : 1.0f;
                vec3 tr = medium_transmittance(sigma, INFINITY);
                add_emission(out, depth - passes, events, continuation, split_highlights, mul3(beta, tr),
                             mul3(beta_g, tr), beta_hl, le, w);
            }
            break;
        }
        vec3 tr = medium_transmittance(sigma, h.t);
        beta = mul3(beta, tr), beta_g = mul3(beta_g, tr);
        vec3 le = material_emission(s, &h);
        /* A continuation's light before its first scattering event is the direct light of the
         * vertex it left (through glass too), which that path has. */
        if (!is_black3(le) && (events > 0 || !continuation)) {
            float w = prev_nee ? nee_emission_weight(s, prev_p, &h, d, prev_pdf) : 1.0f;
            add_emission(out, depth - passes, events, continuation, split_highlights, beta, beta_g, beta_hl, le, w);
        }
        if (depth >= max_depth + PT_MAX_TRANSMISSIONS) break;

        frame3 fr;
        bsdf b = material_bsdf(s, &h, &fr);
        /* The path-space split goes by the lobes as they are, before any widening; only the first
         * vertices ask. */
        int split_vertex =
            (split_highlights && depth + continuation <= 1) || (depth == 0 && fv.lobes == BSDF_NOT_HIGHLIGHT);
        int hl_mask = split_vertex ? bsdf_highlight_lobe(&b) : 0;
        float image_alpha = depth == 0 && continuation ? reg.image_alpha : 0.0f;
        float floor_alpha = fmaxf(reg.min_alpha, image_alpha);
        if (floor_alpha > 0.0f) bsdf_regularize(&b, floor_alpha);
        vec3 wo = to_local(fr, neg3(d));
        int capped = events >= max_depth;
        int hold = !capped && depth == 0 && fv.lobes == BSDF_NOT_HIGHLIGHT && s->has_glass ? hl_mask : 0;
        int lobes = capped                           ? BSDF_TRANSMIT
                    : depth > 0 || hold              ? BSDF_ALL
                    : fv.lobes == BSDF_NOT_HIGHLIGHT ? BSDF_ALL & ~hl_mask
                                                     : fv.lobes;
        if (!(bsdf_lobes(&b) & lobes)) break;

        /* Next-event estimation: lights above the surface through the reflecting lobes (shadow rays
         * pass only smooth unbent glass), and lights beyond rough glass through its transmission,
         * at a capped vertex too (a transmission is no scattering event). The share held for the
         * highlights is the path's at a vertex's own light. */
        vec3 nee_beta = add3(beta, held), nee_beta_g = add3(beta_g, held); /* held: a glossy lobe's */
        int through = (lobes & BSDF_TRANSMIT) && bsdf_transmits_rough(&b) && (events > 0 || !continuation);
        if (through) {
            float u_sel = rng_float(rng);
            vec2 u_light = rng_vec2(rng);
            bsdf_lobe lobe = {&b, fr, wo, BSDF_TRANSMIT, lobes, 1, 0.0f, 0.0f};
            vec3 beyond = material_medium_after(&s->materials[h.material], h.backface, BSDF_TRANSMIT, sigma);
            light_sample ls;
            vec3 f;
            vec3 arrival = nee_direct(s, h.p, neg3(h.ng), beyond, u_sel, u_light, rng, bsdf_lobe_toward, &lobe,
                                      &rays[RAY_SHADOW], &f, &ls);
            if (!is_black3(arrival)) {
                vec3 c = mul3(mul3(nee_beta, f), arrival);
                put(out, component_of(events), c,
                    depth == 0 ? c : mul3(mul3(nee_beta_g, f), arrival)); /* transmitted */
            }
        }
        if (!capped) {
            float u_sel = depth == 0 && fv.u_select >= 0.0f ? fv.u_select : rng_float(rng);
            vec2 u_light = rng_vec2(rng);
            bsdf_lobe lobe = {&b, fr, wo, lobes & ~hold, lobes, 0, image_alpha, h.t};
            light_sample ls;
            vec3 f;
            vec3 arrival = nee_direct(s, h.p, h.ng, sigma, u_sel, u_light, rng, bsdf_lobe_toward, &lobe,
                                      &rays[RAY_SHADOW], &f, &ls);
            if (!is_black3(arrival)) {
                vec3 c = mul3(mul3(nee_beta, f), arrival), g = mul3(mul3(nee_beta_g, f), arrival);
                bsdf store;
                vec3 wi = to_local(fr, ls.wi);
                if (out.glossy && depth == 0) /* the light's own direction through the view-dependent lobes */
                    g = mul3(
                        scale3(bsdf_eval(bsdf_lobe_for(&lobe, &ls, &store), wo, wi, lobe.lobes & BSDF_VIEW_DEPENDENT),
                               fabsf(wi.z)),
                        arrival);
                if (split_highlights && depth + continuation == 1 && events + continuation == 1) {
                    vec3 fg = scale3(bsdf_eval(bsdf_lobe_for(&lobe, &ls, &store), wo, wi, hl_mask), wi.z);
                    put_split(out, c, g, mul3(mul3(beta_hl, fg), arrival));
                } else {
                    put(out, component_of(events + 1), c, g);
                }
            }
        }

        /* Continue the path by sampling the BSDF. */
        float u_lobe = rng_float(rng);
        vec2 u_dir = depth == 0 && fv.run ? qmc_run_point(*fv.run, 0) : rng_vec2(rng);
        bsdf_sample_result bs;
        if (!bsdf_sample(&b, wo, lobes, u_lobe, u_dir, &bs) || !(bs.pdf > 0.0f)) break;
        vec3 wi = to_world(fr, bs.wi);
        if (!bsdf_side_ok(bs.wi, dot3(wi, h.ng))) break; /* the shading normal's side, not the surface's */
        vec3 weight = scale3(hold ? bsdf_eval(&b, wo, bs.wi, lobes & ~hold) : bs.f, fabsf(bs.wi.z) / bs.pdf);
        if (out.glossy && depth == 0)
            beta_g = mul3(
                beta, scale3(bsdf_eval(&b, wo, bs.wi, lobes & ~hold & BSDF_VIEW_DEPENDENT), fabsf(bs.wi.z) / bs.pdf));
        else
            beta_g = mul3(beta_g, weight);
        int passed = bs.lobe == BSDF_TRANSMIT && !is_black3(material_pass_through(s, &h, &b, wo));
        if (hold) {
            held = mul3(beta, scale3(bsdf_eval(&b, wo, bs.wi, hold), fabsf(bs.wi.z) / bs.pdf));
        } else if (!is_black3(held)) {
            if (passed)
                held = mul3(held, weight);
            else
                beta = add3(beta, held), beta_g = add3(beta_g, held), held = v3s(0.0f);
        }
        if (split_highlights && depth + continuation <= 1) {
            vec3 fg = scale3(bsdf_eval(&b, wo, bs.wi, hl_mask), bs.wi.z / bs.pdf);
            beta_hl = depth + continuation == 0 ? fg : mul3(beta_hl, fg);
        } else if (passed && events + continuation == 2) {
            beta_hl = mul3(beta_hl, weight);
            passes++;
        }
        beta = mul3(beta, weight);
        if ((is_black3(beta) && is_black3(held)) || !is_finite3(beta) || !is_finite3(held)) break;
        if (bs.lobe == BSDF_TRANSMIT)
            sigma = material_medium_after(&s->materials[h.material], h.backface, bs.lobe, sigma);
        events += bs.lobe != BSDF_TRANSMIT;
        if (!passed) {
            prev_nee = bs.lobe != BSDF_TRANSMIT || through;
            prev_pdf = bs.pdf;
            prev_p = h.p;
        }
        o = offset_origin(s, h.p, h.ng, wi);
        d = wi;

        if (depth >= RR_FIRST_VERTEX && is_black3(held)) {
            float before = max_comp3(beta); /* > 0 where the path goes on */
            if (!russian_roulette(&beta, rng_float(rng))) break;
            beta_g = scale3(beta_g, max_comp3(beta) / before); /* the same 1 / q */
        }
    }
}

void pt_radiance(const scene *s, int max_depth, int split_highlights, vec3 o, vec3 d, const surface_hit *first,
                 qmc_run run, rng_state *rng, vec3 out[COMP_COUNT], vec3 *glossy, uint64_t rays[RAY_KIND_COUNT]) {
    trace_path(s, max_depth, o, d, v3s(0.0f), first, rng, (path_sink){out, glossy}, rays, 0, split_highlights,
               (first_vertex){BSDF_ALL, &run, -1.0f}, (pt_regularize){0});
}

vec3 pt_direct(const scene *s, vec3 o, vec3 d, const surface_hit *first, float u_select, rng_state *rng, vec3 *glossy,
               uint64_t rays[RAY_KIND_COUNT]) {
    vec3 out[COMP_COUNT], g[COMP_COUNT];
    trace_path(s, 1, o, d, v3s(0.0f), first, rng, (path_sink){out, glossy ? g : NULL}, rays, 0, 0,
               (first_vertex){BSDF_ALL, NULL, u_select}, (pt_regularize){0});
    if (glossy) *glossy = g[COMP_DIRECT];
    return out[COMP_DIRECT];
}

int pt_punctual_direct(const scene *s, const light *lights, int n, vec3 d, const surface_hit *first, vec3 *out,
                       uint64_t *shadow_rays) {
    frame3 fr;
    bsdf b = material_bsdf(s, first, &fr);
    for (int k = 0; k < n; k++) out[k] = v3s(0.0f);
    if (bsdf_transmits_rough(&b)) return 0;
    bsdf_lobe lobe = {&b, fr, to_local(fr, neg3(d)), BSDF_ALL, BSDF_ALL, 0, 0.0f, 0.0f};
    for (int k = 0; k < n; k++) {
        light_sample ls;
        if (!light_sample_punctual(&lights[k], first->p, &ls) || !(dot3(ls.wi, first->ng) > 0.0f)) continue;
        float unused;
        vec3 f = bsdf_lobe_toward(&lobe, &ls, &unused);
        if (is_black3(f)) continue;
        out[k] = mul3(mul3(f, ls.radiance), light_sample_visible(s, first->p, first->ng, &ls, v3s(0.0f), shadow_rays));
    }
    return 1;
}

int pt_reflected_direct(const scene *s, vec3 o, vec3 d, vec3 sigma, int lobes, pt_regularize reg, rng_state *rng,
                        vec3 *direct, vec3 *highlights, surface_hit *first, uint64_t rays[RAY_KIND_COUNT]) {
    vec3 out[COMP_COUNT];
    int hit = scene_intersect(s, o, d, INFINITY, first);
    trace_path(s, 1, o, d, sigma, hit ? first : NULL, rng, (path_sink){out, NULL}, rays, 1, highlights != NULL,
               (first_vertex){lobes, NULL, -1.0f}, reg);
    *direct = add3(out[COMP_DIRECT], out[COMP_INDIRECT]); /* INDIRECT: the split's rest */
    if (highlights) *highlights = out[COMP_HIGHLIGHTS];
    return hit;
}
