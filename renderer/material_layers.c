/* The glTF material extensions at a hit: factors times their textures, as each extension's
 * specification combines them, handed to make_bsdf_gltf_layered (docs/design.md, "The glTF
 * material"). */
#include "scene.h"

material_ext material_ext_default(void) {
    material_ext x = {0};
    x.ior = 1.5f;
    x.specular = 1.0f;
    x.specular_color = v3s(1.0f);
    x.specular_tex = x.specular_color_tex = x.sheen_color_tex = x.sheen_roughness_tex = x.clearcoat_tex =
        x.clearcoat_roughness_tex = x.clearcoat_normal_tex = x.transmission_tex = (texture_slot){.texture = -1};
    x.clearcoat_normal_scale = 1.0f;
    x.attenuation_distance = INFINITY;
    x.attenuation_color = v3s(1.0f);
    return x;
}

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
