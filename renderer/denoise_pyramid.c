/* The display filter's pyramid (docs/design.md, "The display: denoising"): the input pooled into
 * the half grid, where the passes run (denoise.c), and their result brought back up to full
 * resolution with the full image's own 3x3 pass. */
#include "denoise_parts.h"

/* The luminance of a run of light (the full image keeps none: only its stops' epsilon needs it). */
static void lum_run(const float *restrict r, const float *restrict g, const float *restrict b, float *restrict l) {
    for (int i = 0; i < CHUNK; i++) l[i] = lum_of(r[i], g[i], b[i]);
}

/* ---- the half grid: pooled, and back up ------------------------------------------------------- */

/* A half pixel X takes the values of the 4x4 full pixels around its block, weighted K4 x K4 (the
 * 3x3 pass's B1 over the block): footprint column c (0 to 3) is full column 2X - 1 + c, of parity
 * FOOT_PHASE[c], at plane column X + FOOT_SHIFT[c]. */
static const int FOOT_PHASE[4] = {1, 0, 1, 0}, FOOT_SHIFT[4] = {-1, 0, 0, 1};

/* v_k chosen by pick (k, 0 to 3) per pixel, times scale, into out. */
static void pick_of(const float *restrict v0, const float *restrict v1, const float *restrict v2,
                    const float *restrict v3, const float *restrict pick, float scale, float *restrict out) {
    for (int i = 0; i < CHUNK; i++) {
        float a = v0[i], b = v1[i], c = v2[i], d = v3[i], k = pick[i];
        float x = k == 1.0f ? b : a;
        x = k == 2.0f ? c : x;
        out[i] = scale * (k == 3.0f ? d : x);
    }
}

/* The geometry weight w_z w_n (not a logarithm) of taps at gt + pt seen from the run of pixels at
 * gc + pc, (dx, dy) away. */
static void tap_weight(const job *j, const geometry *gc, ptrdiff_t pc, const geometry *gt, ptrdiff_t pt, float dx,
                       float dy, float *restrict w) {
    const float *restrict z = gc->z + pc, *restrict nx = gc->nx + pc, *restrict ny = gc->ny + pc;
    const float *restrict nz = gc->nz + pc, *restrict gx = gc->gx + pc, *restrict gy = gc->gy + pc;
    const float *restrict zq = gt->z + pt, *restrict xq = gt->nx + pt, *restrict yq = gt->ny + pt;
    const float *restrict wq = gt->nz + pt, *restrict sn = gc->sn + pc;
    float sz = j->sigma_z, sn0 = j->sigma_n;
    for (int i = 0; i < CHUNK; i++) {
        float cs = nx[i] * xq[i] + ny[i] * yq[i] + nz[i] * wq[i];
        w[i] =
            exp2_neg(normal_log2(cs, sn0 + sn[i]) - fabsf(z[i] - zq[i]) * depth_scale(z[i], gx[i], gy[i], dx, dy, sz));
    }
}

/* The pixel a run of half pixels takes its geometry from (rx, ry: its place in the block). */
enum { CZ, CNX, CNY, CNZ, CGX, CGY, CSN, CRX, CRY, CHOSEN };
typedef struct {
    float v[CHOSEN][CHUNK];
} chosen;

/* The weight k w_z w_n (not a logarithm) of the footprint pixels at plane offset q (parity g),
 * column c and row r of the footprint, seen from the run's chosen pixels. */
static void footprint_weight(const job *j, const chosen *rep, const geometry *g, ptrdiff_t q, int c, int r, float k,
                             float *restrict w) {
    const float *restrict zq = g->z + q, *restrict xq = g->nx + q, *restrict yq = g->ny + q, *restrict wq = g->nz + q;
    const float *restrict z = rep->v[CZ], *restrict nx = rep->v[CNX], *restrict ny = rep->v[CNY];
    const float *restrict nz = rep->v[CNZ], *restrict gx = rep->v[CGX], *restrict gy = rep->v[CGY];
    const float *restrict rx = rep->v[CRX], *restrict ry = rep->v[CRY], *restrict sn = rep->v[CSN];
    float sz = j->sigma_z, sn0 = j->sigma_n, lk = log2f(k), cx = (float)(c - 1), cy = (float)(r - 1);
    for (int i = 0; i < CHUNK; i++) {
        float cs = nx[i] * xq[i] + ny[i] * yq[i] + nz[i] * wq[i];
        float inv = depth_scale(z[i], gx[i], gy[i], cx - rx[i], cy - ry[i], sz);
        w[i] = exp2_neg(lk + normal_log2(cs, sn0 + sn[i]) - fabsf(z[i] - zq[i]) * inv);
    }
}

/* The moments of a footprint's samples' luminance about the chosen pixel's lc (so that the sums
 * do not cancel), for its pooled variance (see pool_variance). */
typedef struct {
    float w[CHUNK], wn[CHUNK], w2n[CHUNK], wnd[CHUNK], wnd2[CHUNK], within[CHUNK], dof_within[CHUNK];
} pool_moments;

static void pool_moment(pool_moments *restrict m, tap t, const float *restrict s2, const float *restrict lc,
                        const float *restrict w) {
    const float *restrict rq = t.r, *restrict gq = t.g, *restrict bq = t.b, *restrict nq = t.n;
    for (int i = 0; i < CHUNK; i++) {
        float n = nq[i], dl = luminance3(v3(rq[i], gq[i], bq[i])) - lc[i];
        float extra = n / COUNT_SCALE - 1.0f; /* the sample variance's own degrees of freedom */
        extra = extra > 0.0f ? extra : 0.0f;
        float young = n > 0.0f && n < YOUNG * COUNT_SCALE ? w[i] : 0.0f, a = young * n;
        m->w[i] += young;
        m->wn[i] += a;
        m->w2n[i] += a * young;
        m->wnd[i] += a * dl;
        m->wnd2[i] += a * dl * dl;
        m->within[i] += w[i] * extra * s2[i];
        m->dof_within[i] += w[i] * extra;
    }
}

/* The one-sample variance of the footprint's samples, pooled: the spread within each pixel (its
 * n - 1 degrees of freedom, weighted w) and, as in SVGF, where pixels have fewer than YOUNG samples
 * (and their own spread says little), between them: the young pixels' means about their weighted
 * mean, of D = sum w - sum w^2 n / sum w n degrees of freedom (unbiased for equal means). Pixels
 * with more samples are not compared: their differences are more likely light than noise. */
static void pool_variance(const pool_moments *restrict m, float *restrict s2) {
    for (int i = 0; i < CHUNK; i++) {
        float wn = m->wn[i], has = wn > 0.0f ? 1.0f : 0.0f, inv = 1.0f / (has > 0.0f ? wn : 1.0f);
        float between = m->wnd2[i] - m->wnd[i] * m->wnd[i] * inv, d = m->w[i] - m->w2n[i] * inv;
        between = between > 0.0f && has > 0.0f ? between / COUNT_SCALE : 0.0f;
        d = d > 0.0f && has > 0.0f ? d : 0.0f;
        float dof = d + m->dof_within[i], v = (between + m->within[i]) / (dof > 0.0f ? dof : 1.0f);
        v = v < S2_MAX ? v : S2_MAX;
        s2[i] = dof > 0.0f ? v : 0.0f;
    }
}

/* A footprint tap into the sums, its weight w times the luminance stop against the chosen pixel's
 * light (rp, gp, bp; il as in add_pair), times its count. */
static void pool_add(sums *restrict s, const float *restrict rp, const float *restrict gp, const float *restrict bp,
                     tap t, const float *restrict il, const float *restrict w) {
    const float *restrict rq = t.r, *restrict gq = t.g, *restrict bq = t.b, *restrict nq = t.n;
    for (int i = 0; i < CHUNK; i++) {
        float d = luminance3(v3(fabsf(rp[i] - rq[i]), fabsf(gp[i] - gq[i]), fabsf(bp[i] - bq[i])));
        float e = w[i] * exp2_neg(-d * il[i]), a = e * nq[i];
        s->a[i] += a;
        s->r[i] += a * rq[i];
        s->g[i] += a * gq[i];
        s->b[i] += a * bq[i];
        s->bb[i] += a * e;
    }
}

/* Row y of the half grid from the full image's input: each half pixel takes the geometry of the
 * pixel of its 2x2 block most alike the other three (by the geometry weights; the first of
 * equals), and pools the 4x4 around the block weighted K4 x K4, by that pixel's geometry weights
 * and luminance stop, and by counts, so that a block across an edge keeps one side (the other is
 * brought back up from its own side's half pixels). Its variance is the footprint's pooled one
 * (pool_variance), by which all later steps' stops go. */
void denoise_pool_row(void *ctx, int y, int worker) {
    (void)worker;
    const job *j = ctx;
    denoiser *d = j->d;
    for (int x0 = 0; x0 < d->half_width; x0 += CHUNK) {
        ptrdiff_t q = at(d, y, x0), foot[4][4]; /* [row][column] plane offsets */
        for (int r = 0; r < 4; r++)
            for (int c = 0; c < 4; c++) foot[r][c] = at(d, 2 * y - 1 + r, x0) + FOOT_SHIFT[c];
        /* block pixel a: footprint column 1 + (a & 1), row 1 + (a >> 1) */
        const geometry *ga[4];
        ptrdiff_t pa[4];
        for (int a = 0; a < 4; a++) {
            ga[a] = &d->full_geo[FOOT_PHASE[1 + (a & 1)]];
            pa[a] = foot[1 + (a >> 1)][1 + (a & 1)];
        }
        float score[4][CHUNK], pick[CHUNK], w[4][4][CHUNK]; /* w[b][a]: a seen from b */
        for (int b = 0; b < 4; b++) {
            for (int a = 0; a < 4; a++) {
                if (a != b)
                    tap_weight(j, ga[b], pa[b], ga[a], pa[a], (float)((a & 1) - (b & 1)), (float)((a >> 1) - (b >> 1)),
                               w[b][a]);
                else
                    for (int i = 0; i < CHUNK; i++) w[b][a][i] = 1.0f;
            }
            for (int i = 0; i < CHUNK; i++) score[b][i] = w[b][0][i] + w[b][1][i] + w[b][2][i] + w[b][3][i];
        }
        for (int i = 0; i < CHUNK; i++) {
            float k = score[1][i] > score[0][i] ? 1.0f : 0.0f,
                  best = score[1][i] > score[0][i] ? score[1][i] : score[0][i];
            k = score[2][i] > best ? 2.0f : k;
            best = score[2][i] > best ? score[2][i] : best;
            pick[i] = score[3][i] > best ? 3.0f : k;
        }
        chosen rep;
        for (int k = 0; k < PLANES_GEOMETRY; k++) {
            const float *v[4];
            for (int a = 0; a < 4; a++) {
                const geometry *g = ga[a];
                const float *each[PLANES_GEOMETRY] = {g->z, g->nx, g->ny, g->nz, g->gx, g->gy, g->sn};
                v[a] = each[k] + pa[a];
            }
            pick_of(v[0], v[1], v[2], v[3], pick, 1.0f, rep.v[k]);
        }
        for (int i = 0; i < CHUNK; i++) {
            rep.v[CRX][i] = pick[i] == 1.0f || pick[i] == 3.0f ? 1.0f : 0.0f;
            rep.v[CRY][i] = pick[i] >= 2.0f ? 1.0f : 0.0f;
        }
        int tail = d->half_width - x0 < CHUNK ? d->half_width - x0 : CHUNK;
        const geometry *hg = &d->half_geo;
        float *dst_geo[CHOSEN] = {hg->z + q,  hg->nx + q, hg->ny + q, hg->nz + q, hg->gx + q,
                                  hg->gy + q, hg->sn + q, d->rx + q,  d->ry + q};
        for (int k = 0; k < CHOSEN; k++) {
            float scale = k == CGX || k == CGY ? 2.0f : 1.0f; /* the slope per half pixel */
            for (int i = 0; i < tail; i++) dst_geo[k][i] = scale * rep.v[k][i];
        }
        float wf[16][CHUNK]; /* the block's own from w */
        for (int t = 0; t < 16; t++) {
            int r = t >> 2, c = t & 3, a = (c - 1) + 2 * (r - 1);
            if (r == 1 || r == 2) {
                if (c == 1 || c == 2) {
                    pick_of(w[0][a], w[1][a], w[2][a], w[3][a], pick, K4[r] * K4[c], wf[t]);
                    continue;
                }
            }
            footprint_weight(j, &rep, &d->full_geo[FOOT_PHASE[c]], foot[r][c], c, r, K4[r] * K4[c], wf[t]);
        }
        for (int c = 0; c < j->comps; c++) {
            tap ft[16];
            const float *fs2[16];
            for (int t = 0; t < 16; t++) {
                const planes *pl = &d->full[FOOT_PHASE[t & 3]][c];
                ft[t] = tap_at(pl, foot[t >> 2][t & 3]);
                fs2[t] = pl->s2 + foot[t >> 2][t & 3];
            }
            float rv[4][CHUNK]; /* the chosen pixel's light and count */
            for (int k = 0; k < 4; k++) {
                const float *v[4];
                for (int a = 0; a < 4; a++) {
                    tap b = ft[4 * (1 + (a >> 1)) + 1 + (a & 1)];
                    const float *each[4] = {b.r, b.g, b.b, b.n};
                    v[a] = each[k];
                }
                pick_of(v[0], v[1], v[2], v[3], pick, 1.0f, rv[k]);
            }
            float lc[CHUNK], s2[CHUNK], il[CHUNK];
            for (int i = 0; i < CHUNK; i++) lc[i] = luminance3(v3(rv[0][i], rv[1][i], rv[2][i]));
            pool_moments m;
            memset(&m, 0, sizeof m);
            for (int t = 0; t < 16; t++) pool_moment(&m, ft[t], fs2[t], lc, wf[t]);
            pool_variance(&m, s2);
            /* the stop against the chosen pixel, by its own value's variance */
            luminance_stop(j, rv[3], lc, s2, j->inv_sqrt_unit, il);
            sums acc;
            memset(&acc, 0, sizeof acc);
            for (int t = 0; t < 16; t++) pool_add(&acc, rv[0], rv[1], rv[2], ft[t], il, wf[t]);
            const planes *dst = &d->half[0][c];
            float out[6][CHUNK];
            finish(&acc, out[0], out[1], out[2], out[3], out[5], j->kappa / 16.0f);
            memcpy(out[4], s2, sizeof s2);
            float *to[6] = {dst->r + q, dst->g + q, dst->b + q, dst->l + q, dst->s2 + q, dst->n + q};
            for (int k = 0; k < 6; k++) { /* the run's tail past the image: no sample */
                memcpy(to[k], out[k], sizeof(float) * (size_t)tail);
                memset(to[k] + tail, 0, sizeof(float) * (size_t)(CHUNK - tail));
            }
        }
    }
}

/* Row y of the half grid's variance steadied: each pixel's pooled one (half[0]'s s2) averaged
 * over its 3x3 with the weights (1, 2, 1) x (1, 2, 1) / 16, pixels without samples left out, into
 * half[1]'s s2, which every later stop goes by. A footprint holds few samples while the image is
 * young: one estimate low by chance would shut its pixels' stops, and their lone samples would
 * show as specks (SVGF steadies its variance with the same 3x3). */
static void add_variance(const float *restrict s2, const float *restrict n, float k, float *restrict sw,
                         float *restrict sv) {
    for (int i = 0; i < CHUNK; i++) {
        float w = n[i] > 0.0f ? k : 0.0f;
        sw[i] += w;
        sv[i] += w * s2[i];
    }
}

void denoise_variance_row(void *ctx, int y, int worker) {
    (void)worker;
    const job *j = ctx;
    const denoiser *d = j->d;
    for (int x0 = 0; x0 < d->half_width; x0 += CHUNK)
        for (int c = 0; c < j->comps; c++) {
            const planes *pl = &d->half[0][c];
            ptrdiff_t p = at(d, y, x0);
            float sw[CHUNK] = {0}, sv[CHUNK] = {0};
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++) {
                    ptrdiff_t q = p + dy * d->stride + dx;
                    add_variance(pl->s2 + q, pl->n + q, B1[dx + 2] * B1[dy + 2], sw, sv);
                }
            float *restrict out = d->half[1][c].s2 + p;
            for (int i = 0; i < CHUNK; i++) out[i] = sv[i] / (sw[i] > 0.0f ? sw[i] : 1.0f);
        }
}

/* The one-sample variance a full pixel's stops go by: the half grid's pooled one (see
 * pool_variance), of the four half pixels around it weighted as their light will be (bilinear and
 * geometry weights w), those with samples; its own where none is on its surface. */
static void add_half_variance(const float *restrict w, const float *restrict n, const float *restrict s2,
                              float *restrict sw, float *restrict sv) {
    for (int i = 0; i < CHUNK; i++) {
        float wi = n[i] > 0.0f ? w[i] : 0.0f;
        sw[i] += wi;
        sv[i] += wi * s2[i];
    }
}

static void half_variance(const float (*w)[CHUNK], const tap *t, const float *const *s2, const float *restrict own,
                          float *restrict v) {
    float sw[CHUNK] = {0}, sv[CHUNK] = {0};
    add_half_variance(w[0], t[0].n, s2[0], sw, sv);
    add_half_variance(w[1], t[1].n, s2[1], sw, sv);
    add_half_variance(w[2], t[2].n, s2[2], sw, sv);
    add_half_variance(w[3], t[3].n, s2[3], sw, sv);
    for (int i = 0; i < CHUNK; i++) {
        float sum = sw[i], u = sv[i] / (sum >= FLT_MIN ? sum : 1.0f);
        v[i] = sum >= FLT_MIN ? u : own[i];
    }
}

/* The geometry weights (base-2 logarithms, kernel weight log2h) of a run of full pixels (c + p)
 * against a half pixel each (h + q, chosen pixel rx + q, ry + q): offset from the pixel by
 * (rx + ox, ry + oy). */
static void half_geometry(const job *j, const geometry *c, ptrdiff_t p, const geometry *h, const float *rx,
                          const float *ry, ptrdiff_t q, float ox, float oy, float log2h, float *restrict w) {
    const float *restrict z = c->z + p, *restrict nx = c->nx + p, *restrict ny = c->ny + p;
    const float *restrict nz = c->nz + p, *restrict gx = c->gx + p, *restrict gy = c->gy + p;
    const float *restrict qz = h->z + q, *restrict qx = h->nx + q, *restrict qy = h->ny + q;
    const float *restrict qnz = h->nz + q, *restrict dx = rx + q, *restrict dy = ry + q, *restrict sn = c->sn + p;
    float sz = j->sigma_z, sn0 = j->sigma_n;
    for (int i = 0; i < CHUNK; i++) {
        float inv = depth_scale(z[i], gx[i], gy[i], dx[i] + ox, dy[i] + oy, sz);
        float cs = nx[i] * qx[i] + ny[i] * qy[i] + nz[i] * qnz[i];
        w[i] = log2h + normal_log2(cs, sn0 + sn[i]) - fabsf(z[i] - qz[i]) * inv;
    }
}

/* The 3x3 pass's pairs (dx, dy) at full resolution: of pixel x = 2 m + phase, the tap x + dx is of
 * parity (phase + dx) & 1, at plane column m + FINE_SHIFT[phase][dx + 1]. */
static const signed char PAIRS3[4][2] = {{1, 0}, {-1, 1}, {0, 1}, {1, 1}};
static const int FINE_SHIFT[2][3] = {{-1, 0, 0}, {0, 0, 1}};

/* A run's output: light and samples (out_unit a scaled count of 1) of full pixels 2 (m0 + i) +
 * phase, both phases interleaved; a whole run at once, the image's last pixel by pixel. */
static void merge_pairs(const float *restrict even, const float *restrict odd, float *restrict run) {
    for (int i = 0; i < CHUNK; i++) {
        run[2 * i] = even[i];
        run[2 * i + 1] = odd[i];
    }
}

static void interleave(const float *restrict r, const float *restrict g, const float *restrict b,
                       const float *restrict n, float unit, float *restrict out, float *restrict count) {
    for (int x = 0; x < RUN; x++) {
        out[3 * x] = r[x];
        out[3 * x + 1] = g[x];
        out[3 * x + 2] = b[x];
        count[x] = clampf_to(n[x] * unit, FLT_MAX);
    }
}

static void write_out(const job *j, int c, int y, int m0, const float (*r)[CHUNK], const float (*g)[CHUNK],
                      const float (*b)[CHUNK], const float (*n)[CHUNK]) {
    const denoiser *d = j->d;
    int x0 = 2 * m0, tail = d->width - x0 < RUN ? d->width - x0 : RUN;
    size_t o = (size_t)y * (size_t)d->width + (size_t)x0;
    float *out = j->out->light[c] + 3 * o, *count = j->out->count[c] ? j->out->count[c] + o : NULL;
    float unit = j->out_unit, spare[RUN];
    if (tail == RUN) {
        float v[4][RUN];
        merge_pairs(r[0], r[1], v[0]);
        merge_pairs(g[0], g[1], v[1]);
        merge_pairs(b[0], b[1], v[2]);
        merge_pairs(n[0], n[1], v[3]);
        interleave(v[0], v[1], v[2], v[3], unit, out, count ? count : spare);
        return;
    }
    for (int x = 0; x < tail; x++) {
        int ph = x & 1, i = x >> 1;
        out[3 * x] = r[ph][i];
        out[3 * x + 1] = g[ph][i];
        out[3 * x + 2] = b[ph][i];
        if (count) count[x] = clampf_to(n[ph][i] * unit, FLT_MAX);
    }
}

/* A pixel whose surface none of the steps above found: a thin feature, or a block's minority
 * side, with no sample of its surface in its 3x3 and none of the half pixels around it on its
 * surface (the half grid shows another). Its light, if any, came at the weight of another surface
 * (below 2^SURFACE_LOG2, kernel weights aside). It is filled as a pass would fill it, from the
 * samples of its surface within FILL pixels (geometry weights and counts): rare, so one pixel at
 * a time. The light and count (in out_unit) go to *r, *g, *b, *n when there are any. */
#define SURFACE_LOG2 (-20.0f)
#define FILL 6

static void fill_hole(const job *j, int c, int x, int y, float *r, float *g, float *b, float *n) {
    const denoiser *d = j->d;
    const geometry *gp = &d->full_geo[x & 1];
    ptrdiff_t p = at(d, y, x >> 1);
    float sa = 0.0f, sr = 0.0f, sg = 0.0f, sb = 0.0f, sq = 0.0f;
    for (int dy = -FILL; dy <= FILL; dy++)
        for (int dx = -FILL; dx <= FILL; dx++) {
            int xx = x + dx, yy = y + dy;
            if (xx < 0 || xx >= d->width || yy < 0 || yy >= d->height) continue;
            const geometry *gq = &d->full_geo[xx & 1];
            const planes *pq = &d->full[xx & 1][c];
            ptrdiff_t q = at(d, yy, xx >> 1);
            if (!(pq->n[q] > 0.0f)) continue;
            float cs = gp->nx[p] * gq->nx[q] + gp->ny[p] * gq->ny[q] + gp->nz[p] * gq->nz[q];
            float inv = depth_scale(gp->z[p], gp->gx[p], gp->gy[p], (float)dx, (float)dy, j->sigma_z);
            float w = exp2_neg(normal_log2(cs, j->sigma_n) - fabsf(gp->z[p] - gq->z[q]) * inv), a = w * pq->n[q];
            sa += a, sq += a * w;
            sr += a * pq->r[q], sg += a * pq->g[q], sb += a * pq->b[q];
        }
    if (!(sa >= FLT_MIN)) return;
    *r = clampf_to(sr / sa, FLT_MAX);
    *g = clampf_to(sg / sa, FLT_MAX);
    *b = clampf_to(sb / sa, FLT_MAX);
    *n = sa * (sa / (sq > FLT_MIN ? sq : FLT_MIN)) / (COUNT_SCALE * j->out_unit); /* (sum a)^2 / sum b */
}

/* Row y of the output, from the full image's input and the half grid's result. First the full
 * resolution's own pass, 3x3 (B1): its value f and count n_f for each pixel. Then, as a pass whose
 * taps are the half grid's, f (weight UP_OWN n_f) and the four half pixels around it: bilinear
 * weights (3/4, 1/4 a side) times geometry weights against the pixel whose geometry each took, the
 * luminance stop against f, and counts. */
void denoise_upsample_row(void *ctx, int y, int worker) {
    (void)worker;
    const job *j = ctx;
    const denoiser *d = j->d;
    const planes *co = d->half[j->coarse];
    int rows[2] = {y >> 1, (y & 1) ? (y >> 1) + 1 : (y >> 1) - 1}; /* near, far */
    float row_dy[2] = {-(float)(y & 1), (y & 1) ? 1.0f : -2.0f};   /* their chosen pixels' offsets */
    static const float BIL[2] = {0.75f, 0.25f};
    for (int m0 = 0; m0 < d->half_width; m0 += CHUNK) {
        float fr[COMP_COUNT][2][CHUNK], fg[COMP_COUNT][2][CHUNK], fb[COMP_COUNT][2][CHUNK], fn[COMP_COUNT][2][CHUNK];
        for (int ph = 0; ph < 2; ph++) {
            const geometry *gc = &d->full_geo[ph];
            ptrdiff_t p = at(d, y, m0);
            /* the four half pixels t = 2 row + column (near 0; far: left of even pixels, right of odd) */
            ptrdiff_t qt[4];
            float lnw[4][CHUNK];
            for (int t = 0; t < 4; t++) {
                int rw = t >> 1, col = t & 1, shift = col ? (ph ? 1 : -1) : 0;
                float ox = col ? (ph ? 1.0f : -2.0f) : -(float)ph;
                qt[t] = at(d, rows[rw], m0) + shift;
                half_geometry(j, gc, p, &d->half_geo, d->rx, d->ry, qt[t], ox, row_dy[rw], log2f(BIL[rw] * BIL[col]),
                              lnw[t]);
            }
            float ew[4][CHUNK]; /* the same, not logarithms */
            for (int t = 0; t < 4; t++)
                for (int i = 0; i < CHUNK; i++) ew[t][i] = exp2_neg(lnw[t][i]);
            /* the 3x3 pass's geometry weights: tap a (dx, dy), tap b its mirror */
            const geometry *fga[4], *fgb[4];
            ptrdiff_t fpa[4], fpb[4];
            float fw[4][2][CHUNK];
            for (int k = 0; k < 4; k++) {
                int dx = PAIRS3[k][0], dy = PAIRS3[k][1];
                fga[k] = &d->full_geo[(ph + dx) & 1];
                fgb[k] = &d->full_geo[(ph - dx) & 1];
                fpa[k] = at(d, y + dy, m0) + FINE_SHIFT[ph][dx + 1];
                fpb[k] = at(d, y - dy, m0) + FINE_SHIFT[ph][1 - dx];
                float log2h = log2f(B1[dx + 2] * B1[dy + 2]);
                pair_geometry(j, gc, p, fga[k], fpa[k], fgb[k], fpb[k], (float)dx, (float)dy, log2h, fw[k][0],
                              fw[k][1]);
            }
            for (int c = 0; c < j->comps; c++) {
                const planes *pl = &d->full[ph][c];
                tap t[4];
                const float *ts2[4];
                for (int k = 0; k < 4; k++) {
                    t[k] = tap_at(&co[c], qt[k]);
                    ts2[k] = d->half[1][c].s2 + qt[k];
                }
                /* the variance the pixel's stops go by (one sample's): the half grid's */
                float v[CHUNK], il[CHUNK];
                half_variance((const float(*)[CHUNK])ew, t, ts2, pl->s2 + p, v);
                /* the 3x3 pass: f, n_f */
                sums acc;
                float l[CHUNK], best[CHUNK]; /* the best tap of its surface: its own sample's 2^0, or a tap's */
                for (int i = 0; i < CHUNK; i++) best[i] = pl->n[p + i] > 0.0f ? 0.0f : -FLT_MAX;
                lum_run(pl->r + p, pl->g + p, pl->b + p, l);
                luminance_stop(j, pl->n + p, l, v, j->inv_sqrt_unit, il);
                add_own(&acc, tap_at(pl, p), B1[2] * B1[2], 1.0f);
                for (int k = 0; k < 4; k++)
                    add_pair(&acc, pl->r + p, pl->g + p, pl->b + p,
                             tap_at(&d->full[(ph + PAIRS3[k][0]) & 1][c], fpa[k]),
                             tap_at(&d->full[(ph - PAIRS3[k][0]) & 1][c], fpb[k]), fw[k][0], fw[k][1], il, best);
                float *r = fr[c][ph], *g = fg[c][ph], *b = fb[c][ph], *n = fn[c][ph];
                finish(&acc, r, g, b, l, n, j->kappa_fine / TAPS);
                /* f and the half grid */
                luminance_stop(j, n, l, v, j->fine_inv_sqrt_unit, il);
                add_own(&acc, (tap){r, g, b, n}, UP_OWN, j->fine_to_coarse);
                add_pair(&acc, r, g, b, t[0], t[1], lnw[0], lnw[1], il, best);
                add_pair(&acc, r, g, b, t[2], t[3], lnw[2], lnw[3], il, best);
                finish(&acc, r, g, b, l, n, j->kappa / 5.0f);
                /* (the kernels' weights are 2^-4 at least) */
                for (int i = 0; i < CHUNK; i++)
                    if (best[i] < SURFACE_LOG2 - 4.0f && 2 * (m0 + i) + ph < d->width)
                        fill_hole(j, c, 2 * (m0 + i) + ph, y, r + i, g + i, b + i, n + i);
            }
        }
        for (int c = 0; c < j->comps; c++)
            write_out(j, c, y, m0, (const float(*)[CHUNK])fr[c], (const float(*)[CHUNK])fg[c],
                      (const float(*)[CHUNK])fb[c], (const float(*)[CHUNK])fn[c]);
    }
}
