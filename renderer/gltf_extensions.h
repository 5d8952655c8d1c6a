// glint — glTF extensions read from tinygltf's JSON values (C++ only, used by gltf_import.cpp):
// KHR_texture_transform on a texture reference, KHR_materials_variants, and the material model's
// KHR_materials_transmission and _volume, and a normal textureInfo's scale inside an extension.
// Each returns "" or the problem, for the importer's one-line error.
#ifndef GLINT_GLTF_EXTENSIONS_H
#define GLINT_GLTF_EXTENSIONS_H

#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include <tiny_gltf.h>

#include "scene.h"

namespace gltf_ext {

constexpr double MAX_UV_TRANSFORM = 1e6; // offsets, scales and rotations of KHR_texture_transform

// A number for a message.
inline std::string num(double v) {
    char b[32];
    std::snprintf(b, sizeof b, "%g", v);
    return b;
}

// KHR_texture_transform (x: the extension's object): the extension's matrix T R S into xf
// (u' = xf[0] u + xf[1] v + xf[2], v' = xf[3] u + xf[4] v + xf[5]) and its texCoord, when it has
// one, into *texcoord.
std::string texture_transform(const tinygltf::Value &x, float xf[6], int *texcoord);

// KHR_materials_transmission or KHR_materials_volume (name; e: the extension's object) into x;
// texture reads one of the extension's textureInfo keys. Factors above their range are clamped
// (*clamped set); a negative factor, a non-positive attenuationDistance or a non-number is the
// problem.
std::string material_transmission_volume(const std::string &name, const tinygltf::Value &e, material_ext *x,
                                         const std::function<texture_slot(const char *)> &texture, bool *clamped);

// The scale of the normal textureInfo under key (e: an extension's object) into *scale, untouched
// when absent; a non-number or one beyond +-limit is the problem.
std::string normal_scale(const tinygltf::Value &e, const char *key, double limit, float *scale);

// The file's material variants, by name, into s.
std::string read_variants(scene *s, const tinygltf::Model &m);

// Primitive p's mappings as one of s's variant tables (*table; -1 when it has none);
// material_map takes the file's materials to the scene's.
std::string variant_table(scene *s, const tinygltf::Primitive &p, const std::vector<int> &material_map, int *table);

} // namespace gltf_ext

#endif
