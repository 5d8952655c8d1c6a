/* An unbiased, consistent estimator's error falls like 1/sqrt(spp): mean squared error against a
 * much longer render is V/n + V/N_ref for per-sample variance V. A bias would show as a floor the
 * error cannot go below; a wrong weighting of samples as a different slope. */
#include <math.h>
#include <stdlib.h>

#include "check.h"
#include "test_scenes.h"

static double mse(const float *a, const float *b, int n) {
    double s = 0.0;
    for (int i = 0; i < 3 * n; i++) s += ((double)a[i] - b[i]) * ((double)a[i] - b[i]);
    return s / (3.0 * n);
}

int main(void) {
    /* A small room: Lambert walls, a large emissive ceiling panel, a glossy Phong box and a Ward
     * box, so every part of the path tracer (NEE, MIS on both lobes, Russian roulette)
     * contributes. The light is large and the lobes moderate so that the per-sample variance is
     * finite and not dominated by rare caustic paths: the squared error of a few hundred pixels
     * then estimates its expectation well. */
    scene *s = ts_new("convergence-room");
    int wall = ts_lambert(s, v3(0.7f, 0.6f, 0.5f), v3s(0), 0);
    int lamp = ts_lambert(s, v3s(0), v3s(3.0f), 0);
    material phong = material_default();
    phong.model = MATERIAL_PHONG;
    phong.kd = v3s(0.2f);
    phong.ks = v3s(0.6f);
    phong.exponent = 12.0f;
    material ward = material_default();
    ward.model = MATERIAL_WARD;
    ward.kd = v3(0.1f, 0.2f, 0.1f);
    ward.ks = v3s(0.7f);
    ward.alpha_x = 0.25f;
    ward.alpha_y = 0.4f;
    int mp = ts_material(s, phong), mw = ts_material(s, ward);
    ts_box(s, v3(-1, 0, -1), v3(1, 2, 1), 1, wall);
    ts_quad(s, v3(-0.8f, 1.99f, -0.8f), v3(0.8f, 1.99f, -0.8f), v3(0.8f, 1.99f, 0.8f), v3(-0.8f, 1.99f, 0.8f), lamp);
    ts_box(s, v3(-0.7f, 0, -0.6f), v3(-0.1f, 0.8f, 0.0f), 0, mp);
    ts_box(s, v3(0.2f, 0, -0.3f), v3(0.7f, 0.5f, 0.3f), 0, mw);
    ts_finalize(s);
    camera cam = camera_look_at(v3(0, 1.0f, 0.95f), v3(0, 0.6f, 0), v3(0, 1, 0), 1.3f);

    const int w = 32, h = 24, n = w * h, n_ref = 4096;
    float *ref = ts_render(s, &cam, w, h, n_ref, 16, 1, COMP_MASK_ALL);
    const int spp[4] = {4, 16, 64, 256};
    double m[4];
    for (int k = 0; k < 4; k++) {
        float *img = ts_render(s, &cam, w, h, spp[k], 16, 100 + (uint64_t)k, COMP_MASK_ALL);
        m[k] = mse(img, ref, n);
        printf("spp %4d  rmse %.5f\n", spp[k], sqrt(m[k]));
        free(img);
    }
    /* V from the shortest render, then the part of each error that is the render's own. */
    double v = m[0] / (1.0 / spp[0] + 1.0 / n_ref);
    double own[4];
    for (int k = 0; k < 4; k++) own[k] = m[k] - v / n_ref;
    double slope = log(own[3] / own[0]) / log((double)spp[3] / spp[0]);
    printf("mse slope %.3f (expected -1: rmse ~ spp^-0.5)\n", slope);
    CHECK(v > 0.0, "the scene has no variance: the test tests nothing");
    CHECK_NEAR(slope, -1.0, 0.12, "error does not fall like 1/sqrt(spp)");
    for (int k = 1; k < 4; k++)
        CHECK_NEAR(own[k] * spp[k] / v, 1.0, 0.25, "mse at %d spp against the 1/spp prediction", spp[k]);
    free(ref);
    scene_destroy(s);
    return check_exit("test_convergence");
}
