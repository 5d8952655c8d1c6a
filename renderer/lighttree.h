/* glint — a light tree over one frame's virtual lights: a binary hierarchy whose nodes bound where
 * their lights sit (box, largest VSL radius), which way they face (a cone of normals), where their
 * glossy lobes point (a cone of mirror directions and the lobes' concentrations) and how much
 * power they reflect diffusely and into glossy lobes. A shading point walks it from the root,
 * choosing each child in proportion to a bound of what the child's lights send to it: distance,
 * both cosines, the senders' lobes and the receiver's lobe. So a pixel draws the lights that
 * matter there (the near ones, the glossy ones aimed at it) rather than the bright ones anywhere,
 * at a cost logarithmic in the light count (the shape of pbrt-v4's and Cycles' light BVHs and of
 * stochastic lightcuts; see docs/design.md).
 *
 * A node's importance is zero only where every light below it sends nothing (the point is behind
 * every light's surface, or every light is behind the point's surface), so sampling is unbiased
 * for the frame's light set. */
#ifndef GLINT_LIGHTTREE_H
#define GLINT_LIGHTTREE_H

#include "vlights.h"
#include "vsl.h"

typedef struct {
    vec3 centre;      /* the box bounding the lights' centres: its centre, */
    float half_diag2; /* ... half-diagonal squared */
    vec3 extent;      /* ... and half-extents */
    float radius;     /* largest sphere radius below (0 for point lights) */
    vec3 n_axis;      /* cone of the geometric normals: axis, cos and sin of its half-angle */
    float n_cos;
    vec3 g_axis; /* cone of the glossy lobes' mirror directions */
    float g_cos;
    float n_sin, g_sin;
    float phi_diffuse; /* luminance of power x diffuse albedo, summed */
    float phi_glossy;  /* luminance of power x glossy albedo, summed (0: no glossy lobe below) */
    float kappa;       /* the sharpest glossy lobe's vMF concentration */
    int child;         /* internal: first child (the second is child + 1); leaf: -1 - light index */
    int parent;        /* -1 at the root */
} lt_node;

typedef struct {
    lt_node *nodes;
    int num_nodes, cap_nodes;
    int *leaf_of; /* light index -> its leaf node */
    int *order;   /* scratch for the build: the lights' order, split keys and leaves */
    float *keys;
    lt_node *leaves;
    int num_lights, cap_lights;
} lighttree;

/* What the tree needs to know of a receiver, made once per shading point. */
typedef struct {
    vec3 p, ng;
    float eps;     /* distances to a plane below this count as in it (the scene's ray offset) */
    float diffuse; /* luminance of the Lambert albedo / pi */
    float glossy;  /* luminance of the glossy lobe's albedo; 0: none */
    vec3 g_axis;   /* the glossy lobe's mirror direction (world) */
    float kappa;   /* ... and its vMF concentration */
} lt_receiver;

/* Builds the tree over set's lights (their radii already set). Returns 0, or -1 out of memory. */
int lighttree_build(lighttree *t, const vlight_set *set);
void lighttree_free(lighttree *t);

/* The receiver x; eps: the scene's smallest ray offset (scene.ray_eps). */
lt_receiver lighttree_receiver(const shading_point *x, float eps);

/* Draws one light for r with u in [0,1): returns its index and its probability in *pmf, or -1
 * when no light can send anything to r. */
int lighttree_sample(const lighttree *t, const lt_receiver *r, float u, float *pmf);
/* The probability that lighttree_sample returns `light` for r (for tests). */
float lighttree_pmf(const lighttree *t, const lt_receiver *r, int index);
/* A node's importance for r: the estimate the draws are proportional to. */
float lighttree_importance(const lt_node *n, const lt_receiver *r);
/* The same for the leaf of one light (t->leaves[light]), faster: resampling's target. */
float lighttree_light_importance(const lt_node *leaf, const lt_receiver *r);

#endif
