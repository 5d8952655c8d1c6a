/* The light tree: its probabilities form a distribution, draws follow it (chi-square), every
 * light that can send something to a point can be drawn there (so sampling is unbiased for the
 * frame's light set), and on a real frame's lights the one-light estimator's variance, computed
 * exactly over all lights, is far below drawing by power; so is that of drawing in proportion to
 * the tree's per-light estimates, which resampling approaches. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "lighttree.h"
#include "rng.h"
#include "stat_tests.h"
#include "test_scenes.h"
#include "vlights.h"

static vec3 random_unit(rng_state *rng) {
    for (;;) {
        vec3 v = v3(2.0f * rng_float(rng) - 1.0f, 2.0f * rng_float(rng) - 1.0f, 2.0f * rng_float(rng) - 1.0f);
        float l = length3(v);
        if (l > 0.1f && l <= 1.0f) return scale3(v, 1.0f / l);
    }
}

static bsdf random_bsdf(rng_state *rng) {
    float kind = rng_float(rng);
    if (kind < 0.35f) return make_bsdf_lambert(v3s(0.2f + 0.6f * rng_float(rng)));
    if (kind < 0.7f)
        return make_bsdf_phong(v3s(0.2f * rng_float(rng)), v3s(0.7f), powf(10.0f, 1.0f + 3.0f * rng_float(rng)));
    return make_bsdf_gltf(v3(0.9f, 0.8f, 0.6f), 1.0f, 0.05f + 0.6f * rng_float(rng), 0.0f);
}

/* n lights in a unit box, random normals and materials, arriving from random directions above
 * their surfaces; every `dup`-th one a copy of the one before (coincident lights). */
static void random_lights(vlight_set *set, int n, int dup, float radius, rng_state *rng) {
    set->v = calloc((size_t)n, sizeof(virtual_light));
    set->count = set->cap = n;
    for (int i = 0; i < n; i++) {
        virtual_light *vl = &set->v[i];
        if (dup && i > 0 && i % dup == 0) {
            *vl = set->v[i - 1];
            continue;
        }
        vl->p = v3(rng_float(rng), rng_float(rng), rng_float(rng));
        vl->ng = random_unit(rng);
        vl->frame = frame_from_normal(vl->ng);
        vec3 wi = random_unit(rng);
        vl->wi = v3(wi.x, wi.y, fabsf(wi.z) + 0.05f);
        vl->wi = normalize3(vl->wi);
        vl->b = random_bsdf(rng);
        vl->power = v3s(0.01f + rng_float(rng));
        vl->radius = radius * (0.5f + rng_float(rng));
        vl->depth = 1 + (i % 3);
    }
}

static shading_point random_receiver(rng_state *rng) {
    shading_point x;
    x.p = v3(-0.5f + 2.0f * rng_float(rng), -0.5f + 2.0f * rng_float(rng), -0.5f + 2.0f * rng_float(rng));
    x.ng = random_unit(rng);
    x.frame = frame_from_normal(x.ng);
    x.b = random_bsdf(rng);
    vec3 wo = random_unit(rng);
    x.wo = normalize3(v3(wo.x, wo.y, fabsf(wo.z) + 0.05f));
    return x;
}

/* What shade_one could get from the light before visibility: its zero tests, then the kernel. */
static int can_contribute(const virtual_light *vl, const shading_point *x) {
    vec3 dir = sub3(vl->p, x->p);
    if (!(dot3(dir, x->ng) > 0.0f) || !(dot3(dir, vl->ng) < 0.0f)) return 0;
    rng_state rng = rng_for(1, 2, 3);
    for (int k = 0; k < 8; k++)
        if (!is_black3(vsl_contribution(vl, x, VL_TERMS_ALL, 1, &rng, NULL))) return 1;
    return 0;
}

static void test_distribution(void) {
    rng_state rng = rng_for(7, 0, 0);
    int sizes[] = {1, 2, 3, 17, 256, 1000};
    for (int si = 0; si < 6; si++) {
        vlight_set set = {0};
        random_lights(&set, sizes[si], si == 4 ? 5 : 0, 0.03f, &rng);
        lighttree t = {0};
        CHECK(lighttree_build(&t, &set) == 0, "build of %d lights failed", sizes[si]);
        int missed = 0, receivers = 0;
        double worst_sum = 0.0, lost = 0.0;
        for (int q = 0; q < 40; q++) {
            shading_point x = random_receiver(&rng);
            lt_receiver r = lighttree_receiver(&x, 1e-6f);
            double sum = 0.0;
            int any = 0;
            for (int j = 0; j < set.count; j++) {
                float p = lighttree_pmf(&t, &r, j);
                CHECK(p >= 0.0f && isfinite(p), "pmf %g", (double)p);
                /* The one-light shortcut resampling uses is the general estimate on a leaf. */
                float general = lighttree_importance(&t.nodes[t.leaf_of[j]], &r);
                CHECK_NEAR(lighttree_light_importance(&t.leaves[j], &r), general, 1e-5 * general + 1e-30,
                           "the one-light estimate differs from the general one");
                sum += p;
                if (can_contribute(&set.v[j], &x)) {
                    any = 1;
                    if (!(p > 0.0f)) missed++;
                }
            }
            /* A node can promise light its children cannot give (bounds of a group are looser than
             * each half's): that mass draws nothing. Never more than one in total. */
            worst_sum = fmax(worst_sum, sum - 1.0);
            if (any) {
                receivers++;
                lost += 1.0 - sum;
            }
            /* A draw returns a light with the probability lighttree_pmf gives it. */
            for (int k = 0; k < 8; k++) {
                float pmf;
                int j = lighttree_sample(&t, &r, rng_float(&rng), &pmf);
                if (j < 0) continue;
                CHECK(j < set.count, "light %d of %d", j, set.count);
                CHECK_NEAR(pmf, lighttree_pmf(&t, &r, j), 1e-4 * pmf + 1e-9, "sample and pmf disagree");
            }
        }
        printf("tree of %d lights: %d receivers lit, mean probability of drawing nothing %.3f, %d lights that can "
               "light a point but cannot be drawn\n",
               sizes[si], receivers, receivers ? lost / receivers : 0.0, missed);
        CHECK(worst_sum < 1e-4, "the probabilities sum to more than 1 (%g over)", worst_sum);
        CHECK(missed == 0, "%d lights could light a point the tree never draws them for", missed);
        lighttree_free(&t);
        vlight_set_free(&set);
    }
}

/* Draws follow the probabilities: chi-square over the lights of one tree for a few receivers. */
static void test_draws_follow_pmf(void) {
    rng_state rng = rng_for(11, 0, 0);
    vlight_set set = {0};
    random_lights(&set, 64, 0, 0.05f, &rng);
    lighttree t = {0};
    lighttree_build(&t, &set);
    double alpha = chi2_significance(0.001, 4);
    for (int q = 0; q < 4; q++) {
        shading_point x = random_receiver(&rng);
        lt_receiver r = lighttree_receiver(&x, 1e-6f);
        /* bin 64: nothing drawn */
        double observed[65] = {0}, expected[65], sum = 0.0;
        const long draws = 200000;
        for (long k = 0; k < draws; k++) {
            float pmf;
            int j = lighttree_sample(&t, &r, rng_float(&rng), &pmf);
            observed[j >= 0 ? j : 64] += 1.0;
        }
        for (int j = 0; j < 64; j++) sum += expected[j] = (double)draws * lighttree_pmf(&t, &r, j);
        expected[64] = fmax((double)draws - sum, 0.0);
        chi2_result res = chi2_counts(observed, expected, 65);
        printf("draws for receiver %d: chi2 %.1f, dof %d, p %.3g\n", q, res.chi2, res.dof, res.p_value);
        CHECK(res.p_value > alpha, "draws do not follow the tree's probabilities (p = %g)", res.p_value);
    }
    lighttree_free(&t);
    vlight_set_free(&set);
}

/* A room lit through a glossy reflector: the lights of a real frame, the receivers the room's own
 * surfaces. The variance of the one-light estimator contribution / pmf is computed exactly over
 * all lights (each light's VSL contribution by many integration samples, no visibility): the
 * tree must beat drawing by power by far. */
static double vsl_mean(const virtual_light *vl, const shading_point *x, rng_state *rng) {
    vec3 dir = sub3(vl->p, x->p);
    if (!(dot3(dir, x->ng) > 0.0f) || !(dot3(dir, vl->ng) < 0.0f)) return 0.0; /* as shade_one */
    double sum = 0.0;
    for (int k = 0; k < 4; k++) sum += avg3(vsl_contribution(vl, x, VL_TERMS_ALL, 1, rng, NULL));
    return sum / 4.0;
}

static void test_variance_against_power(void) {
    scene *s = ts_new("glossy room");
    int white = ts_lambert(s, v3s(0.7f), v3s(0.0f), 0);
    ts_box(s, v3(-1, 0, -1), v3(1, 1.2f, 1), 1, white);
    material plate = ts_phong(v3s(0.02f), v3s(0.9f), 300.0f);
    ts_quad(s, v3(-0.3f, 1.19f, 0.3f), v3(0.3f, 1.19f, 0.3f), v3(0.3f, 1.19f, -0.3f), v3(-0.3f, 1.19f, -0.3f),
            ts_material(s, plate));
    light spot = {.type = LIGHT_POINT, .color = v3s(3.0f), .position = v3(0.2f, 0.6f, 0.1f)};
    scene_add_light(s, &spot);
    ts_finalize(s);
    vlight_set set = {0};
    uint64_t rays = 0;
    vlights_trace(s, 1024, 4, 3, 0, &set, &rays);
    vlights_set_radii(&set, 1.0f, s->diag);
    lighttree t = {0};
    lighttree_build(&t, &set);
    double *power = malloc(sizeof(double) * (size_t)set.count), total_power = 0.0;
    for (int j = 0; j < set.count; j++) total_power += power[j] = luminance3(set.v[j].power);
    rng_state rng = rng_for(5, 0, 0);
    double var_tree = 0.0, var_power = 0.0, var_leaf = 0.0;
    int points = 0;
    for (int q = 0; q < 60; q++) {
        /* a point on a wall, the floor or the ceiling, facing in */
        int face = q % 3;
        vec3 n = face == 0 ? v3(0, 1, 0) : face == 1 ? v3(0, -1, 0) : v3(1, 0, 0);
        vec3 p = face == 0   ? v3(2 * rng_float(&rng) - 1, 0, 2 * rng_float(&rng) - 1)
                 : face == 1 ? v3(2 * rng_float(&rng) - 1, 1.2f, 2 * rng_float(&rng) - 1)
                             : v3(-1, 1.2f * rng_float(&rng), 2 * rng_float(&rng) - 1);
        shading_point x = {.p = p, .ng = n, .frame = frame_from_normal(n), .b = make_bsdf_lambert(v3s(0.7f))};
        x.wo = v3(0, 0, 1);
        lt_receiver r = lighttree_receiver(&x, 1e-6f);
        double sum = 0.0, m2_tree = 0.0, m2_power = 0.0, m2_leaf = 0.0, leaf_sum = 0.0;
        for (int j = 0; j < set.count; j++) leaf_sum += lighttree_light_importance(&t.leaves[j], &r);
        for (int j = 0; j < set.count; j++) {
            double c = vsl_mean(&set.v[j], &x, &rng);
            if (!(c > 0.0)) continue;
            double pt = lighttree_pmf(&t, &r, j), pp = power[j] / total_power;
            sum += c;
            m2_tree += c * c / pt;
            m2_power += c * c / pp;
            m2_leaf += c * c / (lighttree_light_importance(&t.leaves[j], &r) / leaf_sum);
        }
        if (!(sum > 0.0)) continue;
        points++;
        var_tree += (m2_tree - sum * sum) / (sum * sum);
        var_power += (m2_power - sum * sum) / (sum * sum);
        var_leaf += (m2_leaf - sum * sum) / (sum * sum);
    }
    printf("relative variance of one light's estimate over %d points: tree %.3g, power %.3g (%.1fx), in proportion to "
           "the per-light estimates %.3g\n",
           points, var_tree / points, var_power / points, var_power / var_tree, var_leaf / points);
    CHECK(var_leaf < 0.25 * var_power, "the per-light estimates do not beat power by far (%.3g vs %.3g)",
          var_leaf / points, var_power / points);
    CHECK(var_tree < 0.4 * var_power, "the tree does not beat drawing by power (%.3g vs %.3g)", var_tree / points,
          var_power / points);
    free(power);
    lighttree_free(&t);
    vlight_set_free(&set);
    scene_destroy(s);
}

int main(void) {
    test_distribution();
    test_draws_follow_pmf();
    test_variance_against_power();
    return check_exit("test_lighttree");
}
