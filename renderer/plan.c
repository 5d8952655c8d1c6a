#define _POSIX_C_SOURCE 200809L
#include "plan.h"

#include <stdlib.h>
#include <string.h>

#include "clock.h"
#include "lights.h"
#include "params.h"
#include "rng.h"
#include "sampling.h"

/* Probes: about this many in all, shared by area, and at least PROBES_PER_MATERIAL on each
 * material with any area, so a small mirror is not missed. */
#define PROBES_TOTAL 12288
#define PROBES_PER_MATERIAL 64
/* ... and light paths: their first hits are lit for certain, whatever the geometry's sides. */
#define LIGHT_PROBES 4096

static double triangle_area(const scene *s, int t) {
    const uint32_t *i = &s->indices[3 * t];
    vec3 a = s->positions[i[0]], b = s->positions[i[1]], c = s->positions[i[2]];
    return 0.5 * (double)length3(cross3(sub3(b, a), sub3(c, a)));
}

static void note_material(material_summary *m, const bsdf *b) {
    int lobes = bsdf_lobes(b);
    m->lobes |= lobes;
    if (!(lobes & BSDF_GLOSSY)) return;
    float alpha = bsdf_glossy_alpha(b);
    if (m->alpha_max == 0.0f || alpha < m->alpha_min) m->alpha_min = alpha;
    if (alpha > m->alpha_max) m->alpha_max = alpha;
    if (bsdf_glossy_aspect(b) > 1.1f) m->anisotropic = 1;
}

/* Whether h is on a side anything can see: the front, or either side of a double-sided
 * material. The inside of a closed object is neither. */
static int seen_side(const scene *s, const surface_hit *h) {
    return !h->backface ||
           (h->material >= 0 && h->material < s->num_materials && s->materials[h->material].double_sided);
}

/* What a cosine-distributed ray from b (BSDF bb) meets: light b reflects there can be reflected
 * again (indirect light), and between two glossy lobes it is a highlight's path. */
static void transport_from(const scene *s, scene_analysis *a, const surface_hit *b, const bsdf *bb, rng_state *rng) {
    vec3 d = to_world(frame_from_normal(b->ng), sample_cosine_hemisphere(rng_vec2(rng)));
    surface_hit h;
    frame3 f;
    a->probe_rays++;
    if (!scene_intersect(s, offset_origin(s, b->p, b->ng, d), d, INFINITY, &h)) return;
    bsdf bh = material_bsdf(s, &h, &f);
    if (!bsdf_lobes(&bh)) return;
    a->indirect = 1;
    if (bsdf_highlight_lobe(bb) && bsdf_highlight_lobe(&bh)) a->glossy_to_glossy = 1;
}

/* One surface probe: a point of triangle t seen from one side. The point is found by a ray back
 * at the triangle, so the hit record (and the BSDF, textures included) is the renderer's own. */
static void probe_surface(const scene *s, scene_analysis *a, int t, rng_state *rng) {
    const uint32_t *idx = &s->indices[3 * t];
    vec3 p0 = s->positions[idx[0]], p1 = s->positions[idx[1]], p2 = s->positions[idx[2]];
    vec3 n = cross3(sub3(p1, p0), sub3(p2, p0));
    float len = length3(n);
    if (!(len > 0.0f)) return;
    n = scale3(n, (rng_float(rng) < 0.5f ? 1.0f : -1.0f) / len);
    vec2 b = sample_uniform_triangle(rng_vec2(rng));
    vec3 p = add3(scale3(p0, 1.0f - b.x - b.y), add3(scale3(p1, b.x), scale3(p2, b.y)));
    float eps = 4.0f * scene_offset_eps(s, p);
    surface_hit h;
    frame3 f;
    a->probe_rays++;
    if (!scene_intersect(s, madd3(p, n, eps), neg3(n), 2.0f * eps, &h)) return;
    bsdf bh = material_bsdf(s, &h, &f);
    if (h.material >= 0 && h.material < a->num_materials) {
        a->materials[h.material].probes++;
        note_material(&a->materials[h.material], &bh);
    }
    if (!bsdf_lobes(&bh)) return;
    a->reflective = 1;
    if (seen_side(s, &h)) transport_from(s, a, &h, &bh, rng);
}

/* One light probe: a ray emitted by a light (chosen by power), and what the surface it lights
 * passes on: that surface is lit for certain, whichever side. */
static void probe_light(const scene *s, scene_analysis *a, rng_state *rng) {
    light_emission e;
    float u_sel = rng_float(rng);
    vec2 u_pos = rng_vec2(rng), u_dir = rng_vec2(rng);
    if (!light_sample_emission(s, u_sel, u_pos, u_dir, &e)) return;
    surface_hit h;
    frame3 f;
    a->probe_rays++;
    if (!scene_intersect(s, e.on_surface ? offset_origin(s, e.o, e.n, e.d) : e.o, e.d, INFINITY, &h)) return;
    bsdf bh = material_bsdf(s, &h, &f);
    if (bsdf_lobes(&bh)) transport_from(s, a, &h, &bh, rng);
}

int scene_analyse(const scene *s, scene_analysis *a, char *err, size_t errlen) {
    return scene_analyse_within(s, a, PLAN_PROBE_SECONDS, err, errlen);
}

/* Whether the probes have spent their budget (looked at every 64 probes: the clock costs). */
static int spent(scene_analysis *a, uint64_t t0, double seconds) {
    if (a->probe_rays % 64 == 0 && 1e-9 * (double)(clock_ns() - t0) >= seconds) a->cut = 1;
    return a->cut;
}

int scene_analyse_within(const scene *s, scene_analysis *a, double seconds, char *err, size_t errlen) {
    uint64_t t0 = clock_ns();
    memset(a, 0, sizeof *a);
    a->num_materials = s->num_materials;
    a->materials = calloc((size_t)(s->num_materials > 0 ? s->num_materials : 1), sizeof(material_summary));
    /* Triangles grouped by material (counting sort), each group with its cumulative areas. */
    int nm = s->num_materials + 1; /* the last group: triangles without a valid material */
    int *start = calloc((size_t)nm + 1, sizeof(int));
    int *order = malloc(sizeof(int) * (size_t)(s->num_triangles > 0 ? s->num_triangles : 1));
    double *cum = malloc(sizeof(double) * (size_t)(s->num_triangles > 0 ? s->num_triangles : 1));
    if (!a->materials || !start || !order || !cum) {
        free(start), free(order), free(cum);
        scene_analysis_free(a);
        return snprintf(err, errlen, "out of memory for the scene analysis"), -1;
    }
    for (int t = 0; t < s->num_triangles; t++) {
        int m = s->tri_material[t];
        start[(m >= 0 && m < s->num_materials ? m : nm - 1) + 1]++;
    }
    for (int g = 0; g < nm; g++) start[g + 1] += start[g];
    int *fill = calloc((size_t)nm, sizeof(int));
    if (!fill) {
        free(start), free(order), free(cum);
        scene_analysis_free(a);
        return snprintf(err, errlen, "out of memory for the scene analysis"), -1;
    }
    double total_area = 0.0;
    for (int t = 0; t < s->num_triangles; t++) {
        int m = s->tri_material[t];
        int g = m >= 0 && m < s->num_materials ? m : nm - 1;
        order[start[g] + fill[g]++] = t;
        total_area += triangle_area(s, t);
    }
    free(fill);
    rng_state rng = rng_for(0x9e3779b9u, 0, 0x706c616eu);
    for (int g = 0; g < nm && !a->cut; g++) {
        int first = start[g], count = start[g + 1] - first;
        double area = 0.0;
        for (int k = 0; k < count; k++) cum[first + k] = area += triangle_area(s, order[first + k]);
        if (!(area > 0.0)) continue;
        int probes = PROBES_PER_MATERIAL + (int)(PROBES_TOTAL * (area / total_area));
        for (int k = 0; k < probes && !spent(a, t0, seconds); k++) {
            /* A triangle by area: the first whose cumulative area exceeds u. */
            double u = rng_double(&rng) * area;
            int lo = 0, hi = count - 1;
            while (lo < hi) {
                int mid = (lo + hi) / 2;
                if (cum[first + mid] > u)
                    hi = mid;
                else
                    lo = mid + 1;
            }
            probe_surface(s, a, order[first + lo], &rng);
        }
    }
    for (int k = 0; k < LIGHT_PROBES && s->num_lights > 0 && !spent(a, t0, seconds); k++) probe_light(s, a, &rng);
    free(start), free(order), free(cum);

    a->alpha_min = 0.0f;
    a->alpha_max = 0.0f;
    for (int m = 0; m < a->num_materials; m++) {
        const material_summary *ms = &a->materials[m];
        if (!ms->probes) continue;
        int glossy = (ms->lobes & BSDF_GLOSSY) && ms->alpha_min < BSDF_HIGHLIGHT_ALPHA;
        a->rough += (ms->lobes & BSDF_GLOSSY) && !glossy;
        a->diffuse += ms->lobes == BSDF_DIFFUSE;
        a->glossy += glossy;
        a->near_specular += glossy && ms->alpha_min < PLAN_NEAR_SPECULAR_ALPHA;
        a->anisotropic += glossy && ms->anisotropic;
        if (glossy) {
            if (a->alpha_max == 0.0f || ms->alpha_min < a->alpha_min) a->alpha_min = ms->alpha_min;
            a->alpha_max = fmaxf(a->alpha_max, fminf(ms->alpha_max, BSDF_HIGHLIGHT_ALPHA));
        }
    }
    for (int li = 0; li < s->num_lights; li++) {
        light_type type = s->lights[li].type;
        a->punctual += type == LIGHT_POINT || type == LIGHT_SPOT || type == LIGHT_DIRECTIONAL;
        a->area += type == LIGHT_TRIANGLE;
    }
    a->env = s->env != NULL;
    a->seconds = 1e-9 * (double)(clock_ns() - t0);
    return 0;
}

void scene_analysis_free(scene_analysis *a) {
    free(a->materials);
    a->materials = NULL;
    a->num_materials = 0;
}

effect_plan plan_make(const scene_analysis *a, int method, int max_depth, int mode) {
    effect_plan p;
    memset(&p, 0, sizeof p);
    p.full = mode == PLAN_FULL || a->cut; /* what a cut probe did not find may be there */
    p.max_depth = max_depth;
    int many = method == METHOD_VPL || method == METHOD_VSL || method == METHOD_VSL_HL || method == METHOD_AUTO;
    int vsl = method == METHOD_VSL || method == METHOD_VSL_HL || method == METHOD_AUTO;
    int emitters = a->punctual + a->area + a->env;
    int each = nee_each_count(a->punctual), candidates = each + (emitters > each); /* lights.h */
    snprintf(p.why_direct, sizeof p.why_direct, "%s%s%s%s%s%s%s", emitters ? "" : "none: no emitters",
             a->punctual ? "punctual lights by one shadow ray each" : "", a->punctual && a->area + a->env ? "; " : "",
             a->area ? "area lights by light and BSDF sampling (MIS)" : "", a->area && a->env ? "; " : "",
             a->env ? "the environment by importance and BSDF sampling (MIS)" : "",
             candidates > 1 ? "; a sample's light kept among candidates by what each would bring" : "");
    if (p.full) {
        p.virtual_lights = many;
        p.vsl_all_strategies = vsl;
        p.highlights = method == METHOD_VSL_HL;
        p.env_prefilter = p.highlights && a->env;
        const char *why = mode == PLAN_FULL ? "--plan full" : "the scene's probe stopped at its time budget";
        char forced[96];
        snprintf(forced, sizeof forced, "forced on (%s)", why);
        snprintf(p.why_depth, sizeof p.why_depth, "%d, as asked (%s)", max_depth, why);
        snprintf(p.why_virtual, sizeof p.why_virtual, "%s", many ? forced : "not this method");
        snprintf(p.why_kernel, sizeof p.why_kernel, "%s",
                 vsl ? "three strategies for every pair (every pass on)" : "not this method");
        snprintf(p.why_highlights, sizeof p.why_highlights, "%s", p.highlights ? forced : "not this method");
        snprintf(p.why_env, sizeof p.why_env, "%s",
                 p.env_prefilter ? forced
                 : !a->env       ? "no environment map"
                                 : "no highlight pass");
        return p;
    }
    /* The path tracer is the reference: it keeps the depth asked, whatever the probes found. */
    if (method == METHOD_PT) {
        snprintf(p.why_depth, sizeof p.why_depth, "%d, as asked (path tracing, the reference, never drops bounces)",
                 max_depth);
    } else if (max_depth > 1 && (!a->indirect || !emitters)) {
        p.max_depth = 1;
        snprintf(p.why_depth, sizeof p.why_depth, "1 of %d asked: %s", max_depth,
                 !emitters ? "nothing emits" : "no reflecting surface sees another (direct light only)");
    } else {
        snprintf(p.why_depth, sizeof p.why_depth, "%d, as asked", max_depth);
    }
    p.virtual_lights = many && p.max_depth > 1;
    snprintf(p.why_virtual, sizeof p.why_virtual, "%s",
             !many              ? "not this method"
             : p.virtual_lights ? "on: reflecting surfaces see each other"
                                : "off: no indirect light to carry");
    if (!vsl || !p.virtual_lights)
        snprintf(p.why_kernel, sizeof p.why_kernel, "%s", !vsl ? "not this method" : "no virtual lights");
    else if (a->glossy)
        snprintf(p.why_kernel, sizeof p.why_kernel,
                 "three strategies where a glossy lobe (alpha < %g) takes part, two for the rest",
                 (double)BSDF_HIGHLIGHT_ALPHA);
    else
        snprintf(p.why_kernel, sizeof p.why_kernel,
                 "diffuse-only (points on the disk): no glossy lobe sharper than alpha %g",
                 (double)BSDF_HIGHLIGHT_ALPHA);
    if (method != METHOD_VSL_HL) {
        snprintf(p.why_highlights, sizeof p.why_highlights, "not this method");
    } else if (p.max_depth < 2 || !emitters) {
        snprintf(p.why_highlights, sizeof p.why_highlights, "off: no indirect light");
    } else if (!a->glossy_to_glossy) {
        snprintf(p.why_highlights, sizeof p.why_highlights,
                 "off: no glossy surface sees a glossy surface (the VSLs keep those paths)");
    } else {
        p.highlights = 1;
        snprintf(p.why_highlights, sizeof p.why_highlights, "on: glossy surfaces see each other");
    }
    p.env_prefilter = p.highlights && a->env;
    snprintf(p.why_env, sizeof p.why_env, "%s",
             p.env_prefilter ? "on: highlights lit by the environment"
             : !a->env       ? "off: no environment map"
                             : "off: no highlight pass");
    return p;
}

void plan_print(FILE *f, const scene *s, const scene_analysis *a, const effect_plan *p) {
    fprintf(f, "analysis:   %d diffuse, %d rough (glossy lobes of alpha >= %g only), %d glossy", a->diffuse, a->rough,
            (double)BSDF_HIGHLIGHT_ALPHA, a->glossy);
    if (a->glossy)
        fprintf(f, " (alpha %.3g to %.3g; %d near-specular, %d anisotropic)", (double)a->alpha_min,
                (double)a->alpha_max, a->near_specular, a->anisotropic);
    fprintf(f, " materials\n");
    fprintf(f, "            emitters: %d punctual, %d emissive triangles, %s\n", a->punctual, a->area,
            a->env ? "an environment map" : "no environment map");
    fprintf(f, "            indirect light %s; glossy-to-glossy transport %s (%ld probe rays, %.0f ms%s); scale %.3g\n",
            a->indirect ? "possible" : "impossible", a->glossy_to_glossy ? "possible" : "not found", a->probe_rays,
            1e3 * a->seconds, a->cut ? ", stopped at the time budget: a partial look" : "", (double)s->diag);
    char text[1200];
    plan_summary(p, text, sizeof text);
    const char *line = text;
    for (int first = 1; *line; first = 0) {
        const char *end = strchr(line, '\n');
        int n = end ? (int)(end - line) : (int)strlen(line);
        fprintf(f, "%s%.*s\n", first ? "plan:       " : "            ", n, line);
        line += n + (end != NULL);
    }
}

void plan_summary(const effect_plan *p, char *buf, size_t len) {
    snprintf(buf, len,
             "direct light: %s\nmax depth: %s\nvirtual lights: %s\nVSL kernel: %s\nhighlights: %s\n"
             "environment prefiltering: %s",
             p->why_direct, p->why_depth, p->why_virtual, p->why_kernel, p->why_highlights, p->why_env);
}
