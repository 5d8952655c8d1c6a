#include "lighttree.h"

#include <stdlib.h>
#include <string.h>

#include "vmf.h"

/* A glossy lobe's value never drops below this in the importance (per steradian, per unit of
 * reflected power): the vMF stand-in falls off far faster than GGX's tails, and a light drawn with
 * a vanishing probability for a point its tail does reach is a firefly. */
#define LT_LOBE_FLOOR 0.01f

void lighttree_free(lighttree *t) {
    free(t->nodes);
    free(t->leaf_of);
    free(t->order);
    free(t->keys);
    free(t->leaves);
    memset(t, 0, sizeof *t);
}

/* ---- cones of directions ------------------------------------------------------------------- */

typedef struct {
    vec3 axis;
    float theta; /* half-angle in [0, pi]; < 0: empty */
} cone;

static cone cone_union(cone a, cone b) {
    if (a.theta < 0.0f) return b;
    if (b.theta < 0.0f) return a;
    float between = acosf(clampf(dot3(a.axis, b.axis), -1.0f, 1.0f));
    if (fminf(between + b.theta, PI_F) <= a.theta) return a;
    if (fminf(between + a.theta, PI_F) <= b.theta) return b;
    float theta = 0.5f * (a.theta + between + b.theta);
    vec3 w = cross3(a.axis, b.axis);
    float wl = length3(w);
    if (theta >= PI_F || !(wl > 1e-7f))
        return (cone){a.axis, theta >= PI_F || dot3(a.axis, b.axis) < 0.0f ? PI_F : theta};
    /* Turn a's axis toward b's by what the half-angle grew (Rodrigues, w perpendicular to it). */
    float turn = theta - a.theta;
    vec3 axis = add3(scale3(a.axis, cosf(turn)), scale3(cross3(scale3(w, 1.0f / wl), a.axis), sinf(turn)));
    return (cone){normalize3(axis), theta};
}

static void set_cone(vec3 *axis, float *c, float *s, cone k) {
    *axis = k.axis;
    *c = k.theta < 0.0f ? 1.0f : cosf(k.theta);
    *s = k.theta < 0.0f ? 0.0f : fmaxf(sinf(k.theta), 0.0f); /* sinf(PI_F) is slightly negative */
}

static cone get_cone(vec3 axis, float c, float s) { return (cone){axis, atan2f(fmaxf(s, 0.0f), c)}; }

/* ---- importance ---------------------------------------------------------------------------- */

/* The importance runs some 20 times per light drawn: no libm calls in it. */
static inline float maxf(float a, float b) { return a > b ? a : b; }

/* e^x for x <= 0 to about 1e-4 relative (0 below -80): a power of two from the exponent bits
 * times a polynomial for the fraction. */
static inline float exp_neg(float x) {
    if (!(x > -80.0f)) return 0.0f;
    float t = x * 1.44269504f;
    float fl = (float)(int)t;
    if (fl > t) fl -= 1.0f;
    float f = t - fl;
    float p = 1.0f + f * (0.69314718f + f * (0.24022651f + f * (0.05550411f + f * (0.00961813f + f * 0.00133336f))));
    union {
        float f;
        int32_t i;
    } u = {p};
    u.i += (int32_t)fl * (1 << 23);
    return u.f;
}

/* cos(max(0, theta - delta)) from cos theta and delta's cos and sin, without trigonometry. */
static inline float cos_minus_clamped(float cos_theta, float cos_delta, float sin_delta) {
    if (cos_theta >= cos_delta) return 1.0f;
    return cos_theta * cos_delta + sqrtf(maxf(1.0f - cos_theta * cos_theta, 0.0f)) * sin_delta;
}

/* The cos and sin of the sum of two angles in [0, pi], saturating at pi. */
static inline void angle_sum(float c1, float s1, float c2, float s2, float *c, float *s) {
    *c = c1 * c2 - s1 * s2;
    *s = s1 * c2 + c1 * s2;
    if (*s < 0.0f || (*s == 0.0f && c1 + c2 < 0.0f)) *c = -1.0f, *s = 0.0f;
}

static inline float vmf_peak(float kappa) {
    if (kappa > 8.0f) return kappa * INV_2PI_F; /* e^{-2 kappa} below 1e-7 */
    return kappa < 1e-3f ? INV_4PI_F : kappa * INV_2PI_F / (1.0f - exp_neg(-2.0f * kappa));
}

/* What a glossy lobe (a vMF of concentration kappa) sends toward a direction at cos_angle from
 * its axis when the axis and the direction are only known to within angles whose 1 - cos add up
 * to blur: the lobe widened by the blur (vMF widths add as 1 / kappa), so a group of sharp lobes
 * spread over a cone gets their energy over that cone, not the peak of the best aligned one (a
 * peak would hand the whole group its probability), and falls off smoothly outside. Never below
 * LT_LOBE_FLOOR: the vMF stand-in falls off far faster than GGX's tails, and a light drawn with a
 * vanishing probability for a point its tail does reach is a firefly. */
static inline float lobe_estimate(float kappa, float blur, float cos_angle) {
    float k = 1.0f / (1.0f / maxf(kappa, 1e-6f) + blur);
    return maxf(vmf_peak(k) * exp_neg(-k * (1.0f - cos_angle)), LT_LOBE_FLOOR);
}

/* The cos and sin of the angle under which a ball of radius `reach` is seen from distance^2
 * dist2 (pi from inside it). */
static inline void ball_angle(float reach, float dist2, float *c, float *s) {
    *c = -1.0f, *s = 0.0f;
    if (dist2 > reach * reach) {
        float s2 = reach * reach / dist2;
        *s = sqrtf(s2);
        *c = sqrtf(1.0f - s2);
    }
}

/* The largest of dot(corner - p, n) over the box's corners. */
static inline float box_plane_max(vec3 centre, vec3 extent, vec3 p, vec3 n) {
    return dot3(sub3(centre, p), n) + extent.x * fabsf(n.x) + extent.y * fabsf(n.y) + extent.z * fabsf(n.z);
}

float lighttree_importance(const lt_node *n, const lt_receiver *r) {
    /* Exact plane tests first: a group lying in (or behind) the receiver's plane, or a group of
     * one orientation with the receiver in (or behind) its plane, sends nothing (within eps of a
     * plane is in it, as for shade_one, whose offsets cannot tell the sides apart); the cone bounds
     * below cannot see that for flat groups, and their children would all say zero (the draw
     * would then come back empty). */
    if (!(box_plane_max(n->centre, n->extent, r->p, r->ng) > r->eps)) return 0.0f;
    vec3 d = sub3(n->centre, r->p);
    float dist2 = length_sq3(d), dist = sqrtf(dist2), half_diag = sqrtf(n->half_diag2);
    /* In front of light j's plane means dot(x - p_j, n_j) > 0, and with n_j within the cone that
     * is at most dot(x - p_j, axis) + |x - p_j| sin(cone). */
    if (n->n_cos > 0.0f &&
        !(box_plane_max(n->centre, n->extent, r->p, neg3(n->n_axis)) + (dist + half_diag) * n->n_sin > r->eps))
        return 0.0f;
    vec3 dir = dist > 0.0f ? scale3(d, 1.0f / dist) : r->ng;
    /* Two angles bound how far any light's direction strays from dir: that of the ball holding the
     * centres, and that of the ball holding the spheres. The centres decide where nothing can
     * arrive: shade_one drops a light whose centre is behind (or in) either surface. The spheres
     * widen what does arrive: a VSL's disk straddling a horizon still sends part of its light. */
    float cos_c, sin_c, cos_b, sin_b, cos_r, sin_r;
    ball_angle(half_diag, dist2, &cos_c, &sin_c);
    ball_angle(half_diag + n->radius, dist2, &cos_b, &sin_b);
    float cx = dot3(r->ng, dir);
    float cos_x = cos_minus_clamped(cx, cos_c, sin_c);
    if (!(cos_x > 0.0f)) return 0.0f; /* every centre behind the receiver's surface */
    cos_x = 0.5f * (cos_x + cos_minus_clamped(cx, cos_b, sin_b));
    float c, s;
    angle_sum(n->n_cos, n->n_sin, cos_c, sin_c, &c, &s);
    float ce = -dot3(n->n_axis, dir);
    float cos_e = cos_minus_clamped(ce, c, s);
    if (!(cos_e > 0.0f)) return 0.0f; /* the receiver behind every light's surface */
    angle_sum(n->n_cos, n->n_sin, cos_b, sin_b, &c, &s);
    cos_e = 0.5f * (cos_e + cos_minus_clamped(ce, c, s));
    float emit = n->phi_diffuse * cos_e * INV_PI_F;
    /* The lobes: blurred by how much their axes differ, by the spheres (the VSL integral averages
     * a lobe over the light's disk) and by where in the group the light sits. */
    ball_angle(n->radius, dist2, &cos_r, &sin_r);
    float blur = 0.5f * ((1.0f - cos_r) + (1.0f - cos_c));
    if (n->phi_glossy > 0.0f)
        emit += n->phi_glossy * lobe_estimate(n->kappa, blur + 0.5f * (1.0f - n->g_cos), -dot3(n->g_axis, dir));
    float recv = r->diffuse * cos_x;
    if (r->glossy > 0.0f) recv += r->glossy * lobe_estimate(r->kappa, blur, dot3(r->g_axis, dir));
    /* Near a node (or inside a sphere) the estimate stops growing, as the VSL kernel does. */
    float dist2_clamped = maxf(maxf(dist2, n->half_diag2), maxf(n->radius * n->radius, 1e-20f));
    float v = emit * recv / dist2_clamped;
    return v < 1e30f ? v : (v > 0.0f ? 1e30f : 0.0f);
}

float lighttree_light_importance(const lt_node *leaf, const lt_receiver *r) {
    /* lighttree_importance for a node of one light, where the box and the cones collapse: the same
     * value, at a fraction of the cost (it runs for every resampling candidate). */
    vec3 d = sub3(leaf->centre, r->p);
    if (!(dot3(d, r->ng) > r->eps) || !(-dot3(d, leaf->n_axis) > r->eps)) return 0.0f;
    float dist2 = length_sq3(d), inv = 1.0f / sqrtf(dist2);
    vec3 dir = scale3(d, inv);
    float cos_r = -1.0f, sin_r = 0.0f;
    ball_angle(leaf->radius, dist2, &cos_r, &sin_r);
    float cx = dot3(r->ng, dir), ce = -dot3(leaf->n_axis, dir);
    float cos_x = 0.5f * (cx + cos_minus_clamped(cx, cos_r, sin_r));
    float cos_e = 0.5f * (ce + cos_minus_clamped(ce, cos_r, sin_r));
    float blur = 0.5f * (1.0f - cos_r);
    float emit = leaf->phi_diffuse * cos_e * INV_PI_F;
    if (leaf->phi_glossy > 0.0f) emit += leaf->phi_glossy * lobe_estimate(leaf->kappa, blur, -dot3(leaf->g_axis, dir));
    float recv = r->diffuse * cos_x;
    if (r->glossy > 0.0f) recv += r->glossy * lobe_estimate(r->kappa, blur, dot3(r->g_axis, dir));
    float v = emit * recv / maxf(maxf(dist2, leaf->radius * leaf->radius), 1e-20f);
    return v < 1e30f ? v : 1e30f;
}

lt_receiver lighttree_receiver(const shading_point *x, float eps) {
    lt_receiver r = {0};
    r.eps = eps;
    r.p = x->p;
    r.ng = x->ng;
    r.diffuse = luminance3(bsdf_diffuse_albedo(&x->b, x->wo)) * INV_PI_F; /* the sheen's too: no false zero */
    vmf lobe;
    vec3 albedo;
    if (vmf_fit_glossy(&x->b, x->wo, &lobe, &albedo)) {
        r.glossy = luminance3(albedo);
        r.g_axis = normalize3(to_world(x->frame, lobe.mu));
        r.kappa = lobe.kappa;
    }
    return r;
}

/* ---- sampling ------------------------------------------------------------------------------ */

int lighttree_sample(const lighttree *t, const lt_receiver *r, float u, float *pmf) {
    if (t->num_lights == 0) return -1;
    const lt_node *nodes = t->nodes;
    int n = 0;
    float p = 1.0f;
    while (nodes[n].child >= 0) {
        int c = nodes[n].child;
        float a = lighttree_importance(&nodes[c], r), b = lighttree_importance(&nodes[c + 1], r);
        float sum = a + b;
        if (!(sum > 0.0f)) return -1;
        float pa = a / sum, pb = b / sum;
        if (u < pa) {
            n = c;
            p *= pa;
            u /= pa;
        } else {
            n = c + 1;
            p *= pb;
            u = (u - pa) / pb;
        }
        u = clampf(u, 0.0f, 0x1.fffffep-1f); /* reused below: rounding must keep it in [0,1) */
    }
    *pmf = p;
    return -1 - nodes[n].child;
}

float lighttree_pmf(const lighttree *t, const lt_receiver *r, int index) {
    if (index < 0 || index >= t->num_lights) return 0.0f;
    float p = 1.0f;
    for (int n = t->leaf_of[index]; t->nodes[n].parent >= 0; n = t->nodes[n].parent) {
        int c = t->nodes[t->nodes[n].parent].child;
        float a = lighttree_importance(&t->nodes[c], r), b = lighttree_importance(&t->nodes[c + 1], r);
        if (!(a + b > 0.0f)) return 0.0f;
        p *= lighttree_importance(&t->nodes[n], r) / (a + b);
    }
    return p;
}

/* ---- building ------------------------------------------------------------------------------ */

static void set_box(lt_node *n, vec3 lo, vec3 hi) {
    n->centre = scale3(add3(lo, hi), 0.5f);
    n->extent = scale3(sub3(hi, lo), 0.5f);
    n->half_diag2 = length_sq3(n->extent);
}

static lt_node leaf_of_light(const virtual_light *vl, int index) {
    lt_node n;
    memset(&n, 0, sizeof n);
    set_box(&n, vl->p, vl->p);
    n.radius = vl->radius;
    n.phi_diffuse = luminance3(mul3(vl->power, bsdf_diffuse_albedo(&vl->b, vl->wi)));
    set_cone(&n.n_axis, &n.n_cos, &n.n_sin, (cone){vl->ng, 0.0f});
    set_cone(&n.g_axis, &n.g_cos, &n.g_sin, (cone){vl->ng, -1.0f});
    vmf lobe;
    vec3 albedo;
    if (vmf_fit_glossy(&vl->b, vl->wi, &lobe, &albedo)) {
        n.phi_glossy = luminance3(mul3(vl->power, albedo));
        set_cone(&n.g_axis, &n.g_cos, &n.g_sin, (cone){normalize3(to_world(vl->frame, lobe.mu)), 0.0f});
        n.kappa = lobe.kappa;
    }
    if (!(n.phi_diffuse >= 0.0f) || !isfinite(n.phi_diffuse)) n.phi_diffuse = 0.0f;
    if (!(n.phi_glossy >= 0.0f) || !isfinite(n.phi_glossy)) n.phi_glossy = 0.0f;
    n.child = -1 - index;
    return n;
}

static void merge_children(lt_node *n, const lt_node *a, const lt_node *b) {
    set_box(n, min3(sub3(a->centre, a->extent), sub3(b->centre, b->extent)),
            max3(add3(a->centre, a->extent), add3(b->centre, b->extent)));
    n->radius = fmaxf(a->radius, b->radius);
    n->phi_diffuse = a->phi_diffuse + b->phi_diffuse;
    n->phi_glossy = a->phi_glossy + b->phi_glossy;
    set_cone(&n->n_axis, &n->n_cos, &n->n_sin,
             cone_union(get_cone(a->n_axis, a->n_cos, a->n_sin), get_cone(b->n_axis, b->n_cos, b->n_sin)));
    cone ga = a->phi_glossy > 0.0f ? get_cone(a->g_axis, a->g_cos, a->g_sin) : (cone){a->g_axis, -1.0f};
    cone gb = b->phi_glossy > 0.0f ? get_cone(b->g_axis, b->g_cos, b->g_sin) : (cone){b->g_axis, -1.0f};
    set_cone(&n->g_axis, &n->g_cos, &n->g_sin, cone_union(ga, gb));
    n->kappa = fmaxf(a->phi_glossy > 0.0f ? a->kappa : 0.0f, b->phi_glossy > 0.0f ? b->kappa : 0.0f);
}

/* Where a light is for the split: its position, its normal, and its glossy lobe's mirror direction
 * scaled by the share of its reflected power the lobe carries (zero for a diffuse light). */
#define LT_KEYS 9

/* Puts order[lo..hi) in the order that has the element of rank `mid` (by key k) at mid, smaller
 * keys before it and larger after (quickselect, median of three). */
static void select_median(int *order, int lo, int hi, int mid, const float *keys, int k) {
#define KEY(i) keys[(size_t)order[i] * LT_KEYS + (size_t)k]
    while (hi - lo > 2) {
        int m = lo + (hi - lo) / 2;
        float a = KEY(lo), b = KEY(m), c = KEY(hi - 1);
        float pivot = a < b ? (b < c ? b : (a < c ? c : a)) : (a < c ? a : (b < c ? c : b));
        int i = lo, j = hi - 1;
        while (i <= j) {
            while (KEY(i) < pivot) i++;
            while (KEY(j) > pivot) j--;
            if (i <= j) {
                int tmp = order[i];
                order[i++] = order[j];
                order[j--] = tmp;
            }
        }
        if (mid <= j)
            hi = j + 1;
        else if (mid >= i)
            lo = i;
        else
            return;
    }
    if (hi - lo == 2 && KEY(lo) > KEY(lo + 1)) {
        int tmp = order[lo];
        order[lo] = order[lo + 1];
        order[lo + 1] = tmp;
    }
#undef KEY
}

/* Node `at` over order[lo..hi): split at the median of the widest dimension. Positions count in
 * metres; normals by a quarter of the node's size (lights facing apart in a corner part early);
 * mirror directions by a fixed share of the whole tree's size (angle_scale): a sharp lobe reaches
 * far, so glossy lights group partly by where their lobes go, which for lights lit from nearby
 * differs even between neighbours. The share was measured (test scenes' exact one-draw variance:
 * 0.15 beats 0, 0.05, 0.5 and 1). */
#define LT_ANGLE_SCALE 0.15f
static void build_node(lighttree *t, const float *keys, const lt_node *leaves, float angle_scale, int at, int lo,
                       int hi, int parent) {
    if (hi - lo == 1) {
        t->nodes[at] = leaves[t->order[lo]];
        t->nodes[at].parent = parent;
        t->leaf_of[t->order[lo]] = at;
        return;
    }
    float klo[LT_KEYS], khi[LT_KEYS];
    for (int k = 0; k < LT_KEYS; k++) klo[k] = INFINITY, khi[k] = -INFINITY;
    for (int i = lo; i < hi; i++) {
        const float *key = keys + (size_t)t->order[i] * LT_KEYS;
        for (int k = 0; k < LT_KEYS; k++) klo[k] = fminf(klo[k], key[k]), khi[k] = fmaxf(khi[k], key[k]);
    }
    float size = fmaxf(khi[0] - klo[0], fmaxf(khi[1] - klo[1], khi[2] - klo[2]));
    int best_k = 0;
    float best = -1.0f;
    for (int k = 0; k < LT_KEYS; k++) {
        float e = (khi[k] - klo[k]) * (k < 3 ? 1.0f : k < 6 ? 0.25f * size : angle_scale);
        if (e > best) best = e, best_k = k;
    }
    int mid = lo + (hi - lo) / 2;
    select_median(t->order, lo, hi, mid, keys, best_k);
    int c = t->num_nodes;
    t->num_nodes += 2;
    build_node(t, keys, leaves, angle_scale, c, lo, mid, at);
    build_node(t, keys, leaves, angle_scale, c + 1, mid, hi, at);
    merge_children(&t->nodes[at], &t->nodes[c], &t->nodes[c + 1]);
    t->nodes[at].child = c;
    t->nodes[at].parent = parent;
}

int lighttree_build(lighttree *t, const vlight_set *set) {
    int n = set->count;
    t->num_lights = 0;
    t->num_nodes = 0;
    if (n <= 0) return 0;
    if (n > t->cap_lights) {
        int *leaf = realloc(t->leaf_of, sizeof(int) * (size_t)n);
        if (!leaf) return -1;
        t->leaf_of = leaf;
        int *order = realloc(t->order, sizeof(int) * (size_t)n);
        if (!order) return -1;
        t->order = order;
        float *keys = realloc(t->keys, sizeof(float) * LT_KEYS * (size_t)n);
        if (!keys) return -1;
        t->keys = keys;
        lt_node *leaves = realloc(t->leaves, sizeof(lt_node) * (size_t)n);
        if (!leaves) return -1;
        t->leaves = leaves;
        t->cap_lights = n;
    }
    if (2 * n - 1 > t->cap_nodes) {
        lt_node *nodes = realloc(t->nodes, sizeof(lt_node) * (size_t)(2 * n - 1));
        if (!nodes) return -1;
        t->nodes = nodes;
        t->cap_nodes = 2 * n - 1;
    }
    bounds3 all = bounds_empty();
    for (int i = 0; i < n; i++) {
        const lt_node *leaf = &t->leaves[i];
        t->leaves[i] = leaf_of_light(&set->v[i], i);
        t->order[i] = i;
        all = bounds_add(all, leaf->centre);
        float glossy = leaf->phi_glossy > 0.0f ? leaf->phi_glossy / (leaf->phi_glossy + leaf->phi_diffuse) : 0.0f;
        float *key = t->keys + (size_t)i * LT_KEYS;
        for (int k = 0; k < 3; k++) {
            key[k] = comp3(leaf->centre, k);
            key[3 + k] = comp3(leaf->n_axis, k);
            key[6 + k] = glossy * comp3(leaf->g_axis, k);
        }
    }
    t->num_nodes = 1;
    build_node(t, t->keys, t->leaves, LT_ANGLE_SCALE * bounds_diagonal(all), 0, 0, n, -1);
    t->num_lights = n;
    return 0;
}
