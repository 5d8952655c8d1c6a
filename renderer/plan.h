/* glint — simulate only what the scene calls for (docs/design.md). The scene is analysed once (which
 * kinds of surfaces and emitters it has, which can see which) and each session decides from that
 * and its parameters which passes to run. A decision never changes the answer beyond noise: a
 * pass the plan drops either has nothing to add (no surface can pass light on: no virtual
 * lights), or the estimate it owned goes back to the estimator that covers it without it (no
 * glossy surface sees another: the VSL gather keeps the glossy-glossy paths), or it only chooses
 * how to sample (diffuse-only pairs: the VSL integral by points on the light's disk). `--plan
 * full` runs every pass, so tests can compare. */
#ifndef GLINT_PLAN_H
#define GLINT_PLAN_H

#include <stdio.h>

#include "scene.h"

/* A material is glossy when a lobe of it is sharper than BSDF_HIGHLIGHT_ALPHA (bsdf_highlight_lobe),
 * near-specular (mirror-like) when sharper than this. */
#define PLAN_NEAR_SPECULAR_ALPHA 0.05f

/* One material as the probes saw it. */
typedef struct {
    int probes;                 /* surface samples on it (0: no area) */
    int lobes;                  /* BSDF_DIFFUSE | BSDF_GLOSSY seen anywhere on it (textures included) */
    float alpha_min, alpha_max; /* its glossy lobes' roughness (0, 0 without one) */
    int anisotropic;            /* a glossy lobe whose two roughnesses differ */
} material_summary;

typedef struct {
    int num_materials;
    material_summary *materials; /* num_materials */
    /* materials per class: diffuse (no glossy lobe), rough (glossy lobes no sharper than
     * BSDF_HIGHLIGHT_ALPHA), glossy; near-specular and anisotropic are kinds of glossy */
    int diffuse, rough, glossy, near_specular, anisotropic;
    float alpha_min, alpha_max; /* over the glossy class */
    int punctual, area, env;    /* emitters: punctual lights, emissive triangles, a map */
    int reflective;             /* some surface reflects light at all */
    int indirect;               /* a reflecting surface sees another: indirect light can exist */
    int glossy_to_glossy;       /* a glossy surface sees a glossy surface */
    long probe_rays;            /* rays the visibility probes traced */
    int cut;                    /* the probes stopped at their time budget: what they found is partial */
    double seconds;             /* the analysis's wall time */
} scene_analysis;

/* Analyses s (read-only, thread-safe queries): probes random surface points on both sides,
 * each material in proportion to its area with a floor per material, and the first hits of
 * light paths; from each point on a side that can be seen (or lit), one cosine-distributed ray
 * finds what it passes light on to. Deterministic unless cut short (below). Returns 0, or -1 (out
 * of memory) with err set; free with scene_analysis_free. */
int scene_analyse(const scene *s, scene_analysis *a, char *err, size_t errlen);
/* The same within a time budget: the probes stop once it is spent (cut set; a scene whose rays
 * each test a million coincident triangles took two minutes), and a plan made from a cut analysis
 * turns every pass on. scene_analyse's budget is PLAN_PROBE_SECONDS. */
#define PLAN_PROBE_SECONDS 2.0
int scene_analyse_within(const scene *s, scene_analysis *a, double seconds, char *err, size_t errlen);
void scene_analysis_free(scene_analysis *a);

/* The passes of one session. */
typedef struct {
    int full;               /* PLAN_FULL: every pass on */
    int max_depth;          /* scattering events the scene needs (at most what was asked) */
    int virtual_lights;     /* vpl, vsl, vsl+hl: trace virtual lights and gather from them */
    int vsl_all_strategies; /* the three-strategy VSL integral for every pair (else only where a
                             * glossy lobe is involved; diffuse pairs by points on the disk) */
    int highlights;         /* vsl+hl: the highlight pass (else the VSL gather keeps those paths) */
    int env_prefilter;      /* vsl+hl: the vMF-prefiltered environment */
    /* why, one line each */
    char why_depth[160], why_virtual[160], why_kernel[160], why_highlights[160], why_env[160], why_direct[256];
} effect_plan;

/* The plan for method `method` (render_method), asked max_depth, PLAN_AUTO or PLAN_FULL. */
effect_plan plan_make(const scene_analysis *a, int method, int max_depth, int mode);

/* The plan's decisions, one "pass: why" line each (the viewer's panel, glint info). */
void plan_summary(const effect_plan *p, char *buf, size_t len);
/* The analysis and the plan as indented text lines (glint info). */
void plan_print(FILE *f, const scene *s, const scene_analysis *a, const effect_plan *p);

#endif
