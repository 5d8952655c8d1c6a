/* glint tests — a bsdf at a fixed wo as the direction sampler and pdf stat_tests.h checks. */
#ifndef GLINT_BSDF_SAMPLER_H
#define GLINT_BSDF_SAMPLER_H

#include "bsdf.h"

typedef struct {
    const bsdf *b;
    vec3 wo;
} bsdf_ctx;

static inline int sample_fn(void *c, float u_lobe, vec2 u, vec3 *w) {
    const bsdf_ctx *x = c;
    bsdf_sample_result s;
    if (!bsdf_sample(x->b, x->wo, BSDF_ALL, u_lobe, u, &s)) return 0;
    *w = s.wi;
    return 1;
}

static inline double pdf_fn(void *c, vec3 w) {
    const bsdf_ctx *x = c;
    return bsdf_pdf(x->b, x->wo, w, BSDF_ALL);
}

#endif
