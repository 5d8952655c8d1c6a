#include "knn.h"

#include <stdlib.h>
#include <string.h>

/* Balanced k-d tree over an index permutation: a node owns idx[lo, hi) and splits at the median
 * position (not value), so the depth is log2(n / LEAF) whatever the data, duplicates included. */
#define LEAF 8

typedef struct {
    int lo, hi;
    int axis;    /* -1: leaf */
    float split; /* coordinate of the median point */
    int left, right;
} kd_node;

typedef struct {
    float *xyz; /* 3 per finite point, in input order of the compacted set */
    int *idx;
    kd_node *nodes;
    int num_nodes;
} kd_tree;

static inline float coord(const kd_tree *t, int i, int axis) { return t->xyz[3 * i + axis]; }

/* Three-way quickselect of idx[lo, hi) on one axis so that position nth holds its order
 * statistic; equal keys are grouped, so many duplicates cost linear time, not quadratic. */
static void select_nth(const kd_tree *t, int *idx, int lo, int hi, int nth, int axis) {
    uint64_t state = 0x9e3779b97f4a7c15ULL ^ (uint64_t)(hi - lo);
    while (hi - lo > 1) {
        state = state * 6364136223846793005ULL + 1442695040888963407ULL;
        float pivot = coord(t, idx[lo + (int)((state >> 33) % (uint64_t)(hi - lo))], axis);
        int lt = lo, i = lo, gt = hi; /* [lo,lt) < pivot, [lt,i) == pivot, [gt,hi) > pivot */
        while (i < gt) {
            float c = coord(t, idx[i], axis);
            if (c < pivot) {
                int s = idx[lt];
                idx[lt++] = idx[i];
                idx[i++] = s;
            } else if (c > pivot) {
                int s = idx[--gt];
                idx[gt] = idx[i];
                idx[i] = s;
            } else {
                i++;
            }
        }
        if (nth < lt)
            hi = lt;
        else if (nth >= gt)
            lo = gt;
        else
            return;
    }
}

/* Builds the subtree over idx[lo, hi) with an explicit stack; returns the root's index. */
static int build(kd_tree *t, int n) {
    int cap = n / 2 + 3; /* leaves hold at least LEAF / 2 points: at most n / 4 + 1 of them */
    t->nodes = malloc(sizeof(kd_node) * (size_t)cap);
    int *stack = malloc(sizeof(int) * 128);
    if (!t->nodes || !stack) {
        free(stack);
        return -1;
    }
    t->num_nodes = 1;
    t->nodes[0] = (kd_node){0, n, -1, 0.0f, -1, -1};
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        kd_node *nd = &t->nodes[stack[--top]];
        int lo = nd->lo, hi = nd->hi;
        if (hi - lo <= LEAF) continue;
        float mn[3] = {INFINITY, INFINITY, INFINITY}, mx[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (int i = lo; i < hi; i++)
            for (int a = 0; a < 3; a++) {
                float c = coord(t, t->idx[i], a);
                mn[a] = fminf(mn[a], c);
                mx[a] = fmaxf(mx[a], c);
            }
        int axis = 0;
        for (int a = 1; a < 3; a++)
            if (mx[a] - mn[a] > mx[axis] - mn[axis]) axis = a;
        int mid = (lo + hi) / 2;
        select_nth(t, t->idx, lo, hi, mid, axis);
        nd->axis = axis;
        nd->split = coord(t, t->idx[mid], axis);
        int l = t->num_nodes++, r = t->num_nodes++;
        nd->left = l;
        nd->right = r;
        t->nodes[l] = (kd_node){lo, mid, -1, 0.0f, -1, -1};
        t->nodes[r] = (kd_node){mid, hi, -1, 0.0f, -1, -1};
        stack[top++] = l; /* depth <= log2(n) < 64: two entries per level fit */
        stack[top++] = r;
    }
    free(stack);
    return 0;
}

/* A max-heap of the k smallest squared distances seen. */
typedef struct {
    float *d;
    int size, k;
} bounded_heap;

static void heap_offer(bounded_heap *h, float d) {
    if (h->size < h->k) {
        int i = h->size++;
        while (i > 0 && h->d[(i - 1) / 2] < d) {
            h->d[i] = h->d[(i - 1) / 2];
            i = (i - 1) / 2;
        }
        h->d[i] = d;
    } else if (d < h->d[0]) {
        int i = 0;
        for (;;) { /* sift the new value down from the root */
            int c = 2 * i + 1;
            if (c >= h->k) break;
            if (c + 1 < h->k && h->d[c + 1] > h->d[c]) c++;
            if (h->d[c] <= d) break;
            h->d[i] = h->d[c];
            i = c;
        }
        h->d[i] = d;
    }
}

static inline float heap_bound(const bounded_heap *h) { return h->size < h->k ? INFINITY : h->d[0]; }

static void query(const kd_tree *t, int self, bounded_heap *h, int *stack) {
    const float *q = &t->xyz[3 * self];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const kd_node *nd = &t->nodes[stack[--top]];
        if (nd->axis < 0) {
            for (int i = nd->lo; i < nd->hi; i++) {
                int j = t->idx[i];
                if (j == self) continue;
                const float *p = &t->xyz[3 * j];
                float dx = p[0] - q[0], dy = p[1] - q[1], dz = p[2] - q[2];
                heap_offer(h, dx * dx + dy * dy + dz * dz);
            }
            continue;
        }
        float diff = q[nd->axis] - nd->split;
        int near = diff < 0.0f ? nd->left : nd->right, far = diff < 0.0f ? nd->right : nd->left;
        /* The far side only when the splitting plane is strictly closer than the k-th best (a
         * tie cannot improve the heap, and pruning ties keeps identical points linear); pushed
         * first, so the near side is searched first and tightens the bound. */
        if (diff * diff < heap_bound(h)) stack[top++] = far;
        stack[top++] = near;
    }
}

int knn_distances(const vec3 *points, size_t stride, int n, int k, float *out) {
    if (n <= 0) return 0;
    kd_tree t = {0};
    int *finite_of = malloc(sizeof(int) * (size_t)n);
    t.xyz = malloc(sizeof(float) * 3 * (size_t)n);
    t.idx = malloc(sizeof(int) * (size_t)n);
    int m = 0;
    if (finite_of && t.xyz && t.idx) {
        for (int i = 0; i < n; i++) {
            vec3 p = *(const vec3 *)(const void *)((const char *)points + (size_t)i * stride);
            finite_of[i] = -1;
            if (!is_finite3(p)) continue;
            t.xyz[3 * m] = p.x;
            t.xyz[3 * m + 1] = p.y;
            t.xyz[3 * m + 2] = p.z;
            t.idx[m] = m;
            finite_of[i] = m++;
        }
    }
    int kk = k < m - 1 ? k : m - 1;
    float *heap = malloc(sizeof(float) * (size_t)(kk > 0 ? kk : 1));
    int *stack = malloc(sizeof(int) * 256);
    int status = -1;
    if (finite_of && t.xyz && t.idx && heap && stack && build(&t, m) == 0) {
        for (int i = 0; i < n; i++) {
            int self = finite_of[i];
            if (self < 0) {
                out[i] = INFINITY;
                continue;
            }
            if (kk <= 0) {
                out[i] = 0.0f;
                continue;
            }
            bounded_heap h = {heap, 0, kk};
            query(&t, self, &h, stack);
            out[i] = sqrtf(h.d[0]);
        }
        status = 0;
    }
    free(finite_of);
    free(t.xyz);
    free(t.idx);
    free(t.nodes);
    free(heap);
    free(stack);
    return status;
}
