/* glint — image error against a reference, on HDR radiance (DESIGN.md, "Accuracy and its cost in
 * time"). Both images are n float values (pixels x channels), compared value by value. */
#ifndef GLINT_METRICS_H
#define GLINT_METRICS_H

#include <stddef.h>

/* The papers' relative L2 error ||I - R||_2 / ||R||_2. A zero reference gives 0 when the image
 * is zero too, else INFINITY. */
double metric_rel_l2(const float *img, const float *ref, size_t n);

/* Relative mean squared error: mean of (I - R)^2 / (R^2 + METRIC_RELMSE_EPS). The epsilon keeps
 * black reference pixels from dominating. */
#define METRIC_RELMSE_EPS 1e-2
double metric_relmse(const float *img, const float *ref, size_t n);

#endif
