#include "manylight.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mrcs.h"
#include "pt.h"
#include "sampling.h"

void manylight_deinit(manylight *m) {
    vlight_set_free(&m->set);
    free(m->entries);
    alias_deinit(&m->pick);
    lighttree_free(&m->tree);
    memset(m, 0, sizeof *m);
}

float vsl_radius_mult_at(float mult, float shrink, long long i) {
    if (!(shrink > 0.0f)) return mult;
    double r = mult;
    for (long long k = 1; k < i; k++) r *= sqrt(((double)k + (double)shrink) / ((double)k + 1.0));
    return (float)r;
}

float vpl_clamp_at(float c, float growth, long long i) {
    return growth > 0.0f && i > 1 ? c * powf((float)i, growth) : c;
}

shading_point shading_point_at(const scene *s, const surface_hit *h, vec3 ray_dir) {
    shading_point x;
    x.p = h->p;
    x.ng = h->ng;
    x.b = material_bsdf(s, h, &x.frame);
    x.wo = to_local(x.frame, neg3(ray_dir));
    x.material = h->material;
    x.backface = h->backface;
    return x;
}

/* One light's contribution to x: kernel, then visibility (only when there is something to
 * block), then the clamp. */
static vec3 shade_one(const manylight *m, const scene *s, const virtual_light *vl, const shading_point *x,
                      vl_terms terms, rng_state *rng, render_stats *st) {
    st->vl_connections++;
    /* Visibility is to the light's centre. A centre behind x's surface, or one x would see from
     * behind the light's own surface, is blocked by that surface: the ray would start or end
     * inside it. Within the ray offset of either plane counts as behind: offsetting the ends
     * cannot tell the sides apart when both points lie in one plane (VSLs on the back of a thin
     * panel lit x on its front). */
    vec3 dir = sub3(vl->p, x->p);
    if (!(dot3(dir, x->ng) > scene_offset_eps(s, x->p)) || !(dot3(dir, vl->ng) < -scene_offset_eps(s, vl->p)))
        return v3(0, 0, 0);
    vec3 c;
    if (m->kernel == VL_KERNEL_VSL) {
        int n = 0;
        c = vsl_contribution(vl, x, terms, m->all_strategies, rng, &n);
        st->vsl_samples += (uint64_t)n;
    } else {
        c = vpl_contribution(vl, x, m->kernel == VL_KERNEL_VPL_GLOSSY, terms);
    }
    if (is_black3(c) || !is_finite3(c)) return v3(0, 0, 0);
    vec3 org = offset_origin(s, x->p, x->ng, dir);
    vec3 target = offset_origin(s, vl->p, vl->ng, neg3(dir));
    vec3 span = sub3(target, org);
    float dist = length3(span);
    st->rays[RAY_SHADOW]++;
    /* Points closer than the offsets see each other (a VSL enclosing x). */
    if (dist > 0.0f && dot3(span, dir) > 0.0f && scene_occluded(s, org, scale3(span, 1.0f / dist), dist))
        return v3(0, 0, 0);
    if (m->clamp) {
        float peak = max_comp3(c);
        if (peak > m->clamp_bound) {
            c = scale3(c, m->clamp_bound / peak);
            st->clamped++;
        }
    }
    return c;
}

/* One draw of an entry for x with u in [0,1): by the light tree, or by the frame's pick
 * distribution. Returns the entry (-1: none can light x) and its probability in *pmf. */
static int draw_entry(const manylight *m, const lt_receiver *r, float u, float *pmf) {
    if (m->use_tree) return lighttree_sample(&m->tree, r, u, pmf);
    return alias_sample(&m->pick, u, pmf);
}

vec3 manylight_shade(const manylight *m, const scene *s, const shading_point *x, vl_terms terms, int candidates,
                     rng_state *rng, render_stats *st) {
    vec3 sum = v3(0, 0, 0);
    if (m->num_entries == 0 || !bsdf_lobes(&x->b)) return sum;
    if (m->per_pixel == 0) {
        for (int e = 0; e < m->num_entries; e++) {
            vec3 c = shade_one(m, s, &m->set.v[m->entries[e].light], x, terms, rng, st);
            sum = madd3(sum, c, m->entries[e].scale);
        }
        return sum;
    }
    lt_receiver r;
    if (m->tree.num_lights > 0) r = lighttree_receiver(x, s->ray_eps);
    /* The pixel's lights are picked at u = (k + shift) / per_pixel: stratified over [0,1). A draw
     * maps to each entry a part of [0,1) as large as its probability, so each stratum's pick
     * weighted by 1 / (per_pixel pmf) keeps the sum unbiased while the picks spread out. */
    float shift = rng_float(rng);
    if (candidates <= 1) {
        for (int k = 0; k < m->per_pixel; k++) {
            float pmf;
            int e = draw_entry(m, &r, fminf(((float)k + shift) / (float)m->per_pixel, 0x1.fffffep-1f), &pmf);
            if (e >= 0 && pmf > 0.0f)
                sum = madd3(sum, shade_one(m, s, &m->set.v[m->entries[e].light], x, terms, rng, st),
                            m->entries[e].scale / pmf);
        }
        return scale3(sum, 1.0f / (float)m->per_pixel);
    }
    /* Resampled importance sampling (Talbot et al. 2005): `candidates` draws, each weighted by
     * target / pmf where the target is the light tree's estimate of what the light sends to x
     * (lighttree_importance on its leaf: distance, both cosines, both lobes, no visibility), and
     * the pixel's lights picked from them in proportion to the weights, stratified. Each pick y
     * stands for the sum over all entries with weight (w_sum / candidates) / target(y): unbiased
     * wherever the target is positive where a light can send something (the importance's zeros
     * are exact). Cost: one estimate per candidate, one shading per pick. */
    int cand[VL_MAX_CANDIDATES];
    double cum[VL_MAX_CANDIDATES];
    float target[VL_MAX_CANDIDATES];
    double w_sum = 0.0;
    int n = 0;
    for (int c = 0; c < candidates; c++) {
        float pmf;
        int e = draw_entry(m, &r, rng_float(rng), &pmf);
        if (e < 0 || !(pmf > 0.0f)) continue;
        float t = lighttree_light_importance(&m->tree.leaves[m->entries[e].light], &r) * m->entries[e].scale;
        if (!(t > 0.0f) || !isfinite(t)) continue;
        w_sum += (double)t / (double)pmf;
        cand[n] = e;
        target[n] = t;
        cum[n++] = w_sum;
    }
    if (n == 0 || !(w_sum > 0.0)) return sum;
    for (int k = 0, i = 0; k < m->per_pixel; k++) {
        double u = ((double)k + (double)shift) / (double)m->per_pixel * w_sum;
        while (i < n - 1 && cum[i] <= u) i++;
        const ml_entry *en = &m->entries[cand[i]];
        float weight = (float)(w_sum / (double)candidates / (double)target[i]) * en->scale;
        sum = madd3(sum, shade_one(m, s, &m->set.v[en->light], x, terms, rng, st), weight);
    }
    return scale3(sum, 1.0f / (float)m->per_pixel);
}

/* ---- matrix row-column sampling -------------------------------------------------------------- */

typedef struct {
    manylight *m;
    const scene *s;
    const camera *cam;
    const render_params *p;
    long long frame;
    int rows;
    float *matrix;           /* rows x lights, luminance */
    render_stats *row_stats; /* one per row, summed afterwards */
} row_job;

/* Row r: a random pixel in the r-th slice of the image, its camera hit, every light's clamped
 * contribution (with visibility) as luminance. */
static void compute_row(void *ctx, int r, int worker) {
    (void)worker;
    row_job *job = ctx;
    const render_params *p = job->p;
    int n = job->m->set.count;
    float *row = job->matrix + (size_t)r * (size_t)n;
    memset(row, 0, sizeof(float) * (size_t)n);
    render_stats *st = &job->row_stats[r];
    long long pixels = (long long)p->width * p->height;
    rng_state rng = rng_for(0x726f7773ULL + (uint64_t)r, (uint64_t)job->frame, p->seed);
    long long lo = pixels * r / job->rows, hi = pixels * (r + 1) / job->rows;
    long long pixel = lo + (long long)(rng_double(&rng) * (double)(hi - lo));
    if (pixel >= hi) pixel = hi - 1;
    float x = ((float)(pixel % p->width) + rng_float(&rng)) / (float)p->width;
    float y = ((float)(pixel / p->width) + rng_float(&rng)) / (float)p->height;
    vec3 d = camera_ray_dir(job->cam, (float)p->width / (float)p->height, x, y);
    surface_hit h;
    st->rays[RAY_CAMERA]++;
    if (!scene_intersect(job->s, job->cam->position, d, INFINITY, &h)) return;
    shading_point sp = shading_point_at(job->s, &h, d);
    if (!bsdf_lobes(&sp.b)) return;
    for (int j = 0; j < n; j++)
        row[j] = luminance3(shade_one(job->m, job->s, &job->m->set.v[j], &sp, job->m->terms, &rng, st));
}

static int reserve_entries(manylight *m, int n) {
    if (n <= m->cap_entries) return 0;
    ml_entry *e = realloc(m->entries, sizeof(ml_entry) * (size_t)n);
    if (!e) return -1;
    m->entries = e;
    m->cap_entries = n;
    return 0;
}

static int cluster_lights(manylight *m, const scene *s, const camera *cam, const render_params *p, long long frame,
                          threadpool *pool, render_stats *st) {
    int n = m->set.count, rows = p->vl.rows; /* p is resolved (manylight_begin_frame) */
    /* A row is a pixel: more rows than pixels would only repeat them (and the matrix is rows x n). */
    if ((long long)rows > (long long)p->width * p->height) rows = p->width * p->height;
    float *matrix = malloc(sizeof(float) * (size_t)rows * (size_t)n);
    render_stats *row_stats = calloc((size_t)rows, sizeof(render_stats));
    mrcs_cluster *clusters = malloc(sizeof(mrcs_cluster) * (size_t)p->vl.columns);
    int status = -1;
    if (matrix && row_stats && clusters && reserve_entries(m, p->vl.columns) == 0) {
        row_job job = {m, s, cam, p, frame, rows, matrix, row_stats};
        threadpool_run(pool, compute_row, &job, rows);
        for (int r = 0; r < rows; r++) render_stats_add(st, &row_stats[r]);
        rng_state rng = rng_for(0x636c7573ULL, (uint64_t)frame, p->seed);
        int k = mrcs_cluster_columns(matrix, rows, n, p->vl.columns, &rng, clusters);
        if (k >= 0) {
            float *weights = malloc(sizeof(float) * (size_t)(k > 0 ? k : 1));
            if (weights) {
                for (int c = 0; c < k; c++) {
                    m->entries[c] = (ml_entry){clusters[c].representative, clusters[c].scale};
                    weights[c] = clusters[c].weight;
                }
                m->num_entries = k;
                alias_deinit(&m->pick);
                status = k == 0 || m->per_pixel == 0 ? 0 : alias_init(&m->pick, weights, k);
                free(weights);
            }
        }
    }
    free(matrix);
    free(row_stats);
    free(clusters);
    return status;
}

/* The lobes of x traced through rather than gathered: a glossy lobe sharper than trace_alpha,
 * where a handful of lights cannot represent the incoming light, and any transmission, which
 * no virtual light is seen through (docs/design.md, "Transmission and volume"). */
static int traced_lobes(const manylight *m, const bsdf *b) {
    int lobes = bsdf_lobes(b);
    int sharp = (lobes & BSDF_GLOSSY) && bsdf_glossy_alpha(b) < m->trace_alpha;
    return (sharp ? BSDF_GLOSSY : 0) | (lobes & BSDF_TRANSMIT);
}

/* One direction (u_lobe, u) through x's traced lobes (x is scattering event k, reached with weight
 * beta in a medium of absorption *sigma): the direct light at the next hit, weighted (*t), its
 * glossy lobes widened by reg (pt_regularize), and what carrying the path on needs (*b, *h, *wi,
 * *sigma, *lobe). Through a transmission *t is 0 unless through_direct: a transmission is no
 * scattering event, and the direct estimator that reached x (its paths carry on through x's
 * transmission) has the next hit's direct light; glass reached by a gathered lobe's direction
 * (glass_direction) had no such estimator before it, so there the next hit's direct light is taken.
 * Returns 0 when the direction ends there (sampled on the wrong side of the surface, Russian
 * roulette, a miss). */
static int glossy_direction(const scene *s, const shading_point *x, int traced, int through_direct, vec3 beta, int k,
                            int lobes, pt_regularize reg, float u_lobe, vec2 u, rng_state *rng, render_stats *st,
                            vec3 *t, vec3 *t_hl, vec3 *b, surface_hit *h, vec3 *wi, vec3 *sigma, int *lobe) {
    bsdf_sample_result bs;
    if (!bsdf_sample(&x->b, x->wo, traced, u_lobe, u, &bs) || !(bs.pdf > 0.0f)) return 0;
    *wi = to_world(x->frame, bs.wi);
    if (!bsdf_side_ok(bs.wi, dot3(*wi, x->ng))) return 0;
    *b = mul3(beta, scale3(bs.f, fabsf(bs.wi.z) / bs.pdf));
    if (k - 1 >= RR_FIRST_VERTEX && !russian_roulette(b, rng_float(rng))) return 0;
    if (is_black3(*b) || !is_finite3(*b)) return 0;
    st->glossy_bounces++;
    *lobe = bs.lobe;
    *sigma = material_medium_after(&s->materials[x->material], x->backface, bs.lobe, *sigma);
    vec3 o = offset_origin(s, x->p, x->ng, *wi);
    *t = v3(0, 0, 0);
    if (t_hl) *t_hl = v3(0, 0, 0);
    if (bs.lobe == BSDF_TRANSMIT && !through_direct) {
        st->rays[RAY_BOUNCE]++;
        if (!scene_intersect(s, o, *wi, INFINITY, h)) return 0;
    } else {
        /* Emission at the next hit is the direct light at x, which the shared estimator has. With
         * t_hl, the part through both hits' highlight lobes goes there (pt.c's split). */
        int hl = t_hl ? bsdf_highlight_lobe(&x->b) : 0;
        vec3 direct, direct_hl;
        if (!pt_reflected_direct(s, o, *wi, *sigma, lobes, reg, rng, &direct, hl ? &direct_hl : NULL, h, st->rays))
            return 0;
        *t = mul3(*b, direct);
        if (hl) {
            vec3 b_hl = mul3(beta, scale3(bsdf_eval(&x->b, x->wo, bs.wi, hl), fabsf(bs.wi.z) / bs.pdf));
            *t_hl = mul3(b_hl, direct_hl);
            /* the rest of the highlight lobes' light: the lobes add up to the BSDF */
            *t = add3(*t, sub3(mul3(*b, direct_hl), *t_hl));
        }
    }
    *b = mul3(*b, medium_transmittance(*sigma, h->t));
    return 1;
}

/* A path whose edge from x (event k) to its next scattering event crosses glass, which no virtual
 * light is seen through (docs/design.md, "Transmission and volume"): one direction from x's
 * gathered lobes (x->b) whose hit g transmits, then g's transmission alone (its reflection is the
 * virtual lights' on g). Fills what glossy_direction fills: *t the direct light at the hit beyond g
 * (the light of x's first bounce there, which the gather cannot see through g). Returns 0 when the
 * direction meets no glass (those paths are the gather's) or ends. */
static int glass_direction(const scene *s, const shading_point *x, vec3 beta, int k, rng_state *rng, render_stats *st,
                           vec3 *t, vec3 *b, surface_hit *h, vec3 *wi, vec3 *sigma) {
    bsdf_sample_result bs;
    float u_lobe = rng_float(rng);
    if (!bsdf_sample(&x->b, x->wo, BSDF_ALL, u_lobe, rng_vec2(rng), &bs) || !(bs.pdf > 0.0f)) return 0;
    vec3 d = to_world(x->frame, bs.wi);
    if (!bsdf_side_ok(bs.wi, dot3(d, x->ng))) return 0;
    surface_hit g;
    st->rays[RAY_BOUNCE]++;
    if (!scene_intersect(s, offset_origin(s, x->p, x->ng, d), d, INFINITY, &g)) return 0;
    shading_point gp = shading_point_at(s, &g, d);
    if (!(bsdf_lobes(&gp.b) & BSDF_TRANSMIT)) return 0;
    beta = mul3(beta, scale3(bs.f, fabsf(bs.wi.z) / bs.pdf));
    beta = mul3(beta, medium_transmittance(*sigma, g.t));
    int lobe;
    return glossy_direction(s, &gp, BSDF_TRANSMIT, 1, beta, k + 1, BSDF_ALL, (pt_regularize){0}, 0.0f, rng_vec2(rng),
                            rng, st, t, NULL, b, h, wi, sigma, &lobe);
}

/* The camera hit's gather. With highlights, the paths in every term, the highlights' own to
 * *highlights: a second gather of that term alone where x's gathered lobes hold a highlight lobe. */
static vec3 camera_gather(const manylight *m, const scene *s, const shading_point *x, vec3 *highlights, rng_state *rng,
                          render_stats *st) {
    if (!highlights) return manylight_shade(m, s, x, m->terms, m->candidates, rng, st);
    if (bsdf_highlight_lobe(&x->b))
        *highlights = add3(*highlights, manylight_shade(m, s, x, VL_TERMS_HIGHLIGHTS, m->candidates, rng, st));
    return manylight_shade(m, s, x, VL_TERMS_NO_HIGHLIGHTS, m->candidates, rng, st);
}

vec3 manylight_indirect(const manylight *m, const scene *s, const shading_point *x0, vec3 *highlights, vec3 *glossy,
                        int max_depth, int split_first, qmc_run seq, pixel_record *rec, rng_state *rng,
                        render_stats *st) {
    vec3 sum = v3(0, 0, 0), beta = v3s(1.0f), sigma = v3s(0.0f), g = v3(0, 0, 0);
    shading_point x = *x0;
    if (glossy) *glossy = g;
    if (!m->glass && !traced_lobes(m, &x.b)) {
        vec3 l = camera_gather(m, s, &x, highlights, rng, st);
        if (glossy && bsdf_lobes(&x.b) & BSDF_GLOSSY) *glossy = l;
        return l;
    }
    int through = 0;               /* x was reached through a transmission */
    int traced_on = 0;             /* the path left the camera hit through its traced lobes: its light is glossy... */
    vec3 at_leaving = v3(0, 0, 0); /* ...all it adds to sum after the camera hit */
    /* x is scattering event k: gathering there makes paths of k + 1 events or more. A
     * transmission leaves k as it is (pt.c counts depth so). */
    for (int k = 1, vertex = 0; k + 1 <= max_depth && vertex <= max_depth + PT_MAX_TRANSMISSIONS; vertex++) {
        /* Only at the camera hit do the highlights own part of the gathered paths. */
        int at_camera = k == 1 && !through;
        int traced = traced_lobes(m, &x.b);
        shading_point gathered = x;
        gathered.b = bsdf_only(&x.b, BSDF_ALL & ~traced);
        int gather = bsdf_lobes(&gathered.b) != 0;
        int candidates = at_camera ? m->candidates : m->candidates_beyond;
        if (gather) {
            vec3 l = mul3(beta, at_camera ? camera_gather(m, s, &gathered, highlights, rng, st)
                                          : manylight_shade(m, s, &gathered, VL_TERMS_ALL, candidates, rng, st));
            sum = add3(sum, l);
            if (at_camera && bsdf_lobes(&gathered.b) & BSDF_GLOSSY) g = add3(g, l);
        }
        /* The gathered lobes' paths through glass (scenes with glass only), and the traced lobes',
         * each carry the path on with probability 1/2 when both are there. */
        int glass = gather && m->glass;
        if (!traced && !glass) break;
        int via_glass = glass && (!traced || rng_float(rng) < 0.5f);
        float pick = traced && glass ? 2.0f : 1.0f;

        /* At the camera hit the lobe is split: `split` directions, the pixel's next points of
         * its run, each take the direct light at their next hit (the reflection of lit surfaces,
         * where a single direction is the noisiest part of the image), and one of them, chosen at
         * random, carries the rest of the path (with weight 1: it stands for the mean of the
         * split's continuations). */
        int split = at_camera ? split_first : 1;
        qmc_run run = seq;
        if (!at_camera) run.scramble_x = rng_next_u32(rng), run.scramble_y = rng_next_u32(rng), run.index = 0;
        int chosen = split > 1 ? (int)fminf(rng_float(rng) * (float)split, (float)(split - 1)) : 0;
        /* With highlights on, glossy(x) - glossy(next hit) - light is theirs (docs/design.md) when both
         * lobes are highlight lobes: left to their estimator, or here split off into *highlights. */
        int split_hl = at_camera && highlights;
        int lobes = at_camera && !highlights && m->terms == VL_TERMS_NO_HIGHLIGHTS && bsdf_highlight_lobe(&x.b)
                        ? BSDF_NOT_HIGHLIGHT
                        : BSDF_ALL;
        /* The hit a traced direction reaches sees a light through lobes widened so that the
         * light's image there is no narrower than a share of x's lobe (docs/design.md,
         * "Regularised images"), and a chain of two traced lobes or more widens them to a floor
         * besides: there a point light's reflection in a mirror seen in another is a rare
         * direction worth thousands of times the pixel ("Regularised chains"). */
        pt_regularize reg = {k >= 2 ? m->reg_alpha : 0.0f, m->reg_image * bsdf_glossy_alpha(&x.b)};
        vec3 next_beta = v3(0, 0, 0), next_wi = v3(0, 0, 1), next_sigma = sigma;
        surface_hit next;
        int have_next = 0, next_lobe = 0;
        for (int j = 0; traced && j < split; j++) {
            vec3 t = v3(0, 0, 0), t_hl = v3(0, 0, 0), b, sg = sigma;
            surface_hit h;
            vec3 wi;
            int lobe;
            float u_lobe = rng_float(rng);
            int ok = glossy_direction(s, &x, traced, 0, beta, k, lobes, reg, u_lobe, qmc_run_point(run, j), rng, st, &t,
                                      split_hl ? &t_hl : NULL, &b, &h, &wi, &sg, &lobe);
            if (at_camera && rec) pixel_record_add(rec, avg3(add3(t, t_hl)));
            if (!ok) continue;
            sum = madd3(sum, t, 1.0f / (float)split);
            if (at_camera) g = madd3(g, t, 1.0f / (float)split);
            if (split_hl) *highlights = madd3(*highlights, t_hl, 1.0f / (float)split);
            if (j == chosen && !via_glass)
                next_beta = b, next = h, next_wi = wi, next_sigma = sg, next_lobe = lobe, have_next = 1;
        }
        if (glass) {
            vec3 t = v3(0, 0, 0), b, sg = sigma, wi;
            surface_hit h;
            if (glass_direction(s, &gathered, beta, k, rng, st, &t, &b, &h, &wi, &sg)) {
                sum = add3(sum, t);
                if (via_glass) next_beta = b, next = h, next_wi = wi, next_sigma = sg, next_lobe = 0, have_next = 1;
            }
        }
        if (at_camera) traced_on = !via_glass, at_leaving = sum;
        if (!have_next) break;
        beta = scale3(next_beta, pick);
        sigma = next_sigma;
        if (next_lobe == BSDF_TRANSMIT) {
            through = 1;
        } else {
            through |= via_glass;
            k++;
        }
        x = shading_point_at(s, &next, next_wi);
    }
    if (glossy) *glossy = traced_on ? add3(g, sub3(sum, at_leaving)) : g;
    return sum;
}

int manylight_begin_frame(manylight *m, const scene *s, const camera *cam, const render_params *p,
                          const effect_plan *plan, long long frame, threadpool *pool, render_stats *st, char *err,
                          size_t errlen) {
    const render_params r = render_params_resolve(p); /* the defaults, in one place */
    const vl_params *vp = &r.vl;
    long long i = frame + 1;
    m->kernel = p->method == METHOD_VSL || p->method == METHOD_VSL_HL || p->method == METHOD_AUTO
                    ? VL_KERNEL_VSL
                    : (vp->vpl_glossy ? VL_KERNEL_VPL_GLOSSY : VL_KERNEL_VPL);
    m->terms = plan->highlights ? VL_TERMS_NO_HIGHLIGHTS : VL_TERMS_ALL;
    m->all_strategies = plan->vsl_all_strategies;
    m->clamp = vp->clamp == VL_CLAMP_ON;
    float growth = vp->clamp_growth > 0.0f ? vp->clamp_growth : 0.0f; /* negative: off */
    float shrink = vp->radius_shrink > 0.0f ? vp->radius_shrink : 0.0f;
    m->clamp_bound = vpl_clamp_at(vp->clamp_value, growth, i);
    m->radius_mult = vsl_radius_mult_at(vp->radius_mult, shrink, i);
    /* The VSLs' schedule: the chains' blur shrinks as the spheres do, so both converge together. */
    m->reg_alpha = vp->regularize > 0.0f ? vsl_radius_mult_at(vp->regularize, shrink, i) : 0.0f;
    m->reg_image = vp->reg_image > 0.0f ? vsl_radius_mult_at(vp->reg_image, shrink, i) : 0.0f;
    m->num_entries = 0;
    m->clustered = 0;
    m->use_tree = 0;
    m->tree.num_lights = 0;
    int count = vp->count;
    if (vlights_trace(s, count, plan->max_depth, p->seed, (uint64_t)frame, &m->set, &st->rays[RAY_BOUNCE]) != 0)
        return snprintf(err, errlen, "out of memory for %d virtual lights", count), -1;
    st->virtual_lights += (uint64_t)m->set.count;
    st->light_paths += (uint64_t)m->set.paths;
    if (m->set.count == 0) return 0;
    if (m->kernel == VL_KERNEL_VSL && vlights_set_radii(&m->set, m->radius_mult, s->diag) != 0)
        return snprintf(err, errlen, "out of memory for the lights' radii"), -1;

    int clustering = vp->columns > 0 && vp->columns < m->set.count;
    m->per_pixel = vl_frame_per_pixel(&p->vl, clustering);
    /* As many picks as there are lights (or clusters) or more: shading every one is exact and no
     * dearer, however large the number asked. */
    if (m->per_pixel >= (clustering ? vp->columns : m->set.count)) m->per_pixel = 0;
    m->candidates = vp->candidates;
    /* Beyond the camera hit a gather's light is a smaller share of the pixel's, through the path's
     * earlier bounces: there a quarter of the draws saves more time than the error it adds
     * (docs/benchmarks.md). */
    m->candidates_beyond = vp->candidates > 4 ? vp->candidates / 4 : 1;
    m->glossy_split = vp->glossy_rays;
    m->glass = 0;
    for (int j = 0; j < s->num_materials; j++) m->glass |= s->materials[j].ext.transmission > 0.0f;
    m->trace_alpha = vp->trace_glossy > 0.0f ? vp->trace_glossy : 0.0f;
    /* The light tree's per-light estimates serve resampling; its hierarchy, drawing through it. */
    if (m->per_pixel > 0 && (vp->select == VL_SELECT_TREE || m->candidates > 1) &&
        lighttree_build(&m->tree, &m->set) != 0)
        return snprintf(err, errlen, "out of memory for the light tree"), -1;
    if (clustering) {
        if (cluster_lights(m, s, cam, &r, frame, pool, st) != 0)
            return snprintf(err, errlen, "out of memory for the light clusters"), -1;
        m->clustered = 1;
        return 0;
    }
    /* Every light its own entry; pixels that sample draw lights through the tree or by power. */
    if (reserve_entries(m, m->set.count) != 0) return snprintf(err, errlen, "out of memory"), -1;
    m->num_entries = m->set.count;
    for (int j = 0; j < m->set.count; j++) m->entries[j] = (ml_entry){j, 1.0f};
    alias_deinit(&m->pick);
    m->use_tree = m->per_pixel > 0 && vp->select == VL_SELECT_TREE;
    if (m->per_pixel > 0 && !m->use_tree) {
        float *power = malloc(sizeof(float) * (size_t)m->set.count);
        if (!power) return snprintf(err, errlen, "out of memory"), -1;
        for (int j = 0; j < m->set.count; j++) power[j] = luminance3(m->set.v[j].power);
        int status = alias_init(&m->pick, power, m->set.count);
        free(power);
        if (status != 0) return snprintf(err, errlen, "out of memory"), -1;
    }
    return 0;
}
