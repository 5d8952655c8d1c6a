/* The shading frame at a hit, the one every estimator shades in (material_bsdf hands it on):
 * the interpolated normal, a normal map's perturbation in glTF's tangent space, and the guards
 * that keep it usable (docs/design.md, "Normal maps"). */
#include "scene_parts.h"

/* Lower bound on the cosine between the shading normal and the geometric one, and the viewer. */
#define MIN_COS 1e-3f

static vec3 interpolate3(vec3 a, vec3 b, vec3 c, float b0, float b1, float b2) {
    return add3(add3(scale3(a, b0), scale3(b, b1)), scale3(c, b2));
}

/* n bent toward w until their cosine is at least MIN_COS (n unit, w unit). */
static vec3 bend_toward(vec3 n, vec3 w) {
    float c = dot3(n, w);
    return c >= MIN_COS ? n : normalize3(madd3(n, w, MIN_COS - c));
}

/* n such that the mirror direction of wo about it stays above the geometric surface: where a
 * normal map (or coarse interpolation) tilts n so far that the reflection would point into the
 * surface, the reflection is lifted to just above the horizon (never above the view's own
 * elevation) and n becomes the half vector of wo and it. Without this a sharp lobe over a tilted
 * map reflects nothing: black rims where the surface should mirror the horizon. */
static vec3 keep_reflection_above(vec3 n, vec3 ng, vec3 wo) {
    float lift = fminf(0.9f * dot3(ng, wo), 0.01f);
    vec3 r = reflect3(wo, n);
    float rn = dot3(r, ng);
    if (rn >= lift) return n;
    vec3 across = sub3(r, scale3(ng, rn));
    float l2 = length_sq3(across);
    if (!(l2 > 1e-20f)) return ng;
    vec3 lifted = madd3(scale3(ng, lift), across, sqrtf(1.0f - lift * lift) / sqrtf(l2));
    vec3 h = add3(wo, lifted);
    float hl = length_sq3(h);
    return hl > 1e-20f ? scale3(h, 1.0f / sqrtf(hl)) : ng;
}

/* The guards every shading normal passes (n unit): above the geometric surface (the mirror
 * direction alone cannot tell n from -n), its reflection above too, facing the viewer. */
static vec3 guard_normal(vec3 n, vec3 ng, vec3 wo) {
    return bend_toward(keep_reflection_above(bend_toward(n, ng), ng, wo), wo);
}

/* A normal map's tangent-space normal at the hit, its x and y turned (and mirrored) as
 * KHR_texture_transform turns the texture on the surface, so that they follow the texture's own
 * u and v there (as tangents made from the transformed uvs would). */
static vec3 map_normal(const scene *s, const texture_slot *slot, float k, const surface_hit *h) {
    vec4 c = texture_lookup(s, *slot, h->uv0, h->uv1, 0);
    float x = (2.0f * c.x - 1.0f) * k, y = (2.0f * c.y - 1.0f) * k, z = 2.0f * c.z - 1.0f;
    if (slot->transformed) {
        /* The texture's u axis in (tangent, bitangent) axes: A^-1 (1, 0) with v turned up the
         * image, for A the transform's linear part; det(A) < 0 mirrors the map's y. */
        const float *a = slot->uv_xf;
        float det = a[0] * a[4] - a[1] * a[3];
        float cu = a[4] * det, su = a[3] * det, len = sqrtf(cu * cu + su * su);
        if (len > 0.0f && isfinite(len)) {
            float hy = det < 0.0f ? -y : y;
            float rx = (cu * x - su * hy) / len, ry = (su * x + cu * hy) / len;
            x = rx;
            y = ry;
        }
    }
    return v3(x, y, z);
}

/* The map's normal in world space through the tangent frame f (front side); a degenerate texel (no
 * direction) keeps f's normal, the interpolated one. */
static vec3 mapped_normal(const scene *s, const texture_slot *slot, float k, const surface_hit *h, frame3 f) {
    vec3 t = map_normal(s, slot, k, h);
    vec3 p = add3(add3(scale3(f.t, t.x), scale3(f.b, t.y)), scale3(f.n, t.z));
    float pl = length_sq3(p);
    return pl > 1e-12f && isfinite(pl) ? scale3(p, 1.0f / sqrtf(pl)) : f.n;
}

void shading_frame_at_hit(const scene *s, surface_hit *h, float b1, float b2, vec3 d) {
    const uint32_t *v = &s->indices[3 * h->tri];
    float b0 = 1.0f - b1 - b2;
    vec3 ng = h->ng, wo = neg3(d);
    vec3 ns = interpolate3(s->normals[v[0]], s->normals[v[1]], s->normals[v[2]], b0, b1, b2);
    float l2 = length_sq3(ns);
    ns = (l2 > 1e-12f && isfinite(l2)) ? scale3(ns, 1.0f / sqrtf(l2)) : ng;
    /* The ray sees the side of the surface whose normal faces it: there the frame is the front
     * one negated as a whole (the same bumps seen from behind). */
    float side = dot3(ns, ng) < 0.0f ? -1.0f : 1.0f;

    const material *m = &s->materials[h->material];
    int mapped = m->normal_tex.texture >= 0;
    int anisotropic = (m->model == MATERIAL_WARD && m->alpha_x != m->alpha_y) ||
                      (m->model == MATERIAL_GLTF && m->anisotropy_strength > 0.0f);
    /* KHR_materials_clearcoat: the coat's normal is its own map's, else the interpolated one (the
     * base's map does not bump the coat). */
    int coated = m->model == MATERIAL_GLTF && m->ext.clearcoat > 0.0f;
    int coat_mapped = coated && m->ext.clearcoat_normal_tex.texture >= 0;
    if (!mapped && !anisotropic && !coat_mapped) {
        h->shading = frame_from_normal(guard_normal(scale3(ns, side), ng, wo));
        h->coat_n = h->shading.n;
        return;
    }
    /* The mesh's tangent frame (glTF: bitangent = cross(n, t) w), front side. */
    const vec4 *tg = s->tangents;
    vec3 tan = interpolate3(v3(tg[v[0]].x, tg[v[0]].y, tg[v[0]].z), v3(tg[v[1]].x, tg[v[1]].y, tg[v[1]].z),
                            v3(tg[v[2]].x, tg[v[2]].y, tg[v[2]].z), b0, b1, b2);
    frame3 f = frame_from_normal_tangent(ns, tan);
    float w = tg[v[0]].w < 0.0f ? -1.0f : 1.0f;
    f.b = scale3(f.b, w);
    vec3 n = mapped ? mapped_normal(s, &m->normal_tex, m->normal_scale, h, f) : ns;
    /* Light arriving below the geometric surface never counts whatever n is: every estimator
     * tests directions against ng as well. */
    n = guard_normal(scale3(n, side), ng, wo);
    h->shading = frame_from_normal_tangent(n, scale3(f.t, side));
    /* Keep the handedness: anisotropy rotations and the map's y turn the right way. */
    h->shading.b = scale3(h->shading.b, w * side);
    h->coat_n = h->shading.n;
    if (coated) {
        vec3 c = coat_mapped ? mapped_normal(s, &m->ext.clearcoat_normal_tex, m->ext.clearcoat_normal_scale, h, f) : ns;
        h->coat_n = guard_normal(scale3(c, side), ng, wo);
    }
}
