/* glint — the environment map prefiltered by von Mises-Fisher lobes, for the highlight estimator
 * (Laurijssen et al. 2010), which lights each glossy lobe gamma(s) = c(kappa) exp(kappa mu.s) by the
 * environment and needs, per lookup and fast,
 *
 *     E(mu, kappa) = integral over the sphere of gamma(s) L_env(s) ds     (RGB).
 *
 * The map is convolved once with lobes at a ladder of concentrations (each level an equirect
 * image with a few texels per lobe width), so a lookup is two bilinear fetches and a blend. The
 * convolution is rotation invariant: it runs in the map's own uv domain and lookups go through
 * env_uv, so the map's rotation is honoured without refiltering. */
#ifndef GLINT_ENVFILTER_H
#define GLINT_ENVFILTER_H

#include <stddef.h>

#include "envmap.h"
#include "vmf.h"

typedef struct env_vmf_filter env_vmf_filter;

/* Prefilters env once over a range of kappa. Borrows env (its image for the sharpest lobes, its
 * rotation for lookups): env must outlive the filter. Returns NULL with err set (one line) when
 * out of memory or env is empty; the caller owns the result (env_vmf_filter_destroy). */
env_vmf_filter *env_vmf_filter_create(const env_map *env, char *err, size_t errlen);
void env_vmf_filter_destroy(env_vmf_filter *f); /* NULL is fine */

/* E(mu, kappa) above for a world direction mu (unit) and any kappa in [0, VMF_MAX_KAPPA]:
 * kappa 0 (or NaN, negative) is the map's solid-angle mean exactly; below the first level a blend
 * linear in kappa from it; between levels bilinear in each and linear in log kappa; past the
 * sharpest level the blend goes on to the map's own bilinear lookup, used alone beyond four times
 * that kappa. Finite for any finite non-negative map. Thread-safe (read only). */
vec3 env_vmf_filter_lookup(const env_vmf_filter *f, vmf lobe);

/* Memory held (levels and the filter itself, not the borrowed map), for reports. 0 for NULL. */
size_t env_vmf_filter_bytes(const env_vmf_filter *f);

#endif
