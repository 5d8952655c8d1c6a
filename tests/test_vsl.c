/* Virtual spherical lights: the Eq. 5 integral estimator against brute force, its r -> 0 limit
 * (the VPL), the path-space split for the highlight estimator, robustness, and whole renders
 * against the path-traced reference. */
#include <stdlib.h>
#include <string.h>

#define PI_D 3.14159265358979323846

#include "check.h"
#include "manylight.h"
#include "test_scenes.h"
#include "vsl.h"

/* ---- hand-made configurations ---------------------------------------------------------------- */

static virtual_light make_vl(vec3 p, vec3 n, vec3 toward_source, bsdf b, float radius, int depth) {
    virtual_light vl;
    memset(&vl, 0, sizeof vl);
    vl.p = p;
    vl.ng = normalize3(n);
    vl.frame = frame_from_normal(vl.ng);
    vl.wi = to_local(vl.frame, normalize3(toward_source));
    vl.b = b;
    vl.power = v3s(1.0f);
    vl.radius = radius;
    vl.depth = depth;
    return vl;
}

static shading_point make_x(vec3 p, vec3 n, vec3 toward_viewer, bsdf b) {
    shading_point x;
    x.p = p;
    x.ng = normalize3(n);
    x.frame = frame_from_normal(x.ng);
    x.b = b;
    x.wo = to_local(x.frame, normalize3(toward_viewer));
    return x;
}

static double avg(vec3 c) { return ((double)c.x + (double)c.y + (double)c.z) / 3.0; }

/* The integral over the light's disk by midpoint quadrature over its area (polar, uniform in the
 * squared radius and the angle), in double: each point's integrand times the solid angle its area
 * spans from x, cos_j dA / t^2. Independent of the estimator's solid-angle sampling. */
static double quadrature_omega(const virtual_light *vl, const shading_point *x, int nt, int np) {
    double sum = 0.0, r = vl->radius;
    frame3 plane = frame_from_normal(vl->ng);
    for (int i = 0; i < nt; i++) {
        double rho = r * sqrt((i + 0.5) / nt);
        for (int j = 0; j < np; j++) {
            double phi = 2.0 * PI_D * (j + 0.5) / np;
            vec3 y = add3(vl->p, to_world(plane, v3((float)(rho * cos(phi)), (float)(rho * sin(phi)), 0.0f)));
            vec3 d = sub3(y, x->p);
            double t2 = (double)length_sq3(d);
            if (!(t2 > 0.0)) continue;
            vec3 l = scale3(d, (float)(1.0 / sqrt(t2)));
            double cos_j = -(double)dot3(l, vl->ng);
            if (!(cos_j > 0.0)) continue;
            sum += avg(vsl_integrand(vl, x, VL_TERMS_ALL, l)) * cos_j / t2;
        }
    }
    return sum * PI_D * r * r / ((double)nt * np);
}

/* Brute force for razor-sharp lobes: plain importance sampling of one BSDF (no MIS, no cone
 * sampling), many samples. at_light picks the light's BSDF. Returns mean, *sem its error. */
static double single_strategy(const virtual_light *vl, const shading_point *x, int at_light, int n, double *sem) {
    rng_state rng = rng_make(99, 7);
    double s = 0.0, s2 = 0.0;
    for (int k = 0; k < n; k++) {
        const bsdf *b = at_light ? &vl->b : &x->b;
        bsdf_sample_result bs;
        double v = 0.0;
        float u_lobe = rng_float(&rng);
        vec2 u = rng_vec2(&rng);
        if (bsdf_sample(b, at_light ? vl->wi : x->wo, BSDF_ALL, u_lobe, u, &bs) && bs.pdf > 0.0f) {
            vec3 l = to_world(at_light ? vl->frame : x->frame, bs.wi);
            if (at_light) l = neg3(l);
            v = avg(vsl_integrand(vl, x, VL_TERMS_ALL, l)) / (double)bs.pdf;
        }
        s += v;
        s2 += v * v;
    }
    double mean = s / n;
    *sem = sqrt(fmax(s2 / n - mean * mean, 0.0) / n);
    return mean;
}

/* Whether estimate() asks for the three strategies everywhere (else the effect plan's choice). */
static int all_strategies = 1;

/* Mean of `runs` calls of vsl_integral and its standard error; checks every value is finite. */
static double estimate(const virtual_light *vl, const shading_point *x, int runs, double *sem, const char *name) {
    rng_state rng = rng_make(1234, 5);
    double s = 0.0, s2 = 0.0;
    int bad = 0;
    for (int k = 0; k < runs; k++) {
        vec3 c = vsl_integral(vl, x, VL_TERMS_ALL, all_strategies, &rng, NULL);
        bad += !is_finite3(c) || c.x < 0.0f || c.y < 0.0f || c.z < 0.0f;
        double v = avg(c);
        s += v;
        s2 += v * v;
    }
    CHECK(bad == 0, "%s: %d non-finite or negative estimates", name, bad);
    double mean = s / runs;
    *sem = sqrt(fmax(s2 / runs - mean * mean, 0.0) / runs);
    return mean;
}

static void agree(const char *name, double got, double got_sem, double want, double want_sem, double rel_quad) {
    double tol = 5.0 * sqrt(got_sem * got_sem + want_sem * want_sem) + rel_quad * fabs(want);
    CHECK(want > 0.0, "%s: the reference is zero: a configuration with nothing to test", name);
    CHECK_NEAR(got, want, tol, "%s (estimator sem %.3g, reference sem %.3g)", name, got_sem, want_sem);
}

static void test_integral_against_brute_force(void) {
    bsdf diffuse = make_bsdf_lambert(v3s(0.8f));
    bsdf phong = make_bsdf_phong(v3s(0.3f), v3s(0.6f), 50.0f);
    bsdf ward_aniso = make_bsdf_ward(v3s(0.1f), v3s(0.8f), 0.05f, 0.3f);
    bsdf mirror = make_bsdf_gltf(v3s(0.95f), 1.0f, 0.0f, 0.0f); /* GGX at the smallest alpha */
    bsdf phong_sharp = make_bsdf_phong(v3s(0.0f), v3s(0.9f), 1e4f);
    double sem, ref, ref_sem = 0.0;

    /* x inside the sphere, close above the disk: 100 samples each. */
    {
        virtual_light vl = make_vl(v3(0.3f, 0, 0.3f), v3(-1, 0, 0), v3(-1, 0, 1), diffuse, 1.0f, 2);
        shading_point x = make_x(v3(0, 0, 0), v3(0, 0, 1), v3(0, 0.3f, 1), phong);
        ref = quadrature_omega(&vl, &x, 600, 600);
        double got = estimate(&vl, &x, 4000, &sem, "inside");
        agree("inside", got, sem, ref, 0.0, 2e-3);
    }
    /* Touching: the sphere's surface just off x, the disk seen nearly edge-on. */
    {
        vec3 p = v3(0.8f, 0.0f, 0.6f);
        virtual_light vl = make_vl(p, v3(-1, 0, -0.2f), v3(-1, 0.5f, 0), phong, length3(p) / 1.0001f, 2);
        shading_point x = make_x(v3(0, 0, 0), v3(0, 0, 1), v3(-1, 0, 1), diffuse);
        ref = quadrature_omega(&vl, &x, 800, 800);
        double got = estimate(&vl, &x, 4000, &sem, "touching");
        agree("touching", got, sem, ref, 0.0, 2e-3);
    }
    /* Far away: r/d = 1e-3, a solid angle of ~3e-6 sr, one sample. */
    {
        virtual_light vl = make_vl(v3(6, 0, 8), v3(-0.6f, 0, -0.8f), v3(0, 0, -1), phong, 0.01f, 2);
        shading_point x = make_x(v3(0, 0, 0), v3(0, 0, 1), v3(-1, 0, 1), phong);
        ref = quadrature_omega(&vl, &x, 64, 64);
        double got = estimate(&vl, &x, 20000, &sem, "far");
        agree("far", got, sem, ref, 0.0, 2e-3);
    }
    /* Grazing at both ends, anisotropic Ward at the light lit at a grazing angle. */
    {
        virtual_light vl = make_vl(v3(5, 0, 0.15f), v3(-1, 0, 0.02f), v3(-0.03f, 1, 0), ward_aniso, 0.5f, 2);
        shading_point x = make_x(v3(0, 0, 0), v3(0, 0, 1), v3(-1, 0, 0.05f), diffuse);
        ref = quadrature_omega(&vl, &x, 800, 800);
        double got = estimate(&vl, &x, 20000, &sem, "grazing Ward");
        agree("grazing Ward at the light", got, sem, ref, 0.0, 3e-3);
    }
    /* Ward at x viewed at a grazing angle, the light ahead of the reflection. */
    {
        virtual_light vl = make_vl(v3(3, 0, 0.6f), v3(-1, 0, 0), v3(-1, 0, 1), diffuse, 0.9f, 2);
        shading_point x = make_x(v3(0, 0, 0), v3(0, 0, 1), v3(-1, 0, 0.03f), ward_aniso);
        ref = quadrature_omega(&vl, &x, 1000, 1000);
        double got = estimate(&vl, &x, 20000, &sem, "grazing Ward at x");
        agree("grazing Ward at x", got, sem, ref, 0.0, 3e-3);
    }
    /* A mirror at x reflecting the view into the sphere: brute force samples x's lobe. */
    {
        virtual_light vl = make_vl(v3(2, 0, 2), v3(-1, 0, -1), v3(0, 0, -1), diffuse, 0.5f, 2);
        shading_point x = make_x(v3(0, 0, 0), v3(0, 0, 1), v3(-1, 0, 1), mirror);
        ref = single_strategy(&vl, &x, 0, 400000, &ref_sem);
        double got = estimate(&vl, &x, 20000, &sem, "mirror at x");
        agree("mirror at x", got, sem, ref, ref_sem, 0.0);
    }
    /* A mirror at the light reflecting its incoming light toward x. */
    {
        virtual_light vl = make_vl(v3(2, 0, 2), v3(0, 0, -1), v3(1, 0, -1), mirror, 0.5f, 2);
        shading_point x = make_x(v3(0, 0, 0), v3(0, 0, 1), v3(-1, 0.2f, 1), diffuse);
        ref = single_strategy(&vl, &x, 1, 400000, &ref_sem);
        double got = estimate(&vl, &x, 20000, &sem, "mirror at the light");
        agree("mirror at the light", got, sem, ref, ref_sem, 0.0);
    }
    /* Phong exponent 1e4 at the light. */
    {
        virtual_light vl = make_vl(v3(2, 0, 2), v3(0, 0, -1), v3(1, 0, -1), phong_sharp, 0.5f, 2);
        shading_point x = make_x(v3(0, 0, 0), v3(0, 0, 1), v3(-1, 0.2f, 1), phong);
        ref = single_strategy(&vl, &x, 1, 400000, &ref_sem);
        double got = estimate(&vl, &x, 20000, &sem, "Phong 1e4");
        agree("Phong 1e4 at the light", got, sem, ref, ref_sem, 0.0);
    }
}

/* Pairs without a glossy lobe (Lambert, or GGX rough enough to count as diffuse) take points on
 * the disk and x's BSDF alone unless all strategies are asked for: both must match the quadrature. */
static void test_diffuse_kernel(void) {
    bsdf diffuse = make_bsdf_lambert(v3s(0.7f));
    bsdf rough = make_bsdf_gltf(v3(0.8f, 0.6f, 0.4f), 0.0f, 0.9f, 0.0f); /* alpha 0.81 */
    CHECK(!bsdf_highlight_lobe(&diffuse) && !bsdf_highlight_lobe(&rough), "the pair must count as diffuse");
    CHECK(bsdf_highlight_lobe(&(bsdf){.model = GLOSSY_GGX, .specular = v3s(0.04f), .alpha_x = 0.3f, .alpha_y = 0.3f}),
          "GGX at alpha 0.3 must count as glossy");
    for (int mode = 0; mode < 2; mode++) {
        all_strategies = mode;
        double sem, ref;
        char name[64];
        virtual_light vl = make_vl(v3(0.3f, 0, 0.3f), v3(-1, 0, 0), v3(-1, 0, 1), diffuse, 1.0f, 2);
        shading_point x = make_x(v3(0, 0, 0), v3(0, 0, 1), v3(0, 0.3f, 1), rough);
        ref = quadrature_omega(&vl, &x, 600, 600);
        snprintf(name, sizeof name, "diffuse pair inside, all strategies %d", mode);
        double got = estimate(&vl, &x, 4000, &sem, name);
        agree(name, got, sem, ref, 0.0, 2e-3);
        vl = make_vl(v3(2, 0.5f, 1.5f), v3(-1, 0, -0.5f), v3(0, 0, -1), rough, 0.6f, 2);
        x = make_x(v3(0, 0, 0), v3(0, 0, 1), v3(-1, 0.2f, 1), diffuse);
        ref = quadrature_omega(&vl, &x, 600, 600);
        snprintf(name, sizeof name, "diffuse pair outside, all strategies %d", mode);
        got = estimate(&vl, &x, 4000, &sem, name);
        agree(name, got, sem, ref, 0.0, 2e-3);
    }
    all_strategies = 1;
}

/* As the radius goes to zero the VSL becomes the (unclamped) VPL with the light's full BSDF. */
static void test_zero_radius_limit(void) {
    bsdf phong = make_bsdf_phong(v3s(0.4f), v3s(0.4f), 20.0f);
    bsdf ward = make_bsdf_ward(v3s(0.3f), v3s(0.5f), 0.2f, 0.3f);
    shading_point x = make_x(v3(0, 0, 0), v3(0, 0, 1), v3(-1, 0.3f, 1), phong);
    virtual_light vl = make_vl(v3(1.5f, 0.5f, 2), v3(-0.5f, 0, -1), v3(-1, 0, -1), ward, 0.0f, 2);
    vec3 vpl = vpl_contribution(&vl, &x, 1, VL_TERMS_ALL);
    double prev_err = INFINITY;
    for (float r = 0.1f; r >= 1e-4f; r *= 0.1f) {
        vl.radius = r;
        rng_state rng = rng_make(77, 1);
        double s = 0.0;
        int runs = 30000;
        for (int k = 0; k < runs; k++) s += avg(vsl_contribution(&vl, &x, VL_TERMS_ALL, 1, &rng, NULL));
        double err = fabs(s / runs - avg(vpl)) / avg(vpl);
        if (r < 2e-3f) CHECK(err < 0.02, "r = %g: VSL %.6g vs VPL %.6g", (double)r, s / runs, avg(vpl));
        prev_err = fmin(prev_err, err);
    }
    CHECK(prev_err < 0.02, "the VSL never approached the VPL (best relative error %.3g)", prev_err);
    vl.radius = 0.0f;
    rng_state rng = rng_make(1, 1);
    vec3 c = vsl_contribution(&vl, &x, VL_TERMS_ALL, 1, &rng, NULL);
    CHECK(avg(c) == avg(vpl), "r = 0 is the VPL exactly");
}

/* With highlights on, depth-1 lights drop glossy x glossy; the two parts add up to the whole. */
static void test_terms_split(void) {
    bsdf a = make_bsdf_phong(v3s(0.3f), v3s(0.5f), 80.0f);
    bsdf b = make_bsdf_gltf(v3(0.9f, 0.6f, 0.3f), 1.0f, 0.3f, 0.0f);
    shading_point x = make_x(v3(0, 0, 0), v3(0, 0, 1), v3(-1, 0.1f, 1), a);
    for (int depth = 1; depth <= 2; depth++) {
        virtual_light vl = make_vl(v3(1, 0, 1), v3(-1, 0, 0), v3(-1, 0.2f, 1), b, 0.4f, depth);
        double all = 0, split = 0, hl = 0;
        for (int k = 0; k < 2000; k++) {
            rng_state r1 = rng_make((uint64_t)k, 3), r2 = r1, r3 = r1;
            all += avg(vsl_contribution(&vl, &x, VL_TERMS_ALL, 1, &r1, NULL));
            split += avg(vsl_contribution(&vl, &x, VL_TERMS_NO_HIGHLIGHTS, 1, &r2, NULL));
            hl += avg(vsl_contribution(&vl, &x, VL_TERMS_HIGHLIGHTS, 1, &r3, NULL));
        }
        CHECK_NEAR(split + hl, all, 1e-4 * all, "depth %d: without + only highlights = all", depth);
        if (depth == 1)
            CHECK(hl > 0.05 * all, "depth 1: the glossy-glossy part is missing (%.3g of %.3g)", hl, all);
        else
            CHECK(hl == 0.0, "depth %d: lights past the first bounce have no highlight part", depth);
        /* The VPL kernels split the same way. */
        double v_all = avg(vpl_contribution(&vl, &x, 1, VL_TERMS_ALL));
        double v_split = avg(vpl_contribution(&vl, &x, 1, VL_TERMS_NO_HIGHLIGHTS)) +
                         avg(vpl_contribution(&vl, &x, 1, VL_TERMS_HIGHLIGHTS));
        CHECK_NEAR(v_split, v_all, 1e-5 * v_all, "VPL depth %d split", depth);
    }
}

/* Degenerate configurations: never NaN, Inf or negative. */
static void test_degenerate(void) {
    bsdf mats[4] = {make_bsdf_lambert(v3s(1.0f)), make_bsdf_phong(v3s(0.0f), v3s(1.0f), 1e6f),
                    make_bsdf_ward(v3s(0.0f), v3s(1.0f), 1e-3f, 1e-3f), make_bsdf_gltf(v3s(1.0f), 1.0f, 0.0f, 0.0f)};
    float dists[6] = {0.0f, 1e-7f, 1e-3f, 1.0f, 1e4f, 1e7f};
    float radii[5] = {1e-20f, 1e-6f, 1.0f, 1e3f, 1e20f};
    float tilts[4] = {0.0f, 1e-7f, 0.3f, 1.0f};
    rng_state rng = rng_make(5, 5);
    int bad = 0, total = 0;
    for (int m = 0; m < 16; m++)
        for (int di = 0; di < 6; di++)
            for (int ri = 0; ri < 5; ri++)
                for (int ti = 0; ti < 4; ti++) {
                    float d = dists[di], t = tilts[ti];
                    virtual_light vl = make_vl(v3(d, 0, d * t), v3(-1, 0, t), v3(-1, t, t), mats[m & 3], radii[ri], 1);
                    shading_point x = make_x(v3(0, 0, 0), v3(0, 0, 1), v3(1, 0, t), mats[m >> 2]);
                    vec3 c[3] = {vsl_contribution(&vl, &x, VL_TERMS_ALL, 1, &rng, NULL),
                                 vsl_contribution(&vl, &x, VL_TERMS_NO_HIGHLIGHTS, 1, &rng, NULL),
                                 vpl_contribution(&vl, &x, 1, VL_TERMS_ALL)};
                    for (int k = 0; k < 3; k++) {
                        total++;
                        if (!is_finite3(c[k]) || c[k].x < 0 || c[k].y < 0 || c[k].z < 0) {
                            if (bad++ < 5)
                                fprintf(stderr, "degenerate: mats %d d %g r %g tilt %g kernel %d -> %g %g %g\n", m,
                                        (double)d, (double)radii[ri], (double)t, k, (double)c[k].x, (double)c[k].y,
                                        (double)c[k].z);
                        }
                    }
                }
    CHECK(bad == 0, "%d of %d degenerate configurations gave NaN, Inf or negative values", bad, total);
}

/* Energy by a wall: a diffuse light on the floor at distance delta from a wall sends the wall half
 * its power (its cosine lobe, half of it toward the wall), whatever delta. Integrated over the wall
 * (a grid dense near the light), the VSL must deliver that within 6% for delta from 0.05 r to 2 r
 * (measured: within 2%, the disk's share in front of the wall carrying the part beyond it; the
 * sphere's cone gave 0.26 at 0.05 r and 0.36 at 0.5 r without a share, within 4% with one).
 * The point light on the same grid gives the quadrature's own error (its tail beyond the grid). */
static void test_energy_by_a_wall(void) {
    bsdf white = make_bsdf_lambert(v3s(1.0f));
    const float deltas[] = {0.05f, 0.25f, 0.5f, 1.0f, 2.0f};
    for (int k = 0; k < 5; k++) {
        float delta = deltas[k];
        virtual_light vl = make_vl(v3(0, 0, delta), v3(0, 1, 0), v3(0, 1, 0), white, 1.0f, 2);
        rng_state rng = rng_make(31, (uint64_t)k);
        /* the wall z = 0, y > 0, on a grid uniform in asinh(x / a), asinh(y / a) */
        const double a = 0.05, S = asinh(40.0 / a);
        const int nx = 160, ny = 80;
        double vsl = 0.0, vpl = 0.0;
        for (int i = 0; i < nx; i++)
            for (int j = 0; j < ny; j++) {
                double s = -S + (i + 0.5) * 2.0 * S / nx, t = (j + 0.5) * S / ny;
                double x = a * sinh(s), y = a * sinh(t), area = a * cosh(s) * a * cosh(t) * (2.0 * S / nx) * (S / ny);
                shading_point p = make_x(v3((float)x, (float)y, 0), v3(0, 0, 1), v3(0, 0, 1), white);
                double L = 0.0;
                for (int n = 0; n < 4; n++) L += avg(vsl_contribution(&vl, &p, VL_TERMS_ALL, 0, &rng, NULL));
                vsl += L / 4.0 * PI_D * area; /* irradiance from radiance off a white Lambert wall */
                double d2 = x * x + y * y + (double)delta * delta;
                vpl += y * delta / (PI_D * d2 * d2) * area;
            }
        printf("light at %.2f r from a wall: the wall receives %.4f of its power (point light on the grid %.4f)\n",
               (double)delta, vsl, vpl);
        CHECK(fabs(vsl / vpl - 1.0) < 0.06, "a light %.2f r from a wall sends it %.4f, the point light %.4f",
              (double)delta, vsl, vpl);
    }
}

/* Energy to a facing surface: a diffuse light on a plane sends all its power to a parallel plane
 * facing it at height h, whatever h. Integrating over the sphere's cone (the paper's Eq. 5, with a
 * front share for the sphere's part behind either plane) delivered 2.29 times that at h = 0.02 r
 * and 1.35 at 0.5 r (the Cornell box's ceiling over its lamp, 1 cm below it); the disk delivers it
 * within 1% (measured). Checked within 4%. */
static void test_energy_to_a_facing_plane(void) {
    bsdf white = make_bsdf_lambert(v3s(1.0f));
    const float heights[] = {0.02f, 0.1f, 0.5f, 2.0f};
    for (int k = 0; k < 4; k++) {
        float h = heights[k];
        virtual_light vl = make_vl(v3(0, 0, 0), v3(0, 0, 1), v3(0.3f, 0, 1), white, 1.0f, 2);
        rng_state rng = rng_make(37, (uint64_t)k);
        /* the plane z = h facing down, on a grid uniform in asinh(x / a), asinh(y / a) */
        const double a = 0.02, S = asinh(60.0 / a);
        const int n = 120;
        double vsl = 0.0, vpl = 0.0;
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n; j++) {
                double s = -S + (i + 0.5) * 2.0 * S / n, t = -S + (j + 0.5) * 2.0 * S / n;
                double x = a * sinh(s), y = a * sinh(t),
                       area = a * cosh(s) * a * cosh(t) * (2.0 * S / n) * (2.0 * S / n);
                shading_point p = make_x(v3((float)x, (float)y, h), v3(0, 0, -1), v3(0.1f, 0, -1), white);
                double L = 0.0;
                for (int m = 0; m < 4; m++) L += avg(vsl_contribution(&vl, &p, VL_TERMS_ALL, 0, &rng, NULL));
                vsl += L / 4.0 * PI_D * area;
                double d2 = x * x + y * y + (double)h * h;
                vpl += (double)h * h / (PI_D * d2 * d2) * area;
            }
        printf("light %.2f r below a facing plane: the plane receives %.4f of its power (point light %.4f)\n",
               (double)h, vsl, vpl);
        CHECK(fabs(vsl / vpl - 1.0) < 0.04, "a light %.2f r below a facing plane sends it %.4f, the point light %.4f",
              (double)h, vsl, vpl);
    }
}

/* ---- whole renders against the path tracer ----------------------------------------------------- */

/* A closed 2 m box, one material everywhere, a point light inside; the camera looks into a
 * corner so the image has the corners where VPLs darken and spike. */
static scene *closed_box(material m, vec3 light_pos) {
    scene *s = ts_new("closed box");
    int mat = ts_material(s, m);
    ts_box(s, v3(-1, -1, -1), v3(1, 1, 1), 1, mat);
    ts_point_light(s, light_pos);
    ts_finalize(s);
    return s;
}

static double rel_l2(const float *img, const float *ref, int n) {
    double e = 0, r = 0;
    for (int i = 0; i < 3 * n; i++) {
        e += ((double)img[i] - ref[i]) * ((double)img[i] - ref[i]);
        r += (double)ref[i] * ref[i];
    }
    return sqrt(e / r);
}

static double image_mean(const float *img, int n) {
    double m = 0;
    for (int i = 0; i < 3 * n; i++) m += img[i];
    return m / (3.0 * n);
}

static int all_finite(const float *img, int n) {
    for (int i = 0; i < 3 * n; i++)
        if (!isfinite(img[i])) return 0;
    return 1;
}

enum { W = 24, H = 18, NPIX = W * H };
static const unsigned INDIRECT = 1u << COMP_INDIRECT;

static camera box_camera(void) { return camera_look_at(v3(0.2f, 0.1f, 0.9f), v3(-1, -1, -1), v3(0, 1, 0), 1.2f); }

static render_params vl_params_for(render_method m, int count) {
    render_params p = {.width = W, .height = H, .method = m, .max_depth = 8, .seed = 11};
    p.vl.count = count;
    p.vl.per_pixel = -1;
    return p;
}

static void test_diffuse_box_against_pt(void) {
    material m = material_default();
    m.model = MATERIAL_PHONG;
    m.kd = v3s(0.6f);
    m.ks = v3s(0.0f);
    scene *s = closed_box(m, v3(0.3f, 0.5f, 0.2f));
    camera cam = box_camera();
    float *ref = ts_render(s, &cam, W, H, 2048, 8, 1, INDIRECT);
    /* 1024 lights a frame in a 2 m box: radii of a multiplier of 1 are already ~0.3 m. */
    render_params p = vl_params_for(METHOD_VSL, 1024);
    p.vl.radius_mult = 1.0f;
    float *vsl = ts_render_with(s, &cam, &p, 32, INDIRECT);
    double err = rel_l2(vsl, ref, NPIX), bias = image_mean(vsl, NPIX) / image_mean(ref, NPIX) - 1.0;
    printf("diffuse box: VSL relative L2 error %.4f, mean bias %+.4f\n", err, bias);
    /* Stated tolerance: 10% L2 and 6% in the mean. The radius blurs light over ~0.3 m and the
     * VSL approximation loses a little near corners (measured: -4%); the reference's noise is ~1%. */
    CHECK(err < 0.10, "diffuse box: VSL indirect differs from path tracing by %.3f (relative L2)", err);
    CHECK(fabs(bias) < 0.06, "diffuse box: VSL indirect mean is off by %+.3f", bias);
    CHECK(all_finite(vsl, NPIX), "diffuse box: non-finite pixels");

    /* Shrinking radii: a deliberately large radius is biased (half the light lost); shrinking it
     * over frames removes the bias, so the error keeps falling where the fixed radius stalls.
     * Lights are sampled per pixel to keep this cheap. */
    p = vl_params_for(METHOD_VSL, 256);
    p.vl.radius_mult = 4.0f;
    p.vl.per_pixel = 8;
    p.vl.radius_shrink = -1.0f;
    float *fixed = ts_render_with(s, &cam, &p, 256, INDIRECT);
    p.vl.radius_shrink = 0.3f;
    double errs[3];
    int frames[3] = {16, 64, 256};
    for (int k = 0; k < 3; k++) {
        float *img = ts_render_with(s, &cam, &p, frames[k], INDIRECT);
        errs[k] = rel_l2(img, ref, NPIX);
        free(img);
    }
    double err_fixed = rel_l2(fixed, ref, NPIX);
    printf("radius shrink: error %.4f, %.4f, %.4f after 16, 64, 256 frames; fixed radius %.4f\n", errs[0], errs[1],
           errs[2], err_fixed);
    CHECK(errs[1] < errs[0] && errs[2] < errs[1], "radius shrink: the error does not decrease (%.4f %.4f %.4f)",
          errs[0], errs[1], errs[2]);
    CHECK(errs[2] < 0.7 * err_fixed, "radius shrink: %.4f is not clearly below the fixed radius's %.4f", errs[2],
          err_fixed);
    free(fixed);
    free(vsl);
    free(ref);
    scene_destroy(s);
}

static void test_glossy_box_energy(void) {
    material m = material_default();
    m.model = MATERIAL_PHONG;
    m.kd = v3s(0.15f);
    m.ks = v3s(0.7f);
    m.exponent = 60.0f;
    scene *s = closed_box(m, v3(0.3f, 0.5f, 0.2f));
    camera cam = box_camera();
    float *ref = ts_render(s, &cam, W, H, 2048, 8, 2, INDIRECT);
    render_params p = vl_params_for(METHOD_VPL, 1024);
    p.vl.clamp_value = 0.1f;   /* a typical bound: below the brightest indirect radiance (~0.4) */
    p.vl.clamp_growth = -1.0f; /* the paper's baseline: a fixed bound */
    p.vl.trace_glossy = -1.0f; /* the paper's baseline: every lobe gathered */
    float *vpl = ts_render_with(s, &cam, &p, 16, INDIRECT);
    p = vl_params_for(METHOD_VSL, 1024);
    p.vl.radius_mult = 1.0f;
    p.vl.trace_glossy = -1.0f; /* the VSL kernel itself gathers the glossy lobes, as in the paper */
    float *vsl = ts_render_with(s, &cam, &p, 16, INDIRECT);
    double r = image_mean(ref, NPIX), a = image_mean(vpl, NPIX) / r, b = image_mean(vsl, NPIX) / r;
    printf("glossy box: indirect energy vs path tracing: clamped VPL %.3f, VSL %.3f; L2 error VPL %.3f, VSL %.3f\n", a,
           b, rel_l2(vpl, ref, NPIX), rel_l2(vsl, ref, NPIX));
    /* Measured: clamped VPLs keep ~22%, VSLs ~92%. */
    CHECK(a < 0.5, "clamped VPLs kept %.3f of the indirect energy: the clamp should cost energy here", a);
    CHECK(b > 0.85 && b < 1.1, "VSLs recovered %.3f of the indirect energy", b);
    CHECK(rel_l2(vsl, ref, NPIX) < rel_l2(vpl, ref, NPIX), "VSL is not closer to the reference than clamped VPL");
    free(ref);
    free(vpl);
    free(vsl);
    scene_destroy(s);
}

/* The glTF layers as the many-light methods treat them: the sheen gathered with the diffuse lobe,
 * a sharp clear coat traced (with the base's glossy lobe under it), a coated secondary hit lit
 * through its own BSDF by the highlights. In a closed box of velvet under a clear coat, vsl and
 * vsl+hl reach the path tracer's indirect light (for vsl+hl with its highlights). */
static void test_layered_box_against_pt(void) {
    material m = material_default();
    m.base_color = v3(0.5f, 0.3f, 0.2f);
    m.metallic = 0.0f;
    m.roughness = 0.7f;
    m.ext.sheen_color = v3(0.3f, 0.5f, 0.9f);
    m.ext.sheen_roughness = 0.4f;
    m.ext.clearcoat = 1.0f;
    m.ext.clearcoat_roughness = 0.2f; /* alpha 0.04: sharp, traced and a highlight lobe */
    scene *s = closed_box(m, v3(0.3f, 0.5f, 0.2f));
    camera cam = box_camera();
    const unsigned hl = 1u << COMP_HIGHLIGHTS;
    float *ref = ts_render(s, &cam, W, H, 2048, 8, 3, INDIRECT);
    for (int method = METHOD_VSL; method <= METHOD_VSL_HL; method++) {
        render_params p = vl_params_for((render_method)method, 1024);
        p.vl.radius_mult = 1.0f;
        p.vl.per_pixel = 32; /* resampled: the layered lobes cost more than Phong's to shade */
        float *img = ts_render_with(s, &cam, &p, 64, INDIRECT | hl);
        double ratio = image_mean(img, NPIX) / image_mean(ref, NPIX), err = rel_l2(img, ref, NPIX);
        printf("layered box, %s: indirect mean ratio to PT %.4f, relative L2 %.4f\n", method_name(p.method), ratio,
               err);
        /* the diffuse box's tolerances: the VSLs' radius costs a few percent near the corners */
        CHECK(fabs(ratio - 1.0) < 0.06, "layered box, %s: indirect mean off by %+.4f", method_name(p.method),
              ratio - 1.0);
        CHECK(err < 0.12, "layered box, %s: relative L2 %.4f", method_name(p.method), err);
        CHECK(all_finite(img, NPIX), "layered box, %s: non-finite pixels", method_name(p.method));
        free(img);
    }
    free(ref);
    scene_destroy(s);
}

/* Per-pixel light selection is unbiased: with the same light sets (same seed, so every frame
 * traces the same lights), sampling a few lights per pixel, by power or through the light tree,
 * shaded as drawn or resampled from candidates, averages to the sum over every light; for VSLs
 * resampling and the tree get there with less noise than drawing by power. */
static void test_light_selection_unbiased(void) {
    material m = material_default();
    m.model = MATERIAL_PHONG;
    m.kd = v3s(0.3f);
    m.ks = v3s(0.6f);
    m.exponent = 80.0f;
    scene *s = closed_box(m, v3(0.3f, 0.5f, 0.2f));
    camera cam = box_camera();
    static const struct {
        const char *name;
        int select, candidates;
    } ways[] = {{"by power", VL_SELECT_POWER, 1},
                {"resampled from power draws", VL_SELECT_POWER, 16},
                {"through the tree", VL_SELECT_TREE, 1},
                {"resampled from tree draws", VL_SELECT_TREE, 8}};
    for (int method = METHOD_VPL; method <= METHOD_VSL; method++) {
        const int frames = 128;
        render_params p = vl_params_for((render_method)method, 256);
        p.vl.clamp = VL_CLAMP_OFF;
        p.vl.trace_glossy = -1.0f; /* every lobe gathered: the selection is all that differs */
        float *all = ts_render_with(s, &cam, &p, frames, INDIRECT);
        double ma = image_mean(all, NPIX), e_power = 0.0;
        p.vl.per_pixel = 2;
        for (int w = 0; w < 4; w++) {
            p.vl.select = ways[w].select;
            p.vl.candidates = ways[w].candidates;
            float *img = ts_render_with(s, &cam, &p, frames, INDIRECT);
            double ratio = image_mean(img, NPIX) / ma, e = rel_l2(img, all, NPIX);
            printf("light selection, %s, %s: mean ratio %.4f, L2 to the exhaustive sum %.3f\n", method_name(p.method),
                   ways[w].name, ratio, e);
            /* The mean over the image carries the noise of a few hundred correlated pixels: unclamped
             * VPLs drawn by power leave ~0.46 relative L2, about 2% on the mean. */
            CHECK_NEAR(ratio, 1.0, fmax(0.03, 3.0 * e / sqrt((double)NPIX)), "%s: selection %s is biased",
                       method_name(p.method), ways[w].name);
            if (w == 0) e_power = e;
            /* For VPLs the noise is their 1/d^2 spikes, which no estimate of a light's share fixes. */
            else if (method == METHOD_VSL)
                CHECK(e < 0.8 * e_power, "%s: %s is no less noisy than by power (%.3f vs %.3f)", method_name(p.method),
                      ways[w].name, e, e_power);
            free(img);
        }
        free(all);
    }
    scene_destroy(s);
}

/* Receivers whose glossy lobe is sharper than --trace-glossy are traced through, not gathered.
 * In a box of purely glossy walls below the threshold nothing is ever gathered, so the
 * many-light methods' indirect light is path tracing through the lobes with direct light at each
 * next hit: it must match the path tracer's within noise, at several depths. With the threshold
 * below the walls' roughness, no path is continued and the light comes from the virtual lights. */
static void test_trace_glossy_matches_pt(void) {
    material m = material_default();
    m.model = MATERIAL_PHONG;
    m.kd = v3s(0.0f);
    m.ks = v3s(0.8f);
    m.exponent = 30.0f; /* alpha 0.13: broad enough that a few bright pixels do not make the mean */
    camera cam = box_camera();
    /* The point light's box; then the same walls lit by an emissive panel under the ceiling, whose
     * emission the traced paths hit and must leave to the direct estimator. */
    scene *boxes[2] = {closed_box(m, v3(0.3f, 0.5f, 0.2f)), ts_new("glossy box with a panel light")};
    ts_box(boxes[1], v3(-1, -1, -1), v3(1, 1, 1), 1, ts_material(boxes[1], m));
    ts_quad(boxes[1], v3(-0.3f, 0.98f, -0.3f), v3(0.3f, 0.98f, -0.3f), v3(0.3f, 0.98f, 0.3f), v3(-0.3f, 0.98f, 0.3f),
            ts_lambert(boxes[1], v3s(0.0f), v3s(4.0f), 0));
    ts_finalize(boxes[1]);
    int depths[2] = {2, 5};
    for (int k = 0; k < 2; k++) {
        const scene *s = boxes[k];
        const int frames = 1024;
        float *ref = ts_render(s, &cam, W, H, 4 * frames, depths[k], 5, INDIRECT);
        float *pt = ts_render(s, &cam, W, H, frames, depths[k], 6, INDIRECT);
        render_params p = vl_params_for(METHOD_VSL, 64);
        p.max_depth = depths[k];
        p.vl.trace_glossy = 0.3f;
        p.vl.regularize = -1.0f; /* exactly the path tracer's paths */
        p.vl.reg_image = -1.0f;
        char err[256];
        render_session *rs = session_create(s, &cam, &p, err, sizeof err);
        for (int f = 0; f < frames; f++) session_render_frame(rs);
        float *traced = malloc(sizeof(float) * 3 * NPIX);
        film_resolve(session_film(rs), INDIRECT, traced);
        render_stats st = session_stats(rs);
        session_destroy(rs);
        double ratio = image_mean(traced, NPIX) / image_mean(ref, NPIX);
        double e_traced = rel_l2(traced, ref, NPIX), e_pt = rel_l2(pt, ref, NPIX);
        printf("traced glossy box %d, depth %d: mean ratio to PT %.4f, L2 %.4f (an equal PT render: %.4f, %.4f), %llu "
               "bounces\n",
               k, depths[k], ratio, e_traced, image_mean(pt, NPIX) / image_mean(ref, NPIX), e_pt,
               (unsigned long long)st.glossy_bounces);
        CHECK(fabs(ratio - 1.0) < 0.03, "depth %d: traced glossy indirect mean off by %+.4f", depths[k], ratio - 1.0);
        CHECK(e_traced < 1.5 * e_pt + 0.01, "depth %d: traced glossy indirect L2 %.4f vs path tracing's %.4f",
              depths[k], e_traced, e_pt);
        CHECK(st.glossy_bounces >= (uint64_t)(0.95 * frames * NPIX), "depth %d: only %llu glossy bounces", depths[k],
              (unsigned long long)st.glossy_bounces);
        CHECK(st.vl_connections == 0, "depth %d: %llu virtual lights shaded where nothing is gathered", depths[k],
              (unsigned long long)st.vl_connections);
        free(ref);
        free(pt);
        free(traced);
    }
    render_params p = vl_params_for(METHOD_VSL, 64);
    p.vl.trace_glossy = 0.1f; /* below the walls' alpha: gathered */
    char err[256];
    render_session *rs = session_create(boxes[0], &cam, &p, err, sizeof err);
    session_render_frame(rs);
    render_stats st = session_stats(rs);
    CHECK(st.glossy_bounces == 0 && st.vl_connections > 0, "lobes above the threshold: %llu bounces, %llu connections",
          (unsigned long long)st.glossy_bounces, (unsigned long long)st.vl_connections);
    session_destroy(rs);
    scene_destroy(boxes[0]);
    scene_destroy(boxes[1]);
}

/* --regularize widens sharp lobes only at a hit lit past two traced lobes. In a box of glossy walls
 * traced through, paths of two scattering events (camera hit, next hit, light) take no widened
 * lobe: with a floor far above the walls' roughness the image is the same, bit for bit, as without.
 * Three events widen the third hit's lobes, so the image changes, and its mean stays within a few
 * per cent of the unwidened render's (widening blurs, it does not absorb). */
static void test_regularize_past_two_lobes(void) {
    material m = material_default();
    m.model = MATERIAL_PHONG;
    m.kd = v3s(0.0f);
    m.ks = v3s(0.8f);
    m.exponent = 300.0f; /* alpha 0.04 */
    scene *s = closed_box(m, v3(0.3f, 0.5f, 0.2f));
    camera cam = box_camera();
    const int frames = 256;
    for (int depth = 2; depth <= 3; depth++) {
        float *img[2];
        for (int k = 0; k < 2; k++) {
            render_params p = vl_params_for(METHOD_VSL, 64);
            p.max_depth = depth;
            p.vl.trace_glossy = 0.3f;
            p.vl.regularize = k ? 0.5f : -1.0f;
            p.vl.reg_image = -1.0f;     /* the chains' floor alone */
            p.vl.radius_shrink = -1.0f; /* the floor stays at 0.5 */
            char err[256];
            render_session *rs = session_create(s, &cam, &p, err, sizeof err);
            for (int f = 0; f < frames; f++) session_render_frame(rs);
            img[k] = malloc(sizeof(float) * 3 * NPIX);
            film_resolve(session_film(rs), INDIRECT, img[k]);
            session_destroy(rs);
        }
        int same = memcmp(img[0], img[1], sizeof(float) * 3 * NPIX) == 0;
        double ratio = image_mean(img[1], NPIX) / image_mean(img[0], NPIX);
        printf("regularised glossy box, depth %d: %s, mean ratio %.4f\n", depth, same ? "same" : "changed", ratio);
        if (depth == 2) CHECK(same, "two events: the regularised image differs (mean ratio %.4f)", ratio);
        if (depth == 3) {
            CHECK(!same, "three events: regularisation changed nothing");
            CHECK(fabs(ratio - 1.0) < 0.05, "three events: regularised mean off by %+.4f", ratio - 1.0);
        }
        free(img[0]);
        free(img[1]);
    }
    scene_destroy(s);
}

/* A zero-thickness divider splits a closed box; the light is above it, the camera below. No
 * light can reach the lower half, so its indirect light is exactly zero (the path tracer's is);
 * virtual lights on the divider's upper side, in the same plane as the points below, must not
 * leak through it, nor may lights whose spheres reach across. */
static void test_no_leak_through_thin_walls(void) {
    material m = material_default();
    m.model = MATERIAL_PHONG;
    m.kd = v3s(0.7f);
    m.ks = v3s(0.0f);
    scene *s = ts_new("divided box");
    int mat = ts_material(s, m);
    ts_box(s, v3(-1, -1, -1), v3(1, 1, 1), 1, mat);
    /* the divider: one quad, lit on its upper side, seen on its lower side */
    ts_quad(s, v3(-1, 0, -1), v3(1, 0, -1), v3(1, 0, 1), v3(-1, 0, 1), mat);
    ts_point_light(s, v3(0.2f, 0.5f, 0.1f));
    ts_finalize(s);
    camera cam = camera_look_at(v3(0.3f, -0.8f, 0.8f), v3(-0.5f, 0.0f, -0.5f), v3(0, 1, 0), 1.3f);
    for (int method = METHOD_VPL; method <= METHOD_VSL; method++) {
        render_params p = vl_params_for((render_method)method, 512);
        p.vl.clamp = VL_CLAMP_OFF;
        p.vl.radius_mult = 4.0f; /* spheres that reach well across the divider */
        float *img = ts_render_with(s, &cam, &p, 8, INDIRECT);
        int lit = 0;
        for (int i = 0; i < 3 * NPIX; i++) lit += img[i] != 0.0f;
        CHECK(lit == 0, "%s: %d pixel channels below the divider got light through it", method_name(p.method), lit);
        free(img);
    }
    float *pt = ts_render(s, &cam, W, H, 64, 8, 1, INDIRECT);
    int lit = 0;
    for (int i = 0; i < 3 * NPIX; i++) lit += pt[i] != 0.0f;
    CHECK(lit == 0, "path tracing: %d channels below the divider lit (the scene is not closed)", lit);
    free(pt);
    scene_destroy(s);
}

/* A point light on a wall and one a micrometre off it: 500 frames of 32 lights each, for each
 * method and way of treating sharp lobes, nothing non-finite. */
static void test_lights_touching_surfaces(void) {
    material m = material_default();
    m.model = MATERIAL_PHONG;
    m.kd = v3s(0.5f);
    m.ks = v3s(0.4f);
    m.exponent = 500.0f;
    vec3 spots[2] = {v3(0.2f, -1.0f, 0.1f), v3(-0.999999f, 0.2f, 0.1f)};
    for (int k = 0; k < 2; k++) {
        scene *s = closed_box(m, spots[k]);
        camera cam = box_camera();
        for (int run = 0; run < 4; run++) { /* vpl, vsl; sharp lobes traced through, then gathered */
            render_params p = {
                .width = 8, .height = 6, .method = (render_method)(METHOD_VPL + run / 2), .max_depth = 6, .seed = 3};
            p.vl.trace_glossy = run % 2 ? -1.0f : 0.0f;
            p.vl.count = 32;
            p.vl.per_pixel = 4;
            p.vl.clamp = VL_CLAMP_OFF;
            char err[256];
            render_session *rs = session_create(s, &cam, &p, err, sizeof err);
            for (int f = 0; f < 500; f++) session_render_frame(rs);
            float img[8 * 6 * 3];
            film_resolve(session_film(rs), COMP_MASK_ALL, img);
            render_stats st = session_stats(rs);
            CHECK(st.rejected_samples == 0, "light %d, %s, run %d: %llu samples were NaN or Inf", k,
                  method_name(p.method), run, (unsigned long long)st.rejected_samples);
            CHECK(all_finite(img, 48), "light %d, %s, run %d: non-finite pixels", k, method_name(p.method), run);
            CHECK(st.virtual_lights >= 500u * 32u, "light %d: virtual_lights_total %llu", k,
                  (unsigned long long)st.virtual_lights);
            session_destroy(rs);
        }
        scene_destroy(s);
    }
}

/* Numbers far above what a frame has: --per-pixel above its light or cluster count shades every
 * light (the same image as "all", not a million picks), --rows above its pixel count samples every
 * pixel once (the same clusters as rows = pixels). */
static void test_counts_beyond_the_frame(void) {
    material m = material_default();
    scene *s = closed_box(m, v3(0.3f, 0.5f, -0.2f));
    camera cam = box_camera();
    const struct {
        const char *what;
        int per_pixel, rows, columns, ref_per_pixel, ref_rows;
    } cases[] = {
        {"--per-pixel 1000000 of 64 lights", 1000000, 0, 0, -1, 0},
        {"--per-pixel 1000000 of 16 clusters", 1000000, 0, 16, -1, 0},
        {"--rows 100000 of 432 pixels", 0, 100000, 16, 0, NPIX},
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        render_params p = vl_params_for(METHOD_VSL, 64), q;
        p.vl.columns = cases[c].columns;
        q = p;
        p.vl.per_pixel = cases[c].per_pixel;
        p.vl.rows = cases[c].rows;
        q.vl.per_pixel = cases[c].ref_per_pixel;
        q.vl.rows = cases[c].ref_rows;
        float *a = ts_render_with(s, &cam, &p, 2, ~0u), *b = ts_render_with(s, &cam, &q, 2, ~0u);
        CHECK(memcmp(a, b, sizeof(float) * 3 * NPIX) == 0 && all_finite(a, NPIX),
              "%s: not the image of every light / every pixel (rel. L2 %g)", cases[c].what, rel_l2(a, b, NPIX));
        free(a);
        free(b);
    }
    scene_destroy(s);
}

int main(void) {
    test_integral_against_brute_force();
    test_diffuse_kernel();
    test_zero_radius_limit();
    test_terms_split();
    test_degenerate();
    test_energy_by_a_wall();
    test_energy_to_a_facing_plane();
    test_diffuse_box_against_pt();
    test_glossy_box_energy();
    test_layered_box_against_pt();
    test_light_selection_unbiased();
    test_trace_glossy_matches_pt();
    test_regularize_past_two_lobes();
    test_no_leak_through_thin_walls();
    test_lights_touching_surfaces();
    test_counts_beyond_the_frame();
    return check_exit("test_vsl");
}
