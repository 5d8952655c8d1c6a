#include "gbuffer.h"

#include <stdlib.h>
#include <string.h>

#include "camera.h"

int gbuffer_init(gbuffer *g, int width, int height) {
    memset(g, 0, sizeof *g);
    size_t n = (size_t)width * (size_t)height;
    g->pos = malloc(sizeof(float) * 3 * n);
    g->normal = malloc(sizeof(float) * 3 * n);
    g->depth = malloc(sizeof(float) * n);
    g->albedo = malloc(sizeof(float) * 3 * n);
    g->gloss = malloc(sizeof(float) * n);
    g->alpha = malloc(sizeof(float) * n);
    g->material = malloc(sizeof(int32_t) * n);
    if (!g->pos || !g->normal || !g->depth || !g->albedo || !g->gloss || !g->alpha || !g->material) {
        gbuffer_deinit(g);
        return -1;
    }
    g->width = width;
    g->height = height;
    /* nothing traced yet: every ray escapes */
    memset(g->depth, 0, sizeof(float) * n);
    for (size_t i = 0; i < n; i++) g->material[i] = -1;
    return 0;
}

void gbuffer_deinit(gbuffer *g) {
    free(g->pos);
    free(g->normal);
    free(g->depth);
    free(g->albedo);
    free(g->gloss);
    free(g->alpha);
    free(g->material);
    memset(g, 0, sizeof *g);
}

static void put3(float *a, size_t i, vec3 v) {
    a[3 * i] = v.x;
    a[3 * i + 1] = v.y;
    a[3 * i + 2] = v.z;
}

/* What the G-buffer keeps of a BSDF: the lobes' own colours, not their directional albedos (a
 * point's albedo must not change as the view turns, or light divided by it at one view and
 * multiplied at another would: the display's history follows points across views), the glossy
 * lobe's share of them and its width. */
typedef struct {
    vec3 albedo;
    float gloss, alpha;
} surface_look;

static surface_look look_of(const bsdf *b) {
    vec3 spec = v3(fminf(b->specular.x, 1.0f), fminf(b->specular.y, 1.0f), fminf(b->specular.z, 1.0f));
    if (!(bsdf_lobes(b) & BSDF_GLOSSY)) spec = v3(0, 0, 0);
    vec3 total = add3(add3(b->diffuse, spec), b->transmission);
    float all = luminance3(total), a = bsdf_glossy_alpha(b);
    return (surface_look){
        v3(fmaxf(total.x, GBUFFER_MIN_ALBEDO), fmaxf(total.y, GBUFFER_MIN_ALBEDO), fmaxf(total.z, GBUFFER_MIN_ALBEDO)),
        all > 0.0f ? clampf(luminance3(spec) / all, 0.0f, 1.0f) : 0.0f, a > 0.0f ? a : 1.0f};
}

/* Whether a material's look is the same at every point: no texture among what sets its lobes. */
static int uniform_look(const material *m) {
    const material_ext *x = &m->ext;
    const texture_slot *slots[] = {&m->base_color_tex,      &m->metal_rough_tex,    &m->anisotropy_tex,
                                   &x->specular_tex,        &x->specular_color_tex, &x->sheen_color_tex,
                                   &x->sheen_roughness_tex, &x->clearcoat_tex,      &x->clearcoat_roughness_tex,
                                   &x->transmission_tex};
    for (size_t k = 0; k < sizeof slots / sizeof slots[0]; k++)
        if (slots[k]->texture >= 0) return 0;
    return 1;
}

typedef struct {
    gbuffer *g;
    const scene *s;
    camera_raster raster;
    const surface_look *looks;    /* per material, where uniform (the rest looked up at the hit)... */
    const unsigned char *uniform; /* ...NULL (out of memory): every hit looked up */
} trace_job;

/* One pixel from its centre ray's hit h (NULL: it escaped) along unit direction d. The shading
 * normal is the hit's (normal maps included); a material's rotation of the tangent does not move it. */
static void fill_pixel(const trace_job *job, size_t i, vec3 d, const surface_hit *h) {
    gbuffer *g = job->g;
    if (!h) {
        put3(g->pos, i, madd3(g->cam.position, d, 1e30f));
        put3(g->normal, i, neg3(d));
        g->depth[i] = 0.0f;
        put3(g->albedo, i, v3s(1.0f));
        g->gloss[i] = 0.0f;
        g->alpha[i] = 1.0f;
        g->material[i] = -1;
        return;
    }
    surface_look look;
    if (job->uniform && job->uniform[h->material]) {
        look = job->looks[h->material];
    } else {
        frame3 f;
        bsdf b = material_bsdf(job->s, h, &f);
        look = look_of(&b);
    }
    put3(g->pos, i, h->p);
    put3(g->normal, i, h->shading.n);
    g->depth[i] = h->t;
    put3(g->albedo, i, look.albedo);
    g->gloss[i] = look.gloss;
    g->alpha[i] = look.alpha;
    g->material[i] = h->material;
}

/* One row of 4x4-pixel packets: neighbouring centre rays share most of their traversal. */
static void trace_packet_row(void *ctx, int row, int worker) {
    (void)worker;
    trace_job *job = ctx;
    gbuffer *g = job->g;
    int y0 = 4 * row;
    for (int x0 = 0; x0 < g->width; x0 += 4) {
        vec3 d[SCENE_PACKET];
        surface_hit hit[SCENE_PACKET];
        size_t idx[SCENE_PACKET];
        int n = 0;
        for (int y = y0; y < y0 + 4 && y < g->height; y++)
            for (int x = x0; x < x0 + 4 && x < g->width; x++, n++) {
                idx[n] = (size_t)y * (size_t)g->width + (size_t)x;
                d[n] = camera_raster_dir(&job->raster, (float)x + 0.5f, (float)y + 0.5f);
            }
        unsigned hits = scene_intersect_packet(job->s, g->cam.position, d, n, hit);
        for (int k = 0; k < n; k++) fill_pixel(job, idx[k], d[k], (hits >> k & 1u) ? &hit[k] : NULL);
    }
}

void gbuffer_trace(gbuffer *g, const scene *s, const camera *cam, threadpool *pool) {
    g->cam = *cam;
    /* A material without textures on its lobes looks the same at every hit: looked up once. */
    size_t nm = s->num_materials > 0 ? (size_t)s->num_materials : 1;
    surface_look *looks = malloc(sizeof(surface_look) * nm);
    unsigned char *uniform = looks ? calloc(nm, 1) : NULL;
    for (int m = 0; uniform && m < s->num_materials; m++) {
        if (!(uniform[m] = (unsigned char)uniform_look(&s->materials[m]))) continue;
        surface_hit h = {.material = m, .shading = {v3(1, 0, 0), v3(0, 1, 0), v3(0, 0, 1)}, .coat_n = v3(0, 0, 1)};
        frame3 f;
        bsdf b = material_bsdf(s, &h, &f);
        looks[m] = look_of(&b);
    }
    trace_job job = {g, s, camera_raster_make(cam, g->width, g->height), looks, uniform};
    int rows = (g->height + 3) / 4;
    if (pool) {
        threadpool_run(pool, trace_packet_row, &job, rows);
    } else {
        for (int r = 0; r < rows; r++) trace_packet_row(&job, r, 0);
    }
    free(looks);
    free(uniform);
}

gbuffer_projector gbuffer_projector_of(const gbuffer *g) {
    const camera *c = &g->cam;
    float th = tanf(0.5f * c->yfov), aspect = (float)g->width / (float)g->height;
    return (gbuffer_projector){c->position,
                               c->right,
                               c->up,
                               c->forward,
                               (float)g->width / (2.0f * th * aspect),
                               (float)g->height / (2.0f * th),
                               0.5f * (float)g->width,
                               0.5f * (float)g->height};
}

int gbuffer_project(const gbuffer *g, vec3 p, float *x, float *y) {
    gbuffer_projector pr = gbuffer_projector_of(g);
    return gbuffer_project_with(&pr, p, x, y);
}
