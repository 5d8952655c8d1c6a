#include "choice.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A tile's sums over its pixels' records, per estimator: each pixel's squared deviations about
 * its own mean (the light's changes across a tile are no estimator's noise) and their degrees of
 * freedom, the work and the samples. */
struct tile_sums {
    double m2[EST_COUNT], dof[EST_COUNT], work[EST_COUNT], n[EST_COUNT];
};

int choice_init(estimator_choice *c, int width, int height) {
    memset(c, 0, sizeof *c);
    c->width = width, c->height = height;
    c->tiles_x = (width + CHOICE_TILE - 1) / CHOICE_TILE;
    c->tiles_y = (height + CHOICE_TILE - 1) / CHOICE_TILE;
    size_t tiles = (size_t)c->tiles_x * (size_t)c->tiles_y;
    c->rec = calloc((size_t)width * (size_t)height, sizeof *c->rec);
    c->mode = malloc(tiles);
    c->paths = malloc(tiles);
    c->sums = malloc(tiles * sizeof *c->sums);
    if (!c->rec || !c->mode || !c->paths || !c->sums) {
        choice_free(c);
        return -1;
    }
    choice_reset(c);
    return 0;
}

void choice_free(estimator_choice *c) {
    free(c->rec);
    free(c->mode);
    free(c->paths);
    free(c->sums);
    memset(c, 0, sizeof *c);
}

void choice_reset(estimator_choice *c) {
    if (!c->rec) return;
    memset(c->rec, 0, (size_t)c->width * (size_t)c->height * sizeof *c->rec);
    memset(c->mode, CHOICE_VL, (size_t)c->tiles_x * (size_t)c->tiles_y);
    memset(c->paths, 1, (size_t)c->tiles_x * (size_t)c->tiles_y);
    c->vl_tiles = 0;
    c->judgements = 0;
}

static void add_tile_sums(const estimator_choice *c, int tx, int ty, tile_sums *s) {
    int x1 = (tx + 1) * CHOICE_TILE < c->width ? (tx + 1) * CHOICE_TILE : c->width;
    int y1 = (ty + 1) * CHOICE_TILE < c->height ? (ty + 1) * CHOICE_TILE : c->height;
    for (int y = ty * CHOICE_TILE; y < y1; y++)
        for (int x = tx * CHOICE_TILE; x < x1; x++) {
            const choice_record *r = &c->rec[(size_t)y * (size_t)c->width + (size_t)x];
            for (int e = 0; e < EST_COUNT; e++) {
                if (r->e[e].n >= 2.0f) s->m2[e] += (double)r->e[e].m2, s->dof[e] += (double)r->e[e].n - 1.0;
                s->work[e] += (double)r->e[e].work, s->n[e] += (double)r->e[e].n;
            }
        }
}

static double sums_variance(const tile_sums *s, int e) { return s->dof[e] > 0.0 ? s->m2[e] / s->dof[e] : 0.0; }

/* A tile judged by its pixels' records. At equal time a pixel's error from an estimator whose
 * sample has variance V and costs C is V C / T: the tile takes the estimator of the smaller V C.
 * The estimator a tile has not taken has only the probe's and the measuring samples, tens to
 * hundreds where the one it took has thousands, and where it is weak its variance lies in rare
 * bright samples that few miss (the Cornell box's path tracer: 64 samples a tile show a twentieth
 * of the variance 8000 show). Its V is the larger of the tile's and that of the 3x3 tiles around
 * it, nine times the samples: a tile turns only on evidence that holds around it too, while the
 * estimator it took answers for its own thousands. At the first judgement, after the probe,
 * neither has been taken and both are judged so. A tile taking path tracing traces as many paths
 * a frame as one virtual-light sample costs, so that it spends the frame's time a pixel as the
 * rest of the image does. A tile whose samples do not vary at all (the sky, a black wall) takes
 * one path. */
static void judge_tile(estimator_choice *c, int tx, int ty) {
    size_t t = (size_t)ty * (size_t)c->tiles_x + (size_t)tx;
    const tile_sums own = c->sums[t];
    tile_sums around = {0};
    for (int y = ty - 1; y <= ty + 1; y++)
        for (int x = tx - 1; x <= tx + 1; x++) {
            if (x < 0 || y < 0 || x >= c->tiles_x || y >= c->tiles_y) continue;
            const tile_sums *s = &c->sums[(size_t)y * (size_t)c->tiles_x + (size_t)x];
            for (int e = 0; e < EST_COUNT; e++) {
                around.m2[e] += s->m2[e], around.dof[e] += s->dof[e];
                around.work[e] += s->work[e], around.n[e] += s->n[e];
            }
        }
    int taken = c->judgements == 0 ? -1 : c->mode[t] == CHOICE_VL ? EST_VL : EST_PT;
    double var[EST_COUNT], cost[EST_COUNT];
    for (int e = 0; e < EST_COUNT; e++) {
        var[e] = sums_variance(&own, e);
        if (e != taken) var[e] = fmax(var[e], sums_variance(&around, e));
        cost[e] = own.n[e] > 0.0 ? own.work[e] / own.n[e] : 0.0;
    }
    int vl = own.n[EST_VL] > 0.0 && var[EST_VL] * cost[EST_VL] < var[EST_PT] * cost[EST_PT];
    c->mode[t] = (uint8_t)(vl ? CHOICE_VL : CHOICE_PT);
    int varies = sums_variance(&own, EST_PT) > 0.0;
    double paths = cost[EST_PT] > 0.0 && varies ? floor(cost[EST_VL] / cost[EST_PT] + 0.5) : 1.0;
    c->paths[t] = (uint8_t)(paths < 1.0 ? 1 : paths > CHOICE_MAX_PATHS ? CHOICE_MAX_PATHS : paths);
}

void choice_judge(estimator_choice *c) {
    if (!c->rec) return;
    memset(c->sums, 0, (size_t)c->tiles_x * (size_t)c->tiles_y * sizeof *c->sums);
    for (int ty = 0; ty < c->tiles_y; ty++) /* each tile's once, for itself and its neighbours */
        for (int tx = 0; tx < c->tiles_x; tx++) add_tile_sums(c, tx, ty, &c->sums[ty * c->tiles_x + tx]);
    c->vl_tiles = 0;
    for (int ty = 0; ty < c->tiles_y; ty++)
        for (int tx = 0; tx < c->tiles_x; tx++) {
            judge_tile(c, tx, ty);
            c->vl_tiles += c->mode[ty * c->tiles_x + tx] == CHOICE_VL;
        }
    c->judgements++;
}

float choice_vl_share(const estimator_choice *c, int pixel, double film_samples) {
    if (!c->rec || !(film_samples > 0.0)) return 0.0f;
    return (float)((double)c->rec[pixel].vl_weight / film_samples);
}
