// glint — what the glTF importer reads besides the JSON's meaning (C++ only, used by
// gltf_import.cpp): files, read only when they are regular files, without blocking, within a size
// limit and inside the scene's folder; images, decoded only within a memory budget; and a check
// of the JSON's nesting before the recursive parser sees it.
#ifndef GLINT_GLTF_INPUT_H
#define GLINT_GLTF_INPUT_H

#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include <tiny_gltf.h>

namespace gltf_input {

constexpr unsigned long long MAX_FILE_BYTES = 2ull << 30;        // a scene, buffer or image file
constexpr int MAX_JSON_DEPTH = 64;                               // nested arrays and objects
constexpr unsigned long long MAX_IMAGE_BYTES = 256ull << 20;     // one image, decoded as RGBA
constexpr unsigned long long IMAGE_BUDGET_BYTES = 1024ull << 20; // all of a scene's images, decoded
constexpr int MAX_IMAGE_SIDE = 16384;

// Reads a regular file whole: opened without blocking (a FIFO or a device is refused, never read)
// and at most MAX_FILE_BYTES. Returns "" or the problem ("is a directory", strerror's text, ...).
std::string read_regular_file(const std::string &path, std::vector<unsigned char> *out);

// The deepest nesting of arrays and objects in JSON text, counted outside strings, or limit + 1
// as soon as it passes limit.
int json_depth(const char *text, size_t size, int limit);

// What one load reads: external URIs resolve in base_dir and below (no absolute paths, no '..'
// above it); why a file or image was not read is kept for the error that names it.
struct context {
    std::string base_dir;
    const tinygltf::Model *model = nullptr;          // being parsed: images in bufferViews are checked against it
    unsigned long long image_bytes = 0;              // decoded so far
    std::map<std::string, std::string> uri_problems; // URI -> why it was not read
    std::map<int, std::string> image_problems;       // image index -> why it was not decoded
    std::string last_problem;                        // "'URI': why", the latest
};

// Makes loader read through ctx: its file access and its image decoder.
void install(tinygltf::TinyGLTF *loader, context *ctx);

} // namespace gltf_input

#endif
