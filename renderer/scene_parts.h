/* glint — the scene module's parts that live in files of their own, one idea each: tangent
 * generation (tangents.c), the shading frame at a hit (shading_frame.c), the ray-traced geometry
 * with its alpha filters (alpha.c), what emissive textures make lights (emissive.c) and material
 * variants (variants.c); the scene's private record (scene_box). scene.c, what is built from it
 * (scene_make.c, lights.c) and the ray queries (scene_query.c) use these; the estimators never do. */
#ifndef GLINT_SCENE_PARTS_H
#define GLINT_SCENE_PARTS_H

#include "scene.h"

/* A scene as scene_create allocates it: the warning sink and the light edits beside the public
 * struct (scene.c makes it, scene_make.c edits and frees it). */
typedef struct {
    scene_warn_fn fn;
    void *user;
} warn_sink;

typedef struct {
    scene s;
    warn_sink warn;
    /* Per light group, made on the first change of intensity: the multiplier and what it
     * multiplies (the colour or emission as loaded), so gains are exact, never compounded. */
    int num_gains;
    float *gains;
    vec3 *gain_bases;
} scene_box;

/* The uv set uv (s->uv0 or s->uv1) of triangle t at barycentrics (b1, b2). */
static inline vec2 triangle_uv(const scene *s, const vec2 *uv, int t, float b1, float b2) {
    const uint32_t *v = &s->indices[3 * t];
    float b0 = 1.0f - b1 - b2;
    return v2(b0 * uv[v[0]].x + b1 * uv[v[1]].x + b2 * uv[v[2]].x, b0 * uv[v[0]].y + b1 * uv[v[1]].y + b2 * uv[v[2]].y);
}

/* ---- tangents.c ---------------------------------------------------------------------------- */

/* A mesh rebuilt with tangents: the arrays behind mesh (positions, normals, tangents, uvs,
 * indices) are owned here. */
typedef struct {
    mesh_desc mesh;
    float *positions, *normals, *tangents, *uv0, *uv1;
    uint32_t *indices;
} tangent_mesh;

/* Tangents for a mesh whose file has none (or whose tangents glTF says to ignore: no normals),
 * computed the way MikkTSpace computes them from the uv set uv_set (0 or 1), with glTF's
 * bitangent convention; flat normals when the mesh has none. Vertices shared by triangles of
 * opposite uv orientation (mirrored uvs) are split, as MikkTSpace splits them. The mesh must have
 * that uv set and valid indices. Returns 0, or -1 when out of memory. */
int tangents_generate(const mesh_desc *mesh, int uv_set, tangent_mesh *out);
void tangent_mesh_free(tangent_mesh *t);

/* ---- shading_frame.c ----------------------------------------------------------------------- */

/* Fills h->shading for a hit at barycentrics (b1, b2) of triangle h->tri seen along ray direction
 * d: the interpolated normal, perturbed by the material's normal map, kept on the side of h->ng
 * and facing the viewer; its tangent follows the mesh's tangents when the material is
 * anisotropic or normal-mapped. h->ng, h->uv0, h->uv1 and h->material must be set. */
void shading_frame_at_hit(const scene *s, surface_hit *h, float b1, float b2, vec3 d);

/* ---- texture.c ----------------------------------------------------------------------------- */

/* Texel index i in a row or column of n texels under a wrap mode. */
int texture_wrap(int i, int n, wrap_mode mode);
/* sRGB-encoded 8-bit value -> linear, as texture_lookup decodes colour (256 entries). */
const float *texture_srgb_table(void);

/* ---- emissive.c ---------------------------------------------------------------------------- */

/* For every emissive triangle with an emissive texture, the texture's mean over the triangle
 * (s->tri_emit_tex): zero in exactly the channels where the texture is black all over the
 * triangle (then it emits nothing there and is no light), never below a thousandth of the
 * channel's maximum elsewhere. Bounded work per triangle (pyramids of the textures). Call after
 * materials change; scene_build_lights reads it. Returns 0, or -1 with err set. */
int scene_emissive_analyse(scene *s, char *err, size_t errlen);

/* ---- alpha.c ------------------------------------------------------------------------------- */

/* Builds (or rebuilds, after materials changed) the Embree scene: the device on first use, the
 * opaque geometry, the alpha-tested one with its filters. Returns 0, or -1 with err set. */
int scene_build_bvh(scene *s, char *err, size_t errlen);
/* After vertices moved (a light edit): Embree refits. Returns 0 or -1. */
int scene_bvh_vertices_moved(scene *s);
/* Releases the Embree scene and the alpha tables (not the device). */
void scene_bvh_free(scene *s);
/* The scene triangle Embree's hit (geometry, primitive) stands for. */
static inline int scene_hit_triangle(const scene *s, unsigned geom, unsigned prim) {
    return s->bvh_tri[geom] ? s->bvh_tri[geom][prim] : (int)prim;
}
/* 1 when no ray can see triangle t (its material's alpha is zero, or below its cutoff,
 * everywhere): it is not in the BVH and emits nothing. */
int scene_triangle_invisible(const scene *s, int t);
/* Alpha of material m at uv: baseColorFactor's alpha times the base colour texture's. */
float material_alpha(const scene *s, const material *m, vec2 uv0, vec2 uv1);
/* How much of a hit's surface is there, for what samples points on it (emission): 1 for opaque
 * materials, MASK 1 or 0, BLEND its alpha. */
float material_coverage(const scene *s, const surface_hit *h);
/* BLEND's number in [0, 1) for the ray (o, d) meeting triangle tri (tests compare against it). */
float alpha_ray_hash(vec3 o, vec3 d, int tri);
/* Whether shadow rays may pass material m's glass (then bsdf_pass_through decides at a hit). */
int scene_material_passes_shadows(const scene *s, int m);
/* The context of every occlusion query (scene_query.c): Embree hands the filters its first member.
 * With record set, the glass a shadow ray may pass is recorded here (each triangle once, at most
 * SCENE_MAX_GLASS; more blocks the ray) instead of blocking it; without, glass blocks. */
typedef struct {
    struct RTCIntersectContext rtc;
    int record, count;
    struct {
        int tri;
        float b1, b2;
    } hit[SCENE_MAX_GLASS];
} shadow_context;

/* ---- variants.c ---------------------------------------------------------------------------- */

/* Rewrites the triangles' materials for variant v (-1: the defaults) and nothing else (the caller
 * rebuilds). Returns 0, or -1 for a variant the scene does not have, or out of memory. */
int scene_apply_variant(scene *s, int v);
void scene_variants_free(scene *s);
/* 1 when some variant gives a primitive an emissive material. */
int scene_variants_emit(const scene *s);

#endif
