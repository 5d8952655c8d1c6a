/* What an emissive texture makes of its triangles (docs/design.md, "Emissive textures"): a
 * triangle on which the texture is black all over emits nothing and is no light (a mostly black
 * emissive map must not make every triangle a light), and a light's power for selection is the
 * texture's mean over the triangle's uv footprint. Both with bounded work per triangle, on a max
 * and a mean pyramid of each emissive texture. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene_parts.h"

#define MAX_LEVELS 16    /* 16384 texels on a side: 15 levels */
#define ZERO_TEST_SPAN 8 /* the zero test visits at most this many texels a side (+1) per span */
#define MEAN_SPAN 16     /* the mean is integrated on the level where the footprint spans this many */
#define MEAN_FLOOR 1e-6f /* the mean never drops below this share of the maximum where it is not 0 */
#define HUGE_COORD 1e8f  /* texel coordinates beyond: the whole texture (texture_lookup reads 0, 0) */

/* Level 0 is the image itself (decoded on reading); levels 1.. halve it, keeping per texel and
 * channel the mean (linear, 16-bit fixed point) and the maximum (the encoded 8-bit value: sRGB
 * decoding keeps the order). 9 bytes a level-1 texel: the whole pyramid takes 3/4 of the image's
 * own memory, and only while the image's triangles are measured. */
typedef struct {
    const scene_image *img;
    int levels;
    int w[MAX_LEVELS], h[MAX_LEVELS];
    uint16_t *mean[MAX_LEVELS];
    uint8_t *max[MAX_LEVELS];
} pyramid;

static vec3 texel(const pyramid *p, int level, int x, int y, int want_max) {
    const float *srgb = texture_srgb_table();
    size_t i = 3 * ((size_t)y * (size_t)p->w[level] + (size_t)x);
    if (level == 0 || want_max) {
        const uint8_t *c = level == 0 ? p->img->rgba + 4 * (i / 3) : p->max[level] + i;
        return v3(srgb[c[0]], srgb[c[1]], srgb[c[2]]);
    }
    const uint16_t *m = p->mean[level] + i;
    return scale3(v3((float)m[0], (float)m[1], (float)m[2]), 1.0f / 65535.0f);
}

static void pyramid_free(pyramid *p) {
    for (int l = 1; l < p->levels; l++) {
        free(p->mean[l]);
        free(p->max[l]);
    }
    memset(p, 0, sizeof *p);
}

static int pyramid_build(const scene_image *img, pyramid *p) {
    memset(p, 0, sizeof *p);
    p->img = img;
    p->w[0] = img->width;
    p->h[0] = img->height;
    p->levels = 1;
    while ((p->w[p->levels - 1] > 1 || p->h[p->levels - 1] > 1) && p->levels < MAX_LEVELS) {
        int l = p->levels, pw = p->w[l - 1], ph = p->h[l - 1];
        int w = (pw + 1) / 2, h = (ph + 1) / 2;
        p->w[l] = w;
        p->h[l] = h;
        p->mean[l] = malloc(3 * sizeof(uint16_t) * (size_t)w * (size_t)h);
        p->max[l] = malloc(3 * (size_t)w * (size_t)h);
        p->levels++;
        if (!p->mean[l] || !p->max[l]) return -1;
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                vec3 sum = v3(0, 0, 0);
                uint8_t mx[3] = {0, 0, 0};
                int n = 0;
                for (int k = 0; k < 4; k++) {
                    int cx = 2 * x + (k & 1), cy = 2 * y + (k >> 1);
                    if (cx >= pw || cy >= ph) continue;
                    sum = add3(sum, texel(p, l - 1, cx, cy, 0));
                    size_t j = (size_t)cy * (size_t)pw + (size_t)cx;
                    const uint8_t *c = l == 1 ? img->rgba + 4 * j : p->max[l - 1] + 3 * j;
                    for (int ch = 0; ch < 3; ch++) mx[ch] = c[ch] > mx[ch] ? c[ch] : mx[ch];
                    n++;
                }
                size_t i = 3 * ((size_t)y * (size_t)w + (size_t)x);
                vec3 mean = scale3(sum, 65535.0f / (float)n);
                p->mean[l][i] = (uint16_t)(mean.x + 0.5f);
                p->mean[l][i + 1] = (uint16_t)(mean.y + 0.5f);
                p->mean[l][i + 2] = (uint16_t)(mean.z + 0.5f);
                memcpy(p->max[l] + i, mx, 3);
            }
    }
    return 0;
}

typedef struct {
    int lo, hi;
} span;

/* The texels a run [x0, x1] of level-0 texel indices reads in a row of n under a wrap mode, as at
 * most two spans (the whole row when the run reaches around it). */
static int wrap_spans(long long x0, long long x1, int n, wrap_mode mode, span out[2]) {
    if (mode == WRAP_CLAMP) {
        out[0] = (span){x0 < 0 ? 0 : (x0 >= n ? n - 1 : (int)x0), x1 < 0 ? 0 : (x1 >= n ? n - 1 : (int)x1)};
        return 1;
    }
    if (x1 - x0 + 1 >= n) {
        out[0] = (span){0, n - 1};
        return 1;
    }
    /* Shorter than a row: within two consecutive stretches of n texels, each of which both modes
     * read in one direction (mirror: backwards every other stretch). */
    long long seg0 = x0 >= 0 ? x0 / n : -((-x0 + n - 1) / n);
    int k = 0;
    for (long long seg = seg0; seg * n <= x1 && k < 2; seg++) {
        long long lo = x0 > seg * n ? x0 : seg * n, hi = x1 < seg * n + n - 1 ? x1 : seg * n + n - 1;
        int a = texture_wrap((int)lo, n, mode), b = texture_wrap((int)hi, n, mode);
        out[k++] = (span){a < b ? a : b, a < b ? b : a};
    }
    return k;
}

/* The largest texel (per channel) in a rectangle of level-0 texels, read on the coarsest level
 * that keeps it to a few texels a side: never smaller than the truth. */
static vec3 rect_max(const pyramid *p, span xs, span ys) {
    int l = 0;
    while (l + 1 < p->levels &&
           ((xs.hi >> l) - (xs.lo >> l) >= ZERO_TEST_SPAN || (ys.hi >> l) - (ys.lo >> l) >= ZERO_TEST_SPAN))
        l++;
    vec3 mx = v3(0, 0, 0);
    for (int y = ys.lo >> l; y <= ys.hi >> l; y++)
        for (int x = xs.lo >> l; x <= xs.hi >> l; x++) mx = max3(mx, texel(p, l, x, y, 1));
    return mx;
}

/* Texel (i, j) of level l's means, wrapped. */
static vec3 level_texel(const pyramid *p, const scene_texture *tex, int l, int i, int j) {
    return texel(p, l, texture_wrap(i, p->w[l], tex->wrap_s), texture_wrap(j, p->h[l], tex->wrap_t), 0);
}

/* The bilinear interpolant of level l at (x, y) in its texel coordinates (centres at integers),
 * from the cell's four texels c[4] ((i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1)). */
static vec3 cell_eval(const vec3 c[4], float x, float y) {
    return add3(scale3(add3(scale3(c[0], 1.0f - x), scale3(c[1], x)), 1.0f - y),
                scale3(add3(scale3(c[2], 1.0f - x), scale3(c[3], x)), y));
}

/* Keeps the part of polygon (n points) where sign * (coordinate axis - at) >= 0. */
static int clip(vec2 *pts, int n, int axis, float at, float sign, vec2 *out) {
    int m = 0;
    for (int k = 0; k < n; k++) {
        vec2 a = pts[k], b = pts[(k + 1) % n];
        float da = sign * ((axis ? a.y : a.x) - at), db = sign * ((axis ? b.y : b.x) - at);
        if (da >= 0.0f) out[m++] = a;
        if ((da >= 0.0f) != (db >= 0.0f)) {
            float t = da / (da - db);
            out[m++] = v2(a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t);
        }
    }
    return m;
}

/* The integral of level l's bilinear interpolant over the triangle (xs, ys) given in its texel
 * coordinates: the triangle clipped to each texel cell, the bilinear part integrated exactly
 * (the edge-midpoint rule is exact up to degree 2). */
static vec3 triangle_integral(const pyramid *p, const scene_texture *tex, int l, const float xs[3], const float ys[3]) {
    int i0 = (int)floorf(fminf(xs[0], fminf(xs[1], xs[2]))), i1 = (int)floorf(fmaxf(xs[0], fmaxf(xs[1], xs[2])));
    int j0 = (int)floorf(fminf(ys[0], fminf(ys[1], ys[2]))), j1 = (int)floorf(fmaxf(ys[0], fmaxf(ys[1], ys[2])));
    vec3 sum = v3(0, 0, 0);
    for (int j = j0; j <= j1; j++)
        for (int i = i0; i <= i1; i++) {
            vec2 a[10] = {v2(xs[0] - (float)i, ys[0] - (float)j), v2(xs[1] - (float)i, ys[1] - (float)j),
                          v2(xs[2] - (float)i, ys[2] - (float)j)},
                 b[10];
            int n = clip(a, 3, 0, 0.0f, 1.0f, b);
            n = clip(b, n, 0, 1.0f, -1.0f, a);
            n = clip(a, n, 1, 0.0f, 1.0f, b);
            n = clip(b, n, 1, 1.0f, -1.0f, a);
            if (n < 3) continue;
            vec3 c[4] = {level_texel(p, tex, l, i, j), level_texel(p, tex, l, i + 1, j),
                         level_texel(p, tex, l, i, j + 1), level_texel(p, tex, l, i + 1, j + 1)};
            for (int k = 1; k + 1 < n; k++) {
                vec2 q0 = a[0], q1 = a[k], q2 = a[k + 1];
                float area = 0.5f * fabsf((q1.x - q0.x) * (q2.y - q0.y) - (q2.x - q0.x) * (q1.y - q0.y));
                vec3 f = add3(add3(cell_eval(c, 0.5f * (q0.x + q1.x), 0.5f * (q0.y + q1.y)),
                                   cell_eval(c, 0.5f * (q1.x + q2.x), 0.5f * (q1.y + q2.y))),
                              cell_eval(c, 0.5f * (q2.x + q0.x), 0.5f * (q2.y + q0.y)));
                sum = madd3(sum, f, area / 3.0f);
            }
        }
    return sum;
}

/* The texture's mean over triangle t, and (in *mx) its maximum over every texel a lookup on the
 * triangle can read; both zero when nothing on the triangle can emit. */
static vec3 triangle_mean(const scene *s, const pyramid *p, const scene_texture *tex, texture_slot slot, int t,
                          int mean_span, vec3 *mx) {
    const uint32_t *v = &s->indices[3 * t];
    float xs[3], ys[3];
    int whole = 0;
    for (int c = 0; c < 3; c++) {
        vec2 uv = slot.texcoord == 1 ? s->uv1[v[c]] : s->uv0[v[c]];
        if (slot.transformed) {
            const float *m = slot.uv_xf;
            uv = v2(m[0] * uv.x + m[1] * uv.y + m[2], m[3] * uv.x + m[4] * uv.y + m[5]);
        }
        xs[c] = uv.x * (float)p->w[0] - 0.5f;
        ys[c] = uv.y * (float)p->h[0] - 0.5f;
        whole |= !(fabsf(xs[c]) <= HUGE_COORD && fabsf(ys[c]) <= HUGE_COORD);
    }
    int top = p->levels - 1;
    if (whole) {
        *mx = rect_max(p, (span){0, p->w[0] - 1}, (span){0, p->h[0] - 1});
        return texel(p, top, 0, 0, 0);
    }
    float x_lo = fminf(xs[0], fminf(xs[1], xs[2])), x_hi = fmaxf(xs[0], fmaxf(xs[1], xs[2]));
    float y_lo = fminf(ys[0], fminf(ys[1], ys[2])), y_hi = fmaxf(ys[0], fmaxf(ys[1], ys[2]));
    /* A bilinear lookup at x reads texels floor(x) and floor(x) + 1. */
    span sx[2], sy[2];
    int nx = wrap_spans((long long)floorf(x_lo), (long long)floorf(x_hi) + 1, p->w[0], tex->wrap_s, sx);
    int ny = wrap_spans((long long)floorf(y_lo), (long long)floorf(y_hi) + 1, p->h[0], tex->wrap_t, sy);
    *mx = v3(0, 0, 0);
    for (int i = 0; i < nx; i++)
        for (int j = 0; j < ny; j++) *mx = max3(*mx, rect_max(p, sx[i], sy[j]));
    if (is_black3(*mx)) return *mx;

    /* The mean: the exact integral of the interpolant, on the level where the footprint spans at
     * most mean_span texels (a box-filtered copy beyond: the cost stays bounded). */
    int l = 0;
    float width = fmaxf(x_hi - x_lo, y_hi - y_lo);
    while (l < top && width > (float)(mean_span << l)) l++;
    /* Wider than that even on the coarsest level: the footprint covers the image many times over
     * (or clamps far past it); the image's mean stands for it. */
    if (width > (float)(mean_span << l)) return texel(p, top, 0, 0, 0);
    float k = 1.0f / (float)(1 << l), lx[3], ly[3];
    for (int c = 0; c < 3; c++) lx[c] = (xs[c] + 0.5f) * k - 0.5f, ly[c] = (ys[c] + 0.5f) * k - 0.5f;
    float area = 0.5f * fabsf((lx[1] - lx[0]) * (ly[2] - ly[0]) - (lx[2] - lx[0]) * (ly[1] - ly[0]));
    if (!(area > 1e-12f)) { /* no uv extent: the texel value where it sits */
        float cx = (lx[0] + lx[1] + lx[2]) / 3.0f, cy = (ly[0] + ly[1] + ly[2]) / 3.0f, fx = floorf(cx),
              fy = floorf(cy);
        int i = (int)fx, j = (int)fy;
        vec3 c[4] = {level_texel(p, tex, l, i, j), level_texel(p, tex, l, i + 1, j), level_texel(p, tex, l, i, j + 1),
                     level_texel(p, tex, l, i + 1, j + 1)};
        return cell_eval(c, cx - fx, cy - fy);
    }
    vec3 mean = scale3(triangle_integral(p, tex, l, lx, ly), 1.0f / area);
    /* At the image's own level the integral is exact: zero means nothing emits there. */
    if (l == 0 && is_black3(mean)) *mx = mean;
    return mean;
}

static int textured_emitter(const material *m) { return max_comp3(m->emission) > 0.0f && m->emissive_tex.texture >= 0; }

int scene_emissive_analyse(scene *s, char *err, size_t errlen) {
    free(s->tri_emit_tex);
    s->tri_emit_tex = NULL;
    /* The emissive textured triangles, grouped by the image they show (a counting sort): each
     * image's pyramid is built once, however many textures and materials share it. */
    int *start = calloc((size_t)s->num_images + 2, sizeof(int)), n = 0;
    if (!start) return snprintf(err, errlen, "%s: out of memory", s->path), -1;
    for (int t = 0; t < s->num_triangles; t++) {
        const material *m = &s->materials[s->tri_material[t]];
        if (textured_emitter(m)) start[s->textures[m->emissive_tex.texture].image + 1]++, n++;
    }
    if (n == 0) return free(start), 0;
    for (int i = 0; i < s->num_images; i++) start[i + 1] += start[i];
    int *order = malloc(sizeof(int) * (size_t)n), *fill = calloc((size_t)s->num_images + 1, sizeof(int));
    s->tri_emit_tex = calloc((size_t)s->num_triangles + 1, sizeof(vec3));
    int status = order && fill && s->tri_emit_tex ? 0 : -1;
    for (int t = 0; status == 0 && t < s->num_triangles; t++) {
        const material *m = &s->materials[s->tri_material[t]];
        if (!textured_emitter(m)) continue;
        int img = s->textures[m->emissive_tex.texture].image;
        order[start[img] + fill[img]++] = t;
    }
    /* The integral's cells per triangle shrink with their number: a few hundred each for a
     * model's emitters, a handful each for millions (the whole stays below about 2^26). */
    int mean_span = (int)sqrtf((float)(1 << 26) / (float)n);
    mean_span = mean_span < 2 ? 2 : (mean_span > MEAN_SPAN ? MEAN_SPAN : mean_span);
    for (int img = 0; status == 0 && img < s->num_images; img++) {
        if (start[img] == start[img + 1]) continue;
        pyramid p;
        if ((status = pyramid_build(&s->images[img], &p)) == 0)
            for (int k = start[img]; k < start[img + 1]; k++) {
                int t = order[k];
                const material *m = &s->materials[s->tri_material[t]];
                vec3 mx, mean = triangle_mean(s, &p, &s->textures[m->emissive_tex.texture], m->emissive_tex, t,
                                              mean_span, &mx);
                /* Zero exactly where nothing emits; elsewhere never zero (a coarse level's integral
                 * is an estimate, and a light the texture lights somewhere must stay reachable). */
                s->tri_emit_tex[t] = v3(mx.x > 0.0f ? fmaxf(mean.x, MEAN_FLOOR * mx.x) : 0.0f,
                                        mx.y > 0.0f ? fmaxf(mean.y, MEAN_FLOOR * mx.y) : 0.0f,
                                        mx.z > 0.0f ? fmaxf(mean.z, MEAN_FLOOR * mx.z) : 0.0f);
            }
        pyramid_free(&p);
    }
    free(start);
    free(order);
    free(fill);
    return status == 0 ? 0 : (snprintf(err, errlen, "%s: out of memory", s->path), -1);
}
