#define _POSIX_C_SOURCE 200809L
#include <float.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "clock.h"
#include "display_parts.h"
#include "vecmath.h"

display *display_create(int width, int height, int threads, char *err, size_t errlen) {
    display *d = calloc(1, sizeof *d);
    if (!d) return snprintf(err, errlen, "out of memory"), NULL;
    size_t n = (size_t)width * (size_t)height;
    d->width = width;
    d->height = height;
    int ok = gbuffer_init(&d->g[0], width, height) == 0 && gbuffer_init(&d->g[1], width, height) == 0;
    for (int k = 0; ok && k < 2; k++) ok = (d->h[k] = calloc(n, sizeof(pixel_history))) != NULL;
    d->tiles_x = (width + TILE_PX - 1) / TILE_PX;
    d->tiles_y = (height + TILE_PX - 1) / TILE_PX;
    if (ok) ok = (d->stale = calloc(n, sizeof(pixel_history))) != NULL;
    if (ok) ok = (d->tiles = calloc((size_t)d->tiles_x * (size_t)d->tiles_y, sizeof(light_tile))) != NULL;
    if (ok) ok = (d->relit = calloc(n, 1)) != NULL;
    for (int c = 0; ok && c < COMP_COUNT; c++) {
        d->sink.rgb[c] = malloc(sizeof(float) * 3 * n);
        d->light[c] = malloc(sizeof(float) * 3 * n);
        d->count[c] = malloc(sizeof(float) * n);
        d->variance[c] = malloc(sizeof(float) * n);
        d->out[c] = malloc(sizeof(float) * 3 * n);
        d->out_count[c] = malloc(sizeof(float) * n);
        d->gap[c] = malloc(sizeof(float) * n);
        ok =
            d->sink.rgb[c] && d->light[c] && d->count[c] && d->variance[c] && d->out[c] && d->out_count[c] && d->gap[c];
    }
    if (ok) ok = (d->sink.stamp = calloc(n, sizeof(uint32_t))) != NULL;
    size_t packets = (size_t)((width + SESSION_PACKET - 1) / SESSION_PACKET) *
                     (size_t)((height + SESSION_PACKET - 1) / SESSION_PACKET);
    if (ok) ok = (d->need = calloc(packets, 1)) != NULL;
    if (ok) ok = (d->need_gain = calloc(packets, sizeof(float))) != NULL;
    if (ok) ok = (d->spread = malloc(sizeof(float) * n)) != NULL;
    if (ok) ok = (d->spread_own = malloc(sizeof(float) * n)) != NULL;
    if (ok) ok = (d->plan_n = malloc(sizeof(float) * n)) != NULL;
    if (ok) ok = (d->plan_kind = malloc(n)) != NULL;
    if (ok) ok = (d->extra_pixels = malloc(sizeof(int) * n)) != NULL;
    if (ok) ok = (d->dn = denoiser_create(width, height)) != NULL;
    if (!ok) {
        display_destroy(d);
        return snprintf(err, errlen, "out of memory for a %dx%d display", width, height), NULL;
    }
    d->sink.serial = 1; /* stamps start at 0: no pixel is taken before its first sample */
    if (!(d->pool = threadpool_create(threads))) {
        display_destroy(d);
        return snprintf(err, errlen, "cannot start the display's threads"), NULL;
    }
    if (!(d->extra_hist = malloc(sizeof(extra_histogram) * (size_t)threadpool_size(d->pool)))) {
        display_destroy(d);
        return snprintf(err, errlen, "out of memory for a %dx%d display", width, height), NULL;
    }
    return d;
}

void display_destroy(display *d) {
    if (!d) return;
    threadpool_destroy(d->pool);
    denoiser_destroy(d->dn);
    for (int k = 0; k < 2; k++) {
        gbuffer_deinit(&d->g[k]);
        free(d->h[k]);
    }
    free(d->stale);
    free(d->tiles);
    free(d->relit);
    free(d->seen);
    for (int c = 0; c < COMP_COUNT; c++) {
        free(d->sink.rgb[c]);
        free(d->light[c]);
        free(d->count[c]);
        free(d->variance[c]);
        free(d->out[c]);
        free(d->out_count[c]);
        free(d->gap[c]);
    }
    free(d->sink.stamp);
    free(d->need);
    free(d->need_gain);
    free(d->spread);
    free(d->spread_own);
    free(d->plan_n);
    free(d->plan_kind);
    free(d->extra_pixels);
    free(d->extra_hist);
    free(d);
}

const sample_sink *display_sink(const display *d) { return &d->sink; }
display_stats display_get_stats(const display *d) { return d->st; }
const gbuffer *display_gbuffer(const display *d) { return &d->g[d->cur]; }

/* ---- carrying history over a change of view ------------------------------------------------ */

typedef struct {
    display *d;
    const gbuffer *from, *to;
    const pixel_history *old;
    pixel_history *now;
    unsigned change;
    int same_camera;
    float plane_tol;            /* how far off its plane a point may lie, per unit of its depth */
    gbuffer_projector old_view; /* into the old image */
    atomic_llong carried, lost;
} carry_job;

/* The new view's pixel whose point the carry looks for in the old view, read once. */
typedef struct {
    int32_t material;
    vec3 normal, pos;
    float tol; /* how far off its plane an old point may lie */
} carry_point;

/* Whether old pixel q shows the surface point p (positions, normals, materials). */
static int same_point(const gbuffer *old, const carry_point *p, size_t q) {
    if (p->material != old->material[q]) return 0;
    vec3 nq = get3(old->normal, q);
    float c = dot3(p->normal, nq);
    if (p->material < 0) return c > 0.99999f; /* the sky: the same direction */
    return c >= REPROJECT_MIN_COS && fabsf(dot3(sub3(p->pos, get3(old->pos, q)), nq)) <= p->tol;
}

/* The old pixels around where new pixel i's point was seen, (fx, fy) in the old image's pixel
 * centres' coordinates (project_chunk), bilinear taps, each kept only if it shows the same point.
 * Returns how many (weights normalised), 0 when none does. */
static int find_taps(const carry_job *j, size_t i, float fx, float fy, size_t taps[4], float weights[4]) {
    int w = j->d->width, h = j->d->height;
    int n = 0;
    if (j->same_camera) {
        taps[0] = i, weights[0] = 1.0f, n = 1;
    } else if (fx > -2.0f && fy > -2.0f && fx < (float)w + 1.0f && fy < (float)h + 1.0f) {
        int x0 = (int)floorf(fx), y0 = (int)floorf(fy);
        float ax = fx - (float)x0, ay = fy - (float)y0;
        for (int k = 0; k < 4; k++) {
            int tx = x0 + (k & 1), ty = y0 + (k >> 1);
            if (tx < 0 || ty < 0 || tx >= w || ty >= h) continue;
            taps[n] = (size_t)ty * (size_t)w + (size_t)tx;
            weights[n] = ((k & 1) ? ax : 1.0f - ax) * ((k >> 1) ? ay : 1.0f - ay);
            n++;
        }
    }
    const gbuffer *a = j->to;
    carry_point p = {a->material[i], get3(a->normal, i), get3(a->pos, i), j->plane_tol * a->depth[i]};
    int kept = 0;
    float total = 0.0f;
    for (int k = 0; k < n; k++) {
        if (weights[k] > 0.0f && same_point(j->from, &p, taps[k])) {
            taps[kept] = taps[k], weights[kept] = weights[k], kept++;
            total += weights[k];
        }
    }
    if (total < 1e-3f) return 0;
    for (int k = 0; k < kept; k++) weights[k] /= total;
    return kept;
}

/* A chunk of a row's pixels: their taps, and what survives of each component there (keep_factors). */
#define CARRY_CHUNK 64
typedef struct {
    int kept[CARRY_CHUNK]; /* taps that show the pixel's point, 0: lost */
    size_t taps[CARRY_CHUNK][4];
    float weights[CARRY_CHUNK][4];
    /* keep_factors' input: the view's mean turn at the taps (out: with this move's), the point, its
     * glossy lobe (gloss 0: none, or the camera did not move) */
    float turn[CARRY_CHUNK], px[CARRY_CHUNK], py[CARRY_CHUNK], pz[CARRY_CHUNK];
    float fx[CARRY_CHUNK], fy[CARRY_CHUNK]; /* where the point was in the old image (project_chunk) */
    float gloss[CARRY_CHUNK], alpha[CARRY_CHUNK];
    float spread2[CARRY_CHUNK]; /* the squared turn of the normal across the pixel (normal_spread2) */
    /* ...and its output: the share of the samples the highlights and the rest keep, their caps, and
     * whether either holds too little to count (DISPLAY_MIN_HELD) */
    float glossy[CARRY_CHUNK], diffuse[CARRY_CHUNK], cap_glossy[CARRY_CHUNK], cap_all[CARRY_CHUNK];
    float last_glossy[CARRY_CHUNK], last_all[CARRY_CHUNK]; /* 1: the history is a last resort */
} carry_chunk;

/* What survives of each component: all of its diffuse share, and of its glossy share (the
 * highlights are all glossy) what the lobe allows. The reflected lobe turns about twice as far as
 * the view, and its width is about its microfacet alpha, so light gathered a turn t of the view ago
 * holds G(t) = exp(-(t / alpha)^2 / 2) of itself: a move from turn t0 to t1 keeps G(t1) / G(t0) of
 * what is left, so many small turns cost what one turn as large does. The turn is the chord between
 * the directions from the point to the two eyes, 2 sin(turn / 2) (within 2% of the turn to 40
 * degrees), from sin^2 and cos (chord^2 = 2 sin^2 / (1 + cos)), which keep their precision for a
 * drag's small steps.
 * What no longer holds caps what the history may count: where a share `held` of its light holds
 * since its samples were taken, a bias of about (1 - held) of the light L, which the mean of n
 * samples of spread s matches in its noise at n = (s / L)^2 / (1 - held)^2; the cap is that per unit
 * of one sample's relative variance (s / L)^2. Many samples (the display's extra ones) of a
 * highlight that has since moved would otherwise outweigh the new ones for seconds.
 * Whether a history still counts at all asks what share of the pixel's light holds: the lobe's
 * albedo share g (not the worst case: an oak floor keeps its diffuse half) of the light the pixel
 * sees over its footprint, whose normals turn by the spread (a curved surface's highlight stays in
 * its pixel as the view turns: the lobe there is as wide as alpha and the spread together). Less
 * than DISPLAY_MIN_HELD, and the history is more wrong than right: it is a last resort (a steel
 * panel's reflection of a lit wall stayed where it had been through an orbit, outweighing the new
 * samples around it in the filter).
 * Vector code (vecmath.h's rules): one pixel at a time, with its taps, its roots, divisions and
 * exponentials were a third of the carry's time. */
static void keep_factors(carry_chunk *restrict k, vec3 from, vec3 to) {
    const float cap = DISPLAY_MAX_CARRIED;
    for (int x = 0; x < CARRY_CHUNK; x++) {
        float ux = from.x - k->px[x], uy = from.y - k->py[x], uz = from.z - k->pz[x];
        float vx = to.x - k->px[x], vy = to.y - k->py[x], vz = to.z - k->pz[x];
        float uv = (ux * ux + uy * uy + uz * uz) * (vx * vx + vy * vy + vz * vz);
        uv = uv > FLT_MIN ? uv : FLT_MIN;
        float cx = uy * vz - uz * vy, cy = uz * vx - ux * vz, cz = ux * vy - uy * vx;
        float s2 = (cx * cx + cy * cy + cz * cz) / uv, c = (ux * vx + uy * vy + uz * vz) / sqrtf(uv);
        float opposite = 1.0f + c > 1e-3f ? 1.0f + c : 1e-3f;
        float gloss = k->gloss[x], alpha = k->alpha[x];
        float step = gloss > 0.0f ? sqrtf(2.0f * s2 / opposite) : 0.0f;
        float t0 = k->turn[x], t1 = t0 + step, a2 = alpha * alpha;
        float e = -0.5f * LOG2E / (a2 > 1e-6f ? a2 : 1e-6f); /* alpha 1e-3 at least */
        float xh = e * t1 * t1, xg = e * (t1 * t1 - t0 * t0);
        float held = exp2_neg(xh), glossy = exp2_neg(xg); /* G(t1), G(t1) / G(t0) */
        held = xh > EXP2_FLOOR ? held : 0.0f; /* nothing holds: the history goes (exp2_neg stops at its floor) */
        glossy = xg > EXP2_FLOOR ? glossy : 0.0f;
        float share = gbuffer_glossy_share(gloss, alpha);
        float wide2 = a2 + k->spread2[x], xw = -0.5f * LOG2E * t1 * t1 / (wide2 > 1e-6f ? wide2 : 1e-6f);
        float held_wide = exp2_neg(xw); /* G(t1) over the pixel */
        held_wide = xw > EXP2_FLOOR ? held_wide : 0.0f;
        int turned = step > 0.0f;
        float held_all = (1.0f - gloss) + gloss * held_wide;
        k->last_glossy[x] = turned && held_wide < DISPLAY_MIN_HELD ? 1.0f : 0.0f;
        k->last_all[x] = turned && held_all < DISPLAY_MIN_HELD ? 1.0f : 0.0f;
        held = turned ? held : 1.0f;
        glossy = turned ? glossy : 1.0f;
        share = turned ? share : 0.0f;
        float lost = 1.0f - held, lost_all = share * lost;
        float cap_glossy = 1.0f / (lost * lost), cap_all = 1.0f / (lost_all * lost_all);
        k->turn[x] = t1;
        k->glossy[x] = glossy;
        k->diffuse[x] = (1.0f - share) + share * glossy;
        k->cap_glossy[x] = lost > 1e-3f && cap_glossy < cap ? cap_glossy : cap;
        k->cap_all[x] = lost_all > 1e-3f && cap_all < cap ? cap_all : cap;
    }
}

/* Where the chunk's points were in the old image, in its pixel centres' coordinates (x - 0.5, y -
 * 0.5); far outside it where a point was behind the old eye. Vector code: one pixel at a time the
 * projection's division held up the taps. */
static void project_chunk(const gbuffer_projector *pr, carry_chunk *restrict k) {
    for (int x = 0; x < CARRY_CHUNK; x++) {
        float ox, oy, z = gbuffer_project_raw(pr, v3(k->px[x], k->py[x], k->pz[x]), &ox, &oy);
        k->fx[x] = z > 0.0f ? ox - 0.5f : -1e30f;
        k->fy[x] = z > 0.0f ? oy - 0.5f : -1e30f;
    }
}

/* The cosine between pixel i's normal and pixel o's; 1 on another surface. */
static inline float normal_cos(const float *nm, const int32_t *mat, ptrdiff_t i, ptrdiff_t o) {
    float c = nm[3 * i] * nm[3 * o] + nm[3 * i + 1] * nm[3 * o + 1] + nm[3 * i + 2] * nm[3 * o + 2];
    return mat[o] == mat[i] ? c : 1.0f;
}

/* The squared angle the normal turns across pixels x0 .. x0 + n - 1 of row y, about 2 (1 - cos) of
 * its largest turn to a neighbour on the same surface; a neighbour beyond the image's edge is the
 * pixel itself. A whole chunk inside the image's left and right edges in a loop of fixed length,
 * which vectorises; the chunks at the edges pixel by pixel. */
static void normal_spread2(const gbuffer *g, int w, int h, int x0, int y, int n, float *restrict out) {
    ptrdiff_t row = (ptrdiff_t)y * w + x0, up = y > 0 ? -(ptrdiff_t)w : 0, down = y + 1 < h ? (ptrdiff_t)w : 0;
    const float *nm = g->normal;
    const int32_t *mat = g->material;
    if (x0 > 0 && x0 + CARRY_CHUNK < w) {
        const float *restrict n0 = nm + 3 * row, *restrict nu = n0 + 3 * up, *restrict nd = n0 + 3 * down;
        const int32_t *restrict m0 = mat + row, *restrict mu = m0 + up, *restrict md = m0 + down;
        for (int x = 0; x < CARRY_CHUNK; x++) {
            float px = n0[3 * x], py = n0[3 * x + 1], pz = n0[3 * x + 2];
            float cl = px * n0[3 * x - 3] + py * n0[3 * x - 2] + pz * n0[3 * x - 1];
            float cr = px * n0[3 * x + 3] + py * n0[3 * x + 4] + pz * n0[3 * x + 5];
            float cu = px * nu[3 * x] + py * nu[3 * x + 1] + pz * nu[3 * x + 2];
            float cd = px * nd[3 * x] + py * nd[3 * x + 1] + pz * nd[3 * x + 2];
            int32_t me = m0[x];
            cl = m0[x - 1] == me ? cl : 1.0f, cr = m0[x + 1] == me ? cr : 1.0f;
            cu = mu[x] == me ? cu : 1.0f, cd = md[x] == me ? cd : 1.0f;
            float c = cl < cr ? cl : cr, c2 = cu < cd ? cu : cd;
            c = c < c2 ? c : c2;
            out[x] = 2.0f * (1.0f - c);
        }
        return;
    }
    for (int x = 0; x < n; x++) {
        ptrdiff_t i = row + x, left = x0 + x > 0 ? i - 1 : i, right = x0 + x + 1 < w ? i + 1 : i;
        float c = fminf(fminf(normal_cos(nm, mat, i, left), normal_cos(nm, mat, i, right)),
                        fminf(normal_cos(nm, mat, i, i + up), normal_cos(nm, mat, i, i + down)));
        out[x] = 2.0f * (1.0f - c);
    }
}

/* Pixels x0 .. x0 + n - 1 of row y: their points, where they were (project_chunk), their taps and
 * their keep factors' input; the rest of the chunk with none. */
static void find_chunk(const carry_job *j, int x0, int y, int n, carry_chunk *k) {
    const gbuffer *to = j->to;
    size_t i0 = (size_t)y * (size_t)j->d->width + (size_t)x0;
    for (int x = 0; x < CARRY_CHUNK; x++) {
        vec3 p = x < n ? get3(to->pos, i0 + (size_t)x) : v3(0, 0, 0);
        k->px[x] = p.x, k->py[x] = p.y, k->pz[x] = p.z;
    }
    project_chunk(&j->old_view, k);
    /* whether a pixel's history may become a last resort: a lobe of more than half the albedo, or the highlights */
    int any = 0;
    for (int x = 0; x < CARRY_CHUNK; x++) {
        size_t i = i0 + (size_t)x;
        int in = x < n;
        k->kept[x] =
            in && !(j->change & DISPLAY_RESTART) ? find_taps(j, i, k->fx[x], k->fy[x], k->taps[x], k->weights[x]) : 0;
        float turn = 0.0f;
        for (int t = 0; t < k->kept[x]; t++) turn += k->weights[x][t] * j->old[k->taps[x][t]].turn;
        k->turn[x] = turn;
        int glossy = in && !j->same_camera && to->material[i] >= 0 && to->gloss[i] > 0.0f;
        k->gloss[x] = glossy ? to->gloss[i] : 0.0f;
        k->alpha[x] = in ? to->alpha[i] : 1.0f;
        any |= glossy && (to->gloss[i] > DISPLAY_MIN_HELD || j->d->active[COMP_HIGHLIGHTS]);
    }
    memset(k->spread2, 0, sizeof k->spread2);
    if (any) normal_spread2(to, j->d->width, j->d->height, x0, y, n, k->spread2);
}

static void carry_row(void *ctx, int y, int worker) {
    (void)worker;
    carry_job *j = ctx;
    int w = j->d->width;
    long long carried = 0, lost = 0;
    const float cap = DISPLAY_MAX_CARRIED;
    carry_chunk k;
    for (int x0 = 0; x0 < w; x0 += CARRY_CHUNK) {
        int n = w - x0 < CARRY_CHUNK ? w - x0 : CARRY_CHUNK;
        find_chunk(j, x0, y, n, &k);
        keep_factors(&k, j->from->cam.position, j->to->cam.position);
        for (int x = 0; x < n; x++) {
            pixel_history *now = &j->now[(size_t)y * (size_t)w + (size_t)(x0 + x)];
            memset(now, 0, sizeof *now);
            int kept = k.kept[x];
            if (!kept) {
                lost += !(j->change & DISPLAY_RESTART);
                continue;
            }
            carried++;
            now->turn = k.turn[x];
            for (int c = 0; c < COMP_COUNT; c++) {
                if (!j->d->active[c]) continue;
                float count = 0.0f, m2 = 0.0f, m[3] = {0.0f, 0.0f, 0.0f};
                for (int t = 0; t < kept; t++) {
                    const pixel_history *o = &j->old[k.taps[x][t]];
                    float wt = k.weights[x][t];
                    count += wt * o->c[c].count;
                    m2 += wt * o->c[c].m2;
                    for (int e = 0; e < 3; e++) m[e] += wt * o->c[c].mean[e];
                }
                /* the cap per unit of one sample's relative variance, one sample at least */
                float at_most = c == COMP_HIGHLIGHTS ? k.cap_glossy[x] : k.cap_all[x];
                if (at_most < cap) {
                    float l = luminance3(v3(m[0], m[1], m[2])), rel = sample_variance(m2, l, count) / (l * l);
                    if (isfinite(rel)) at_most = fmaxf(rel * at_most, 1.0f);
                }
                count = fminf(count * (c == COMP_HIGHLIGHTS ? k.glossy[x] : k.diffuse[x]), at_most);
                int last_resort = (c == COMP_HIGHLIGHTS ? k.last_glossy[x] : k.last_all[x]) > 0.0f;
                count = last_resort && count > 0.0f ? fminf(count, DISPLAY_LAST_RESORT) : count;
                if (!(count > 0.0f)) continue;
                now->c[c].count = count;
                now->c[c].m2 = m2;
                for (int e = 0; e < 3; e++) now->c[c].mean[e] = m[e];
            }
        }
    }
    atomic_fetch_add(&j->carried, carried);
    atomic_fetch_add(&j->lost, lost);
}

void display_change_view(display *d, const scene *s, const camera *cam, unsigned change) {
    uint64_t t0 = clock_ns();
    int prev = d->cur, next = 1 - d->cur;
    light was[RELIGHT_MAX], now[RELIGHT_MAX];
    int relight = (change & DISPLAY_LIGHTS) && !(change & DISPLAY_RESTART) && d->have_view
                      ? changed_punctual(d, s, was, now)
                      : -1;
    if (change == DISPLAY_LIGHTS && relight >= 0 && !memcmp(&d->g[prev].cam, cam, sizeof *cam)) {
        /* punctual lights alone changed, not the view nor a surface: the G-buffer and each pixel's
         * history stand */
        begin_judging(d, s, was, now, relight);
        display_lights_seen(d, s, 1);
        d->sink.serial++;
        d->st.gbuffer_ms = 0.0;
        d->st.view_ms = 1e-6 * (double)(clock_ns() - t0);
        return;
    }
    gbuffer_trace(&d->g[next], s, cam, d->pool);
    uint64_t t1 = clock_ns();
    d->st.gbuffer_ms = 1e-6 * (double)(t1 - t0);
    if (!d->have_view) change |= DISPLAY_RESTART;
    if (d->judging && (change & DISPLAY_RESTART)) {
        memset(d->stale, 0, (size_t)d->width * (size_t)d->height * sizeof *d->stale);
        d->judging = 0;
    } else if (d->judging && memcmp(&d->g[prev].cam, cam, sizeof *cam) != 0) {
        end_judging(d, d->h[prev]);
    }
    carry_job j = {.d = d,
                   .from = &d->g[prev],
                   .to = &d->g[next],
                   .old = d->h[prev],
                   .now = d->h[next],
                   .change = change,
                   .same_camera = memcmp(&d->g[prev].cam, cam, sizeof *cam) == 0,
                   .plane_tol = REPROJECT_PLANE_PIXELS * 2.0f * tanf(0.5f * cam->yfov) / (float)d->height,
                   .old_view = gbuffer_projector_of(&d->g[prev])};
    threadpool_run(d->pool, carry_row, &j, d->height);
    d->cur = next;
    d->have_view = 1;
    if ((change & DISPLAY_LIGHTS) && !(change & DISPLAY_RESTART)) begin_judging(d, s, was, now, relight);
    if (change & (DISPLAY_LIGHTS | DISPLAY_RESTART)) display_lights_seen(d, s, relight >= 0);
    d->st.carried = atomic_load(&j.carried);
    d->st.lost = atomic_load(&j.lost);
    if (change & DISPLAY_RESTART) memset(d->active, 0, sizeof d->active);
    /* samples written for the old view are not for this one */
    d->sink.serial++;
    d->st.view_ms = 1e-6 * (double)(clock_ns() - t0);
}

/* ---- samples in, the image out ------------------------------------------------------------- */

long long display_take_samples(display *d) {
    const gbuffer *g = &d->g[d->cur];
    pixel_history *h = d->h[d->cur];
    size_t n = (size_t)d->width * (size_t)d->height;
    uint32_t serial = d->sink.serial;
    long long taken = 0;
    for (size_t i = 0; i < n; i++) {
        if (d->sink.stamp[i] != serial) continue;
        taken++;
        vec3 a = get3(g->albedo, i), e[COMP_COUNT];
        for (int c = 0; c < COMP_COUNT; c++) e[c] = div3(get3(d->sink.rgb[c], i), a);
        if (d->judging) gather_evidence(d, i, e, 1.0f);
        float q[COMP_COUNT];
        for (int c = 0; c < COMP_COUNT; c++) q[c] = luminance3(e[c]) * luminance3(e[c]);
        history_add(d, &h[i], e, q, 1.0f);
    }
    if (d->judging) judge_tiles(d);
    d->sink.serial++;
    if (d->sink.serial == 0) { /* wrapped: no stale stamp may match again */
        memset(d->sink.stamp, 0, sizeof(uint32_t) * n);
        d->sink.serial = 1;
    }
    if (taken) d->st.updates++;
    d->st.samples += (uint64_t)taken;
    return taken;
}

/* What one more sample would take off pixel k's squared error as shown: a mean of n samples of
 * one-sample variance s2 errs by s2 / n, one more by s2 / (n + 1). Summed over the components with
 * light, each's variance of its light times the albedo (what the image shows); -1 where a component
 * has fewer than two samples (its spread unknown). */
static float sample_gain(const display *d, const pixel_history *p, size_t k) {
    float a = luminance3(get3(d->g[d->cur].albedo, k)), gain = 0.0f;
    if (!(p->c[COMP_DIRECT].count >= 2.0f)) return -1.0f; /* every sample counts in every component */
    for (int c = 0; c < COMP_COUNT; c++) {
        if (!d->active[c]) continue;
        float n = p->c[c].count, s2 = shown_spread(p, c, a);
        if (s2 < 0.0f) return -1.0f;
        gain += s2 / (n * (n + 1.0f));
    }
    return isfinite(gain) ? gain : -1.0f;
}

/* A packet's need, in two bands. Where some pixel's spread is unknown (fewer than two samples of a
 * component) the upper band, 8 to 15, by the lack of samples, 1 / (1 + n) on average; elsewhere the
 * lower, 0 to 7, by what a sample of each pixel would take off the error shown, summed over the
 * packet, in factors of two about the mean known packet's (level 4). The sky needs nothing. */
const uint8_t *display_packet_need(display *d) {
    const pixel_history *h = d->h[d->cur];
    const gbuffer *g = &d->g[d->cur];
    int px = (d->width + SESSION_PACKET - 1) / SESSION_PACKET, py = (d->height + SESSION_PACKET - 1) / SESSION_PACKET;
    float *gain = d->need_gain; /* per packet: the gain summed, or -(the lack) where a spread is unknown */
    double total = 0.0;
    int known = 0;
    for (int j = 0; j < py; j++)
        for (int i = 0; i < px; i++) {
            double sum = 0.0;
            float lack = 0.0f;
            int unknown = 0, m = 0;
            for (int y = SESSION_PACKET * j; y < SESSION_PACKET * (j + 1) && y < d->height; y++)
                for (int x = SESSION_PACKET * i; x < SESSION_PACKET * (i + 1) && x < d->width; x++) {
                    size_t k = (size_t)y * (size_t)d->width + (size_t)x;
                    if (g->material[k] < 0) continue;
                    m++;
                    lack += 1.0f / (1.0f + h[k].c[COMP_DIRECT].count);
                    float gk = sample_gain(d, &h[k], k);
                    if (gk < 0.0f)
                        unknown = 1;
                    else
                        sum += (double)gk;
                }
            size_t q = (size_t)j * (size_t)px + (size_t)i;
            sum = sum < (double)FLT_MAX ? sum : (double)FLT_MAX;
            gain[q] = !m ? 0.0f : unknown ? -lack / (float)m : (float)sum;
            if (m && !unknown) total += sum, known++;
        }
    double mean = known ? total / known : 0.0;
    for (size_t q = 0; q < (size_t)px * (size_t)py; q++) {
        float v = gain[q];
        int level;
        if (v < 0.0f) {
            level = SESSION_NEED_LEVELS / 2 + (int)(-v * (float)(SESSION_NEED_LEVELS / 2 - 1) + 0.5f);
        } else {
            level = v > 0.0f && mean > 0.0 ? (int)floor(log2((double)v / mean)) + SESSION_NEED_LEVELS / 4 : 0;
            level = level < 0 ? 0 : level > SESSION_NEED_LEVELS / 2 - 1 ? SESSION_NEED_LEVELS / 2 - 1 : level;
        }
        d->need[q] = (uint8_t)level;
    }
    return d->need;
}

typedef struct {
    display *d;
    unsigned mask; /* the components shown that have light */
    int filtered;
    float *rgb;
    atomic_llong samples; /* the direct light's, over all pixels: how young the image is */
    atomic_llong holes;   /* pixels with no sample of a component shown */
} resolve_job;

/* Component c of pixel i's history as shown: its own; or, while a light change is judged and the
 * pixel has none of its own since, the stale history's as a last resort (DISPLAY_LAST_RESORT
 * samples), unless its light is mostly its glossy lobe's (a light's reflection moves with the light,
 * and where it was would stay bright until the tile is judged); a relit direct light
 * (display_light.c) whole, merged with the pixel's own new samples in *mix. NULL when there is
 * nothing. */
static const float *shown_history(const display *d, size_t i, int c, float *count, float *m2, pixel_history *mix) {
    const pixel_history *p = &d->h[d->cur][i], *st = &d->stale[i];
    const gbuffer *g = &d->g[d->cur];
    if (c == COMP_DIRECT && d->judging && d->relit[i]) {
        *mix = *p;
        history_merge_one(mix, st, c, INFINITY);
        if (!(mix->c[c].count > 0.0f)) return NULL;
        *count = mix->c[c].count;
        *m2 = mix->c[c].m2;
        return mix->c[c].mean;
    }
    if (!(p->c[c].count > 0.0f) && d->judging && st->c[c].count > 0.0f && !mostly_glossy(g, i)) {
        p = st;
        *count = fminf(p->c[c].count, DISPLAY_LAST_RESORT);
    } else if (p->c[c].count > 0.0f) {
        *count = p->c[c].count;
    } else {
        return NULL;
    }
    *m2 = p->c[c].m2;
    return p->c[c].mean;
}

/* The filter's input: each component's history as planes, its variance from the moments. */
static void split_row(void *ctx, int y, int worker) {
    (void)worker;
    resolve_job *j = ctx;
    display *d = j->d;
    double samples = 0.0;
    long long holes = 0;
    for (int x = 0; x < d->width; x++) {
        size_t i = (size_t)y * (size_t)d->width + (size_t)x;
        samples += (double)d->h[d->cur][i].c[COMP_DIRECT].count;
        int hole = 0;
        for (int c = 0; c < COMP_COUNT; c++) {
            if (!(j->mask >> c & 1u)) continue;
            float count = 0.0f, m2 = 0.0f;
            pixel_history mix;
            const float *m = shown_history(d, i, c, &count, &m2, &mix);
            static const float none[3] = {0.0f, 0.0f, 0.0f};
            if (!m) m = none;
            float l = luminance3(v3(m[0], m[1], m[2]));
            for (int e = 0; e < 3; e++) d->light[c][3 * i + (size_t)e] = m[e];
            d->count[c][i] = count;
            hole |= !(count > 0.0f);
            d->variance[c][i] = sample_variance(m2, l, count); /* the filter wants the unbiased one */
        }
        holes += hole;
    }
    atomic_fetch_add(&j->samples, (long long)samples);
    atomic_fetch_add(&j->holes, holes);
}

/* The filter's value against the pixel's own mean at pixel i, component c: (f - x)^2, whose
 * expectation is b^2 + var x - var f (the filter's value f takes the pixel's own x with weight about
 * var f / var x). -1 where the pixel has no variance of its own yet. */
static float filter_gap(const display *d, int c, size_t i) {
    if (!(d->count[c][i] >= 2.0f)) return -1.0f;
    const float *x = d->light[c] + 3 * i, *f = d->out[c] + 3 * i;
    float diff = luminance3(v3(f[0] - x[0], f[1] - x[1], f[2] - x[2]));
    return diff * diff;
}

/* Each pixel's gap, once: take_chunk reads nine. */
static void gap_row(void *ctx, int y, int worker) {
    (void)worker;
    resolve_job *j = ctx;
    display *d = j->d;
    size_t i0 = (size_t)y * (size_t)d->width;
    for (int c = 0; c < COMP_COUNT; c++) {
        if (!(j->mask >> c & 1u)) continue;
        for (size_t i = i0; i < i0 + (size_t)d->width; i++) d->gap[c][i] = filter_gap(d, c, i);
    }
}

/* One neighbour q of a pixel (take_window): where it lies on the pixel's surface (mat_q == me) and
 * has a gap (not -1), its variance into s2 and k, and its gap, times `other` (0 for the pixel
 * itself), into gap and m. */
static inline void take_tap(float gap_q, float var_q, int32_t mat_q, int32_t me, float other, float *s2, float *k,
                            float *gap, float *m) {
    float ok = mat_q == me ? gap_q : -1.0f; /* another surface's: none */
    int in = ok >= -0.5f;
    *s2 += in ? var_q : 0.0f;
    *k += in ? 1.0f : 0.0f;
    *gap += in ? other * gap_q : 0.0f;
    *m += in ? other : 0.0f;
}

/* take_chunk's arithmetic: the rows of gaps, variances and materials about the chunk, and its own
 * row's counts, variances and the filter's counts, all from pixel x0 - 1 (window_row). Not inlined:
 * in take_chunk's loops gcc does not vectorise it. */
__attribute__((noinline)) static void take_window(const float *const gap_w[3], const float *const var_w[3],
                                                  const int32_t *const mat[3], const float *restrict n,
                                                  const float *restrict vown, const float *restrict fn,
                                                  float *restrict take) {
    const float *restrict g0 = gap_w[0], *restrict g1 = gap_w[1], *restrict g2 = gap_w[2];
    const float *restrict v0 = var_w[0], *restrict v1 = var_w[1], *restrict v2 = var_w[2];
    const int32_t *restrict m0 = mat[0], *restrict m1 = mat[1], *restrict m2 = mat[2];
    for (int x = 0; x < WINDOW_CHUNK; x++) {
        float s2 = 0.0f, k = 0.0f, gap = 0.0f, m = 0.0f;
        int32_t me = m1[x + 1];
        take_tap(g0[x], v0[x], m0[x], me, 1.0f, &s2, &k, &gap, &m);
        take_tap(g0[x + 1], v0[x + 1], m0[x + 1], me, 1.0f, &s2, &k, &gap, &m);
        take_tap(g0[x + 2], v0[x + 2], m0[x + 2], me, 1.0f, &s2, &k, &gap, &m);
        take_tap(g1[x], v1[x], m1[x], me, 1.0f, &s2, &k, &gap, &m);
        take_tap(g1[x + 1], v1[x + 1], me, me, 0.0f, &s2, &k, &gap, &m);
        take_tap(g1[x + 2], v1[x + 2], m1[x + 2], me, 1.0f, &s2, &k, &gap, &m);
        take_tap(g2[x], v2[x], m2[x], me, 1.0f, &s2, &k, &gap, &m);
        take_tap(g2[x + 1], v2[x + 1], m2[x + 1], me, 1.0f, &s2, &k, &gap, &m);
        take_tap(g2[x + 2], v2[x + 2], m2[x + 2], me, 1.0f, &s2, &k, &gap, &m);
        float nx = n[x + 1], v = s2 / (k > 1.0f ? k : 1.0f); /* k >= 1 where n >= 2: the pixel itself */
        v = vown[x + 1] > v ? vown[x + 1] : v;
        float vx = v / nx, vf = v / (fn[x + 1] > nx ? fn[x + 1] : nx);
        float b2 = gap / (m > 1.0f ? m : 1.0f) - vx + vf;
        b2 = m > 0.0f && b2 > 0.0f ? b2 : 0.0f;
        float t = vx / (vx + vf + b2 + 1e-30f), finite = t - t; /* 0 unless t is infinite or NaN */
        float clamped = t > 1.0f ? 1.0f : t;
        clamped = clamped < 0.0f ? 0.0f : clamped;
        t = finite == 0.0f ? clamped : 1.0f;
        take[x] = nx >= 2.0f ? t : 1.0f;
    }
}

/* How much of the filtered value each pixel of a chunk of row y takes of component c (x0 to x0 +
 * WINDOW_CHUNK - 1, past the image's edge anything): the mix of its own mean x
 * (unbiased, variance v_x) and the filter's f (variance v_f, bias b) with the least expected squared
 * error, v_x / (v_x + v_f + b^2). A noisy pixel takes the filter; a converged one, or one where the
 * filter blurs a feature its own samples resolve, keeps its own mean: the filter fades out as the
 * image converges, pixel by pixel. A pixel without a variance of its own yet (fewer than two
 * samples) takes the filter.
 * b^2 comes from the gaps (f - x)^2 of the pixel's neighbours on the same surface, less what their
 * noise puts in them, reckoned with the variance of the whole 3x3 neighbourhood: a pixel's own gap
 * would make the pixels whose few samples fell far keep them (a peppered image), and one pixel's
 * variance from a few samples misses the rare bright ones, which read as bias. Vector code
 * (vecmath.h's rules): pixel by pixel, with its branches, it was a twentieth of the viewer's time. */
static void take_chunk(const display *d, int c, int x0, int y, float *restrict take) {
    int w = d->width, h = d->height;
    float buf_gap[3][WINDOW_SPAN], buf_var[3][WINDOW_SPAN], buf_n[WINDOW_SPAN], buf_fn[WINDOW_SPAN];
    int32_t buf_mat[3][WINDOW_SPAN];
    const float *gap_w[3], *var_w[3];
    const int32_t *mat[3];
    for (int r = 0; r < 3; r++) {
        gap_w[r] = window_row(buf_gap[r], d->gap[c], w, h, x0, y - 1 + r, -1.0f); /* no gap: not taken */
        var_w[r] = window_row(buf_var[r], d->variance[c], w, h, x0, y - 1 + r, 0.0f);
        mat[r] = window_row_int(buf_mat[r], d->g[d->cur].material, w, h, x0, y - 1 + r, -1);
    }
    const float *n = window_row(buf_n, d->count[c], w, h, x0, y, 0.0f), *vown = var_w[1];
    const float *fn = window_row(buf_fn, d->out_count[c], w, h, x0, y, 0.0f);
    take_window(gap_w, var_w, mat, n, vown, fn, take);
}

static void modulate_row(void *ctx, int y, int worker) {
    (void)worker;
    resolve_job *j = ctx;
    display *d = j->d;
    const gbuffer *g = &d->g[d->cur];
    for (int x0 = 0; x0 < d->width; x0 += WINDOW_CHUNK) {
        float take[COMP_COUNT][WINDOW_CHUNK];
        for (int c = 0; c < COMP_COUNT; c++)
            if (j->filtered && j->mask >> c & 1u) take_chunk(d, c, x0, y, take[c]);
        for (int x = x0; x < x0 + WINDOW_CHUNK && x < d->width; x++) {
            size_t i = (size_t)y * (size_t)d->width + (size_t)x;
            vec3 sum = v3(0, 0, 0);
            for (int c = 0; c < COMP_COUNT; c++) {
                if (!(j->mask >> c & 1u)) continue;
                float count, m2;
                pixel_history mix;
                const float *m;
                if (j->filtered) {
                    vec3 own = get3(d->light[c], i), f = get3(d->out[c], i);
                    sum = add3(sum, madd3(own, sub3(f, own), take[c][x - x0]));
                } else if ((m = shown_history(d, i, c, &count, &m2, &mix)))
                    sum = add3(sum, v3(m[0], m[1], m[2]));
            }
            vec3 v = mul3(sum, get3(g->albedo, i));
            if (!is_finite3(v)) v = v3(0, 0, 0);
            j->rgb[3 * i] = v.x;
            j->rgb[3 * i + 1] = v.y;
            j->rgb[3 * i + 2] = v.z;
        }
    }
}

/* The filter's count cap (denoise_params): a few times the average pixel's samples. */
static float count_cap_of(double mean) { return fmaxf(COUNT_CAP_MIN, COUNT_CAP_MEAN * (float)mean); }

void display_resolve(display *d, unsigned mask, int denoise, float *rgb) {
    uint64_t t0 = clock_ns();
    resolve_job j = {.d = d, .filtered = denoise, .rgb = rgb};
    for (int c = 0; c < COMP_COUNT; c++)
        if (mask >> c & 1u && d->active[c]) j.mask |= 1u << c;
    d->st.levels = 0;
    d->st.filter_ms = 0.0;
    if (denoise) {
        threadpool_run(d->pool, split_row, &j, d->height);
        d->st.mean_count = (double)atomic_load(&j.samples) / ((double)d->width * (double)d->height);
        /* each component shown that has light, filtered on its own */
        denoise_input in = {.g = &d->g[d->cur]};
        denoise_output out = {.light = {NULL}};
        for (int c = 0; c < COMP_COUNT; c++) {
            if (!(j.mask >> c & 1u)) continue;
            int k = in.components++;
            in.light[k] = d->light[c];
            in.count[k] = d->count[c];
            in.variance[k] = d->variance[c];
            out.light[k] = d->out[c];
            out.count[k] = d->out_count[c];
        }
        /* a level more for each halving of the pixels with samples, up to all five */
        double covered = 1.0 - (double)atomic_load(&j.holes) / ((double)d->width * (double)d->height);
        int levels = DENOISE_LEVELS;
        for (double k = 0.5; covered < k && levels < DENOISE_MAX_LEVELS; k *= 0.5) levels++;
        denoise_params p = {.levels = levels, .count_cap = count_cap_of(d->st.mean_count)};
        uint64_t t1 = clock_ns();
        if (in.components) denoise_run(d->dn, &in, &p, &out, d->pool);
        d->st.filter_ms = 1e-6 * (double)(clock_ns() - t1);
        threadpool_run(d->pool, gap_row, &j, d->height);
        d->st.levels = levels;
    }
    threadpool_run(d->pool, modulate_row, &j, d->height);
    d->st.resolve_ms = 1e-6 * (double)(clock_ns() - t0);
}
