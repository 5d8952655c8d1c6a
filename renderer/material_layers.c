/* A surface hit's material: its BSDF and emission, and the glTF material extensions at the hit
 * (factors times their textures, as each extension's specification combines them, handed to
 * make_bsdf_gltf_layered; docs/design.md, "The glTF material"). */
#include "scene.h"

/* The texture's value at the hit, or 1 in every channel without one. */
static vec4 lookup_or_one(const scene *s, texture_slot slot, const surface_hit *h, int srgb) {
    return slot.texture >= 0 ? texture_lookup(s, slot, h->uv0, h->uv1, srgb) : (vec4){1.0f, 1.0f, 1.0f, 1.0f};
}

gltf_layers material_layers(const scene *s, const material *m, const surface_hit *h) {
    const material_ext *x = &m->ext;
    gltf_layers l = gltf_layers_default();
    /* KHR_materials_ior and _specular: F0 = ((ior - 1) / (ior + 1))^2 specularColor (clamped to 1
     * by the bsdf), strength specularFactor times the specular texture's alpha. */
    float r = (x->ior - 1.0f) / (x->ior + 1.0f);
    vec4 sc = lookup_or_one(s, x->specular_color_tex, h, 1);
    l.dielectric_f0 = scale3(mul3(x->specular_color, v3(sc.x, sc.y, sc.z)), r * r);
    l.specular = x->specular * lookup_or_one(s, x->specular_tex, h, 0).w;
    if (!is_black3(x->sheen_color)) {
        vec4 c = lookup_or_one(s, x->sheen_color_tex, h, 1);
        l.sheen_color = mul3(x->sheen_color, v3(c.x, c.y, c.z));
        l.sheen_roughness = x->sheen_roughness * lookup_or_one(s, x->sheen_roughness_tex, h, 0).w;
    }
    if (x->clearcoat > 0.0f) {
        l.clearcoat = x->clearcoat * lookup_or_one(s, x->clearcoat_tex, h, 0).x;
        l.clearcoat_roughness = x->clearcoat_roughness * lookup_or_one(s, x->clearcoat_roughness_tex, h, 0).y;
    }
    if (x->transmission > 0.0f) {
        l.transmission = x->transmission * lookup_or_one(s, x->transmission_tex, h, 0).x;
        /* A volume refracts: entering through the front (winding) side the index below is the
         * ior, leaving through the back it is air's; thin-walled (or ior below 1, the spec-gloss
         * convention) is not bent (docs/design.md, "Transmission and volume"). */
        l.eta = 1.0f;
        if (material_is_volume(m) && x->ior >= 1.0f) l.eta = h->backface ? 1.0f / x->ior : x->ior;
    }
    return l;
}

vec3 material_absorption(const material *m) {
    const material_ext *x = &m->ext;
    if (!material_is_volume(m) || !isfinite(x->attenuation_distance) || !(x->attenuation_distance > 0.0f))
        return v3s(0.0f);
    /* A black channel absorbs at the rate of 1e-6 per attenuation distance: finite, so that
     * exp(-sigma t) is 0 but sigma 0 never meets an infinity (a NaN). */
    vec3 c = min3(max3(x->attenuation_color, v3s(1e-6f)), v3s(1.0f));
    float inv = 1.0f / x->attenuation_distance;
    return v3(-logf(c.x) * inv, -logf(c.y) * inv, -logf(c.z) * inv);
}

vec3 material_medium_after(const material *m, int backface, int lobe, vec3 sigma) {
    if (lobe != BSDF_TRANSMIT || !material_is_volume(m)) return sigma;
    return backface ? v3s(0.0f) : material_absorption(m);
}

/* ---- materials at hits --------------------------------------------------------------------- */

/* Rotates the frame's tangent by angle about n (toward b for positive angles). */
static void rotate_tangent(frame3 *f, float c, float sn) {
    vec3 t = add3(scale3(f->t, c), scale3(f->b, sn));
    vec3 b = sub3(scale3(f->b, c), scale3(f->t, sn));
    f->t = t;
    f->b = b;
}

bsdf material_bsdf(const scene *s, const surface_hit *h, frame3 *frame) {
    const material *m = &s->materials[h->material];
    *frame = h->shading;
    vec3 tint = v3s(1.0f);
    if (m->base_color_tex.texture >= 0) {
        vec4 c = texture_lookup(s, m->base_color_tex, h->uv0, h->uv1, 1);
        tint = v3(c.x, c.y, c.z);
    }
    switch (m->model) {
    case MATERIAL_PHONG: return make_bsdf_phong(mul3(m->kd, tint), m->ks, m->exponent);
    case MATERIAL_WARD:
        if (m->anisotropy_rotation != 0.0f)
            rotate_tangent(frame, cosf(m->anisotropy_rotation), sinf(m->anisotropy_rotation));
        return make_bsdf_ward(mul3(m->kd, tint), m->ks, m->alpha_x, m->alpha_y);
    case MATERIAL_GLTF:
    default: {
        float metallic = m->metallic, roughness = m->roughness;
        if (m->metal_rough_tex.texture >= 0) {
            vec4 mr = texture_lookup(s, m->metal_rough_tex, h->uv0, h->uv1, 0);
            roughness *= mr.y;
            metallic *= mr.z;
        }
        float aniso = m->anisotropy_strength;
        if (aniso > 0.0f) {
            float dx = 1.0f, dy = 0.0f;
            if (m->anisotropy_tex.texture >= 0) {
                vec4 a = texture_lookup(s, m->anisotropy_tex, h->uv0, h->uv1, 0);
                dx = 2.0f * a.x - 1.0f;
                dy = 2.0f * a.y - 1.0f;
                aniso *= a.z;
            }
            float c = cosf(m->anisotropy_rotation), sn = sinf(m->anisotropy_rotation);
            float rx = c * dx - sn * dy, ry = sn * dx + c * dy;
            float len = sqrtf(rx * rx + ry * ry);
            if (len > 1e-6f) rotate_tangent(frame, rx / len, ry / len);
        }
        gltf_layers layers = material_layers(s, m, h);
        bsdf b = make_bsdf_gltf_layered(mul3(m->base_color, tint), metallic, roughness, aniso, &layers);
        if (b.coat > 0.0f) b.coat_n = to_local(*frame, h->coat_n);
        return b;
    }
    }
}

vec3 material_emission(const scene *s, const surface_hit *h) {
    const material *m = &s->materials[h->material];
    if (is_black3(m->emission) || (h->backface && !m->double_sided)) return v3(0, 0, 0);
    vec3 e = m->emission;
    if (m->emissive_tex.texture >= 0) {
        vec4 c = texture_lookup(s, m->emissive_tex, h->uv0, h->uv1, 1);
        e = mul3(e, v3(c.x, c.y, c.z));
    }
    return e;
}
