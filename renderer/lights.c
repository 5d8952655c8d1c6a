/* Lights: building the list, sampling for next-event estimation, pdfs for MIS, the environment. */
#include "lights.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene_parts.h"

/* ---- environment map ----------------------------------------------------------------------- */

vec3 env_eval(const scene *s, vec3 d) {
    if (!s->env) return v3(0, 0, 0);
    return env_lookup(s->env, env_uv(s->env, d));
}

int scene_set_env_image(scene *s, image_rgb *image, float rotation, char *err, size_t errlen) {
    env_map *env = env_map_create(image, rotation, err, errlen);
    if (!env) return -1;
    env_map *old = s->env;
    s->env = env;
    if (scene_build_lights(s, err, errlen) != 0) {
        char ignored[256];
        s->env = old;
        env_map_destroy(env);
        scene_build_lights(s, ignored, sizeof ignored);
        return -1;
    }
    env_map_destroy(old);
    return 0;
}

int scene_set_env(scene *s, const char *path, float rotation, char *err, size_t errlen) {
    image_rgb img;
    if (image_rgb_load(path, &img, err, errlen) != 0) return -1;
    char sub[256];
    if (scene_set_env_image(s, &img, rotation, sub, sizeof sub) != 0)
        return snprintf(err, errlen, "%s: %s", path, sub), -1;
    return 0;
}

/* ---- the light list ------------------------------------------------------------------------ */

static float triangle_area(const scene *s, int t) {
    const uint32_t *v = &s->indices[3 * t];
    vec3 p0 = s->positions[v[0]], p1 = s->positions[v[1]], p2 = s->positions[v[2]];
    return 0.5f * length3(cross3(sub3(p1, p0), sub3(p2, p0)));
}

int scene_build_lights(scene *s, char *err, size_t errlen) {
    /* Keep the punctual lights (the importer added them), drop derived ones. */
    int kept = 0;
    for (int i = 0; i < s->num_lights; i++)
        if (s->lights[i].type != LIGHT_TRIANGLE && s->lights[i].type != LIGHT_ENV) s->lights[kept++] = s->lights[i];
    s->num_lights = kept;
    s->env_light = -1;
    float r = 0.5f * s->diag;
    for (int i = 0; i < s->num_lights; i++) {
        light *l = &s->lights[i];
        float lum = luminance3(l->color);
        switch (l->type) {
        case LIGHT_POINT: l->power = 4.0f * PI_F * lum; break;
        case LIGHT_SPOT: l->power = 2.0f * PI_F * (1.0f - 0.5f * (l->cos_inner + l->cos_outer)) * lum; break;
        case LIGHT_DIRECTIONAL: l->power = PI_F * r * r * lum; break;
        default: l->power = 0.0f; break;
        }
    }
    for (int t = 0; t < s->num_triangles; t++) {
        s->tri_light[t] = -1;
        const material *m = &s->materials[s->tri_material[t]];
        /* What it emits on average: an emissive texture black all over the triangle makes it no
         * light (emissive.c). */
        vec3 mean = m->emission;
        if (m->emissive_tex.texture >= 0 && s->tri_emit_tex) mean = mul3(mean, s->tri_emit_tex[t]);
        if (!(max_comp3(mean) > 0.0f) || scene_triangle_invisible(s, t)) continue;
        light l;
        memset(&l, 0, sizeof l);
        l.type = LIGHT_TRIANGLE;
        l.triangle = t;
        l.color = m->emission;
        snprintf(l.name, sizeof l.name, "%s", m->name);
        l.power = triangle_area(s, t) * PI_F * (m->double_sided ? 2.0f : 1.0f) * luminance3(mean);
        int idx = scene_add_light(s, &l);
        if (idx < 0) return snprintf(err, errlen, "%s: out of memory", s->path), -1;
        s->tri_light[t] = idx;
    }
    if (s->env && s->env->mean_luminance > 0.0f) {
        light l;
        memset(&l, 0, sizeof l);
        l.type = LIGHT_ENV;
        snprintf(l.name, sizeof l.name, "environment");
        /* As pbrt-v4: the flux through a disk of the scene's radius from every direction. */
        l.power = 4.0f * PI_F * PI_F * r * r * s->env->mean_luminance;
        s->env_light = scene_add_light(s, &l);
        if (s->env_light < 0) return snprintf(err, errlen, "%s: out of memory", s->path), -1;
    }
    dist1d_deinit(&s->light_dist);
    dist1d_deinit(&s->nee_dist);
    s->nee_each = nee_each_count(kept);
    s->nee_draws = s->num_lights > s->nee_each;
    if (s->num_lights > 0) {
        float *power = malloc(sizeof(float) * (size_t)s->num_lights);
        if (!power) return snprintf(err, errlen, "%s: out of memory", s->path), -1;
        for (int i = 0; i < s->num_lights; i++) power[i] = s->lights[i].power;
        int status = dist1d_init(&s->light_dist, power, s->num_lights);
        for (int i = 0; i < s->nee_each; i++) power[i] = 0.0f;
        if (status == 0 && s->nee_draws) status = dist1d_init(&s->nee_dist, power, s->num_lights);
        free(power);
        if (status != 0) return snprintf(err, errlen, "%s: out of memory", s->path), -1;
    }
    return 0;
}

/* ---- sampling ------------------------------------------------------------------------------ */

/* glTF spot cone: full inside the inner angle, a smooth (squared linear) ramp to the outer one.
 * d is the direction from the light. */
static float spot_falloff(const light *l, vec3 d) {
    float t = clampf((dot3(d, l->direction) - l->cos_outer) / fmaxf(l->cos_inner - l->cos_outer, 1e-4f), 0.0f, 1.0f);
    return t * t;
}

/* A uniform point on emissive triangle t: position, unit winding normal, twice the area, and a
 * hit record (front side) for looking up its emission. */
static surface_hit triangle_point(const scene *s, int t, vec2 u, vec3 *q, vec3 *n, float *area2) {
    const uint32_t *v = &s->indices[3 * t];
    vec3 p0 = s->positions[v[0]], p1 = s->positions[v[1]], p2 = s->positions[v[2]];
    vec2 b = sample_uniform_triangle(u);
    float b0 = 1.0f - b.x - b.y;
    *q = add3(add3(scale3(p0, b0), scale3(p1, b.x)), scale3(p2, b.y));
    vec3 c = cross3(sub3(p1, p0), sub3(p2, p0));
    *area2 = length3(c);
    *n = *area2 > 0.0f ? scale3(c, 1.0f / *area2) : v3(0, 0, 1);
    surface_hit h;
    memset(&h, 0, sizeof h);
    h.tri = t;
    h.material = s->tri_material[t];
    h.p = *q;
    h.ng = *n;
    h.uv0 = triangle_uv(s, s->uv0, t, b.x, b.y);
    h.uv1 = triangle_uv(s, s->uv1, t, b.x, b.y);
    return h;
}

static int sample_light(const scene *s, int li, float pmf, vec3 p, vec2 u, light_sample *out);

int light_sample_direct(const scene *s, vec3 p, float u_select, vec2 u, light_sample *out) {
    if (!s->nee_draws) return 0;
    float pmf;
    int li = dist1d_sample_discrete(&s->nee_dist, u_select, &pmf, NULL);
    if (!(pmf > 0.0f)) return 0;
    return sample_light(s, li, pmf, p, u, out);
}

int light_sample_one(const scene *s, int li, vec3 p, vec2 u, light_sample *out) {
    if (li < 0 || li >= s->num_lights) return 0;
    return sample_light(s, li, 1.0f, p, u, out);
}

int light_sample_punctual(const light *l, vec3 p, light_sample *out) {
    out->light = -1;
    out->delta = 1;
    out->pdf = 1.0f;
    switch (l->type) {
    case LIGHT_POINT:
    case LIGHT_SPOT: {
        vec3 d = sub3(l->position, p);
        float d2 = length_sq3(d);
        if (!(d2 > 0.0f)) return 0;
        float dist = sqrtf(d2);
        out->wi = scale3(d, 1.0f / dist);
        out->dist = dist;
        out->p_light = l->position;
        out->n_light = neg3(out->wi);
        float falloff = l->type == LIGHT_SPOT ? spot_falloff(l, neg3(out->wi)) : 1.0f;
        if (falloff <= 0.0f) return 0;
        out->radiance = scale3(l->color, falloff / d2);
        return 1;
    }
    case LIGHT_DIRECTIONAL:
        out->wi = neg3(l->direction);
        out->dist = INFINITY;
        out->p_light = p;
        out->n_light = l->direction;
        out->radiance = l->color;
        return 1;
    default: return 0;
    }
}

/* Light li chosen with probability pmf: the sample's pdf includes it. */
static int sample_light(const scene *s, int li, float pmf, vec3 p, vec2 u, light_sample *out) {
    const light *l = &s->lights[li];
    out->light = li;
    out->delta = 0;
    switch (l->type) {
    case LIGHT_POINT:
    case LIGHT_SPOT:
    case LIGHT_DIRECTIONAL: {
        int ok = light_sample_punctual(l, p, out);
        out->light = li;
        out->pdf = pmf;
        return ok;
    }
    case LIGHT_TRIANGLE: {
        vec3 q, n;
        float area2;
        surface_hit h = triangle_point(s, l->triangle, u, &q, &n, &area2);
        vec3 d = sub3(q, p);
        float d2 = length_sq3(d);
        if (!(d2 > 0.0f)) return 0;
        float dist = sqrtf(d2);
        vec3 wi = scale3(d, 1.0f / dist);
        float cos_l = dot3(n, wi); /* > 0: we see the back (winding) side */
        h.backface = cos_l > 0.0f;
        vec3 le = scale3(material_emission(s, &h), material_coverage(s, &h)); /* none from a cut-out */
        float abs_cos = fabsf(cos_l);
        if (is_black3(le) || !(abs_cos > 0.0f)) return 0;
        out->wi = wi;
        out->dist = dist;
        out->p_light = q;
        out->n_light = cos_l > 0.0f ? neg3(n) : n; /* facing the shading point */
        out->radiance = le;
        out->pdf = pmf * d2 / (abs_cos * 0.5f * area2);
        return isfinite(out->pdf) && out->pdf > 0.0f;
    }
    case LIGHT_ENV: {
        float pdf_uv;
        vec2 uv = dist2d_sample(&s->env->dist, u, &pdf_uv);
        float st = sinf(PI_F * uv.y);
        if (!(pdf_uv > 0.0f) || !(st > 0.0f)) return 0;
        out->wi = env_direction(s->env, uv);
        out->dist = INFINITY;
        out->p_light = p;
        out->n_light = neg3(out->wi);
        out->radiance = env_lookup(s->env, uv);
        out->pdf = pmf * pdf_uv / (2.0f * PI_F * PI_F * st);
        return isfinite(out->pdf) && out->pdf > 0.0f;
    }
    }
    return 0;
}

vec3 light_sample_visible(const scene *s, vec3 p, vec3 ng, const light_sample *ls, vec3 sigma, uint64_t *shadow_rays) {
    vec3 org = offset_origin(s, p, ng, ls->wi);
    vec3 dir = ls->wi;
    float tmax = INFINITY;
    if (isfinite(ls->dist)) {
        vec3 target = ls->delta ? ls->p_light : offset_origin(s, ls->p_light, ls->n_light, neg3(ls->wi));
        vec3 span = sub3(target, org);
        tmax = length3(span);
        if (!(tmax > 0.0f)) return v3s(0.0f);
        dir = scale3(span, 1.0f / tmax);
    }
    ++*shadow_rays;
    return scene_transmittance(s, org, dir, tmax, sigma);
}

float light_pdf_triangle(const scene *s, int li, vec3 p, const surface_hit *h) {
    const uint32_t *v = &s->indices[3 * h->tri];
    vec3 p0 = s->positions[v[0]], p1 = s->positions[v[1]], p2 = s->positions[v[2]];
    float area = 0.5f * length3(cross3(sub3(p1, p0), sub3(p2, p0)));
    vec3 d = sub3(h->p, p);
    float d2 = length_sq3(d);
    float cos_l = fabsf(dot3(h->ng, d)) / sqrtf(d2);
    if (!(cos_l > 0.0f) || !(area > 0.0f)) return 0.0f;
    return dist1d_pmf(&s->nee_dist, li) * d2 / (cos_l * area);
}

float nee_emission_weight(const scene *s, vec3 p, const surface_hit *h, vec3 d, float lobe_pdf) {
    if (!h) return mis_power(lobe_pdf, light_pdf_env(s, d));
    int li = s->tri_light[h->tri];
    return mis_power(lobe_pdf, li >= 0 ? light_pdf_triangle(s, li, p, h) : 0.0f);
}

/* One candidate of next-event estimation: its sample, the lobe toward it, its MIS weight over its
 * pdf, and what it would bring before its shadow ray, the luminance of f Le w / pdf. */
typedef struct {
    light_sample ls;
    vec3 f;
    float w_pdf, w;
} nee_candidate;

vec3 nee_direct(const scene *s, vec3 p, vec3 ng, vec3 sigma, float u_select, vec2 u, rng_state *rng, nee_lobe_fn lobe,
                const void *ctx, uint64_t *shadow_rays, vec3 *f, light_sample *out) {
    nee_candidate c[NEE_EACH_MAX + 1];
    int m = 0;
    float sum = 0.0f;
    *f = v3(0, 0, 0);
    for (int j = 0; j <= s->nee_each; j++) {
        nee_candidate *cj = &c[m];
        if (j < s->nee_each ? !light_sample_one(s, j, p, u, &cj->ls) : !light_sample_direct(s, p, u_select, u, &cj->ls))
            continue;
        if (!(dot3(cj->ls.wi, ng) > 0.0f)) continue;
        float lobe_pdf = 0.0f;
        cj->f = lobe(ctx, &cj->ls, &lobe_pdf);
        cj->w_pdf = nee_light_weight(&cj->ls, lobe_pdf) / cj->ls.pdf;
        cj->w = luminance3(mul3(cj->f, cj->ls.radiance)) * cj->w_pdf;
        if (!(cj->w > 0.0f) || !(cj->w < INFINITY)) continue;
        sum += cj->w;
        m++;
    }
    if (m == 0) return v3(0, 0, 0);
    int k = 0;
    if (m > 1) { /* one in proportion to what it brings */
        float x = rng_float(rng) * sum;
        while (k < m - 1 && x >= c[k].w) x -= c[k++].w;
    }
    if (out) *out = c[k].ls;
    *f = c[k].f;
    vec3 tr = light_sample_visible(s, p, ng, &c[k].ls, sigma, shadow_rays);
    /* Resampled: the pick's own estimate times the candidates' sum over its share of it. */
    return is_black3(tr) ? tr : mul3(tr, scale3(c[k].ls.radiance, c[k].w_pdf * (sum / c[k].w)));
}

float light_pdf_env(const scene *s, vec3 d) {
    if (s->env_light < 0) return 0.0f;
    vec2 uv = env_uv(s->env, d);
    float st = sinf(PI_F * uv.y);
    if (!(st > 0.0f)) return 0.0f;
    return dist1d_pmf(&s->nee_dist, s->env_light) * dist2d_pdf(&s->env->dist, uv) / (2.0f * PI_F * PI_F * st);
}

/* ---- emission (light tracing) -------------------------------------------------------------- */

/* A point on the disk of the scene's bounding sphere facing direction d (the ray then travels
 * along d): where directional and environment light enters the scene. Returns the disk area. */
static float entry_disk_point(const scene *s, vec3 d, vec2 u, vec3 *o) {
    float r = 0.5f * s->diag;
    vec3 c = bounds_center(s->bounds);
    frame3 f = frame_from_normal(d);
    vec2 k = sample_concentric_disk(u);
    *o = add3(madd3(c, d, -r), add3(scale3(f.t, k.x * r), scale3(f.b, k.y * r)));
    return PI_F * r * r;
}

int light_sample_emission(const scene *s, float u_select, vec2 u_pos, vec2 u_dir, light_emission *out) {
    if (s->num_lights == 0) return 0;
    float pmf;
    int li = dist1d_sample_discrete(&s->light_dist, u_select, &pmf, NULL);
    if (!(pmf > 0.0f)) return 0;
    const light *l = &s->lights[li];
    memset(out, 0, sizeof *out);
    switch (l->type) {
    case LIGHT_POINT:
        out->o = l->position;
        out->d = sample_uniform_sphere(u_dir);
        out->power = scale3(l->color, 4.0f * PI_F / pmf);
        break;
    case LIGHT_SPOT: {
        /* Uniform in the outer cone; the falloff rides on the power. */
        float omc = fmaxf(1.0f - l->cos_outer, 1e-7f);
        frame3 f = frame_from_normal(l->direction);
        out->o = l->position;
        out->d = to_world(f, sample_uniform_cone(u_dir, omc));
        out->power = scale3(l->color, spot_falloff(l, out->d) / (pdf_uniform_cone(omc) * pmf));
        break;
    }
    case LIGHT_DIRECTIONAL: {
        out->d = l->direction;
        float area = entry_disk_point(s, l->direction, u_pos, &out->o);
        out->power = scale3(l->color, area / pmf);
        break;
    }
    case LIGHT_TRIANGLE: {
        vec3 q, n;
        float area2;
        surface_hit h = triangle_point(s, l->triangle, u_pos, &q, &n, &area2);
        /* A double-sided emitter picks a face with probability 1/2 (the u_dir.x bit reused). */
        float sides = 1.0f;
        if (s->materials[h.material].double_sided) {
            sides = 2.0f;
            if (u_dir.x < 0.5f) {
                u_dir.x *= 2.0f;
            } else {
                u_dir.x = fminf(2.0f * u_dir.x - 1.0f, 0x1.fffffep-1f);
                n = neg3(n);
                h.backface = 1;
            }
        }
        vec3 le = scale3(material_emission(s, &h), material_coverage(s, &h));
        if (is_black3(le) || !(area2 > 0.0f)) return 0;
        /* Cosine-weighted: Le cos / (pdf_area pdf_dir) = Le pi area. */
        out->o = q;
        out->n = n;
        out->on_surface = 1;
        out->d = to_world(frame_from_normal(n), sample_cosine_hemisphere(u_dir));
        out->power = scale3(le, PI_F * 0.5f * area2 * sides / pmf);
        break;
    }
    case LIGHT_ENV: {
        float pdf_uv;
        vec2 uv = dist2d_sample(&s->env->dist, u_dir, &pdf_uv);
        float st = sinf(PI_F * uv.y);
        if (!(pdf_uv > 0.0f) || !(st > 0.0f)) return 0;
        vec3 w = env_direction(s->env, uv); /* toward the environment */
        float pdf_w = pdf_uv / (2.0f * PI_F * PI_F * st);
        out->d = neg3(w);
        float area = entry_disk_point(s, out->d, u_pos, &out->o);
        out->power = scale3(env_lookup(s->env, uv), area / (pdf_w * pmf));
        break;
    }
    }
    return is_finite3(out->power) && !is_black3(out->power);
}
