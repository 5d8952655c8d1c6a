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
        x.clearcoat_roughness_tex = (texture_slot){.texture = -1};
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
    return l;
}
