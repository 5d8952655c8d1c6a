/* glint — the display after a light change (docs/design.md, "Light moves"): the history set aside
 * and judged, tile by tile, from the new samples; and where punctual lights alone changed, each
 * pixel's direct light computed again for them as they were and as they are (relit), not judged. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "camera.h"
#include "display_parts.h"
#include "lights.h"
#include "pt.h"

/* Adds b's samples to a's, per component, b's counted at most cap each; all but the direct light
 * where `but_direct` (a relit pixel's, which comes back whole). */
static void history_merge(pixel_history *a, const pixel_history *b, float cap, int but_direct) {
    float da = a->c[COMP_DIRECT].count, db = fminf(b->c[COMP_DIRECT].count, cap);
    if (da + db > 0.0f) a->turn = (da * a->turn + db * b->turn) / (da + db);
    for (int c = but_direct ? COMP_DIRECT + 1 : 0; c < COMP_COUNT; c++) history_merge_one(a, b, c, cap);
}

/* The components a light change's new samples judge at pixel i: all, or all but the direct light
 * where it was relit. */
static int judged_from(const display *d, size_t i) { return d->relit[i] ? COMP_DIRECT + 1 : 0; }

/* Luminance of components from .. COMP_COUNT - 1 of a history entry, summed, and its samples'
 * variance. */
static float total_luminance(const pixel_history *p, int from, float *variance) {
    float l = 0.0f, v = 0.0f;
    for (int c = from; c < COMP_COUNT; c++) {
        float lc = luminance3(v3(p->c[c].mean[0], p->c[c].mean[1], p->c[c].mean[2]));
        l += lc;
        v += fmaxf(p->c[c].m2 - lc * lc, 0.0f);
    }
    *variance = v;
    return l;
}

/* Whether a pixel's new samples (h) disagree with its stale history (s) of many samples beyond
 * their noise (a new sample as spread as the stale ones, at least; the components' variances
 * summed COMP_COUNT times, as they may go together), in the components judged from `from`: a speck
 * the light lit before (its reflection in a mirror, with the many extra samples such a pixel takes)
 * has moved, though its tile as a whole has not changed. */
#define STALE_MANY 8.0f
static int pixel_changed(const pixel_history *h, const pixel_history *s, int from) {
    float n = h->c[COMP_DIRECT].count, m = s->c[COMP_DIRECT].count, vh, vs;
    if (!(n >= 1.0f) || !(m >= STALE_MANY)) return 0;
    float lh = total_luminance(h, from, &vh), ls = total_luminance(s, from, &vs), diff = fabsf(lh - ls);
    float noise = sqrtf((float)COMP_COUNT * (vs / m + fmaxf(vh, vs) / n));
    return diff > 3.0f * noise && diff > 0.1f * fmaxf(lh, ls);
}

/* A tile's verdict: where the light did not change its stale history comes back, but for pixels
 * whose new samples contradict it; where it did the stale history goes. A pixel with samples of its
 * own that agree takes it back in full; one without takes it back as one sample (the tile's verdict
 * is its sampled pixels', and a speck the light lit may have moved where none was sampled), and not
 * at all where its light is mostly its glossy lobe's, which moves with the light. A relit pixel's
 * direct light comes back whole whatever the verdict. */
static void settle_tile(display *d, int t, int state) {
    d->tiles[t].state = state;
    int x0 = (t % d->tiles_x) * TILE_PX, y0 = (t / d->tiles_x) * TILE_PX;
    pixel_history *h = d->h[d->cur];
    const gbuffer *g = &d->g[d->cur];
    for (int y = y0; y < y0 + TILE_PX && y < d->height; y++)
        for (int x = x0; x < x0 + TILE_PX && x < d->width; x++) {
            size_t i = (size_t)y * (size_t)d->width + (size_t)x;
            int relit = d->relit[i];
            if (state == TILE_SAME && !pixel_changed(&h[i], &d->stale[i], judged_from(d, i))) {
                if (h[i].c[COMP_DIRECT].count >= 1.0f)
                    history_merge(&h[i], &d->stale[i], INFINITY, relit);
                else if (!mostly_glossy(g, i))
                    history_merge(&h[i], &d->stale[i], 1.0f, relit);
            }
            if (relit) history_merge_one(&h[i], &d->stale[i], COMP_DIRECT, INFINITY);
            memset(&d->stale[i], 0, sizeof d->stale[i]);
            d->relit[i] = 0;
        }
}

/* ---- relighting: a punctual light's change to each pixel's direct light, computed ---------- */

static uint64_t fnv(uint64_t h, const void *p, size_t n) {
    for (size_t k = 0; k < n; k++) h = (h ^ ((const unsigned char *)p)[k]) * 1099511628211ull;
    return h;
}

/* The scene's punctual lights lead its light list. */
static int punctual_count(const scene *s) {
    int n = 0;
    while (n < s->num_lights && s->lights[n].type <= LIGHT_DIRECTIONAL) n++;
    return n;
}

/* A fingerprint of the scene's light other than its punctual lights: emissive triangles (where
 * they are, their materials' emission, their powers) and the environment. */
static uint64_t other_light_print(const scene *s, int from) {
    uint64_t h = fnv(1469598103934665603ull, &s->num_lights, sizeof s->num_lights);
    for (int i = from; i < s->num_lights; i++) {
        const light *l = &s->lights[i];
        h = fnv(h, &l->type, sizeof l->type);
        h = fnv(h, &l->color, sizeof l->color);
        h = fnv(h, &l->power, sizeof l->power);
        if (l->type != LIGHT_TRIANGLE || l->triangle < 0 || l->triangle >= s->num_triangles) continue;
        for (int k = 0; k < 3; k++) h = fnv(h, &s->positions[s->indices[3 * l->triangle + k]], sizeof(vec3));
        h = fnv(h, &s->materials[s->tri_material[l->triangle]].emission, sizeof(vec3));
    }
    h = fnv(h, &s->env, sizeof s->env);
    if (s->env) {
        const env_map *e = s->env;
        h = fnv(h, &e->image.rgb, sizeof e->image.rgb);
        h = fnv(h, &e->rotation, sizeof e->rotation);
        h = fnv(h, &e->mean_luminance, sizeof e->mean_luminance);
    }
    return h;
}

void display_lights_seen(display *d, const scene *s, int rest_unchanged) {
    int n = punctual_count(s);
    uint64_t rest = rest_unchanged && d->num_seen == n ? d->seen_rest : other_light_print(s, n);
    d->num_seen = -1; /* unknown, unless the copy below is made */
    if (n > d->cap_seen) {
        light *grown = realloc(d->seen, sizeof(light) * (size_t)n);
        if (!grown) return;
        d->seen = grown;
        d->cap_seen = n;
    }
    if (n > 0) memcpy(d->seen, s->lights, sizeof(light) * (size_t)n);
    d->seen_rest = rest;
    d->num_seen = n;
}

int changed_punctual(const display *d, const scene *s, light *was, light *now) {
    int n = punctual_count(s), k = 0;
    if (n != d->num_seen || other_light_print(s, n) != d->seen_rest) return -1;
    for (int i = 0; i < n; i++) {
        if (!memcmp(&s->lights[i], &d->seen[i], sizeof(light))) continue;
        if (k == RELIGHT_MAX) return -1;
        was[k] = d->seen[i], now[k] = s->lights[i], k++;
    }
    return k;
}

typedef struct {
    display *d;
    const scene *s;
    camera_raster raster;
    light lights[2 * RELIGHT_MAX]; /* the changed lights as they are, then as they were */
    int n;                         /* how many changed */
} relight_job;

/* Pixel i's stale direct light, a mean over its albedo, moved by the change `delta` of the light
 * it reflects; its spread kept. */
static void relight_pixel(display *d, size_t i, vec3 delta) {
    float *m = d->stale[i].c[COMP_DIRECT].mean, *m2 = &d->stale[i].c[COMP_DIRECT].m2;
    vec3 a = get3(d->g[d->cur].albedo, i);
    float l0 = luminance3(v3(m[0], m[1], m[2]));
    m[0] = fmaxf(m[0] + delta.x / a.x, 0.0f);
    m[1] = fmaxf(m[1] + delta.y / a.y, 0.0f);
    m[2] = fmaxf(m[2] + delta.z / a.z, 0.0f);
    float l1 = luminance3(v3(m[0], m[1], m[2]));
    *m2 = fmaxf(*m2 - l0 * l0 + l1 * l1, l1 * l1);
    d->relit[i] = 1;
}

/* Whether a changed light reaches point p as it was or as it is. */
static int reached(const relight_job *j, vec3 p) {
    light_sample ls;
    for (int l = 0; l < 2 * j->n; l++)
        if (light_sample_punctual(&j->lights[l], p, &ls)) return 1;
    return 0;
}

/* One row of 4x4-pixel packets: the centre rays of the pixels to relight (on a surface, with stale
 * direct light, not mostly glossy: a sharp lobe's light at the pixel's centre is not its
 * footprint's), traced again to their hits, where the path tracer's next-event estimate of each
 * changed light is taken as it was and as it is. */
static void relight_row(void *ctx, int row, int worker) {
    (void)worker;
    relight_job *j = ctx;
    display *d = j->d;
    const gbuffer *g = &d->g[d->cur];
    for (int x0 = 0; x0 < d->width; x0 += 4) {
        vec3 dir[SCENE_PACKET];
        surface_hit hit[SCENE_PACKET];
        size_t idx[SCENE_PACKET];
        int n = 0;
        for (int y = 4 * row; y < 4 * row + 4 && y < d->height; y++)
            for (int x = x0; x < x0 + 4 && x < d->width; x++) {
                size_t i = (size_t)y * (size_t)d->width + (size_t)x;
                if (g->material[i] < 0 || !(d->stale[i].c[COMP_DIRECT].count > 0.0f) || mostly_glossy(g, i)) continue;
                if (!reached(j, get3(g->pos, i))) { /* outside every changed spot's cone, then and now */
                    relight_pixel(d, i, v3s(0.0f));
                    continue;
                }
                idx[n] = i;
                dir[n++] = camera_raster_dir(&j->raster, (float)x + 0.5f, (float)y + 0.5f);
            }
        if (!n) continue;
        unsigned hits = scene_intersect_packet(j->s, g->cam.position, dir, n, hit);
        for (int k = 0; k < n; k++) {
            if (!(hits >> k & 1u) || hit[k].material != g->material[idx[k]]) continue;
            vec3 delta = v3s(0.0f), got[2 * RELIGHT_MAX];
            uint64_t rays = 0;
            if (!pt_punctual_direct(j->s, j->lights, 2 * j->n, dir[k], &hit[k], got, &rays)) continue;
            for (int l = 0; l < j->n; l++) delta = add3(delta, sub3(got[l], got[j->n + l]));
            if (is_finite3(delta)) relight_pixel(d, idx[k], delta);
        }
    }
}

/* ---- judging --------------------------------------------------------------------------------- */

/* The light changed: what the history says is set aside, to come back where new samples agree with
 * it; where only punctual lights changed (`changed` of them, was and now: changed_punctual), each
 * pixel's direct light is moved by their change and comes back whole (relit). During a drag each step adds what came since the last one to what is
 * set aside. */
void begin_judging(display *d, const scene *s, const light *was, const light *now, int changed) {
    size_t n = (size_t)d->width * (size_t)d->height;
    pixel_history *h = d->h[d->cur];
    if (d->judging) {
        for (size_t i = 0; i < n; i++) history_merge(&d->stale[i], &h[i], INFINITY, 0);
        memset(h, 0, n * sizeof *h);
    } else {
        d->h[d->cur] = d->stale;
        d->stale = h;
        memset(d->h[d->cur], 0, n * sizeof *h);
    }
    memset(d->tiles, 0, sizeof(light_tile) * (size_t)d->tiles_x * (size_t)d->tiles_y);
    memset(d->relit, 0, n);
    d->judging = 1;
    if (changed > 0) {
        relight_job j = {
            .d = d, .s = s, .raster = camera_raster_make(&d->g[d->cur].cam, d->width, d->height), .n = changed};
        memcpy(j.lights, now, sizeof(light) * (size_t)changed);
        memcpy(j.lights + changed, was, sizeof(light) * (size_t)changed);
        threadpool_run(d->pool, relight_row, &j, (d->height + 3) / 4);
    }
}

/* The camera moves before every tile was judged: the stale history of tiles not judged changed
 * comes back as one sample's worth (it may be wrong), a relit direct light whole, and the
 * judgement ends. */
void end_judging(display *d, pixel_history *h) {
    size_t n = (size_t)d->width * (size_t)d->height;
    for (size_t i = 0; i < n; i++) {
        if (d->relit[i]) history_merge_one(&h[i], &d->stale[i], COMP_DIRECT, INFINITY);
        if (d->tiles[tile_of(d, i)].state != TILE_CHANGED) history_merge(&h[i], &d->stale[i], 1.0f, d->relit[i]);
    }
    memset(d->stale, 0, n * sizeof *d->stale);
    memset(d->relit, 0, n);
    d->judging = 0;
}

/* Each tile with enough new samples beside stale history: changed when their difference stands
 * well out of the noise and is a tenth of the light or more; the same when it is shown to be less
 * than a tenth (with twice its noise), or a twentieth; at JUDGE_MAX_SAMPLES by the difference. Not
 * the same by a noisy difference's own size: where samples are noisy (a room lit only by virtual
 * lights) a difference under a tenth by chance kept a light that had changed by far more. */
void judge_tiles(display *d) {
    int nt = d->tiles_x * d->tiles_y, open = 0;
    for (int t = 0; t < nt; t++) {
        light_tile *k = &d->tiles[t];
        if (k->state != TILE_UNKNOWN) continue;
        open++;
        if (k->n < JUDGE_MIN_SAMPLES) continue;
        double z = fabs(k->diff) / sqrt(k->var + 1e-30), r = fabs(k->diff) / (k->base + 1e-30);
        double bound = (fabs(k->diff) + 2.0 * sqrt(k->var)) / (k->base + 1e-30); /* r, at most */
        if (z > 3.0 && r > 0.1)
            settle_tile(d, t, TILE_CHANGED), open--;
        else if (bound < 0.1 || r < 0.05 || k->n >= JUDGE_MAX_SAMPLES)
            settle_tile(d, t, r > 0.1 ? TILE_CHANGED : TILE_SAME), open--;
    }
    if (!open) d->judging = 0;
}

/* A new sample e (each component's, divided by the albedo) at pixel i, as evidence for its tile:
 * of the components judged there; the light it is measured against is all of the pixel's. */
void gather_evidence(display *d, size_t i, const vec3 *e, float k_samples) {
    const pixel_history *st = &d->stale[i];
    if (!(st->c[COMP_DIRECT].count > 0.0f || st->c[COMP_INDIRECT].count > 0.0f)) return;
    light_tile *k = &d->tiles[tile_of(d, i)];
    if (k->state != TILE_UNKNOWN) return;
    int from = judged_from(d, i);
    float var, unused, old = total_luminance(st, from, &var), x = 0.0f;
    for (int c = from; c < COMP_COUNT; c++) x += luminance3(e[c]);
    k->diff += (double)k_samples * (double)(x - old);
    k->var += (double)k_samples * (double)var;
    k->base += (double)k_samples * (double)(from ? total_luminance(st, 0, &unused) : old);
    k->n += (int)k_samples;
}
