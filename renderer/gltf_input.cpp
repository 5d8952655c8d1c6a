// glint — the glTF importer's files and images: regular files only, read without blocking and
// within limits, inside the scene's folder; images decoded only within a memory budget.
#include "gltf_input.h"

#include <cerrno>
#include <cstring>
#include <new>

#include <fcntl.h>
#include <stb_image.h>
#include <sys/stat.h>
#include <unistd.h>

namespace gltf_input {

namespace {

std::string too_large() { return "is larger than " + std::to_string(MAX_FILE_BYTES >> 30) + " GiB"; }

// What a stat says against reading the file, or "".
std::string refuse(const struct stat &st) {
    if (S_ISDIR(st.st_mode)) return "is a directory";
    if (!S_ISREG(st.st_mode)) return "is not a regular file (a pipe or a device?)";
    if ((unsigned long long)st.st_size > MAX_FILE_BYTES) return too_large();
    return "";
}

// The URI a path the parser built names, when it lies in the base folder: the parser tries
// base/URI, then ./URI (the working directory), and only the first is ours.
bool uri_of(const context *ctx, const std::string &path, std::string *uri) {
    std::string prefix = ctx->base_dir;
    if (!prefix.empty() && prefix.back() != '/') prefix += '/';
    if (path.compare(0, prefix.size(), prefix) != 0) return false;
    *uri = path.substr(prefix.size());
    return true;
}

// The policy: URIs are relative paths that stay in the scene's folder.
std::string outside(const std::string &uri) {
    if (uri.empty()) return "empty URI";
    if (uri[0] == '/') return "absolute paths are not read (URIs are relative to the scene's folder)";
    int depth = 0;
    for (size_t a = 0; a <= uri.size();) {
        size_t b = uri.find('/', a);
        if (b == std::string::npos) b = uri.size();
        std::string part = uri.substr(a, b - a);
        if (part == "..") {
            if (--depth < 0) return "'..' leads out of the scene's folder (only files in it and below are read)";
        } else if (!part.empty() && part != ".") {
            depth++;
        }
        a = b + 1;
    }
    return "";
}

void note(context *ctx, const std::string &uri, const std::string &why) {
    ctx->uri_problems.emplace(uri, why);
    ctx->last_problem = "'" + uri + "': " + why;
}

bool file_exists(const std::string &path, void *user) {
    context *ctx = static_cast<context *>(user);
    std::string uri;
    if (!uri_of(ctx, path, &uri)) return false;
    std::string why = outside(uri);
    struct stat st;
    if (why.empty()) why = stat(path.c_str(), &st) != 0 ? std::strerror(errno) : refuse(st);
    if (!why.empty()) note(ctx, uri, why);
    return why.empty();
}

std::string expand_file_path(const std::string &path, void *) { return path; }

bool read_whole_file(std::vector<unsigned char> *out, std::string *err, const std::string &path, void *user) {
    context *ctx = static_cast<context *>(user);
    std::string uri;
    std::string why = uri_of(ctx, path, &uri) ? outside(uri) : "outside the scene's folder";
    if (why.empty()) why = read_regular_file(path, out);
    if (why.empty()) return true;
    note(ctx, uri.empty() ? path : uri, why);
    if (err) *err += why;
    return false;
}

bool write_whole_file(std::string *err, const std::string &, const std::vector<unsigned char> &, void *) {
    if (err) *err += "glint does not write glTF files";
    return false;
}

std::string mib(unsigned long long bytes) { return std::to_string((bytes + (1u << 20) - 1) >> 20) + " MiB"; }

// Decodes into image, or returns why not.
std::string decode(context *ctx, tinygltf::Image *image, const unsigned char *bytes, int size) {
    if (image->bufferView >= 0 && ctx->model) {
        // The parser hands over bufferView bytes without checking that they lie in the buffer.
        const tinygltf::Model &m = *ctx->model;
        const tinygltf::BufferView &bv = m.bufferViews.at((size_t)image->bufferView);
        const tinygltf::Buffer &buf = m.buffers.at((size_t)bv.buffer);
        if (bv.byteOffset > buf.data.size() || bv.byteLength > buf.data.size() - bv.byteOffset)
            return "its bufferView " + std::to_string(image->bufferView) + " extends past the end of its buffer (" +
                   std::to_string(buf.data.size()) + " bytes)";
        if (bv.byteLength > 0x7fffffffu) return "is larger than 2 GiB";
    }
    if (!bytes || size <= 0) return "no image data";
    int w = 0, h = 0, comp = 0;
    if (!stbi_info_from_memory(bytes, size, &w, &h, &comp) || w <= 0 || h <= 0) {
        const char *r = stbi_failure_reason();
        return std::string("cannot be decoded: ") + (r && *r ? r : "unknown format");
    }
    bool sixteen = stbi_is_16_bit_from_memory(bytes, size) != 0;
    // Decoded as stb gives it (at most 4 channels), before the scene's RGBA copy.
    unsigned long long need = (unsigned long long)w * (unsigned long long)h * 4u * (sixteen ? 2u : 1u);
    std::string dims = std::to_string(w) + " x " + std::to_string(h) + " pixels";
    if (w > MAX_IMAGE_SIDE || h > MAX_IMAGE_SIDE)
        return dims + ": more than " + std::to_string(MAX_IMAGE_SIDE) + " on a side";
    if (need > MAX_IMAGE_BYTES)
        return dims + " take " + mib(need) + " decoded, more than the " + mib(MAX_IMAGE_BYTES) + " one image may";
    if (ctx->image_bytes + need > IMAGE_BUDGET_BYTES)
        return dims + " would bring the scene's decoded images past their budget of " + mib(IMAGE_BUDGET_BYTES);
    void *pixels = sixteen ? (void *)stbi_load_16_from_memory(bytes, size, &w, &h, &comp, 0)
                           : (void *)stbi_load_from_memory(bytes, size, &w, &h, &comp, 0);
    if (!pixels) {
        const char *r = stbi_failure_reason();
        return std::string("cannot be decoded: ") + (r && *r ? r : "corrupt data");
    }
    size_t n = (size_t)w * (size_t)h * (size_t)comp * (sixteen ? 2u : 1u);
    try {
        image->image.assign((const unsigned char *)pixels, (const unsigned char *)pixels + n);
    } catch (const std::bad_alloc &) {
        stbi_image_free(pixels);
        return "out of memory";
    }
    stbi_image_free(pixels);
    ctx->image_bytes += need;
    image->width = w;
    image->height = h;
    image->component = comp;
    image->bits = sixteen ? 16 : 8;
    image->pixel_type = sixteen ? TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT : TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
    return "";
}

// An image that cannot be read does not fail the load: only a texture that uses it does, with
// the reason kept here.
bool load_image(tinygltf::Image *image, const int index, std::string *, std::string *, int, int,
                const unsigned char *bytes, int size, void *user) {
    context *ctx = static_cast<context *>(user);
    std::string why = decode(ctx, image, bytes, size);
    if (!why.empty()) {
        ctx->image_problems.emplace(index, why);
        image->image.clear();
        image->width = image->height = 0;
    }
    return true;
}

} // namespace

std::string read_regular_file(const std::string &path, std::vector<unsigned char> *out) {
    out->clear();
    int fd = open(path.c_str(), O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
    if (fd < 0) return std::strerror(errno);
    struct stat st;
    std::string why = fstat(fd, &st) != 0 ? std::strerror(errno) : refuse(st);
    if (why.empty()) {
        try {
            out->resize((size_t)st.st_size);
        } catch (const std::bad_alloc &) {
            why = "out of memory";
        }
    }
    size_t got = 0;
    while (why.empty() && got < out->size()) {
        ssize_t r = read(fd, out->data() + got, out->size() - got);
        if (r < 0 && errno == EINTR) continue;
        if (r < 0) why = std::strerror(errno);
        if (r <= 0) break;
        got += (size_t)r;
    }
    close(fd);
    out->resize(why.empty() ? got : 0); // a file that shrank while read: what was there
    return why;
}

int json_depth(const char *text, size_t size, int limit) {
    int depth = 0, deepest = 0;
    bool in_string = false;
    for (size_t i = 0; i < size; i++) {
        char c = text[i];
        if (in_string) {
            if (c == '\\')
                i++;
            else if (c == '"')
                in_string = false;
        } else if (c == '"') {
            in_string = true;
        } else if (c == '{' || c == '[') {
            if (++depth > deepest && (deepest = depth) > limit) return limit + 1;
        } else if (c == '}' || c == ']') {
            depth--;
        }
    }
    return deepest;
}

void install(tinygltf::TinyGLTF *loader, context *ctx) {
    tinygltf::FsCallbacks fs{};
    fs.FileExists = file_exists;
    fs.ExpandFilePath = expand_file_path;
    fs.ReadWholeFile = read_whole_file;
    fs.WriteWholeFile = write_whole_file;
    fs.user_data = ctx;
    loader->SetFsCallbacks(fs);
    loader->SetImageLoader(load_image, ctx);
}

} // namespace gltf_input
