/* The transmission lobe (KHR_materials_transmission, docs/design.md "Transmission and volume"):
 * sampling matches the pdf over the whole sphere (chi-square), sampled f and pdf are eval's,
 * energy is conserved for light arriving from either side (the adjoint, with eta^2), a smooth
 * dielectric loses nothing and reflects Fresnel's ((1 - ior) / (1 + ior))^2 at normal incidence
 * (through material_layers, from the material's ior), the BTDF obeys the generalised
 * reciprocity f(wo, wi) / n(wo)^2 = f(wi, wo) / n(wi)^2, total internal reflection, and the traps
 * (grazing, roughness 0, ior 1) stay finite. */
#include <stdlib.h>

#include "bsdf.h"
#include "bsdf_sampler.h"
#include "check.h"
#include "rng.h"
#include "scene.h"
#include "stat_tests.h"

#define PI_D 3.14159265358979323846

static vec3 dir_from_angles(double theta_deg, double phi_deg) {
    double t = theta_deg * PI_D / 180.0, p = phi_deg * PI_D / 180.0;
    return normalize3(v3((float)(sin(t) * cos(p)), (float)(sin(t) * sin(p)), (float)cos(t)));
}

/* A glTF dielectric with transmission t, seen from the side where the index below over the index
 * above is eta (1: thin-walled), with optional layers. */
static bsdf glass(vec3 base, float rough, float t, float eta, gltf_layers x) {
    x.transmission = t;
    x.eta = eta;
    return make_bsdf_gltf_layered(base, 0.0f, rough, 0.0f, &x);
}

static gltf_layers ior_layers(float ior) {
    gltf_layers x = gltf_layers_default();
    float r = (ior - 1.0f) / (ior + 1.0f);
    x.dielectric_f0 = v3s(r * r);
    return x;
}

/* Reflected and transmitted energy for light arriving from wo, by sampling: the adjoint weights
 * f(wi, wo) |cos| / pdf. Mean and standard error of their sum in *sem. */
static void energy(const bsdf *b, vec3 wo, int n, uint64_t seed, double *refl, double *trans, double *sem) {
    rng_state rng = rng_make(seed, 7);
    double r = 0, t = 0, s2 = 0;
    for (int k = 0; k < n; k++) {
        bsdf_sample_result s;
        if (!bsdf_sample(b, wo, BSDF_ALL, rng_float(&rng), rng_vec2(&rng), &s)) continue;
        double w = avg3(s.f) * fabs(s.wi.z) / s.pdf * bsdf_adjoint_scale(b, wo, s.wi);
        if (s.wi.z > 0)
            r += w;
        else
            t += w;
        s2 += w * w;
    }
    *refl = r / n;
    *trans = t / n;
    double mean = *refl + *trans;
    *sem = sqrt(fmax(s2 / n - mean * mean, 0.0) / n);
}

static void test_sampling_matches_pdf(void) {
    gltf_layers coat = ior_layers(1.5f);
    coat.clearcoat = 0.6f;
    coat.clearcoat_roughness = 0.5f;
    coat.sheen_color = v3(0.3f, 0.2f, 0.1f);
    coat.sheen_roughness = 0.5f;
    struct {
        const char *name;
        bsdf b;
    } mats[] = {
        {"rough glass entering", glass(v3s(1.0f), 0.6f, 1.0f, 1.5f, ior_layers(1.5f))},
        {"rough glass leaving", glass(v3s(1.0f), 0.5f, 1.0f, 1.0f / 1.5f, ior_layers(1.5f))},
        {"thin rough, half diffuse", glass(v3(0.9f, 0.6f, 0.3f), 0.5f, 0.5f, 1.0f, ior_layers(1.5f))},
        {"coated, sheen, entering ior 2", glass(v3(0.8f, 0.9f, 1.0f), 0.7f, 0.8f, 2.0f, coat)},
    };
    const double angles[][2] = {{5.0, 0.0}, {40.0, 70.0}, {75.0, 200.0}};
    int n = (int)(sizeof mats / sizeof mats[0]);
    double significance = chi2_significance(0.01, n * 3);
    for (int m = 0; m < n; m++)
        for (int a = 0; a < 3; a++) {
            vec3 wo = dir_from_angles(angles[a][0], angles[a][1]);
            bsdf_ctx c = {&mats[m].b, wo};
            /* the bins crowd around the unbent transmitted direction */
            chi2_result r = chi2_directions(sample_fn, pdf_fn, &c, neg3(wo), 48, 64, 150000, (uint64_t)(m * 7 + a));
            CHECK(r.non_finite == 0, "%s at %g deg: %d non-finite samples", mats[m].name, angles[a][0], r.non_finite);
            CHECK(r.outside_support == 0, "%s at %g deg: %d samples where the pdf is 0", mats[m].name, angles[a][0],
                  r.outside_support);
            CHECK(r.p_value > significance, "%s at %g deg: chi2 %.1f, dof %d, p %.3g", mats[m].name, angles[a][0],
                  r.chi2, r.dof, r.p_value);
            CHECK_NEAR(r.produced, r.pdf_integral, 5e-3, "%s at %g deg: draws producing a sample vs pdf integral",
                       mats[m].name, angles[a][0]);
            /* A sample's f and pdf are eval's and pdf's. */
            rng_state rng = rng_make((uint64_t)m, (uint64_t)a);
            int mismatch = 0, bad = 0;
            for (int k = 0; k < 5000; k++) {
                bsdf_sample_result s;
                if (!bsdf_sample(&mats[m].b, wo, BSDF_ALL, rng_float(&rng), rng_vec2(&rng), &s)) continue;
                vec3 f = bsdf_eval(&mats[m].b, wo, s.wi, BSDF_ALL);
                mismatch += max_comp3(sub3(f, s.f)) != 0.0f || bsdf_pdf(&mats[m].b, wo, s.wi, BSDF_ALL) != s.pdf;
                mismatch += (s.lobe == BSDF_TRANSMIT) != (s.wi.z < 0.0f);
                bad += !is_finite3(s.f) || !isfinite(s.pdf);
            }
            CHECK(mismatch == 0 && bad == 0, "%s: %d samples disagree with eval/pdf, %d non-finite", mats[m].name,
                  mismatch, bad);
        }
}

/* A GGX lobe's single-scattering albedo with F = 1 (isotropic, alpha), by quadrature in double from
 * the papers' D and height-correlated G2, no code shared with bsdf.c: a thin-walled non-absorbing
 * dielectric reflects F and transmits 1 - F of the same microfacets, so its total is this. */
static double ggx_albedo_f1(double alpha, vec3 wo) {
    double a2 = alpha * alpha, sum = 0.0;
    int n = 400;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            double z = (i + 0.5) / n, phi = 2.0 * PI_D * (j + 0.5) / n, r = sqrt(1.0 - z * z);
            double wi[3] = {r * cos(phi), r * sin(phi), z}, h[3] = {wo.x + wi[0], wo.y + wi[1], wo.z + wi[2]};
            double hz = h[2] / sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
            double t = (1.0 - hz * hz) / a2 + hz * hz, d = 1.0 / (PI_D * a2 * t * t);
            double so = sqrt(wo.z * wo.z + a2 * (1.0 - wo.z * wo.z)), si = sqrt(z * z + a2 * (1.0 - z * z));
            sum += d * 0.5 / (z * so + wo.z * si) * z; /* D G2 / (4 zo zi) cos */
        }
    return sum * 2.0 * PI_D / ((double)n * n);
}

/* Light arriving from either side of a non-absorbing dielectric is reflected or transmitted,
 * never more: smooth, nothing is lost; thin-walled, exactly the microfacets' single scattering;
 * rough and refracting, single scattering loses more (microfacets that reflect totally inside). */
static void test_energy(void) {
    float roughs[] = {0.0f, 0.3f, 0.7f};
    float etas[] = {1.5f, 1.0f / 1.5f, 1.0f};
    for (int r = 0; r < 3; r++)
        for (int e = 0; e < 3; e++)
            for (int a = 0; a < 4; a++) {
                bsdf b = glass(v3s(1.0f), roughs[r], 1.0f, etas[e], ior_layers(1.5f));
                vec3 wo = dir_from_angles(5.0 + 25.0 * a, 30.0);
                double refl, trans, sem;
                energy(&b, wo, 100000, (uint64_t)(100 * r + 10 * e + a), &refl, &trans, &sem);
                double total = refl + trans;
                CHECK(total <= 1.0 + 4.0 * sem + 1e-3, "rough %.1f eta %.3f at %d deg: albedo %.4f (+- %.4f)",
                      (double)roughs[r], (double)etas[e], 5 + 25 * a, total, sem);
                if (roughs[r] == 0.0f)
                    CHECK_NEAR(total, 1.0, 4.0 * sem + 2e-3, "smooth, eta %.3f at %d deg: reflect %.4f transmit %.4f",
                               (double)etas[e], 5 + 25 * a, refl, trans);
                else if (etas[e] == 1.0f)
                    CHECK_NEAR(total, ggx_albedo_f1((double)(roughs[r] * roughs[r]), wo), 4.0 * sem + 3e-3,
                               "thin, rough %.1f at %d deg", (double)roughs[r], 5 + 25 * a);
                else if (a < 3)
                    CHECK(total > (roughs[r] < 0.5f ? 0.9 : 0.6), "rough %.1f eta %.3f at %d deg: albedo only %.4f",
                          (double)roughs[r], (double)etas[e], 5 + 25 * a, total);
            }
}

/* Fresnel at normal incidence from the material's ior (material_layers: the spec's F0), and total
 * internal reflection beyond the critical angle. */
static void test_fresnel(void) {
    float iors[] = {1.33f, 1.5f, 2.4f};
    for (int i = 0; i < 3; i++) {
        material m = material_default();
        m.roughness = 0.0f;
        m.ext.ior = iors[i];
        m.ext.transmission = 1.0f;
        m.ext.thickness = 1.0f;
        surface_hit h = {0};
        gltf_layers x = material_layers(NULL, &m, &h);
        CHECK_NEAR(x.eta, iors[i], 1e-6, "entering through the front: eta is the ior");
        bsdf b = make_bsdf_gltf_layered(m.base_color, 0.0f, 0.0f, 0.0f, &x);
        double refl, trans, sem, f0 = pow((1.0 - iors[i]) / (1.0 + iors[i]), 2.0);
        energy(&b, v3(0, 0, 1), 200000, (uint64_t)i, &refl, &trans, &sem);
        CHECK_NEAR(refl, f0, 2e-3, "ior %.2f: reflected at normal incidence", (double)iors[i]);
        CHECK_NEAR(trans, 1.0 - f0, 2e-3, "ior %.2f: transmitted at normal incidence", (double)iors[i]);
        h.backface = 1;
        x = material_layers(NULL, &m, &h);
        CHECK_NEAR(x.eta, 1.0 / iors[i], 1e-6, "leaving through the back: eta is 1 / ior");
        b = make_bsdf_gltf_layered(m.base_color, 0.0f, 0.0f, 0.0f, &x);
        double critical = asin(1.0 / iors[i]) * 180.0 / PI_D;
        energy(&b, dir_from_angles(critical + 5.0, 0.0), 50000, 9, &refl, &trans, &sem);
        CHECK(trans == 0.0 && fabs(refl - 1.0) < 2e-3, "ior %.2f from inside past the critical angle: R %.4f T %.4f",
              (double)iors[i], refl, trans);
        energy(&b, dir_from_angles(critical - 10.0, 0.0), 50000, 10, &refl, &trans, &sem);
        CHECK(trans > 0.5, "ior %.2f from inside below the critical angle: T %.4f", (double)iors[i], trans);
        /* Thin-walled (no volume): not bent. */
        m.ext.thickness = 0.0f;
        x = material_layers(NULL, &m, &h);
        CHECK(x.eta == 1.0f, "thin-walled: eta %g", (double)x.eta);
    }
}

/* f(wo, wi) / n(wo)^2 = f(wi, wo) / n(wi)^2: evaluated from below, the same surface is the bsdf
 * with 1 / eta and both directions mirrored. Thin-walled: plain symmetry. And the adjoint scale
 * is the ratio. */
static void test_reciprocity(void) {
    rng_state rng = rng_make(42, 1);
    float etas[] = {1.5f, 1.0f, 2.2f};
    for (int e = 0; e < 3; e++) {
        gltf_layers x = ior_layers(etas[e] > 1.0f ? etas[e] : 1.5f);
        x.clearcoat = 0.5f;
        x.clearcoat_roughness = 0.3f;
        bsdf top = glass(v3(0.9f, 0.7f, 0.5f), 0.4f, 0.9f, etas[e], x);
        bsdf bottom = glass(v3(0.9f, 0.7f, 0.5f), 0.4f, 0.9f, 1.0f / etas[e], x);
        int bad = 0, nonzero = 0;
        for (int k = 0; k < 4000; k++) {
            vec3 wo = normalize3(v3(2 * rng_float(&rng) - 1, 2 * rng_float(&rng) - 1, rng_float(&rng) + 1e-3f));
            vec3 wi = normalize3(v3(2 * rng_float(&rng) - 1, 2 * rng_float(&rng) - 1, -rng_float(&rng) - 1e-3f));
            vec3 f1 = bsdf_eval(&top, wo, wi, BSDF_ALL);
            vec3 f2 = bsdf_eval(&bottom, v3(wi.x, wi.y, -wi.z), v3(wo.x, wo.y, -wo.z), BSDF_ALL);
            float want = f1.x * bsdf_adjoint_scale(&top, wo, wi);
            nonzero += f1.x > 0.0f;
            /* relative, but near total internal reflection 1 - F is a difference of nearly equal floats */
            bad += !(fabsf(want - f2.x) <= 2e-3f * fmaxf(want, f2.x) + 1e-5f);
        }
        CHECK(bad == 0 && nonzero > 500, "eta %.2f: %d of 4000 pairs not reciprocal (%d non-zero)", (double)etas[e],
              bad, nonzero);
    }
}

static void test_traps(void) {
    vec3 wos[] = {v3(0, 0, 1), normalize3(v3(1, 0, 1e-4f)), normalize3(v3(0.3f, -1, 1e-6f))};
    float roughs[] = {0.0f, 1e-4f, 1.0f};
    float etas[] = {1.0f, 1.0005f, 1.5f, 1.0f / 1.5f, 100.0f, 0.01f};
    int bad = 0;
    rng_state rng = rng_make(5, 5);
    for (int w = 0; w < 3; w++)
        for (int r = 0; r < 3; r++)
            for (int e = 0; e < 6; e++) {
                bsdf b = glass(v3s(1.0f), roughs[r], 1.0f, etas[e], ior_layers(1.5f));
                for (int k = 0; k < 200; k++) {
                    bsdf_sample_result s;
                    if (bsdf_sample(&b, wos[w], BSDF_ALL, rng_float(&rng), rng_vec2(&rng), &s)) {
                        /* the flux weight: radiance's own 1 / eta^2 is unbounded as eta -> 0 */
                        float wgt = max_comp3(s.f) * fabsf(s.wi.z) / s.pdf * bsdf_adjoint_scale(&b, wos[w], s.wi);
                        bad += !isfinite(wgt) || !is_finite3(s.wi) || wgt > 50.0f;
                    }
                    vec3 wi = normalize3(v3(2 * rng_float(&rng) - 1, 2 * rng_float(&rng) - 1, 2 * rng_float(&rng) - 1));
                    bad += !is_finite3(bsdf_eval(&b, wos[w], wi, BSDF_ALL)) ||
                           !isfinite(bsdf_pdf(&b, wos[w], wi, BSDF_ALL));
                }
                /* exactly through and exactly back */
                bad += !is_finite3(bsdf_eval(&b, wos[w], neg3(wos[w]), BSDF_ALL));
                bad += !isfinite(bsdf_pdf(&b, wos[w], neg3(wos[w]), BSDF_ALL));
            }
    CHECK(bad == 0, "%d non-finite or huge values at the traps", bad);
    /* ior 1 refracts straight through and reflects nothing at normal incidence. */
    bsdf one = glass(v3s(1.0f), 0.0f, 1.0f, 1.0f, ior_layers(1.0f));
    double refl, trans, sem;
    energy(&one, v3(0, 0, 1), 20000, 3, &refl, &trans, &sem);
    CHECK(refl < 1e-3 && fabs(trans - 1.0) < 4.0 * sem + 1e-3, "ior 1: R %.4f T %.4f", refl, trans);
}

int main(void) {
    test_sampling_matches_pdf();
    test_energy();
    test_fresnel();
    test_reciprocity();
    test_traps();
    return check_exit("test_transmission");
}
