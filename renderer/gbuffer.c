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

/* One pixel from its centre ray's hit h (NULL: it escaped) along unit direction d. */
static void fill_pixel(gbuffer *g, const scene *s, size_t i, vec3 d, const surface_hit *h) {
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
    frame3 f;
    bsdf b = material_bsdf(s, h, &f);
    /* The lobes' own colours, not their directional albedos: a point's albedo must not change as
     * the view turns, or light divided by it at one view and multiplied at another would (the
     * display's history follows points across views). */
    vec3 spec = v3(fminf(b.specular.x, 1.0f), fminf(b.specular.y, 1.0f), fminf(b.specular.z, 1.0f));
    if (!(bsdf_lobes(&b) & BSDF_GLOSSY)) spec = v3(0, 0, 0);
    vec3 total = add3(add3(b.diffuse, spec), b.transmission);
    float all = luminance3(total);
    put3(g->pos, i, h->p);
    put3(g->normal, i, f.n);
    g->depth[i] = h->t;
    put3(
        g->albedo, i,
        v3(fmaxf(total.x, GBUFFER_MIN_ALBEDO), fmaxf(total.y, GBUFFER_MIN_ALBEDO), fmaxf(total.z, GBUFFER_MIN_ALBEDO)));
    g->gloss[i] = all > 0.0f ? clampf(luminance3(spec) / all, 0.0f, 1.0f) : 0.0f;
    float a = bsdf_glossy_alpha(&b);
    g->alpha[i] = a > 0.0f ? a : 1.0f;
    g->material[i] = h->material;
}

typedef struct {
    gbuffer *g;
    const scene *s;
    camera_raster raster;
} trace_job;

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
        for (int k = 0; k < n; k++) fill_pixel(g, job->s, idx[k], d[k], (hits >> k & 1u) ? &hit[k] : NULL);
    }
}

void gbuffer_trace(gbuffer *g, const scene *s, const camera *cam, threadpool *pool) {
    g->cam = *cam;
    trace_job job = {g, s, camera_raster_make(cam, g->width, g->height)};
    int rows = (g->height + 3) / 4;
    if (pool) {
        threadpool_run(pool, trace_packet_row, &job, rows);
    } else {
        for (int r = 0; r < rows; r++) trace_packet_row(&job, r, 0);
    }
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
