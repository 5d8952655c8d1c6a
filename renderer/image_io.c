/* glint — image files: OpenEXR read and written through its C++ library (exr_io.cpp), Radiance
 * HDR through stb_image, PNG through stb_image_write, and the atomic writer every export goes
 * through. See image_io.h. */
#define _XOPEN_SOURCE 700 /* pread, fsync, link, strdup, lstat, clock_gettime, realpath */

#include "image_io.h"
#include "exr_io.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <time.h>
#include <unistd.h>

#include <stb/stb_image.h>
#include <stb/stb_image_write.h>

/* ---- errors ---------------------------------------------------------------------------------- */

/* Writes "PATH: message" to err as one line and returns -1. */
#if defined(__GNUC__)
__attribute__((format(printf, 4, 5)))
#endif
static int
fail(char *err, size_t errlen, const char *path, const char *fmt, ...) {
    if (!err || errlen == 0) return -1;
    int n = snprintf(err, errlen, "%s: ", path ? path : "(null)");
    if (n >= 0 && (size_t)n < errlen) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err + n, errlen - (size_t)n, fmt, ap);
        va_end(ap);
    }
    /* Library messages may carry newlines or tabs; the contract is one line. */
    for (char *c = err; *c; c++)
        if ((unsigned char)*c < 0x20) *c = ' ';
    size_t len = strlen(err);
    while (len > 0 && err[len - 1] == ' ') err[--len] = '\0';
    return -1;
}

/* ---- a growable memory buffer ---------------------------------------------------------------- */

/* Encoders write into memory first so that the file on disk appears only complete (through
 * write_file_atomic), never half written. */
typedef struct {
    unsigned char *data;
    size_t size, cap;
    int failed; /* an allocation failed; the content is incomplete */
} membuf;

/* Writes n bytes at offset, zero filling any gap. */
static int membuf_write_at(membuf *b, size_t offset, const void *src, size_t n) {
    if (b->failed || offset > SIZE_MAX - n) return b->failed = 1, -1;
    size_t end = offset + n;
    if (end > b->cap) {
        size_t cap = b->cap ? b->cap : 4096;
        while (cap < end) cap = cap > SIZE_MAX / 2 ? end : cap * 2;
        unsigned char *p = realloc(b->data, cap);
        if (!p) return b->failed = 1, -1;
        b->data = p;
        b->cap = cap;
    }
    if (offset > b->size) memset(b->data + b->size, 0, offset - b->size);
    if (n) memcpy(b->data + offset, src, n);
    if (end > b->size) b->size = end;
    return 0;
}

/* ---- input files ----------------------------------------------------------------------------- */

/* The one way glint opens a file it reads: non-blocking, since opening a FIFO would otherwise wait
 * for a writer, and only a regular file gets further (where the flag changes nothing). The
 * descriptor and its size, or -1 with errno set: EISDIR for a directory, EINVAL for anything else
 * that is not a regular file. */
static int open_regular_fd(const char *path, int64_t *size) {
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
    if (fd < 0) return -1;
    struct stat st;
    int e = fstat(fd, &st) != 0 ? errno : !S_ISREG(st.st_mode) ? (S_ISDIR(st.st_mode) ? EISDIR : EINVAL) : 0;
    if (e) {
        close(fd);
        errno = e;
        return -1;
    }
    *size = (int64_t)st.st_size;
    return fd;
}

FILE *open_regular_file(const char *path) {
    int64_t size;
    int fd = open_regular_fd(path, &size);
    if (fd < 0) return NULL;
    FILE *f = fdopen(fd, "rb");
    if (!f) close(fd);
    return f;
}

const char *open_regular_problem(int e) { return e == EINVAL || e == EISDIR ? "not a regular file" : strerror(e); }

/* Opens a regular file for reading; returns the descriptor and its size, or -1 with err set. */
static int open_input(const char *path, int64_t *size, char *err, size_t errlen) {
    if (!path || !path[0]) return fail(err, errlen, path ? path : "", "empty file name");
    int fd = open_regular_fd(path, size);
    if (fd < 0)
        return fail(err, errlen, path, "%s",
                    errno == EISDIR   ? "is a directory"
                    : errno == EINVAL ? "not a regular file (a pipe or a device?)"
                                      : strerror(errno));
    return fd;
}

/* Reads up to n bytes at offset; returns the count read (short only at end of file) or -1. */
static int64_t read_at(int fd, void *buf, uint64_t n, uint64_t offset) {
    uint64_t done = 0;
    while (done < n) {
        if (offset + done > (uint64_t)INT64_MAX) break;
        size_t want = n - done > ((size_t)1 << 30) ? ((size_t)1 << 30) : (size_t)(n - done);
        ssize_t got = pread(fd, (unsigned char *)buf + done, want, (off_t)(offset + done));
        if (got < 0) {
            if (errno == EINTR) continue;
            return -1;
        }
        if (got == 0) break;
        done += (uint64_t)got;
    }
    return (int64_t)done;
}

static int size_ok(int64_t w, int64_t h) {
    return w > 0 && h > 0 && w <= MAX_IMAGE_DIM && h <= MAX_IMAGE_DIM && w * h <= MAX_IMAGE_PIXELS;
}

static const unsigned char exr_magic[4] = {0x76, 0x2f, 0x31, 0x01};

/* ---- OpenEXR: reading (exr_io.cpp, through the C++ library) ---------------------------------- */

int exr_image_load(const char *path, exr_image *out, char *err, size_t errlen) {
    memset(out, 0, sizeof *out);
    int64_t size = 0;
    int fd = open_input(path, &size, err, errlen);
    if (fd < 0) return -1;
    int status = exr_read_fd(path, fd, size, EXR_READ_ALL, out, NULL, err, errlen);
    close(fd);
    return status;
}

const float *exr_image_channel(const exr_image *img, const char *name) {
    for (int i = 0; img && name && i < img->num_channels; i++)
        if (strcmp(img->names[i], name) == 0) return img->planes[i];
    return NULL;
}

float *exr_image_layer_rgb(const exr_image *img, const char *prefix) {
    const float *c[3];
    for (int k = 0; k < 3; k++) {
        char name[256];
        snprintf(name, sizeof name, "%s%s%c", prefix, prefix[0] ? "." : "", "RGB"[k]);
        if (!(c[k] = exr_image_channel(img, name))) return NULL;
    }
    size_t n = (size_t)img->width * (size_t)img->height;
    float *rgb = malloc(sizeof(float) * 3 * n);
    if (!rgb) return NULL;
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) rgb[3 * i + (size_t)k] = c[k][i];
    return rgb;
}

int exr_header_string(const char *path, const char *name, char **value, size_t *len, char *err, size_t errlen) {
    *value = NULL;
    *len = 0;
    if (!name || !name[0]) return fail(err, errlen, path, "empty attribute name");
    int64_t size = 0;
    int fd = open_input(path, &size, err, errlen);
    if (fd < 0) return -1;
    int status = exr_read_string_fd(path, fd, size, name, value, len, err, errlen);
    close(fd);
    return status;
}

/* ---- RGB loading ----------------------------------------------------------------------------- */

/* Environment maps feed importance sampling, which needs finite, non-negative texels. */
static int check_texels(const char *path, const image_rgb *img, char *err, size_t errlen) {
    size_t n = (size_t)img->width * (size_t)img->height;
    for (size_t i = 0; i < 3 * n; i++) {
        float v = img->rgb[i];
        if (isfinite(v) && v >= 0.0f) continue;
        size_t p = i / 3;
        return fail(err, errlen, path, "pixel (%zu, %zu) channel %c is %s (%g)", p % (size_t)img->width,
                    p / (size_t)img->width, "RGB"[i % 3], isfinite(v) ? "negative" : "not finite", (double)v);
    }
    return 0;
}

/* Read straight into one interleaved buffer (no second copy of a large map), its texels checked
 * there, within the data window: DWA's DCT rings slightly below zero next to dark texels (even in
 * Blender's own studio lights), coding noise, not data, which reads as zero. */
static int load_exr_rgb(const char *path, int fd, int64_t size, image_rgb *out, char *err, size_t errlen) {
    exr_image ex;
    if (exr_read_fd(path, fd, size, EXR_READ_RGB_INTERLEAVED, &ex, NULL, err, errlen) != 0) return -1;
    out->width = ex.width;
    out->height = ex.height;
    out->rgb = ex.planes[0];
    ex.planes[0] = NULL;
    exr_image_free(&ex);
    return 0;
}

/* stb_image reads through callbacks so that truncation is visible, and so that it cannot hang:
 * stb 2.27 substitutes zero bytes past the end of the file, and a zero run count makes its RLE
 * decoder loop forever. Past the end this reader hands out bytes of 2 instead (a run count that
 * makes progress, a scanline header that fails the length check) and records that it did, which
 * fails the load. A complete file is consumed exactly, never past its end. */
typedef struct {
    int fd;
    int64_t size, pos;
    int past_end, io_error;
} hdr_source;

static int hdr_read(void *user, char *data, int size) {
    hdr_source *src = user;
    if (size <= 0) return 0;
    int64_t got = 0;
    if (src->pos < src->size) {
        int64_t want = src->size - src->pos < size ? src->size - src->pos : size;
        got = read_at(src->fd, data, (uint64_t)want, (uint64_t)src->pos);
        if (got < 0) src->io_error = errno;
    }
    if (got <= 0) { /* stb needs bytes beyond the end (a short read before it is normal) */
        src->past_end = 1;
        memset(data, 2, (size_t)size);
        got = size;
    }
    src->pos += got;
    return (int)got;
}

static void hdr_skip(void *user, int n) {
    hdr_source *src = user;
    src->pos = src->pos + n < 0 ? 0 : src->pos + n;
}

static int hdr_eof(void *user) {
    const hdr_source *src = user;
    return src->pos >= src->size;
}

/* stb reads the header token by token up to an empty line and then the resolution line; the
 * filler bytes above would make that loop endless, so the header must be complete in the file. */
static int hdr_header_complete(int fd, int64_t size) {
    const size_t cap = 65536; /* far more than any real header */
    char *buf = malloc(cap);
    if (!buf) return 0;
    int64_t n = read_at(fd, buf, (uint64_t)(size < (int64_t)cap ? size : (int64_t)cap), 0);
    int complete = 0;
    for (int64_t i = 0; i + 1 < n; i++) {
        if (buf[i] == '\n' && buf[i + 1] == '\n') {
            complete = memchr(buf + i + 2, '\n', (size_t)(n - i - 2)) != NULL;
            break;
        }
    }
    free(buf);
    return complete;
}

static int load_hdr_rgb(const char *path, int fd, int64_t size, image_rgb *out, char *err, size_t errlen) {
    if (!hdr_header_complete(fd, size)) return fail(err, errlen, path, "truncated or malformed Radiance HDR header");
    const stbi_io_callbacks io = {hdr_read, hdr_skip, hdr_eof};
    hdr_source src = {fd, size, 0, 0, 0};
    int w = 0, h = 0, comp = 0;
    /* The header first, so that a corrupt size is refused before stb allocates for it. */
    if (!stbi_info_from_callbacks(&io, &src, &w, &h, &comp)) {
        const char *why = stbi_failure_reason();
        return fail(err, errlen, path, "not a readable Radiance HDR file (%s)", why ? why : "bad header");
    }
    if (!size_ok(w, h)) return fail(err, errlen, path, "unsupported image size %dx%d", w, h);
    /* stb decodes every declared pixel, past the end of the data too: a few bytes declaring a
     * large image would cost its whole allocation and decoding. A scanline takes at least 4
     * bytes a pixel flat (widths below 8 or above 32767), or with run-length encoding its
     * 4-byte marker and one 2-byte run of at most 127 pixels per channel. */
    int64_t row = w < 8 || w > 32767 ? 4 * (int64_t)w : 4 + 8 * (((int64_t)w + 126) / 127);
    if ((int64_t)h * row > size)
        return fail(err, errlen, path, "truncated Radiance HDR file (%dx%d pixels need at least %lld bytes)", w, h,
                    (long long)((int64_t)h * row));
    src = (hdr_source){fd, size, 0, 0, 0};
    float *px = stbi_loadf_from_callbacks(&io, &src, &w, &h, &comp, 3);
    if (!px || src.io_error || src.past_end) {
        const char *why = stbi_failure_reason();
        stbi_image_free(px);
        if (src.io_error) return fail(err, errlen, path, "%s", strerror(src.io_error));
        if (src.past_end) return fail(err, errlen, path, "truncated Radiance HDR file");
        return fail(err, errlen, path, "corrupt Radiance HDR file (%s)", why ? why : "unknown error");
    }
    /* Copied so that image_rgb_free's free() never meets memory from stb's allocator. */
    size_t bytes = sizeof(float) * 3 * (size_t)w * (size_t)h;
    out->rgb = malloc(bytes);
    if (!out->rgb) {
        stbi_image_free(px);
        return fail(err, errlen, path, "out of memory");
    }
    memcpy(out->rgb, px, bytes);
    stbi_image_free(px);
    out->width = w;
    out->height = h;
    return 0;
}

int image_rgb_load(const char *path, image_rgb *out, char *err, size_t errlen) {
    memset(out, 0, sizeof *out);
    int64_t size = 0;
    int fd = open_input(path, &size, err, errlen);
    if (fd < 0) return -1;
    unsigned char magic[4] = {0};
    int64_t got = read_at(fd, magic, sizeof magic, 0);
    int status;
    if (got < 0)
        status = fail(err, errlen, path, "%s", strerror(errno));
    else if (got == 0)
        status = fail(err, errlen, path, "empty file");
    else if (got == 4 && memcmp(magic, exr_magic, 4) == 0)
        status = load_exr_rgb(path, fd, size, out, err, errlen);
    else if (got >= 2 && magic[0] == '#' && magic[1] == '?') /* EXR's texels are checked as read */
        status = load_hdr_rgb(path, fd, size, out, err, errlen) == 0 ? check_texels(path, out, err, errlen) : -1;
    else
        status = fail(err, errlen, path, "not an OpenEXR or Radiance HDR image");
    close(fd);
    if (status != 0) image_rgb_free(out);
    return status;
}

void image_rgb_free(image_rgb *img) {
    if (!img) return;
    free(img->rgb);
    memset(img, 0, sizeof *img);
}

/* ---- OpenEXR: writing (exr_io.cpp, through the C++ library) ---------------------------------- */

int exr_save_layers_attrs(const char *path, int width, int height, const exr_layer *layers, int num_layers,
                          const exr_text_attr *attrs, int num_attrs, write_mode mode, char *err, size_t errlen) {
    if (!path || !path[0]) return fail(err, errlen, path ? path : "", "empty file name");
    if (width <= 0 || height <= 0 || width > MAX_IMAGE_DIM || height > MAX_IMAGE_DIM)
        return fail(err, errlen, path, "invalid image size %dx%d", width, height);
    if (!layers || num_layers <= 0 || num_layers > 1000) return fail(err, errlen, path, "no layers to write");
    for (int l = 0; l < num_layers; l++) {
        if (!layers[l].prefix || !layers[l].rgb) return fail(err, errlen, path, "layer %d has no name or pixels", l);
        /* The format's names end with NUL and take at most 255 bytes. */
        if (strlen(layers[l].prefix) > 250) return fail(err, errlen, path, "layer name too long");
        for (int m = 0; m < l; m++)
            if (strcmp(layers[l].prefix, layers[m].prefix) == 0)
                return fail(err, errlen, path, "layer name '%s' used twice", layers[l].prefix);
    }
    if (num_attrs < 0 || num_attrs > 1000 || (num_attrs > 0 && !attrs))
        return fail(err, errlen, path, "invalid header attributes");
    for (int i = 0; i < num_attrs; i++) {
        if (!attrs[i].name || !attrs[i].name[0] || strlen(attrs[i].name) > 255 || !attrs[i].value)
            return fail(err, errlen, path, "header attribute %d has no name, a name too long or no value", i);
        /* The format stores sizes in 32 bits. */
        if (strlen(attrs[i].value) > ((size_t)1 << 30))
            return fail(err, errlen, path, "header attribute %s is too long", attrs[i].name);
        for (int j = 0; j < i; j++)
            if (strcmp(attrs[i].name, attrs[j].name) == 0)
                return fail(err, errlen, path, "header attribute %s given twice", attrs[i].name);
    }
    void *data;
    size_t size;
    if (exr_encode_layers(path, width, height, layers, num_layers, attrs, num_attrs, &data, &size, err, errlen) != 0)
        return -1;
    int status = write_file_atomic(path, data, size, mode, err, errlen);
    free(data);
    return status;
}

int exr_save_layers(const char *path, int width, int height, const exr_layer *layers, int num_layers, write_mode mode,
                    char *err, size_t errlen) {
    return exr_save_layers_attrs(path, width, height, layers, num_layers, NULL, 0, mode, err, errlen);
}

/* ---- PNG ------------------------------------------------------------------------------------- */

static void png_collect(void *context, void *data, int size) {
    membuf *b = context;
    if (size > 0) membuf_write_at(b, b->size, data, (size_t)size);
}

int png_save_rgb8(const char *path, int width, int height, const unsigned char *rgb, write_mode mode, char *err,
                  size_t errlen) {
    if (!path || !path[0]) return fail(err, errlen, path ? path : "", "empty file name");
    if (width <= 0 || height <= 0 || width > MAX_IMAGE_DIM || height > MAX_IMAGE_DIM || !rgb)
        return fail(err, errlen, path, "invalid image size %dx%d", width, height);
    membuf buf = {0};
    int ok = stbi_write_png_to_func(png_collect, &buf, width, height, 3, rgb, 3 * width);
    int status;
    if (!ok || buf.failed || buf.size == 0)
        status = fail(err, errlen, path, "cannot encode PNG (out of memory)");
    else
        status = write_file_atomic(path, buf.data, buf.size, mode, err, errlen);
    free(buf.data);
    return status;
}

/* ---- atomic file writing --------------------------------------------------------------------- */

/* A hard-to-guess suffix; uniqueness is still enforced by O_EXCL. */
static void temp_suffix(char out[7]) {
    static _Thread_local uint64_t counter;
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    uint64_t x = (uint64_t)ts.tv_nsec ^ ((uint64_t)ts.tv_sec << 30) ^ ((uint64_t)getpid() << 16) ^
                 (++counter * 0x9e3779b97f4a7c15ull) ^ (uint64_t)(uintptr_t)&counter;
    /* splitmix64 finaliser: spreads the bits of the mixed inputs */
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
    x ^= x >> 31;
    static const char alphabet[] = "abcdefghijklmnopqrstuvwxyz0123456789";
    for (int i = 0; i < 6; i++, x /= 36) out[i] = alphabet[x % 36];
    out[6] = '\0';
}

/* The directory part of path, for messages ("." when there is none). */
static void parent_dir(const char *path, char *out, size_t outlen) {
    const char *slash = strrchr(path, '/');
    if (!slash)
        snprintf(out, outlen, ".");
    else if (slash == path)
        snprintf(out, outlen, "/");
    else
        snprintf(out, outlen, "%.*s", (int)(slash - path), path);
}

/* write_file_atomic's work on target (path: the name the user gave, for messages). */
static int write_to(const char *target, const char *path, const void *data, size_t size, write_mode mode, char *err,
                    size_t errlen) {
    /* The temporary file is created next to the target (so rename and link stay within one file
     * system), named after it with ".tmp-" so a leftover is recognisable. mkstemp is not used
     * because it creates files with mode 0600; this honours the umask like any other output. */
    size_t tmplen = strlen(target) + 16;
    char *tmp = malloc(tmplen);
    if (!tmp) return fail(err, errlen, path, "out of memory");
    int fd = -1;
    for (int attempt = 0; attempt < 100 && fd < 0; attempt++) {
        char suffix[7];
        temp_suffix(suffix);
        snprintf(tmp, tmplen, "%s.tmp-%s", target, suffix);
        fd = open(tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd < 0 && errno != EEXIST) break;
    }
    if (fd < 0) {
        int e = errno;
        char dir[1024];
        parent_dir(target, dir, sizeof dir);
        free(tmp);
        if (e == ENOENT) return fail(err, errlen, path, "directory '%s' does not exist", dir);
        if (e == ENOTDIR) return fail(err, errlen, path, "'%s' is not a directory", dir);
        return fail(err, errlen, path, "cannot create a file in '%s': %s", dir, strerror(e));
    }

    int status = 0;
    const unsigned char *p = data;
    size_t left = size;
    while (left > 0 && status == 0) {
        ssize_t n = write(fd, p, left > ((size_t)1 << 30) ? ((size_t)1 << 30) : left);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            status = fail(err, errlen, path, "write failed: %s", n < 0 ? strerror(errno) : "no progress");
            break;
        }
        p += n;
        left -= (size_t)n;
    }
    /* Data must be on disk before the name points at it, or a crash could leave an empty file. */
    if (status == 0 && fsync(fd) != 0) status = fail(err, errlen, path, "fsync failed: %s", strerror(errno));
    if (close(fd) != 0 && status == 0) status = fail(err, errlen, path, "write failed: %s", strerror(errno));

    if (status == 0) {
        if (mode == WRITE_NO_REPLACE) {
            /* link() fails with EEXIST instead of replacing, atomically, even against a racing
             * writer; rename() would silently replace. */
            if (link(tmp, target) != 0)
                status = errno == EEXIST ? fail(err, errlen, path, "file exists")
                                         : fail(err, errlen, path, "cannot create: %s", strerror(errno));
        } else if (rename(tmp, target) != 0) {
            status = fail(err, errlen, path, "cannot replace: %s", strerror(errno));
        }
    }
    /* After a rename the temporary name is gone already and this fails harmlessly; after a link
     * or any failure it removes the temporary file. */
    unlink(tmp);
    free(tmp);

    if (status == 0) {
        /* Make the new directory entry durable too; best effort, as not every file system
         * supports fsync on a directory. */
        char dir[1024];
        parent_dir(target, dir, sizeof dir);
        int dfd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
        if (dfd >= 0) {
            fsync(dfd);
            close(dfd);
        }
    }
    return status;
}

int write_file_atomic(const char *path, const void *data, size_t size, write_mode mode, char *err, size_t errlen) {
    if (!path || !path[0]) return fail(err, errlen, path ? path : "", "empty file name");
    if (!data && size > 0) return fail(err, errlen, path, "no data to write");
    /* Only a regular file is ever replaced: renaming over a device (--stats /dev/null), a
     * directory or a FIFO would destroy it (a session once turned /dev/null into a file). */
    struct stat existing;
    char *through = NULL; /* a symbolic link's target, written through: the link stays a link */
    if (mode == WRITE_REPLACE && lstat(path, &existing) == 0 && S_ISLNK(existing.st_mode)) {
        if (!(through = realpath(path, NULL)))
            return fail(err, errlen, path, "a symbolic link to nothing (%s); not following it", strerror(errno));
        if (stat(through, &existing) != 0 || !S_ISREG(existing.st_mode)) {
            free(through);
            return fail(err, errlen, path, "a symbolic link to something not a regular file; not replacing it");
        }
    }
    if (mode == WRITE_REPLACE && !through && lstat(path, &existing) == 0 && !S_ISREG(existing.st_mode))
        return fail(err, errlen, path, "not a regular file; not replacing it");
    int status = write_to(through ? through : path, path, data, size, mode, err, errlen);
    free(through);
    return status;
}

/* ---- unique names ---------------------------------------------------------------------------- */

int unique_path(const char *path, char *out, size_t outlen) {
    if (!path || !path[0] || !out || outlen == 0) return -1;
    /* The extension is the last '.' of the file name (not of a directory), and a leading dot
     * (".hidden") does not start one. */
    const char *slash = strrchr(path, '/');
    const char *base = slash ? slash + 1 : path;
    const char *dot = strrchr(base, '.');
    if (!dot || dot == base) dot = base + strlen(base);
    int stem_len = (int)(dot - path);
    for (int i = 0; i < 100000; i++) {
        int n = i == 0 ? snprintf(out, outlen, "%s", path) : snprintf(out, outlen, "%.*s-%d%s", stem_len, path, i, dot);
        if (n < 0 || (size_t)n >= outlen) {
            out[0] = '\0';
            return -1;
        }
        /* lstat, so that a dangling symlink counts as taken (link() would refuse it too). Any
         * failure means the name is usable as far as we can tell; the writer reports the rest. */
        struct stat st;
        if (lstat(out, &st) != 0) return 0;
    }
    out[0] = '\0';
    return -1;
}
