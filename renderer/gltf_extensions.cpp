// glint — KHR_texture_transform, KHR_materials_variants, KHR_materials_transmission and
// KHR_materials_volume, and the clear coat's normal map's scale, from tinygltf's JSON values,
// checked (docs/design.md, "Texture transforms", "Material variants", "Transmission and volume").
#include "gltf_extensions.h"

#include <cmath>

namespace gltf_ext {

using tinygltf::Value;

namespace {

// Two numbers under key (out untouched when absent), each finite and at most MAX_UV_TRANSFORM
// in magnitude.
std::string pair(const Value &obj, const char *key, double out[2]) {
    if (!obj.Has(key)) return "";
    const Value &v = obj.Get(key);
    if (!v.IsArray() || v.ArrayLen() != 2 || !v.Get(0).IsNumber() || !v.Get(1).IsNumber())
        return std::string(key) + " is not two numbers";
    for (int i = 0; i < 2; i++) {
        out[i] = v.Get(i).GetNumberAsDouble();
        if (!(std::fabs(out[i]) <= MAX_UV_TRANSFORM))
            return std::string(key) + " " + num(out[i]) + " is not a finite number up to " + num(MAX_UV_TRANSFORM);
    }
    return "";
}

// A whole number in [0, limit) (v: any JSON value), else -1.
long long index_below(const Value &v, double limit) {
    double d = v.IsNumber() ? v.GetNumberAsDouble() : -1.0;
    return d >= 0.0 && d < limit && d == std::floor(d) ? (long long)d : -1;
}

// A number v (named what) into *out: at least lo (a problem below it, and for anything but a
// finite number), clamped to hi (*clamped set).
std::string number_in(const Value &v, const char *what, double lo, double hi, float *out, bool *clamped) {
    double d = v.IsNumber() ? v.GetNumberAsDouble() : NAN;
    if (!std::isfinite(d) || std::fabs(d) > 1e20) return std::string(what) + " is not a finite number";
    if (d < lo) return std::string(what) + " " + num(d) + " is below " + num(lo);
    if (d > hi) d = hi, *clamped = true;
    *out = (float)d;
    return "";
}

// The same for the number under key (out untouched when absent).
std::string bounded(const Value &obj, const char *key, double lo, double hi, float *out, bool *clamped) {
    return obj.Has(key) ? number_in(obj.Get(key), key, lo, hi, out, clamped) : "";
}

} // namespace

std::string material_transmission_volume(const std::string &name, const Value &e, material_ext *x,
                                         const std::function<texture_slot(const char *)> &texture, bool *clamped) {
    if (!e.IsObject()) return name + " is not an object";
    std::string why;
    if (name == "KHR_materials_transmission") {
        why = bounded(e, "transmissionFactor", 0.0, 1.0, &x->transmission, clamped);
        if (why.empty() && e.Has("transmissionTexture")) x->transmission_tex = texture("transmissionTexture");
    } else {
        why = bounded(e, "thicknessFactor", 0.0, 1e20, &x->thickness, clamped);
        // The spec's attenuationDistance is positive; infinity (its default) is no absorption.
        if (why.empty()) why = bounded(e, "attenuationDistance", 1e-30, 1e20, &x->attenuation_distance, clamped);
        if (why.empty() && e.Has("attenuationColor")) {
            const Value &c = e.Get("attenuationColor");
            float rgb[3];
            if (!c.IsArray() || c.ArrayLen() != 3) return name + ": attenuationColor is not three numbers";
            for (int i = 0; i < 3 && why.empty(); i++)
                why = number_in(c.Get(i), "attenuationColor", 0.0, 1.0, &rgb[i], clamped);
            if (why.empty()) x->attenuation_color = v3(rgb[0], rgb[1], rgb[2]);
        }
    }
    return why.empty() ? "" : name + ": " + why;
}

std::string normal_scale(const Value &e, const char *key, double limit, float *scale) {
    if (!e.Has(key) || !e.Get(key).IsObject() || !e.Get(key).Has("scale")) return "";
    const Value &v = e.Get(key).Get("scale");
    double d = v.IsNumber() ? v.GetNumberAsDouble() : NAN;
    if (!(std::fabs(d) <= limit))
        return std::string(key) + ".scale " + num(d) + " is not a finite number up to " + num(limit);
    *scale = (float)d;
    return "";
}

std::string texture_transform(const Value &x, float xf[6], int *texcoord) {
    if (!x.IsObject()) return "not an object";
    double offset[2] = {0.0, 0.0}, scale[2] = {1.0, 1.0}, rotation = 0.0;
    std::string why = pair(x, "offset", offset);
    if (why.empty()) why = pair(x, "scale", scale);
    if (!why.empty()) return why;
    if (x.Has("rotation")) {
        rotation = x.Get("rotation").IsNumber() ? x.Get("rotation").GetNumberAsDouble() : NAN;
        if (!(std::fabs(rotation) <= MAX_UV_TRANSFORM))
            return "rotation is not a finite number up to " + num(MAX_UV_TRANSFORM);
    }
    if (x.Has("texCoord")) {
        long long t = index_below(x.Get("texCoord"), 2147483647.0);
        if (t < 0) return "texCoord is not a valid index";
        *texcoord = (int)t;
    }
    double c = std::cos(rotation), s = std::sin(rotation);
    const double m[6] = {c * scale[0], s * scale[1], offset[0], -s * scale[0], c * scale[1], offset[1]};
    for (int k = 0; k < 6; k++) xf[k] = (float)m[k];
    return "";
}

std::string read_variants(scene *s, const tinygltf::Model &m) {
    auto it = m.extensions.find("KHR_materials_variants");
    if (it == m.extensions.end() || !it->second.Has("variants")) return "";
    const Value &list = it->second.Get("variants");
    if (!list.IsArray()) return "KHR_materials_variants: variants is not a list";
    size_t n = list.ArrayLen();
    if (n > SCENE_MAX_VARIANTS) return "KHR_materials_variants: more than " + num(SCENE_MAX_VARIANTS) + " variants";
    if (n == 0) return "";
    std::vector<std::string> names(n);
    std::vector<const char *> ptrs(n);
    for (size_t i = 0; i < n; i++) {
        const Value &v = list.Get((int)i);
        bool named = v.IsObject() && v.Has("name") && v.Get("name").IsString();
        names[i] = named ? v.Get("name").Get<std::string>() : "variant " + std::to_string(i);
        ptrs[i] = names[i].c_str();
    }
    return scene_add_variants(s, ptrs.data(), (int)n) == 0 ? "" : "out of memory";
}

std::string variant_table(scene *s, const tinygltf::Primitive &p, const std::vector<int> &material_map, int *table) {
    *table = -1;
    auto it = p.extensions.find("KHR_materials_variants");
    if (it == p.extensions.end()) return "";
    const Value &maps = it->second.Get("mappings");
    if (!maps.IsArray()) return "KHR_materials_variants: mappings is not a list";
    std::vector<int> vars, mats;
    for (size_t i = 0; i < maps.ArrayLen(); i++) {
        const Value &mp = maps.Get((int)i);
        long long mat =
            mp.IsObject() && mp.Has("material") ? index_below(mp.Get("material"), (double)material_map.size()) : -1;
        if (mat < 0) return "KHR_materials_variants: a mapping's material is not one of the file's";
        const Value &vs = mp.Get("variants");
        if (!vs.IsArray()) return "KHR_materials_variants: a mapping's variants is not a list";
        for (size_t j = 0; j < vs.ArrayLen(); j++) {
            long long v = index_below(vs.Get((int)j), scene_num_variants(s));
            if (v < 0)
                return "KHR_materials_variants: a mapping names a variant that is not one of the file's " +
                       std::to_string(scene_num_variants(s));
            if (vars.size() >= (size_t)SCENE_MAX_VARIANT_PAIRS) break; // scene_add_variant_table refuses
            vars.push_back((int)v);
            mats.push_back(material_map[(size_t)mat]);
        }
    }
    *table = scene_add_variant_table(s, vars.data(), mats.data(), (int)vars.size());
    return *table >= 0 ? ""
                       : "KHR_materials_variants: the file's mappings hold more than " + num(SCENE_MAX_VARIANT_PAIRS) +
                             " (variant, material) pairs in all";
}

} // namespace gltf_ext
