/* glint — the scene module's parts that live in files of their own, one idea each: tangent
 * generation (tangents.c), the shading frame at a hit (shading_frame.c), the ray-traced geometry
 * with its alpha filters (alpha.c), what emissive textures make lights (emissive.c) and material
 * variants (variants.c). scene.c and lights.c call these; the estimators never do. */
#ifndef GLINT_SCENE_PARTS_H
#define GLINT_SCENE_PARTS_H

#include "scene.h"

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

#endif
