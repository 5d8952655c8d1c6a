#include "mrcs.h"

#include <float.h>
#include <stdlib.h>
#include <string.h>

/* The centre assignment computes JB columns against KB centres at a time (register tiles the
 * compiler vectorises over the centres). */
#define JB 4
#define KB 16
/* 1 - cos below this: the same direction, for the centre assignment. */
#define SAME_DIRECTION 1e-4
/* Split costs within this fraction of (sum of norms)^2 of the best are rounding noise. */
#define FREE_SPLIT 1e-10

/* A cluster: the range [begin, begin + size) of ctx.member. */
typedef struct {
    int begin, size;
    double cost, weight;
} mcluster;

typedef struct {
    int rows, count;     /* R, non-zero columns */
    const int *column;   /* compact index -> column index in m */
    const float *dir;    /* count x rows: column k's direction rho / |rho|, rounded to float */
    const double *norm;  /* |rho| */
    const double *enorm; /* norm * |dir|: the norm of norm * dir, so that one column's cost is 0 */
    int *member;         /* a permutation of 0..count-1; clusters are its ranges */
    /* Scratch for splits. */
    float *line;
    double *sum;                           /* rows */
    double *left, *right, *wleft, *wright; /* count + 1 */
    struct proj {
        float p;
        int k;
    } * proj;
} ctx;

static float dotf(const float *a, const float *b, int n) {
    /* Eight partial sums: independent chains the compiler can turn into one vector. */
    float acc[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    int r = 0;
    for (; r + 8 <= n; r += 8)
        for (int i = 0; i < 8; i++) acc[i] += a[r + i] * b[r + i];
    float s = ((acc[0] + acc[4]) + (acc[1] + acc[5])) + ((acc[2] + acc[6]) + (acc[3] + acc[7]));
    for (; r < n; r++) s += a[r] * b[r];
    return s;
}

/* Adds column k to the running sums of a cluster that then has `members` members (c->sum: the
 * sum of the columns; *sn: of their norms, *w: of |rho|) and returns its cost,
 * (sum of norms)^2 - |sum of columns|^2, never below 0. */
static double add_member(const ctx *c, int k, int members, double *sn, double *w) {
    const float *d = c->dir + (size_t)k * (size_t)c->rows;
    double nk = c->norm[k], q = 0.0;
    for (int r = 0; r < c->rows; r++) {
        c->sum[r] += nk * (double)d[r];
        q += c->sum[r] * c->sum[r];
    }
    *sn += c->enorm[k];
    *w += nk;
    return members < 2 || !(*sn * *sn > q) ? 0.0 : *sn * *sn - q;
}

/* The cost of the members list[0, size); their norm sum to *weight. */
static double cluster_cost(const ctx *c, const int *list, int size, double *weight) {
    double sn = 0.0, cost = 0.0;
    *weight = 0.0;
    memset(c->sum, 0, sizeof(double) * (size_t)c->rows);
    for (int i = 0; i < size; i++) cost = add_member(c, list[i], i + 1, &sn, weight);
    return cost;
}

/* The member of list[0, size) farthest from direction a in d (up to the constant 2 |rho_a|). */
static int farthest(const ctx *c, const int *list, int size, const float *a) {
    int best = list[0];
    double best_d = -INFINITY;
    for (int i = 0; i < size; i++) {
        int k = list[i];
        double d = c->norm[k] * (1.0 - (double)dotf(a, c->dir + (size_t)k * (size_t)c->rows, c->rows));
        if (d > best_d) best_d = d, best = k;
    }
    return best;
}

static int cmp_proj(const void *pa, const void *pb) {
    const struct proj *a = pa, *b = pb;
    if (a->p != b->p) return a->p < b->p ? -1 : 1;
    return (a->k > b->k) - (a->k < b->k);
}

/* Splits cl (size >= 2) into cl (the left part) and *out (the right); both non-empty. */
static void split(ctx *c, mcluster *cl, mcluster *out, rng_state *rng) {
    int R = c->rows, s = cl->size;
    int *list = c->member + cl->begin;
    int a = list[(int)(rng_double(rng) * (double)s) % s];
    int b = farthest(c, list, s, c->dir + (size_t)a * (size_t)R);
    int e = farthest(c, list, s, c->dir + (size_t)b * (size_t)R);
    const float *db = c->dir + (size_t)b * (size_t)R, *de = c->dir + (size_t)e * (size_t)R;
    for (int r = 0; r < R; r++) c->line[r] = de[r] - db[r];
    for (int i = 0; i < s; i++) {
        c->proj[i].p = dotf(c->line, c->dir + (size_t)list[i] * (size_t)R, R);
        c->proj[i].k = list[i];
    }
    qsort(c->proj, (size_t)s, sizeof c->proj[0], cmp_proj);
    for (int i = 0; i < s; i++) list[i] = c->proj[i].k;

    /* left[i]: cost of list[0, i); right[i]: cost of list[i, s). Same for the norm sums. */
    double sn = 0.0, w = 0.0;
    memset(c->sum, 0, sizeof(double) * (size_t)R);
    c->left[0] = c->wleft[0] = 0.0;
    for (int i = 0; i < s; i++) {
        c->left[i + 1] = add_member(c, list[i], i + 1, &sn, &w);
        c->wleft[i + 1] = w;
    }
    double total_sn = sn;
    sn = w = 0.0;
    memset(c->sum, 0, sizeof(double) * (size_t)R);
    c->right[s] = c->wright[s] = 0.0;
    for (int i = s - 1; i >= 0; i--) {
        c->right[i] = add_member(c, list[i], s - i, &sn, &w);
        c->wright[i] = w;
    }

    double best = INFINITY;
    for (int i = 1; i < s; i++)
        if (c->left[i] + c->right[i] < best) best = c->left[i] + c->right[i];
    double limit = best + FREE_SPLIT * total_sn * total_sn, half = 0.5 * c->wleft[s];
    int cut = 1;
    double cut_imbalance = INFINITY;
    for (int i = 1; i < s; i++) {
        double imbalance = fabs(c->wleft[i] - half);
        if (c->left[i] + c->right[i] <= limit && imbalance < cut_imbalance) cut = i, cut_imbalance = imbalance;
    }
    *out = (mcluster){cl->begin + cut, s - cut, c->right[cut], c->wright[cut]};
    *cl = (mcluster){cl->begin, cut, c->left[cut], c->wleft[cut]};
}

/* Heap order: clusters that can split first, then by cost, then by norm. */
static int above(const mcluster *a, const mcluster *b) {
    int sa = a->size > 1, sb = b->size > 1;
    if (sa != sb) return sa > sb;
    if (a->cost != b->cost) return a->cost > b->cost;
    return a->weight > b->weight;
}

static void sift_down(mcluster *h, int n, int i) {
    for (;;) {
        int l = 2 * i + 1, r = l + 1, top = i;
        if (l < n && above(&h[l], &h[top])) top = l;
        if (r < n && above(&h[r], &h[top])) top = r;
        if (top == i) return;
        mcluster t = h[i];
        h[i] = h[top];
        h[top] = t;
        i = top;
    }
}

static void sift_up(mcluster *h, int i) {
    while (i > 0) {
        int p = (i - 1) / 2;
        if (!above(&h[i], &h[p])) return;
        mcluster t = h[i];
        h[i] = h[p];
        h[p] = t;
        i = p;
    }
}

static float clamp_float(double x) { return x < (double)FLT_MAX ? (float)x : FLT_MAX; }

typedef struct {
    double key;
    int k;
} centre_key;

static int cmp_key(const void *pa, const void *pb) {
    const centre_key *a = pa, *b = pb;
    if (a->key != b->key) return a->key < b->key ? -1 : 1;
    return (a->k > b->k) - (a->k < b->k);
}

/* Phase (a): `centres` distinct columns drawn by norm, every column to its nearest centre.
 * Fills c->member and cl with the non-empty clusters; returns their number, -1 when out of memory. */
static int sampling_clustering(ctx *c, int centres, rng_state *rng, mcluster *cl) {
    int R = c->rows, count = c->count;
    int blocks = (centres + KB - 1) / KB;
    centre_key *keys = malloc(sizeof(centre_key) * (size_t)count);
    double *cnorm = malloc(sizeof(double) * (size_t)centres);
    float *packed = calloc((size_t)blocks * (size_t)R * KB, sizeof(float));
    int *assign = malloc(sizeof(int) * (size_t)count);
    int *end = calloc((size_t)centres, sizeof(int));
    int result = -1;
    if (!keys || !cnorm || !packed || !assign || !end) goto done;

    /* Weighted sampling without replacement (Efraimidis-Spirakis): the `centres` smallest
     * Exp(1) / norm. 1 - u is in (0, 1], so the logarithm is finite. */
    for (int k = 0; k < count; k++) keys[k] = (centre_key){-log(1.0 - rng_double(rng)) / c->norm[k], k};
    qsort(keys, (size_t)count, sizeof keys[0], cmp_key);
    /* Centre directions packed KB at a time: block b holds, row by row, KB centres side by side. */
    for (int i = 0; i < centres; i++) {
        int k = keys[i].k;
        cnorm[i] = c->norm[k];
        const float *d = c->dir + (size_t)k * (size_t)R;
        float *p = packed + (size_t)(i / KB) * (size_t)R * KB + (size_t)(i % KB);
        for (int r = 0; r < R; r++) p[(size_t)r * KB] = d[r];
    }

    /* Nearest centre in d(j, c) = 2 |rho_j| |rho_c| (1 - cos): the smallest |rho_c| (1 - cos).
     * 1 - cos below SAME_DIRECTION counts as 0 and ties go to the earlier centre, so columns of
     * one direction (rounding apart) all make the same choice. */
    for (int j0 = 0; j0 < count; j0 += JB) {
        double best[JB];
        int arg[JB];
        const float *x[JB];
        for (int jj = 0; jj < JB; jj++) {
            best[jj] = INFINITY;
            arg[jj] = 0;
            x[jj] = c->dir + (size_t)(j0 + jj < count ? j0 + jj : j0) * (size_t)R;
        }
        for (int b = 0; b < blocks; b++) {
            float acc[JB][KB];
            memset(acc, 0, sizeof acc);
            const float *y = packed + (size_t)b * (size_t)R * KB;
            for (int r = 0; r < R; r++, y += KB)
                for (int jj = 0; jj < JB; jj++) {
                    float xv = x[jj][r];
                    for (int k = 0; k < KB; k++) acc[jj][k] += xv * y[k];
                }
            int kn = centres - b * KB < KB ? centres - b * KB : KB;
            for (int jj = 0; jj < JB; jj++)
                for (int k = 0; k < kn; k++) {
                    double gap = 1.0 - (double)acc[jj][k] - SAME_DIRECTION;
                    double score = gap > 0.0 ? cnorm[b * KB + k] * gap : 0.0;
                    if (score < best[jj]) best[jj] = score, arg[jj] = b * KB + k;
                }
        }
        for (int jj = 0; jj < JB && j0 + jj < count; jj++) assign[j0 + jj] = arg[jj];
    }

    /* Counting sort by centre; empty centres (their own column joined an earlier centre of the
     * same direction) make no cluster. */
    for (int k = 0; k < count; k++) end[assign[k]]++;
    for (int i = 1; i < centres; i++) end[i] += end[i - 1];
    for (int k = count - 1; k >= 0; k--) c->member[--end[assign[k]]] = k; /* end[i] is now the start */
    int n = 0;
    for (int i = 0; i < centres; i++) {
        int begin = end[i], stop = i + 1 < centres ? end[i + 1] : count;
        if (stop == begin) continue;
        cl[n].begin = begin;
        cl[n].size = stop - begin;
        cl[n].cost = cluster_cost(c, c->member + begin, stop - begin, &cl[n].weight);
        n++;
    }
    result = n;
done:
    free(keys);
    free(cnorm);
    free(packed);
    free(assign);
    free(end);
    return result;
}

int mrcs_cluster_columns(const float *m, int rows, int n, int C, rng_state *rng, mrcs_cluster *out) {
    if (!m || !out || rows < 1 || n < 1 || C < 1) return 0;
    int R = rows;
    double *sq = calloc((size_t)n, sizeof(double));
    if (!sq) return -1;
    for (int i = 0; i < R; i++) {
        const float *row = m + (size_t)i * (size_t)n;
        for (int j = 0; j < n; j++) sq[j] += (double)row[j] * (double)row[j];
    }
    int count = 0;
    for (int j = 0; j < n; j++) count += sq[j] > 0.0;
    if (count <= C) { /* every non-zero column its own cluster (none at all: 0) */
        int o = 0;
        for (int j = 0; j < n; j++)
            if (sq[j] > 0.0) out[o++] = (mrcs_cluster){j, 1.0f, clamp_float(sqrt(sq[j])), 1};
        free(sq);
        return count;
    }

    ctx c;
    memset(&c, 0, sizeof c);
    c.rows = R;
    c.count = count;
    int *column = malloc(sizeof(int) * (size_t)count);
    double *norm = malloc(sizeof(double) * (size_t)count);
    double *enorm = malloc(sizeof(double) * (size_t)count);
    float *dir = malloc(sizeof(float) * (size_t)count * (size_t)R);
    c.member = malloc(sizeof(int) * (size_t)count);
    c.line = malloc(sizeof(float) * (size_t)R);
    c.sum = malloc(sizeof(double) * (size_t)R);
    c.left = malloc(sizeof(double) * ((size_t)count + 1));
    c.right = malloc(sizeof(double) * ((size_t)count + 1));
    c.wleft = malloc(sizeof(double) * ((size_t)count + 1));
    c.wright = malloc(sizeof(double) * ((size_t)count + 1));
    c.proj = malloc(sizeof(c.proj[0]) * (size_t)count);
    mcluster *cl = malloc(sizeof(mcluster) * (size_t)C);
    int result = -1;
    if (!column || !norm || !enorm || !dir || !c.member || !c.line || !c.sum || !c.left || !c.right || !c.wleft ||
        !c.wright || !c.proj || !cl)
        goto done;
    c.column = column;
    c.norm = norm;
    c.enorm = enorm;
    c.dir = dir;

    for (int j = 0, k = 0; j < n; j++)
        if (sq[j] > 0.0) column[k] = j, norm[k] = sqrt(sq[j]), k++;
    /* Directions, column by column (a transpose done 64 columns at a time to stay in cache). */
    for (int k0 = 0; k0 < count; k0 += 64) {
        int k1 = k0 + 64 < count ? k0 + 64 : count;
        for (int i = 0; i < R; i++) {
            const float *row = m + (size_t)i * (size_t)n;
            for (int k = k0; k < k1; k++)
                dir[(size_t)k * (size_t)R + (size_t)i] = (float)((double)row[column[k]] / norm[k]);
        }
    }
    for (int k = 0; k < count; k++) {
        const float *d = dir + (size_t)k * (size_t)R;
        double u = 0.0;
        for (int r = 0; r < R; r++) u += (double)d[r] * (double)d[r];
        enorm[k] = norm[k] * sqrt(u);
    }

    /* (a) about 2C/3 clusters by sampling, (b) split the costliest until C. */
    int centres = (int)((long long)C * 2 / 3);
    int ncl = sampling_clustering(&c, centres > 1 ? centres : 1, rng, cl);
    if (ncl < 0) goto done;
    for (int i = ncl / 2 - 1; i >= 0; i--) sift_down(cl, ncl, i);
    while (ncl < C && cl[0].size > 1) {
        mcluster right;
        split(&c, &cl[0], &right, rng);
        sift_down(cl, ncl, 0);
        cl[ncl] = right;
        sift_up(cl, ncl);
        ncl++;
    }

    /* One representative per cluster, drawn by norm. */
    for (int i = 0; i < ncl; i++) {
        const int *list = c.member + cl[i].begin;
        int s = cl[i].size;
        double w = 0.0, acc = 0.0;
        for (int t = 0; t < s; t++) w += norm[list[t]];
        double u = rng_double(rng) * w;
        int pick = list[s - 1];
        for (int t = 0; t < s; t++) {
            acc += norm[list[t]];
            if (u < acc) {
                pick = list[t];
                break;
            }
        }
        out[i] = (mrcs_cluster){column[pick], clamp_float(w / norm[pick]), clamp_float(w), s};
    }
    result = ncl;
done:
    free(sq);
    free(column);
    free(norm);
    free(enorm);
    free(dir);
    free(c.member);
    free(c.line);
    free(c.sum);
    free(c.left);
    free(c.right);
    free(c.wleft);
    free(c.wright);
    free(c.proj);
    free(cl);
    return result;
}
