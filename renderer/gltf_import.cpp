// glint — glTF 2.0 import through tinygltf (Debian's libtinygltf, compiled library: no
// TINYGLTF_IMPLEMENTATION here). The only C++ in the renderer: it validates what tinygltf parsed
// and hands plain arrays to the C scene builder (scene_add_*).
#include "gltf_import.h"

#include <algorithm>
#include <cerrno>
#include <cfloat>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

#include <tiny_gltf.h>

#include "gltf_extensions.h"
#include "gltf_input.h"

namespace {

using tinygltf::Accessor;
using tinygltf::Model;
using tinygltf::Value;

// Thrown inside the importer for any problem with the file; caught at the C boundary.
struct import_error {
    std::string what;
};

[[noreturn]] void fail(const std::string &what) { throw import_error{what}; }

// The first line of a parser's message, cut short (it may quote a whole data URI).
std::string first_line(const std::string &s) {
    size_t a = s.find_first_not_of(" \n\r\t");
    if (a == std::string::npos) return "";
    size_t b = s.find_first_of("\n\r", a);
    std::string line = s.substr(a, b == std::string::npos ? std::string::npos : b - a);
    return line.size() > 160 ? line.substr(0, 150) + "..." : line;
}

// A double as float, beyond float's range as infinity (later checks refuse it) rather than by an
// undefined conversion.
float to_f(double v) { return std::fabs(v) <= (double)FLT_MAX ? (float)v : (float)std::copysign(INFINITY, v); }

// Text from the file (a URI, a name) made fit for a one-line message: control characters become '?'.
std::string printable(std::string t) {
    for (char &c : t)
        if ((unsigned char)c < 0x20 || c == 0x7f) c = '?';
    return t;
}

using gltf_ext::num;

// Limits on what a scene may hold (README states them).
constexpr int MAX_NODE_DEPTH = 4096;                       // nesting of the node hierarchy
constexpr long MAX_NODE_INSTANCES = 1000000;               // node visits, counting each instance of a shared node
constexpr double MAX_INTENSITY = 1e20;                     // light intensities, emission, material factors
constexpr size_t MAX_INSTANCED_ELEMENTS = (size_t)1 << 27; // vertices + indices over all mesh instances

// ---- accessors ----------------------------------------------------------------------------

int component_size(int type) {
    switch (type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_INT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
    default: return 0;
    }
}

int type_components(int type) {
    switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
    default: return 0;
    }
}

template <typename T> T load(const unsigned char *p) {
    T v;
    std::memcpy(&v, p, sizeof v);
    return v;
}

// One component as double: normalized integers map to [0,1] or [-1,1] as the spec says.
double read_component(const unsigned char *p, int type, bool normalized) {
    switch (type) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return load<float>(p);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return normalized ? p[0] / 255.0 : p[0];
    case TINYGLTF_COMPONENT_TYPE_BYTE: return normalized ? std::fmax(load<int8_t>(p) / 127.0, -1.0) : load<int8_t>(p);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return normalized ? load<uint16_t>(p) / 65535.0 : load<uint16_t>(p);
    case TINYGLTF_COMPONENT_TYPE_SHORT:
        return normalized ? std::fmax(load<int16_t>(p) / 32767.0, -1.0) : load<int16_t>(p);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return load<uint32_t>(p);
    case TINYGLTF_COMPONENT_TYPE_INT: return load<int32_t>(p);
    default: return 0.0;
    }
}

// Checked view of `count` elements of `elem_size` bytes in a bufferView; returns the first
// element's address and the stride.
const unsigned char *view_elements(const Model &m, int view_index, size_t offset, size_t count, size_t elem_size,
                                   size_t *stride, const std::string &what) {
    if (view_index < 0 || (size_t)view_index >= m.bufferViews.size())
        fail(what + ": bufferView " + std::to_string(view_index) + " out of range");
    const tinygltf::BufferView &bv = m.bufferViews[(size_t)view_index];
    if (bv.buffer < 0 || (size_t)bv.buffer >= m.buffers.size())
        fail(what + ": buffer " + std::to_string(bv.buffer) + " out of range");
    const tinygltf::Buffer &buf = m.buffers[(size_t)bv.buffer];
    if (bv.byteOffset > buf.data.size() || bv.byteLength > buf.data.size() - bv.byteOffset)
        fail(what + ": bufferView " + std::to_string(view_index) + " extends past the end of its buffer (" +
             std::to_string(buf.data.size()) + " bytes; truncated file?)");
    size_t s = bv.byteStride ? bv.byteStride : elem_size;
    if (s < elem_size) fail(what + ": byteStride smaller than the element");
    if (count > 0) {
        // offset + s*(count-1) + elem_size <= byteLength, without overflow
        if (offset > bv.byteLength || elem_size > bv.byteLength - offset ||
            (count > 1 && (bv.byteLength - offset - elem_size) / s < count - 1))
            fail(what + ": accessor reads past the end of bufferView " + std::to_string(view_index));
    }
    *stride = s;
    return buf.data.data() + bv.byteOffset + offset;
}

// Reads an accessor as `want` doubles per element (sparse accessors applied).
std::vector<double> read_accessor(const Model &m, int index, int want, const std::string &what) {
    if (index < 0 || (size_t)index >= m.accessors.size())
        fail(what + ": accessor " + std::to_string(index) + " out of range");
    const Accessor &a = m.accessors[(size_t)index];
    int nc = type_components(a.type), cs = component_size(a.componentType);
    if (nc != want || cs == 0)
        fail(what + ": accessor " + std::to_string(index) + " has the wrong type (" + std::to_string(nc) +
             " components, expected " + std::to_string(want) + ")");
    if (a.count > (1u << 28)) fail(what + ": accessor " + std::to_string(index) + " is too large");
    // Without a bufferView the elements are zeros (then sparse values): nothing in the file bounds them.
    if (a.bufferView < 0 && a.count > (1u << 20))
        fail(what + ": accessor " + std::to_string(index) + " has no bufferView and more than 1048576 elements");
    size_t stride = 0;
    const unsigned char *p =
        a.bufferView >= 0 ? view_elements(m, a.bufferView, a.byteOffset, a.count, (size_t)(nc * cs), &stride, what)
                          : nullptr;
    std::vector<double> out(a.count * (size_t)want, 0.0);
    if (p) {
        for (size_t i = 0; i < a.count; i++)
            for (int c = 0; c < nc; c++)
                out[i * (size_t)want + (size_t)c] =
                    read_component(p + i * stride + (size_t)(c * cs), a.componentType, a.normalized);
    }
    if (a.sparse.isSparse) {
        size_t n = (size_t)a.sparse.count, istride, vstride;
        int ics = component_size(a.sparse.indices.componentType);
        if (ics == 0 || n > a.count) fail(what + ": invalid sparse accessor " + std::to_string(index));
        const unsigned char *ip = view_elements(m, a.sparse.indices.bufferView, (size_t)a.sparse.indices.byteOffset, n,
                                                (size_t)ics, &istride, what);
        const unsigned char *vp = view_elements(m, a.sparse.values.bufferView, (size_t)a.sparse.values.byteOffset, n,
                                                (size_t)(nc * cs), &vstride, what);
        istride = (size_t)ics; // sparse arrays are tightly packed
        vstride = (size_t)(nc * cs);
        for (size_t i = 0; i < n; i++) {
            double target = read_component(ip + i * istride, a.sparse.indices.componentType, false);
            if (!(target >= 0.0) || target >= (double)a.count) fail(what + ": sparse index out of range");
            for (int c = 0; c < nc; c++)
                out[(size_t)target * (size_t)want + (size_t)c] =
                    read_component(vp + i * vstride + (size_t)(c * cs), a.componentType, a.normalized);
        }
    }
    for (double v : out)
        if (!std::isfinite(v)) fail(what + ": accessor " + std::to_string(index) + " holds non-finite values");
    return out;
}

std::vector<float> to_float(const std::vector<double> &d) {
    std::vector<float> f(d.size());
    for (size_t i = 0; i < d.size(); i++) f[i] = to_f(d[i]);
    return f;
}

// ---- materials and textures ---------------------------------------------------------------

// An index in an extension's JSON: a whole number from 0 to INT_MAX, else an error naming it.
int index_or(const Value &obj, const char *key, int fallback, const std::string &what) {
    if (!obj.IsObject() || !obj.Has(key)) return fallback;
    const Value &v = obj.Get(key);
    double d = v.IsNumber() ? v.GetNumberAsDouble() : -1.0;
    if (!(d >= 0.0 && d <= (double)INT_MAX) || d != std::floor(d))
        fail(what + ": " + key + " " + (v.IsNumber() ? num(d) : "(not a number)") + " is not a valid index");
    return (int)d;
}

// A factor or intensity as float: finite, non-negative, at most MAX_INTENSITY; else an error.
float factor(double v, const std::string &what, const char *name) {
    if (!(std::fabs(v) <= MAX_INTENSITY))
        fail(what + ": " + name + " " + num(v) + " is not a finite number up to " + num(MAX_INTENSITY));
    if (v < 0.0) fail(what + ": " + name + " " + num(v) + " is negative");
    return (float)v;
}

vec3 factor3(const double c[3], const std::string &what, const char *name) {
    return v3(factor(c[0], what, name), factor(c[1], what, name), factor(c[2], what, name));
}

vec3 vec3_from(const std::vector<double> &v, vec3 fallback) {
    return v.size() >= 3 ? v3(to_f(v[0]), to_f(v[1]), to_f(v[2])) : fallback;
}

vec3 factor3_or(const std::vector<double> &v, vec3 fallback, const std::string &what, const char *name) {
    return v.size() >= 3 ? factor3(v.data(), what, name) : fallback;
}

struct importer {
    scene *s;
    const Model &m;
    std::string name;
    std::vector<int> texture_map; // glTF texture -> scene texture (-1 until used)
    std::vector<int> image_map;   // glTF image -> scene image
    std::vector<int> material_map;
    std::vector<char> on_stack; // nodes on the current path: a node met again there is a cycle
    long instances = 0;         // node visits so far
    size_t elements = 0;        // vertices and indices read, over all instances
    const gltf_input::context &in;

    importer(scene *sc, const Model &model, const std::string &n, const gltf_input::context &input)
        : s(sc), m(model), name(n), in(input) {}

    // Why image i has no pixels, as its loader or file access found.
    std::string image_problem(int i) const {
        auto p = in.image_problems.find(i);
        if (p != in.image_problems.end()) return p->second;
        auto u = in.uri_problems.find(m.images[(size_t)i].uri);
        return u != in.uri_problems.end() ? u->second : "missing or unreadable";
    }

    texture_slot texture(int index, int texcoord, const std::string &what) {
        if (index < 0) return texture_slot{-1, 0};
        if ((size_t)index >= m.textures.size()) fail(what + ": texture " + std::to_string(index) + " out of range");
        if (texcoord < 0 || texcoord > 1) {
            scene_warn(s, "%s: %s uses TEXCOORD_%d; only TEXCOORD_0 and _1 are supported, using 0", name.c_str(),
                       what.c_str(), texcoord);
            texcoord = 0;
        }
        int &mapped = texture_map[(size_t)index];
        if (mapped < 0) {
            const tinygltf::Texture &t = m.textures[(size_t)index];
            int src = t.source;
            if (src < 0 || (size_t)src >= m.images.size())
                fail(what + ": texture " + std::to_string(index) + " has no valid image (source " +
                     std::to_string(src) + ")");
            int &img = image_map[(size_t)src];
            if (img < 0) {
                const tinygltf::Image &im = m.images[(size_t)src];
                std::string label = im.uri.empty() ? std::to_string(src) : "'" + im.uri + "'";
                if (im.image.empty() || im.width <= 0 || im.height <= 0)
                    fail("texture image " + label + ": " + image_problem(src));
                size_t need = (size_t)im.width * (size_t)im.height * (size_t)im.component * (size_t)(im.bits / 8);
                if (im.image.size() < need) fail("texture image " + label + " is truncated");
                img = scene_add_image(s, im.width, im.height, im.component, im.bits, im.image.data());
                if (img < 0) fail("texture image " + label + " has an unsupported format");
            }
            scene_texture st{img, WRAP_REPEAT, WRAP_REPEAT};
            if (t.sampler >= 0 && (size_t)t.sampler < m.samplers.size()) {
                auto wrap = [](int w) {
                    return w == TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE     ? WRAP_CLAMP
                           : w == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT ? WRAP_MIRROR
                                                                        : WRAP_REPEAT;
                };
                st.wrap_s = wrap(m.samplers[(size_t)t.sampler].wrapS);
                st.wrap_t = wrap(m.samplers[(size_t)t.sampler].wrapT);
            }
            mapped = scene_add_texture(s, st);
            if (mapped < 0) fail("out of memory");
        }
        return texture_slot{mapped, texcoord};
    }

    // A texture reference (index, texCoord, the reference's extensions) with its
    // KHR_texture_transform: offset, rotation and scale as the extension's matrix T R S, and a
    // texCoord that overrides the reference's. Every texture slot comes through here.
    texture_slot texture_ref(int index, int texcoord, const Value *transform, const std::string &what) {
        if (index < 0) return texture_slot{-1, 0};
        float xf[6] = {1, 0, 0, 0, 1, 0};
        if (transform) {
            std::string why = gltf_ext::texture_transform(*transform, xf, &texcoord);
            if (!why.empty()) fail(what + ": KHR_texture_transform: " + why);
        }
        texture_slot slot = texture(index, texcoord, what);
        slot.transformed = transform != nullptr;
        std::memcpy(slot.uv_xf, xf, sizeof xf);
        return slot;
    }

    static const Value *transform_of(const tinygltf::ExtensionMap &ext) {
        auto it = ext.find("KHR_texture_transform");
        return it == ext.end() ? nullptr : &it->second;
    }
    texture_slot texture(const tinygltf::TextureInfo &t, const std::string &what) {
        return texture_ref(t.index, t.texCoord, transform_of(t.extensions), what);
    }
    texture_slot texture(const tinygltf::NormalTextureInfo &t, const std::string &what) {
        return texture_ref(t.index, t.texCoord, transform_of(t.extensions), what);
    }
    // A textureInfo object inside a material extension (JSON as tinygltf keeps it).
    texture_slot texture(const Value &t, const std::string &what) {
        const Value *transform = nullptr;
        if (t.IsObject() && t.Has("extensions") && t.Get("extensions").Has("KHR_texture_transform"))
            transform = &t.Get("extensions").Get("KHR_texture_transform");
        return texture_ref(index_or(t, "index", -1, what), std::min(index_or(t, "texCoord", 0, what), 2), transform,
                           what);
    }

    // A textureInfo inside an extension's JSON ({index, texCoord, KHR_texture_transform}), or no texture.
    texture_slot ext_texture(const Value &e, const char *key, const std::string &label) {
        if (!e.Has(key)) return texture_slot{-1, 0};
        return texture(e.Get(key), label + ": " + key);
    }

    // The number under key in a material's JSON, or fallback where it is absent; anything there but a
    // number is the file's mistake: said, and the fallback taken.
    double number_or(const Value &obj, const char *key, double fallback, const std::string &what) {
        if (!obj.IsObject() || !obj.Has(key)) return fallback;
        const Value &v = obj.Get(key);
        if (v.IsNumber()) return v.GetNumberAsDouble();
        scene_warn(s, "%s: %s: %s is not a number, using %g", name.c_str(), what.c_str(), key, fallback);
        return fallback;
    }

    // A colour (three numbers, each a factor) under key, the same way.
    vec3 color_or(const Value &obj, const char *key, vec3 fallback, const std::string &what) {
        if (!obj.IsObject() || !obj.Has(key)) return fallback;
        const Value &v = obj.Get(key);
        double c[3];
        bool ok = v.IsArray() && v.ArrayLen() == 3;
        for (int i = 0; ok && i < 3; i++) {
            ok = v.Get(i).IsNumber();
            if (ok) c[i] = v.Get(i).GetNumberAsDouble();
        }
        if (ok) return factor3(c, what, key);
        scene_warn(s, "%s: %s: %s is not three numbers, using (%g, %g, %g)", name.c_str(), what.c_str(), key,
                   (double)fallback.x, (double)fallback.y, (double)fallback.z);
        return fallback;
    }

    // ---- the material model's extensions (docs/design.md, "The glTF material") ----

    void ext_ior(material &mat, const Value &e, const std::string &label) {
        mat.ext.ior = factor(number_or(e, "ior", 1.5, label), label, "ior");
        if (mat.ext.ior < 1.0f) { // no dielectric's index is below vacuum's
            scene_warn(s, "%s: %s: ior %g is below 1, clamped to 1", name.c_str(), label.c_str(), (double)mat.ext.ior);
            mat.ext.ior = 1.0f;
        }
    }

    void ext_specular(material &mat, const Value &e, const std::string &label) {
        mat.ext.specular = factor(number_or(e, "specularFactor", 1.0, label), label, "specularFactor");
        mat.ext.specular_color = color_or(e, "specularColorFactor", v3s(1.0f), label);
        mat.ext.specular_tex = ext_texture(e, "specularTexture", label);
        mat.ext.specular_color_tex = ext_texture(e, "specularColorTexture", label);
    }

    void ext_sheen(material &mat, const Value &e, const std::string &label) {
        mat.ext.sheen_color = color_or(e, "sheenColorFactor", v3s(0.0f), label);
        mat.ext.sheen_roughness =
            factor(number_or(e, "sheenRoughnessFactor", 0.0, label), label, "sheenRoughnessFactor");
        mat.ext.sheen_color_tex = ext_texture(e, "sheenColorTexture", label);
        mat.ext.sheen_roughness_tex = ext_texture(e, "sheenRoughnessTexture", label);
    }

    void ext_clearcoat(material &mat, const Value &e, const std::string &label) {
        mat.ext.clearcoat = factor(number_or(e, "clearcoatFactor", 0.0, label), label, "clearcoatFactor");
        mat.ext.clearcoat_roughness =
            factor(number_or(e, "clearcoatRoughnessFactor", 0.0, label), label, "clearcoatRoughnessFactor");
        mat.ext.clearcoat_tex = ext_texture(e, "clearcoatTexture", label);
        mat.ext.clearcoat_roughness_tex = ext_texture(e, "clearcoatRoughnessTexture", label);
        mat.ext.clearcoat_normal_tex = ext_texture(e, "clearcoatNormalTexture", label);
        std::string why =
            gltf_ext::normal_scale(e, "clearcoatNormalTexture", MAX_INTENSITY, &mat.ext.clearcoat_normal_scale);
        if (!why.empty()) fail(label + ": " + why);
    }

    // glTF's [0, 1] factors: a value above 1 is clamped, with one warning per material
    // (specularColorFactor may exceed 1).
    void clamp_unit(material &mat, const std::string &label) {
        material_ext &x = mat.ext;
        float *f[] = {&mat.base_color.x,     &mat.base_color.y,        &mat.base_color.z,  &mat.metallic,
                      &mat.roughness,        &mat.anisotropy_strength, &x.specular,        &x.sheen_color.x,
                      &x.sheen_color.y,      &x.sheen_color.z,         &x.sheen_roughness, &x.clearcoat,
                      &x.clearcoat_roughness};
        bool clamped = false;
        for (float *v : f)
            if (*v > 1.0f) *v = 1.0f, clamped = true;
        if (clamped)
            scene_warn(s, "%s: %s: a colour or factor above 1 (glTF's range is 0 to 1), clamped to 1", name.c_str(),
                       label.c_str());
    }

    // normalTexture: tangent-space normals in glTF's convention, x and y scaled. The
    // occlusionTexture is ignored on purpose: a path tracer computes occlusion (docs/design.md).
    void normal_map(const tinygltf::Material &gm, material &mat, const std::string &label, const std::string &what) {
        const tinygltf::NormalTextureInfo &nt = gm.normalTexture;
        if (nt.index < 0) return;
        mat.normal_tex = texture(nt, what);
        if (!(std::fabs(nt.scale) <= MAX_INTENSITY))
            fail(label + ": normalTexture.scale " + num(nt.scale) + " is not a finite number up to " +
                 num(MAX_INTENSITY));
        mat.normal_scale = (float)nt.scale;
    }

    // alphaMode with its cutoff, and baseColorFactor's alpha (the base colour texture's alpha
    // multiplies it where a ray meets the surface).
    void alpha(const tinygltf::Material &gm, material &mat, const std::string &label) {
        const std::vector<double> &f = gm.pbrMetallicRoughness.baseColorFactor;
        if (f.size() >= 4) mat.base_alpha = factor(f[3], label, "baseColorFactor's alpha");
        if (mat.base_alpha > 1.0f) {
            mat.base_alpha = 1.0f;
            scene_warn(s, "%s: %s: baseColorFactor's alpha is above 1, clamped to 1", name.c_str(), label.c_str());
        }
        mat.alpha_cutoff = factor(gm.alphaCutoff, label, "alphaCutoff");
        if (gm.alphaMode == "MASK")
            mat.alpha = ALPHA_MASK;
        else if (gm.alphaMode == "BLEND")
            mat.alpha = ALPHA_BLEND;
        else if (!gm.alphaMode.empty() && gm.alphaMode != "OPAQUE")
            scene_warn(s, "%s: %s: unknown alphaMode '%s', drawn opaque", name.c_str(), label.c_str(),
                       gm.alphaMode.c_str());
    }

    void materials() {
        material_map.assign(m.materials.size(), -1);
        for (size_t i = 0; i < m.materials.size(); i++) {
            const tinygltf::Material &gm = m.materials[i];
            std::string what = "material " + std::to_string(i);
            material mat = material_default();
            std::snprintf(mat.name, sizeof mat.name, "%s", gm.name.empty() ? what.c_str() : gm.name.c_str());
            const auto &pbr = gm.pbrMetallicRoughness;
            std::string label = "material '" + std::string(mat.name) + "'";
            mat.base_color = factor3_or(pbr.baseColorFactor, v3s(1.0f), label, "baseColorFactor");
            mat.metallic = factor(pbr.metallicFactor, label, "metallicFactor");
            mat.roughness = factor(pbr.roughnessFactor, label, "roughnessFactor");
            mat.base_color_tex = texture(pbr.baseColorTexture, what);
            mat.metal_rough_tex = texture(pbr.metallicRoughnessTexture, what);
            mat.emission = factor3_or(gm.emissiveFactor, v3s(0.0f), label, "emissiveFactor");
            mat.emissive_tex = texture(gm.emissiveTexture, what);
            mat.double_sided = gm.doubleSided;
            for (const auto &ext : gm.extensions) {
                const Value &e = ext.second;
                if (ext.first == "KHR_materials_emissive_strength") {
                    float k = factor(number_or(e, "emissiveStrength", 1.0, label), label, "emissiveStrength");
                    mat.emission = scale3(mat.emission, k);
                    double c[3] = {mat.emission.x, mat.emission.y, mat.emission.z};
                    factor3(c, label, "emissiveFactor x emissiveStrength");
                } else if (ext.first == "KHR_materials_anisotropy") {
                    mat.anisotropy_strength =
                        factor(number_or(e, "anisotropyStrength", 0.0, label), label, "anisotropyStrength");
                    double rot = number_or(e, "anisotropyRotation", 0.0, label);
                    if (!(std::fabs(rot) <= 1e6)) fail(label + ": anisotropyRotation " + num(rot) + " is not an angle");
                    mat.anisotropy_rotation = (float)rot;
                    if (e.Has("anisotropyTexture"))
                        mat.anisotropy_tex = texture(e.Get("anisotropyTexture"), label + ": anisotropyTexture");
                } else if (ext.first == "KHR_materials_ior") {
                    ext_ior(mat, e, label);
                } else if (ext.first == "KHR_materials_specular") {
                    ext_specular(mat, e, label);
                } else if (ext.first == "KHR_materials_sheen") {
                    ext_sheen(mat, e, label);
                } else if (ext.first == "KHR_materials_clearcoat") {
                    ext_clearcoat(mat, e, label);
                } else if (ext.first == "KHR_materials_transmission" || ext.first == "KHR_materials_volume") {
                    bool clamped = false;
                    std::string why = gltf_ext::material_transmission_volume(
                        ext.first, e, &mat.ext, [&](const char *key) { return ext_texture(e, key, label); }, &clamped);
                    if (!why.empty()) fail(label + ": " + why);
                    if (clamped)
                        scene_warn(s, "%s: %s: %s: a factor out of range, clamped", name.c_str(), label.c_str(),
                                   ext.first.c_str());
                }
            }
            // The papers' lobes: extras.glint = {model: "phong"|"ward", kd, ks, exponent, alpha_x, alpha_y, rotation}
            if (gm.extras.IsObject() && gm.extras.Has("glint")) {
                const Value &g = gm.extras.Get("glint");
                std::string model =
                    g.Has("model") && g.Get("model").IsString() ? g.Get("model").Get<std::string>() : "";
                if (model == "phong" || model == "ward") {
                    mat.model = model == "phong" ? MATERIAL_PHONG : MATERIAL_WARD;
                    mat.kd = color_or(g, "kd", v3s(0.0f), label);
                    mat.ks = color_or(g, "ks", v3s(0.5f), label);
                    mat.exponent = factor(number_or(g, "exponent", 64.0, label), label, "exponent");
                    mat.alpha_x = factor(number_or(g, "alpha_x", 0.1, label), label, "alpha_x");
                    mat.alpha_y = factor(number_or(g, "alpha_y", mat.alpha_x, label), label, "alpha_y");
                    double rot = number_or(g, "rotation", 0.0, label);
                    if (!(std::fabs(rot) <= 1e6)) fail(label + ": rotation " + num(rot) + " is not an angle");
                    mat.anisotropy_rotation = (float)rot;
                    // Textures other than emission do not apply to these lobes, except base colour tinting kd.
                } else if (!model.empty() && model != "gltf") {
                    scene_warn(s, "%s: %s: unknown extras.glint.model '%s', using metallic-roughness", name.c_str(),
                               mat.name, model.c_str());
                }
            }
            clamp_unit(mat, label);
            alpha(gm, mat, label);
            normal_map(gm, mat, label, what);
            material_map[i] = scene_add_material(s, &mat);
            if (material_map[i] < 0) fail("out of memory");
        }
    }

    // KHR_materials_variants: per primitive its mappings as one table, made at its first
    // instance and shared by the others (gltf_extensions.cpp reads them).
    std::vector<std::vector<int>> variant_tables; // [mesh][primitive]: table, -1 none, -2 not read yet

    int variant_table(int mesh, size_t prim, const tinygltf::Primitive &p, const std::string &what) {
        int &table = variant_tables[(size_t)mesh][prim];
        std::string why = table == -2 ? gltf_ext::variant_table(s, p, material_map, &table) : "";
        if (!why.empty()) fail(what + ": " + why);
        return table;
    }

    // ---- nodes, meshes, lights, cameras ----------------------------------------------------

    static mat4 node_local(const tinygltf::Node &n) {
        mat4 r = mat4_identity();
        if (n.matrix.size() == 16) {
            for (int c = 0; c < 4; c++)
                for (int row = 0; row < 4; row++) r.m[row][c] = to_f(n.matrix[(size_t)(c * 4 + row)]); // column-major
            return r;
        }
        vec3 t = vec3_from(n.translation, v3s(0.0f));
        vec3 sc = vec3_from(n.scale, v3s(1.0f));
        double q[4] = {0, 0, 0, 1};
        if (n.rotation.size() == 4)
            for (int i = 0; i < 4; i++) q[i] = n.rotation[(size_t)i];
        double qn = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
        if (qn > 0)
            for (double &c : q) c /= qn;
        double x = q[0], y = q[1], z = q[2], w = q[3];
        double R[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
                          {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
                          {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}};
        float scl[3] = {sc.x, sc.y, sc.z};
        for (int row = 0; row < 3; row++)
            for (int c = 0; c < 3; c++) r.m[row][c] = to_f(R[row][c] * scl[c]);
        r.m[0][3] = t.x;
        r.m[1][3] = t.y;
        r.m[2][3] = t.z;
        return r;
    }

    void mesh(int index, const mat4 &xf) {
        if (index < 0 || (size_t)index >= m.meshes.size()) fail("mesh " + std::to_string(index) + " out of range");
        const tinygltf::Mesh &gm = m.meshes[(size_t)index];
        for (size_t pi = 0; pi < gm.primitives.size(); pi++) {
            const tinygltf::Primitive &p = gm.primitives[pi];
            std::string what = "mesh " + std::to_string(index) + " primitive " + std::to_string(pi);
            int mode = p.mode < 0 ? TINYGLTF_MODE_TRIANGLES : p.mode;
            if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
                mode != TINYGLTF_MODE_TRIANGLE_FAN) {
                scene_warn(s, "%s: skipping %s: points and lines are not rendered", name.c_str(), what.c_str());
                continue;
            }
            auto attr = [&](const char *key) {
                auto it = p.attributes.find(key);
                return it == p.attributes.end() ? -1 : it->second;
            };
            if (attr("POSITION") < 0) fail(what + " has no POSITION");
            std::vector<float> pos = to_float(read_accessor(m, attr("POSITION"), 3, what + " POSITION"));
            size_t nv = pos.size() / 3;
            if (nv == 0) continue;
            auto optional = [&](const char *key, int comps) {
                std::vector<float> v;
                if (attr(key) >= 0) {
                    v = to_float(read_accessor(m, attr(key), comps, what + " " + key));
                    if (v.size() / (size_t)comps != nv) fail(what + ": " + key + " count differs from POSITION");
                }
                return v;
            };
            std::vector<float> nrm = optional("NORMAL", 3), tan = optional("TANGENT", 4);
            std::vector<float> uv0 = optional("TEXCOORD_0", 2), uv1 = optional("TEXCOORD_1", 2);
            std::vector<uint32_t> idx;
            if (p.indices >= 0) {
                if ((size_t)p.indices >= m.accessors.size()) fail(what + ": index accessor out of range");
                const Accessor &ia = m.accessors[(size_t)p.indices];
                if (ia.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
                    ia.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
                    ia.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
                    fail(what + ": indices must be unsigned integers");
                std::vector<double> raw = read_accessor(m, p.indices, 1, what + " indices");
                idx.reserve(raw.size());
                for (double d : raw) {
                    if (d >= (double)nv)
                        fail(what + ": vertex index " + std::to_string((unsigned long long)d) + " out of range (" +
                             std::to_string(nv) + " vertices)");
                    idx.push_back((uint32_t)d);
                }
            } else if (mode != TINYGLTF_MODE_TRIANGLES) {
                for (size_t i = 0; i < nv; i++) idx.push_back((uint32_t)i);
            }
            if (mode == TINYGLTF_MODE_TRIANGLE_STRIP || mode == TINYGLTF_MODE_TRIANGLE_FAN) {
                std::vector<uint32_t> tri;
                for (size_t i = 2; i < idx.size(); i++) {
                    if (mode == TINYGLTF_MODE_TRIANGLE_FAN)
                        tri.insert(tri.end(), {idx[0], idx[i - 1], idx[i]});
                    else if (i % 2 == 0)
                        tri.insert(tri.end(), {idx[i - 2], idx[i - 1], idx[i]});
                    else
                        tri.insert(tri.end(), {idx[i - 1], idx[i - 2], idx[i]});
                }
                idx.swap(tri);
            }
            // Each instance reads its mesh again: bound the total, or shared nodes multiply it.
            if ((elements += nv + idx.size()) > MAX_INSTANCED_ELEMENTS)
                fail(what + ": the scene's mesh instances hold more than " + std::to_string(MAX_INSTANCED_ELEMENTS) +
                     " vertices and indices in all");
            size_t ncount = p.indices >= 0 || mode != TINYGLTF_MODE_TRIANGLES ? idx.size() : nv;
            if (ncount % 3 != 0) {
                scene_warn(s, "%s: %s has %zu indices, not a multiple of 3; dropping the rest", name.c_str(),
                           what.c_str(), ncount);
                ncount -= ncount % 3;
                if (!idx.empty()) idx.resize(ncount);
            }
            if (ncount == 0) continue;
            if (ncount > (1u << 30) || nv > (1u << 30)) fail(what + " is too large");
            int material = -1;
            if (p.material >= 0) {
                if ((size_t)p.material >= material_map.size())
                    fail(what + ": material " + std::to_string(p.material) + " out of range");
                material = material_map[(size_t)p.material];
            }
            mesh_desc md{};
            md.num_vertices = (int)nv;
            md.positions = pos.data();
            md.normals = nrm.empty() ? nullptr : nrm.data();
            md.tangents = tan.empty() ? nullptr : tan.data();
            md.uv0 = uv0.empty() ? nullptr : uv0.data();
            md.uv1 = uv1.empty() ? nullptr : uv1.data();
            md.num_indices = idx.empty() ? 0 : (int)idx.size();
            md.indices = idx.empty() ? nullptr : idx.data();
            if (idx.empty() && nv % 3 != 0) md.num_vertices = (int)(nv - nv % 3);
            md.material = material;
            char err[256];
            int table = variant_table(index, pi, p, what), first = s->num_triangles;
            if (scene_add_mesh(s, &md, &xf, err, sizeof err) != 0) fail(what + ": " + err);
            if (table >= 0 && scene_map_variants(s, first, table) != 0) fail("out of memory");
        }
    }

    void punctual(const Value &ext, const mat4 &xf) {
        int li = index_or(ext, "light", -1, "KHR_lights_punctual");
        if (li < 0 || (size_t)li >= m.lights.size())
            fail("KHR_lights_punctual: light " + std::to_string(li) + " out of range");
        const tinygltf::Light &gl = m.lights[(size_t)li];
        light l;
        std::memset(&l, 0, sizeof l);
        std::snprintf(l.name, sizeof l.name, "%s",
                      gl.name.empty() ? ("light " + std::to_string(li)).c_str() : gl.name.c_str());
        std::string label = std::string("light '") + l.name + "'";
        vec3 color = factor3_or(gl.color, v3s(1.0f), label, "color");
        float intensity = factor(gl.intensity, label, "intensity");
        double c[3] = {(double)color.x * intensity, (double)color.y * intensity, (double)color.z * intensity};
        l.color = factor3(c, label, "color x intensity");
        l.position = xform_point(&xf, v3(0, 0, 0));
        l.direction = normalize3(xform_vector(&xf, v3(0, 0, -1)));
        l.range = factor(gl.range, label, "range");
        check_position(l.position, label);
        if (gl.type == "point") {
            l.type = LIGHT_POINT;
        } else if (gl.type == "spot") {
            l.type = LIGHT_SPOT;
            double outer = std::fmin(std::fmax(gl.spot.outerConeAngle, 0.0), M_PI / 2);
            double inner = std::fmin(std::fmax(gl.spot.innerConeAngle, 0.0), outer);
            l.cos_inner = (float)std::cos(inner);
            l.cos_outer = (float)std::cos(outer);
        } else if (gl.type == "directional") {
            l.type = LIGHT_DIRECTIONAL;
        } else {
            scene_warn(s, "%s: light '%s' has unknown type '%s'; ignored", name.c_str(), l.name, gl.type.c_str());
            return;
        }
        if (!is_finite3(l.color) || !is_finite3(l.position) || !is_finite3(l.direction) ||
            length_sq3(l.direction) == 0.0f)
            fail(std::string("light '") + l.name + "' has an invalid transform or intensity");
        if (scene_add_light(s, &l) < 0) fail("out of memory");
    }

    void add_camera(int ci, const mat4 &xf) {
        if (ci < 0 || (size_t)ci >= m.cameras.size()) fail("camera " + std::to_string(ci) + " out of range");
        const tinygltf::Camera &gc = m.cameras[(size_t)ci];
        if (gc.type != "perspective") {
            scene_warn(s, "%s: camera %d is %s; only perspective cameras are supported", name.c_str(), ci,
                       gc.type.c_str());
            return;
        }
        camera c;
        std::memset(&c, 0, sizeof c);
        std::snprintf(c.name, sizeof c.name, "%s",
                      gc.name.empty() ? ("camera " + std::to_string(ci)).c_str() : gc.name.c_str());
        c.position = xform_point(&xf, v3(0, 0, 0));
        check_position(c.position, "camera " + std::to_string(ci));
        c.forward = normalize3(xform_vector(&xf, v3(0, 0, -1)));
        vec3 up = xform_vector(&xf, v3(0, 1, 0));
        c.right = normalize3(cross3(c.forward, up));
        c.up = cross3(c.right, c.forward);
        c.yfov = to_f(gc.perspective.yfov);
        if (!(c.yfov > 1e-4f && c.yfov < 3.1f) || !is_finite3(c.forward) || !is_finite3(c.right) || !is_finite3(c.up) ||
            length_sq3(c.right) < 0.5f) {
            scene_warn(s, "%s: camera %d has an invalid transform or field of view; ignored", name.c_str(), ci);
            return;
        }
        if (scene_add_camera(s, &c) < 0) fail("out of memory");
    }

    // A point (a light's, a camera's) within the coordinate limit, else an error.
    static void check_position(vec3 p, const std::string &what) {
        if (!(std::fabs(p.x) < SCENE_MAX_COORD && std::fabs(p.y) < SCENE_MAX_COORD && std::fabs(p.z) < SCENE_MAX_COORD))
            fail(what + " lies at (" + num(p.x) + ", " + num(p.y) + ", " + num(p.z) +
                 ") after its transforms; coordinates must be finite and within +-" + num(SCENE_MAX_COORD));
    }

    // Enters node index under parent: checks, then its mesh, camera and light; pushes it.
    struct frame {
        int node;
        size_t next_child;
        mat4 xf;
    };
    void enter(int index, const mat4 &parent, std::vector<frame> &path) {
        if (index < 0 || (size_t)index >= m.nodes.size()) fail("node " + std::to_string(index) + " out of range");
        if (on_stack[(size_t)index]) fail("node hierarchy has a cycle at node " + std::to_string(index));
        if (path.size() >= (size_t)MAX_NODE_DEPTH)
            fail("node hierarchy is deeper than " + std::to_string(MAX_NODE_DEPTH) + " levels (at node " +
                 std::to_string(index) + ")");
        if (++instances > MAX_NODE_INSTANCES)
            fail("node hierarchy has more than " + std::to_string(MAX_NODE_INSTANCES) +
                 " node instances (nodes shared by several parents count once per parent)");
        on_stack[(size_t)index] = 1;
        const tinygltf::Node &n = m.nodes[(size_t)index];
        mat4 xf = mat4_mul(parent, node_local(n));
        if (n.mesh >= 0) mesh(n.mesh, xf);
        if (n.camera >= 0) add_camera(n.camera, xf);
        auto it = n.extensions.find("KHR_lights_punctual");
        if (it != n.extensions.end()) punctual(it->second, xf);
        path.push_back(frame{index, 0, xf});
    }

    // The hierarchy under root, depth first, without recursion.
    void node(int root) {
        std::vector<frame> path;
        enter(root, mat4_identity(), path);
        while (!path.empty()) {
            frame &top = path.back();
            const std::vector<int> &children = m.nodes[(size_t)top.node].children;
            if (top.next_child < children.size()) {
                int c = children[top.next_child++];
                mat4 xf = top.xf; // enter() may move the path
                enter(c, xf, path);
            } else {
                on_stack[(size_t)top.node] = 0;
                path.pop_back();
            }
        }
    }

    void run() {
        static const char *supported[] = {"KHR_lights_punctual",      "KHR_materials_emissive_strength",
                                          "KHR_materials_anisotropy", "KHR_materials_ior",
                                          "KHR_materials_specular",   "KHR_materials_sheen",
                                          "KHR_materials_clearcoat",  "KHR_texture_transform",
                                          "KHR_materials_variants",   "KHR_materials_transmission",
                                          "KHR_materials_volume"};
        for (const std::string &e : m.extensionsUsed) {
            bool ok = false;
            for (const char *sup : supported) ok = ok || e == sup;
            if (!ok) scene_warn(s, "%s: ignoring unsupported extension %s", name.c_str(), e.c_str());
        }
        texture_map.assign(m.textures.size(), -1);
        image_map.assign(m.images.size(), -1);
        on_stack.assign(m.nodes.size(), 0);
        variant_tables.resize(m.meshes.size());
        for (size_t i = 0; i < m.meshes.size(); i++) variant_tables[i].assign(m.meshes[i].primitives.size(), -2);
        materials();
        std::string why = gltf_ext::read_variants(s, m);
        if (!why.empty()) fail(why);
        if (!m.scenes.empty()) {
            int si = m.defaultScene >= 0 && (size_t)m.defaultScene < m.scenes.size() ? m.defaultScene : 0;
            for (int r : m.scenes[(size_t)si].nodes) node(r);
        } else {
            // No scene: render every root node (one that is nobody's child).
            std::vector<char> is_child(m.nodes.size(), 0);
            for (const auto &n : m.nodes)
                for (int c : n.children)
                    if (c >= 0 && (size_t)c < m.nodes.size()) is_child[(size_t)c] = 1;
            for (size_t i = 0; i < m.nodes.size(); i++)
                if (!is_child[i]) node((int)i);
        }
    }
};

// The JSON text of a .gltf, or a GLB's JSON chunk (as far as the data goes).
void check_nesting(const unsigned char *data, size_t size, bool glb) {
    const char *text = (const char *)data;
    size_t n = size;
    if (glb) {
        uint32_t chunk = 0;
        if (size >= 20) std::memcpy(&chunk, data + 12, 4);
        text += size >= 20 ? 20 : size;
        n = size >= 20 ? std::min<size_t>(chunk, size - 20) : 0;
    }
    if (gltf_input::json_depth(text, n, gltf_input::MAX_JSON_DEPTH) > gltf_input::MAX_JSON_DEPTH)
        fail("JSON nests deeper than " + std::to_string(gltf_input::MAX_JSON_DEPTH) + " levels");
}

// The parser's warnings, less those about files and images, which the importer reports itself.
void pass_warnings(scene *s, const std::string &name, const std::string &w) {
    static const char *own[] = {"File not found", "File read error", "File is empty", "Failed to load external"};
    for (size_t a = 0; a < w.size();) {
        size_t b = w.find('\n', a);
        std::string line = first_line(w.substr(a, b == std::string::npos ? std::string::npos : b - a));
        bool skip = line.empty();
        for (const char *o : own) skip = skip || line.compare(0, std::strlen(o), o) == 0;
        if (!skip) scene_warn(s, "%s: %s", name.c_str(), line.c_str());
        if (b == std::string::npos) break;
        a = b + 1;
    }
}

int import(scene *s, const unsigned char *data, size_t size, const std::string &base_dir, const std::string &name,
           char *err, size_t errlen) {
    try {
        if (size < 4) fail("file is empty or truncated");
        if (size > 0x7fffffffu) fail("file is larger than 2 GiB");
        bool glb = std::memcmp(data, "glTF", 4) == 0;
        check_nesting(data, size, glb);
        tinygltf::TinyGLTF loader;
        Model model;
        gltf_input::context input;
        input.base_dir = base_dir;
        input.model = &model;
        gltf_input::install(&loader, &input);
        std::string e, w;
        bool ok = glb ? loader.LoadBinaryFromMemory(&model, &e, &w, data, (unsigned int)size, base_dir)
                      : loader.LoadASCIIFromString(&model, &e, &w, (const char *)data, (unsigned int)size, base_dir);
        if (!ok) {
            std::string why = first_line(e);
            // A buffer file not read: say why, as file access found it.
            if (why.compare(0, 5, "File ") == 0 && !input.last_problem.empty()) why = "buffer " + input.last_problem;
            fail(why.empty() ? "not a valid glTF file" : why);
        }
        pass_warnings(s, name, w);
        importer imp(s, model, name, input);
        imp.run();
        // Images no texture uses are not needed; one that could not be read is worth a word.
        for (size_t i = 0; i < model.images.size(); i++)
            if (imp.image_map[i] < 0 && model.images[i].image.empty()) {
                const std::string &uri = model.images[i].uri;
                scene_warn(s, "%s: unused image %s not read: %s", name.c_str(),
                           uri.empty() ? std::to_string(i).c_str() : printable("'" + uri + "'").c_str(),
                           printable(imp.image_problem((int)i)).c_str());
            }
        return 0;
    } catch (const import_error &ie) {
        std::snprintf(err, errlen, "%s: %s", name.c_str(), printable(ie.what).c_str());
    } catch (const std::bad_alloc &) {
        std::snprintf(err, errlen, "%s: out of memory", name.c_str());
    } catch (const std::exception &ex) {
        std::snprintf(err, errlen, "%s: malformed glTF (%s)", name.c_str(), first_line(ex.what()).c_str());
    }
    return -1;
}

std::string dir_of(const std::string &path) {
    size_t slash = path.find_last_of('/');
    return slash == std::string::npos ? std::string(".") : path.substr(0, slash == 0 ? 1 : slash);
}

} // namespace

extern "C" int gltf_import_file(scene *s, const char *path, char *err, size_t errlen) {
    std::vector<unsigned char> data;
    std::string why;
    try {
        why = gltf_input::read_regular_file(path, &data);
    } catch (const std::exception &) {
        why = "out of memory";
    }
    if (!why.empty()) return std::snprintf(err, errlen, "%s: %s", path, why.c_str()), -1;
    return import(s, data.data(), data.size(), dir_of(path), path, err, errlen);
}

extern "C" int gltf_import_memory(scene *s, const void *data, size_t size, const char *base_dir, const char *name,
                                  char *err, size_t errlen) {
    return import(s, (const unsigned char *)data, size, base_dir ? base_dir : ".", name ? name : "<memory>", err,
                  errlen);
}
