#include "metrics.h"

#include <math.h>

double metric_rel_l2(const float *img, const float *ref, size_t n) {
    double err = 0.0, norm = 0.0;
    for (size_t i = 0; i < n; i++) {
        double d = (double)img[i] - (double)ref[i];
        err += d * d;
        norm += (double)ref[i] * (double)ref[i];
    }
    if (norm > 0.0) return sqrt(err / norm);
    return err > 0.0 ? (double)INFINITY : 0.0;
}

double metric_relmse(const float *img, const float *ref, size_t n) {
    if (n == 0) return 0.0;
    double sum = 0.0;
    for (size_t i = 0; i < n; i++) {
        double d = (double)img[i] - (double)ref[i];
        sum += d * d / ((double)ref[i] * (double)ref[i] + METRIC_RELMSE_EPS);
    }
    return sum / (double)n;
}
