// glint — OpenEXR through OpenEXR's C++ library (Imf), which reads every compression the format
// has and is fuzzed upstream: reading, writing and header attributes. See exr_io.h. Every
// exception stops at the extern "C" functions at the end.
#include "exr_io.h"

#include <Iex.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputPart.h>
#include <ImfMultiPartInputFile.h>
#include <ImfOutputFile.h>
#include <ImfPartType.h>
#include <ImfStringAttribute.h>
#include <ImfTiledInputPart.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#include <unistd.h>

namespace {

#if defined(__GNUC__)
__attribute__((format(printf, 4, 5)))
#endif
// Writes "PATH: message" to err as one line and returns -1 (as image_io.c's fail).
int fail(char *err, size_t errlen, const char *path, const char *fmt, ...) {
    if (!err || errlen == 0) return -1;
    int n = std::snprintf(err, errlen, "%s: ", path ? path : "(null)");
    if (n >= 0 && (size_t)n < errlen) {
        va_list ap;
        va_start(ap, fmt);
        std::vsnprintf(err + n, errlen - (size_t)n, fmt, ap);
        va_end(ap);
    }
    // The library's messages may carry newlines; the contract is one line.
    for (char *c = err; *c; c++)
        if ((unsigned char)*c < 0x20) *c = ' ';
    size_t len = std::strlen(err);
    while (len > 0 && err[len - 1] == ' ') err[--len] = '\0';
    return -1;
}

struct Refused : std::runtime_error { // a file refused by our own checks, with its message
    using std::runtime_error::runtime_error;
};

// The open file as the library reads it, through a 64 KiB buffer of pread: reading past the end
// (a truncated file, an offset pointing nowhere) throws, as the library's own streams do.
class FdStream : public Imf::IStream {
  public:
    FdStream(const char *path, int fd, int64_t size) : Imf::IStream(path), fd_(fd), size_((uint64_t)size) {}

    bool read(char c[], int n) override {
        if (n < 0 || pos_ > size_ || (uint64_t)n > size_ - pos_) throw Iex::InputExc("unexpected end of file");
        uint64_t at = pos_, end = pos_ + (uint64_t)n;
        if (at >= buf_at_ && end <= buf_at_ + buf_len_) {
            std::memcpy(c, buf_.data() + (at - buf_at_), (size_t)n);
        } else if ((size_t)n >= buf_.size()) {
            pread_all(c, (size_t)n, at);
        } else {
            buf_len_ = (size_t)(size_ - at < buf_.size() ? size_ - at : buf_.size());
            buf_at_ = at;
            pread_all(buf_.data(), buf_len_, at);
            std::memcpy(c, buf_.data(), (size_t)n);
        }
        pos_ = end;
        return pos_ < size_;
    }
    uint64_t tellg() override { return pos_; }
    void seekg(uint64_t pos) override { pos_ = pos; }
    uint64_t size() const { return size_; }

  private:
    void pread_all(char *dst, size_t n, uint64_t at) {
        for (size_t done = 0; done < n;) {
            ssize_t got = pread(fd_, dst + done, n - done, (off_t)(at + done));
            if (got < 0 && errno == EINTR) continue;
            if (got < 0) throw Iex::InputExc(std::string("read error: ") + std::strerror(errno));
            if (got == 0) throw Iex::InputExc("unexpected end of file");
            done += (size_t)got;
        }
    }

    int fd_;
    uint64_t size_, pos_ = 0, buf_at_ = 0;
    size_t buf_len_ = 0;
    std::vector<char> buf_ = std::vector<char>(65536);
};

// A NUL-terminated name of at most 255 characters, as the header stores them.
std::string read_name(FdStream &in) {
    std::string s;
    for (;;) {
        char c;
        in.read(&c, 1);
        if (c == '\0') return s;
        if (s.size() == 255) throw Iex::InputExc("an attribute name in the header is too long");
        s += c;
    }
}

uint32_t le32(const unsigned char *b) {
    return (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
}

// The value size of the library's fixed-size attribute types, 0 for the others.
int64_t fixed_size(const std::string &type) {
    static const struct {
        const char *type;
        int64_t size;
    } sizes[] = {{"box2i", 16},
                 {"box2f", 16},
                 {"chromaticities", 32},
                 {"compression", 1},
                 {"deepImageState", 1},
                 {"double", 8},
                 {"envmap", 1},
                 {"float", 4},
                 {"int", 4},
                 {"keycode", 28},
                 {"lineOrder", 1},
                 {"m33d", 72},
                 {"m33f", 36},
                 {"m44d", 128},
                 {"m44f", 64},
                 {"rational", 8},
                 {"tiledesc", 9},
                 {"timecode", 8},
                 {"v2d", 16},
                 {"v2f", 8},
                 {"v2i", 8},
                 {"v3d", 24},
                 {"v3f", 12},
                 {"v3i", 12}};
    for (const auto &t : sizes)
        if (type == t.type) return t.size;
    return 0;
}

// Whether an attribute's value, n bytes at the stream's position, is what the library's reader for
// its type consumes, exactly: the channel list's entries ending with its terminator at n, a
// preview's 8 + 4 x width x height bytes, a string vector's strings filling n.
bool value_fits(FdStream &in, const std::string &type, int64_t n) {
    if (int64_t fixed = fixed_size(type)) return n == fixed;
    if (type == "floatvector") return n % 4 == 0;
    if (type == "idmanifest") return n >= 4;
    if (type == "preview") {
        if (n < 8) return false;
        unsigned char b[8];
        in.read(reinterpret_cast<char *>(b), 8);
        uint64_t pixels = (uint64_t)le32(b) * le32(b + 4); // < 2^64: both are 32-bit
        return pixels <= (uint64_t)(n - 8) / 4 && (uint64_t)n == 8 + 4 * pixels;
    }
    if (type != "chlist" && type != "stringvector") return true; // string, or opaque: n bytes
    std::vector<char> v((size_t)n);
    if (n > 0) in.read(v.data(), (int)n);
    const unsigned char *b = reinterpret_cast<const unsigned char *>(v.data());
    int64_t at = 0;
    if (type == "stringvector") {
        while (at < n) {
            if (n - at < 4 || (int64_t)le32(b + at) > n - at - 4) return false;
            at += 4 + (int64_t)le32(b + at);
        }
        return true;
    }
    for (;;) { // chlist: name, NUL, 16 bytes of description, ..., and an empty name
        const void *nul = at < n ? std::memchr(b + at, 0, (size_t)(n - at)) : nullptr;
        if (!nul) return false;
        int64_t len = static_cast<const unsigned char *>(nul) - (b + at);
        if (len == 0) return at + 1 == n;
        if (len > 255 || n - at - len - 1 < 16) return false;
        at += len + 1 + 16;
    }
}

// OpenEXR 3.1's header reader makes room for an attribute's value at the size the file declares
// before reading it (a string is resized, so zero-filled, first): 40 bytes declaring a 2 GB string
// would cost 2 GB. So every declared size is checked against the bytes left in the file first.
// The reader takes the size on trust only for strings and unknown types; the others read their own
// layout (a channel list up to its terminator, a preview by its width and height), which must then
// fill the declared size exactly: else the two walks through the header part, and the library's
// would meet sizes this one never checked.
void check_attribute_sizes(FdStream &in) {
    char version[4];
    in.seekg(4);
    in.read(version, 4);
    bool multipart = (version[1] & 0x10) != 0; // bit 12 of the version field
    for (bool more = true; more;) {            // one header, or a multi-part file's up to an empty one
        int attrs = 0;
        for (std::string name; !(name = read_name(in)).empty(); attrs++) {
            std::string type = read_name(in);
            unsigned char b[4];
            in.read(reinterpret_cast<char *>(b), 4);
            int64_t n = (int32_t)le32(b);
            if (n < 0 || (uint64_t)n > in.size() - in.tellg())
                throw Iex::InputExc("header attribute " + name + " claims " + std::to_string(n) +
                                    " bytes, more than the file holds");
            uint64_t end = in.tellg() + (uint64_t)n;
            if (!value_fits(in, type, n))
                throw Iex::InputExc("header attribute " + name + " is not a valid " + type + " of " +
                                    std::to_string(n) + " bytes");
            in.seekg(end);
        }
        more = multipart && attrs > 0;
    }
    in.seekg(0);
}

int64_t box_width(const Imath::Box2i &b) { return (int64_t)b.max.x - b.min.x + 1; }
int64_t box_height(const Imath::Box2i &b) { return (int64_t)b.max.y - b.min.y + 1; }

bool size_ok(int64_t w, int64_t h) {
    return w > 0 && h > 0 && w <= MAX_IMAGE_DIM && h <= MAX_IMAGE_DIM && w * h <= MAX_IMAGE_PIXELS;
}

// Re-frames img (fpp floats a pixel in each plane) from its data window onto the display window:
// pixels outside the data window are zero (as EXR defines them), data outside the display window
// is dropped.
void to_display_window(exr_image *img, const Imath::Box2i &dw, const Imath::Box2i &disp, size_t fpp) {
    int dispw = (int)box_width(disp), disph = (int)box_height(disp);
    int64_t x_lo = dw.min.x > disp.min.x ? dw.min.x : disp.min.x;
    int64_t x_hi = dw.max.x < disp.max.x ? dw.max.x : disp.max.x;
    for (int k = 0; k < img->num_channels; k++) {
        float *dst = static_cast<float *>(std::calloc((size_t)dispw * (size_t)disph * fpp, sizeof(float)));
        if (!dst) throw std::bad_alloc();
        const float *src = img->planes[k];
        for (int64_t y = disp.min.y; y <= disp.max.y && x_lo <= x_hi; y++) {
            if (y < dw.min.y || y > dw.max.y) continue;
            std::memcpy(dst + ((size_t)(y - disp.min.y) * (size_t)dispw + (size_t)(x_lo - disp.min.x)) * fpp,
                        src + ((size_t)(y - dw.min.y) * (size_t)img->width + (size_t)(x_lo - dw.min.x)) * fpp,
                        sizeof(float) * (size_t)(x_hi - x_lo + 1) * fpp);
        }
        std::free(img->planes[k]);
        img->planes[k] = dst;
    }
    img->width = dispw;
    img->height = disph;
}

// An environment map's texels, interleaved RGB over the display window: Y spread to G and B, DWA's
// slightly negative coding noise (lossy) read as zero, then every texel finite and non-negative.
// Only the data window's part of the display window holds anything but zeros, so only it is
// visited: a tiny data window in a huge display window costs little.
void finish_rgb(exr_image *img, const Imath::Box2i &dw, const Imath::Box2i &disp, bool gray, bool lossy) {
    int64_t x_lo = std::max(dw.min.x, disp.min.x), x_hi = std::min(dw.max.x, disp.max.x);
    int64_t y_lo = std::max(dw.min.y, disp.min.y), y_hi = std::min(dw.max.y, disp.max.y);
    for (int64_t y = y_lo; y <= y_hi; y++)
        for (int64_t x = x_lo; x <= x_hi; x++) {
            float *p = img->planes[0] + ((size_t)(y - disp.min.y) * (size_t)img->width + (size_t)(x - disp.min.x)) * 3;
            if (gray) p[1] = p[2] = p[0];
            for (int c = 0; c < 3; c++) {
                if (lossy && p[c] < 0.0f) p[c] = 0.0f;
                if (std::isfinite(p[c]) && p[c] >= 0.0f) continue;
                char what[160];
                std::snprintf(what, sizeof what, "pixel (%lld, %lld) channel %c is %s (%g)",
                              (long long)(x - disp.min.x), (long long)(y - disp.min.y), "RGB"[c],
                              std::isfinite(p[c]) ? "negative" : "not finite", (double)p[c]);
                throw Refused(what);
            }
        }
}

// The channels to read, in output order.
std::vector<std::string> pick_channels(const Imf::ChannelList &chans, exr_read_select select) {
    std::vector<std::string> pick;
    if (select != EXR_READ_ALL) {
        if (chans.findChannel("R") && chans.findChannel("G") && chans.findChannel("B"))
            pick = {"R", "G", "B"};
        else if (chans.findChannel("Y"))
            pick = {"Y"};
    } else {
        for (auto it = chans.begin(); it != chans.end(); ++it) pick.emplace_back(it.name());
    }
    if (pick.empty()) throw Refused(select != EXR_READ_ALL ? "no R, G, B or Y channel" : "no channels");
    return pick;
}

// Refuses what glint does not read (subsampled channels), and layouts whose buffers would be
// absurd before the library allocates them: its buffer for one chunk of every channel (up to 256
// scanlines for DWAB, or one tile).
void check_layout(const Imf::Header &h) {
    const Imath::Box2i &dw = h.dataWindow(), &disp = h.displayWindow();
    int64_t w = box_width(dw), ht = box_height(dw);
    if (!size_ok(w, ht) || !size_ok(box_width(disp), box_height(disp)))
        throw Refused("unsupported image size (data window " + std::to_string(w) + "x" + std::to_string(ht) +
                      ", display window " + std::to_string(box_width(disp)) + "x" + std::to_string(box_height(disp)) +
                      ")");
    uint64_t pixel_bytes = 0;
    for (auto it = h.channels().begin(); it != h.channels().end(); ++it) {
        const Imf::Channel &c = it.channel();
        // Subsampled channels come from luminance/chroma images, which would need reconstructing.
        if (c.xSampling != 1 || c.ySampling != 1)
            throw Refused(std::string("channel ") + it.name() +
                          " is subsampled (luminance/chroma images are not supported)");
        pixel_bytes += c.type == Imf::HALF ? 2 : 4;
    }
    const Imf::TileDescription *tile = h.hasTileDescription() ? &h.tileDescription() : nullptr;
    uint64_t chunk = tile ? (uint64_t)tile->xSize * tile->ySize * pixel_bytes : (uint64_t)w * 256 * pixel_bytes;
    if (chunk > ((uint64_t)1 << 28)) { // 256 MiB: a 16384-wide DWAB chunk of 4 floats is 64 MiB
        std::string what =
            std::to_string(pixel_bytes) + " bytes a pixel over " + std::to_string(w) + "x" + std::to_string(ht);
        if (tile) what += " in tiles of " + std::to_string(tile->xSize) + "x" + std::to_string(tile->ySize);
        throw Refused("unsupported image size (" + what + ")");
    }
}

// The first flat part of file: the one glint reads, pixels and attributes alike.
int first_flat_part(Imf::MultiPartInputFile &file) {
    for (int p = 0; p < file.parts(); p++)
        if (!Imf::isDeepData(file.header(p).type())) return p;
    throw Refused("no flat image part (deep data is not supported)");
}

void read_file(const char *path, int fd, int64_t size, exr_read_select select, exr_image *out, int *lossy_dct,
               const char **stage) {
    FdStream in(path, fd, size);
    check_attribute_sizes(in);
    // No worker threads: the renderer has its own. No rebuilt offset table: a damaged file is
    // refused with its error rather than loaded with holes.
    Imf::MultiPartInputFile file(in, 0, false);
    int part = first_flat_part(file);
    const Imf::Header &h = file.header(part);
    check_layout(h);
    std::vector<std::string> pick = pick_channels(h.channels(), select);
    const Imath::Box2i dw = h.dataWindow(), disp = h.displayWindow();
    // What is held at once, at most 2^29 floats (2 GiB), which still holds a 16384x8192 RGB
    // environment map: the planes as read and as re-framed (one at a time); or the interleaved
    // RGB, read in place when the data window lies inside the display window, else read and then
    // re-framed.
    const bool rgb = select == EXR_READ_RGB_INTERLEAVED;
    const bool inside =
        dw.min.x >= disp.min.x && dw.min.y >= disp.min.y && dw.max.x <= disp.max.x && dw.max.y <= disp.max.y;
    const uint64_t dw_px = (uint64_t)box_width(dw) * (uint64_t)box_height(dw);
    const uint64_t disp_px = (uint64_t)box_width(disp) * (uint64_t)box_height(disp);
    const uint64_t held = rgb ? 3 * (disp_px + (inside ? 0 : dw_px)) : pick.size() * std::max(dw_px, disp_px);
    if (held > ((uint64_t)1 << 29))
        throw Refused("unsupported image size (" + std::to_string(pick.size()) + " channels of " +
                      std::to_string(box_width(dw)) + "x" + std::to_string(box_height(dw)) + " in " +
                      std::to_string(box_width(disp)) + "x" + std::to_string(box_height(disp)) + ")");

    const bool in_place = rgb && inside;
    const Imath::Box2i &frame = in_place ? disp : dw; // what the planes cover
    const size_t planes = rgb ? 1 : pick.size(), fpp = rgb ? 3 : 1;
    out->width = (int)box_width(frame);
    out->height = (int)box_height(frame);
    out->names = static_cast<char **>(std::calloc(planes, sizeof(char *)));
    out->planes = static_cast<float **>(std::calloc(planes, sizeof(float *)));
    if (!out->names || !out->planes) throw std::bad_alloc();
    for (size_t k = 0; k < planes; k++) {
        out->num_channels = (int)k + 1;
        out->names[k] = strdup(rgb ? "RGB" : pick[k].c_str());
        out->planes[k] =
            static_cast<float *>(std::calloc((size_t)out->width * (size_t)out->height * fpp, sizeof(float)));
        if (!out->names[k] || !out->planes[k]) throw std::bad_alloc();
    }
    Imf::FrameBuffer fb; // half and uint convert to float
    for (size_t k = 0; k < pick.size(); k++) {
        float *first = rgb ? out->planes[0] + k : out->planes[k]; // the frame's first pixel
        if (in_place)
            first += ((size_t)(dw.min.y - disp.min.y) * (size_t)out->width + (size_t)(dw.min.x - disp.min.x)) * 3;
        fb.insert(pick[k], Imf::Slice::Make(Imf::FLOAT, first, dw, sizeof(float) * fpp,
                                            sizeof(float) * fpp * (size_t)out->width));
    }

    *stage = "corrupt or truncated file";
    if (h.hasTileDescription()) { // level 0 of tiled files, straight into the planes
        Imf::TiledInputPart tiles(file, part);
        tiles.setFrameBuffer(fb);
        tiles.readTiles(0, tiles.numXTiles(0) - 1, 0, tiles.numYTiles(0) - 1, 0, 0);
    } else {
        Imf::InputPart lines(file, part);
        lines.setFrameBuffer(fb);
        lines.readPixels(dw.min.y, dw.max.y);
    }
    const bool lossy = h.compression() == Imf::DWAA_COMPRESSION || h.compression() == Imf::DWAB_COMPRESSION;
    if (lossy_dct) *lossy_dct = lossy;
    if (frame != disp) to_display_window(out, dw, disp, fpp);
    if (rgb) finish_rgb(out, dw, disp, pick.size() == 1, lossy);
}

// The string attribute name of the first flat part's header, copied with malloc into *value;
// returns false when there is none.
bool read_string(const char *path, int fd, int64_t size, const char *name, char **value, size_t *len) {
    FdStream in(path, fd, size);
    check_attribute_sizes(in);
    Imf::MultiPartInputFile file(in, 0, false);
    const Imf::Header &h = file.header(first_flat_part(file));
    Imf::Header::ConstIterator it = h.find(name);
    if (it == h.end()) return false;
    const Imf::StringAttribute *attr = h.findTypedAttribute<Imf::StringAttribute>(name);
    if (!attr)
        throw Refused(std::string("header attribute ") + name + " is of type " + it.attribute().typeName() +
                      ", not string");
    const std::string &v = attr->value();
    char *copy = static_cast<char *>(std::malloc(v.size() + 1));
    if (!copy) throw std::bad_alloc();
    std::memcpy(copy, v.data(), v.size());
    copy[v.size()] = '\0';
    *value = copy;
    *len = v.size();
    return true;
}

// The file as the library writes it, in memory, so that the file on disk appears only complete
// (through write_file_atomic). The library seeks back to fill in the line offset table, and does
// so in OutputFile's destructor, which swallows exceptions: a failed allocation is remembered.
class MemStream : public Imf::OStream {
  public:
    explicit MemStream(const char *path) : Imf::OStream(path) {}
    ~MemStream() override { std::free(data_); }
    MemStream(const MemStream &) = delete;
    MemStream &operator=(const MemStream &) = delete;

    void write(const char c[], int n) override {
        if (n <= 0) return;
        size_t end = pos_ + (size_t)n;
        if (end > cap_) {
            size_t cap = cap_ ? cap_ : (size_t)1 << 16;
            while (cap < end) cap *= 2;
            char *grown = static_cast<char *>(std::realloc(data_, cap));
            if (!grown) {
                failed = true;
                throw std::bad_alloc();
            }
            data_ = grown;
            cap_ = cap;
        }
        if (pos_ > size_) std::memset(data_ + size_, 0, pos_ - size_); // zero fills a gap
        std::memcpy(data_ + pos_, c, (size_t)n);
        pos_ = end;
        size_ = end > size_ ? end : size_;
    }
    uint64_t tellp() override { return pos_; }
    void seekp(uint64_t pos) override { pos_ = (size_t)pos; }

    // The bytes written, handed over as C memory (the caller frees them): no copy of the file.
    char *release(size_t *size) {
        char *d = data_;
        *size = size_;
        data_ = nullptr;
        size_ = cap_ = pos_ = 0;
        return d;
    }

    bool failed = false;

  private:
    char *data_ = nullptr;
    size_t size_ = 0, cap_ = 0, pos_ = 0;
};

// Attributes the format defines or that OpenEXR sets itself: a string under one of these names
// would make the file unreadable or mean something else.
bool reserved_attribute(const Imf::Header &h, const char *name) {
    static const char *const optional[] = {"tiles", "type", "name", "version", "chunkCount", "maxSamplesPerPixel"};
    for (const char *o : optional)
        if (std::strcmp(name, o) == 0) return true;
    return h.find(name) != h.end();
}

// One channel a layer and colour: "R" for the unnamed layer, "direct.R" for layer direct.
void encode(MemStream &out, int width, int height, const exr_layer *layers, int num_layers, const exr_text_attr *attrs,
            int num_attrs) {
    // The defaults are what glint writes: display window = data window = width x height, ZIP (the
    // format's lossless standard, smaller than RLE on renders), increasing y.
    Imf::Header header(width, height);
    for (int i = 0; i < num_attrs; i++) {
        if (reserved_attribute(header, attrs[i].name))
            throw Refused(std::string("header attribute name '") + attrs[i].name + "' is taken by the format");
        header.insert(attrs[i].name, Imf::StringAttribute(attrs[i].value));
    }
    Imf::FrameBuffer fb;
    const size_t xstride = 3 * sizeof(float), ystride = xstride * (size_t)width;
    for (int l = 0; l < num_layers; l++)
        for (int c = 0; c < 3; c++) {
            std::string name = layers[l].prefix[0] ? std::string(layers[l].prefix) + "." : std::string();
            name += "RGB"[c];
            // The library keeps channels sorted by name, as the format requires, and binds the frame
            // buffer by name: the order here does not matter. Slices are only read from.
            header.channels().insert(name, Imf::Channel(Imf::FLOAT));
            char *base = reinterpret_cast<char *>(const_cast<float *>(layers[l].rgb + c));
            fb.insert(name, Imf::Slice(Imf::FLOAT, base, xstride, ystride));
        }
    Imf::OutputFile file(out, header, 0); // no worker threads: the caller may be a render thread
    file.setFrameBuffer(fb);
    file.writePixels(height);
}

// Runs body, turning every exception into "PATH: problem" in err (stage: what the library was
// doing, for its own messages; oom: the message for a failed allocation). Returns 0 or -1.
template <class Body, class Oom>
int guarded(const char *path, char *err, size_t errlen, const char *const &stage, Body body, Oom oom) {
    try {
        body();
        return 0;
    } catch (const Refused &e) {
        return fail(err, errlen, path, "%s", e.what());
    } catch (const std::bad_alloc &) {
        return fail(err, errlen, path, "%s", oom().c_str());
    } catch (const std::exception &e) {
        // The library names the file in its messages, which follow ours: once is enough.
        std::string why = e.what();
        for (const std::string &named : {"image file \"" + std::string(path) + "\"", "\"" + std::string(path) + "\""})
            for (size_t at; (at = why.find(named)) != std::string::npos;) why.replace(at, named.size(), "the file");
        return fail(err, errlen, path, "%s: %s", stage, why.c_str());
    } catch (...) {
        return fail(err, errlen, path, "%s", stage);
    }
}

// The magic number every OpenEXR file starts with, checked before the library sees the file.
int check_magic(const char *path, int fd, int64_t size, char *err, size_t errlen) {
    static const unsigned char magic[4] = {0x76, 0x2f, 0x31, 0x01};
    unsigned char head[4] = {0, 0, 0, 0};
    if (size == 0) return fail(err, errlen, path, "empty file");
    if (pread(fd, head, 4, 0) != 4 || std::memcmp(head, magic, 4) != 0)
        return fail(err, errlen, path, "not an OpenEXR file");
    return 0;
}

} // namespace

extern "C" int exr_read_fd(const char *path, int fd, int64_t size, exr_read_select select, exr_image *out,
                           int *lossy_dct, char *err, size_t errlen) {
    std::memset(out, 0, sizeof *out);
    if (lossy_dct) *lossy_dct = 0;
    if (check_magic(path, fd, size, err, errlen) != 0) return -1;
    const char *stage = "not a readable OpenEXR file";
    int status = guarded(
        path, err, errlen, stage, [&] { read_file(path, fd, size, select, out, lossy_dct, &stage); },
        [&] {
            return out->width > 0 ? "out of memory for a " + std::to_string(out->width) + "x" +
                                        std::to_string(out->height) + " image"
                                  : std::string("out of memory");
        });
    if (status != 0) exr_image_free(out);
    return status;
}

extern "C" int exr_read_string_fd(const char *path, int fd, int64_t size, const char *name, char **value, size_t *len,
                                  char *err, size_t errlen) {
    *value = nullptr;
    *len = 0;
    if (check_magic(path, fd, size, err, errlen) != 0) return -1;
    const char *stage = "not a readable OpenEXR file";
    bool found = false;
    int status = guarded(
        path, err, errlen, stage, [&] { found = read_string(path, fd, size, name, value, len); },
        [] { return std::string("out of memory"); });
    if (status != 0) return -1;
    return found ? 0 : 1;
}

extern "C" int exr_encode_layers(const char *path, int width, int height, const exr_layer *layers, int num_layers,
                                 const exr_text_attr *attrs, int num_attrs, void **out, size_t *size, char *err,
                                 size_t errlen) {
    *out = nullptr;
    *size = 0;
    const char *stage = "cannot encode OpenEXR";
    int status = guarded(
        path, err, errlen, stage,
        [&] {
            MemStream stream(path);
            encode(stream, width, height, layers, num_layers, attrs, num_attrs); // complete once it returns
            if (stream.failed) throw std::bad_alloc();
            *out = stream.release(size);
        },
        [] { return std::string("out of memory"); });
    return status != 0 ? -1 : 0;
}

/* Frees what exr_read_fd reads (declared in image_io.h, for every reader of an exr_image): here,
 * beside the allocation, so that this file calls nothing of image_io.c's. */
extern "C" void exr_image_free(exr_image *img) {
    if (!img) return;
    for (int i = 0; i < img->num_channels; i++) {
        if (img->names) std::free(img->names[i]);
        if (img->planes) std::free(img->planes[i]);
    }
    std::free(img->names);
    std::free(img->planes);
    std::memset(img, 0, sizeof *img);
}
