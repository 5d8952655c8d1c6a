/* glint — image files: OpenEXR through its C API, Radiance HDR through stb_image, PNG through
 * stb_image_write, and the atomic writer every export goes through. See image_io.h. */
#define _POSIX_C_SOURCE 200809L /* pread, fsync, link, strdup, lstat, clock_gettime */

#include "image_io.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <threads.h>
#include <time.h>
#include <unistd.h>

#include <openexr.h>
#include <stb/stb_image.h>
#include <stb/stb_image_write.h>
#include <zlib.h>

/* Guards against corrupt headers that claim absurd sizes: allocation would fail (or, under
 * ASan, abort) long before any pixel data is read. 16k x 16k is far above anything glint uses. */
#define MAX_IMAGE_DIM (1 << 17)
#define MAX_IMAGE_PIXELS ((int64_t)1 << 28)

/* ---- errors ---------------------------------------------------------------------------------- */

/* Writes "PATH: message" to err as one line and returns -1. */
#if defined(__GNUC__)
__attribute__((format(printf, 4, 5)))
#endif
static int fail(char *err, size_t errlen, const char *path, const char *fmt, ...) {
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

/* Writes n bytes at offset (the OpenEXR writer seeks back to fill in its chunk table), zero
 * filling any gap. */
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

/* Opens a regular file for reading; returns the descriptor and its size, or -1 with err set. */
static int open_input(const char *path, int64_t *size, char *err, size_t errlen) {
    if (!path || !path[0]) return fail(err, errlen, path ? path : "", "empty file name");
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0) return fail(err, errlen, path, "%s", strerror(errno));
    struct stat st;
    if (fstat(fd, &st) != 0) {
        int e = errno;
        close(fd);
        return fail(err, errlen, path, "%s", strerror(e));
    }
    if (!S_ISREG(st.st_mode)) {
        close(fd);
        return fail(err, errlen, path, "%s", S_ISDIR(st.st_mode) ? "is a directory" : "not a regular file");
    }
    *size = (int64_t)st.st_size;
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

static const unsigned char exr_magic[4] = {0x76, 0x2f, 0x31, 0x01};

/* ---- OpenEXR: shared plumbing ---------------------------------------------------------------- */

/* The library reports errors through a callback, on the thread that hit them. A thread-local
 * sink lets each call collect its own first (most specific) message without calling back into
 * the library from the handler, and without the default handler printing to stderr. */
typedef struct {
    char msg[256];
} exr_errbox;
static _Thread_local exr_errbox *exr_sink;

static void exr_on_error(exr_const_context_t ctxt, exr_result_t code, const char *msg) {
    (void)ctxt;
    if (exr_sink && !exr_sink->msg[0])
        snprintf(exr_sink->msg, sizeof exr_sink->msg, "%s", msg && msg[0] ? msg : exr_get_default_error_message(code));
}

/* "PATH: what: <library message>" for a failed library call. */
static int exr_fail(char *err, size_t errlen, const char *path, const char *what, exr_result_t rv,
                    const exr_errbox *box) {
    const char *why = box->msg[0] ? box->msg : exr_get_default_error_message(rv);
    return fail(err, errlen, path, "%s: %s", what, why);
}

typedef struct {
    int fd;
    int64_t size;
} exr_source;

static int64_t exr_source_read(exr_const_context_t ctxt, void *userdata, void *buffer, uint64_t sz, uint64_t offset,
                               exr_stream_error_func_ptr_t error_cb) {
    const exr_source *src = userdata;
    int64_t got = read_at(src->fd, buffer, sz, offset);
    if (got < 0) error_cb(ctxt, EXR_ERR_READ_IO, "read error: %s", strerror(errno));
    return got;
}

static int64_t exr_source_size(exr_const_context_t ctxt, void *userdata) {
    (void)ctxt;
    return ((const exr_source *)userdata)->size;
}

static int64_t exr_membuf_write(exr_const_context_t ctxt, void *userdata, const void *buffer, uint64_t sz,
                                uint64_t offset, exr_stream_error_func_ptr_t error_cb) {
    (void)ctxt;
    (void)error_cb; /* out of memory is reported by the caller, which sees membuf.failed */
    membuf *b = userdata;
    if (sz > SIZE_MAX || offset > SIZE_MAX || membuf_write_at(b, (size_t)offset, buffer, (size_t)sz) != 0) return -1;
    return (int64_t)sz;
}

/* ---- OpenEXR: reading ------------------------------------------------------------------------ */

typedef enum {
    EXR_SELECT_ALL, /* every channel */
    EXR_SELECT_RGB, /* R, G, B in that order, else Y */
} exr_select;

static void image_free_partial(exr_image *img) {
    for (int i = 0; i < img->num_channels; i++) {
        if (img->names) free(img->names[i]);
        if (img->planes) free(img->planes[i]);
    }
    free(img->names);
    free(img->planes);
    memset(img, 0, sizeof *img);
}

static int chlist_find(const exr_attr_chlist_t *cl, const char *name) {
    for (int i = 0; i < cl->num_channels; i++) {
        if (strcmp(cl->entries[i].name.str, name) == 0) return i;
    }
    return -1;
}

static int64_t box_width(exr_attr_box2i_t b) { return (int64_t)b.max.x - b.min.x + 1; }
static int64_t box_height(exr_attr_box2i_t b) { return (int64_t)b.max.y - b.min.y + 1; }

static int size_ok(int64_t w, int64_t h) {
    return w > 0 && h > 0 && w <= MAX_IMAGE_DIM && h <= MAX_IMAGE_DIM && w * h <= MAX_IMAGE_PIXELS;
}

/* Points the decoder's channels at the selected planes for the chunk at (x0, y0) of the data
 * window. Unselected channels decode into scratch rather than being left NULL: OpenEXR 3.1's
 * specialised half-to-float unpackers for 3- and 4-channel parts write every channel and crash
 * on a NULL one. */
static int bind_decode_channels(exr_decode_pipeline_t *dec, const exr_image *img, float *scratch, int w, int x0,
                                int y0) {
    for (int c = 0; c < dec->channel_count; c++) {
        exr_coding_channel_info_t *ch = &dec->channels[c];
        if (ch->width != dec->chunk.width || ch->height != dec->chunk.height) return -1;
        ch->decode_to_ptr = (uint8_t *)scratch;
        for (int k = 0; k < img->num_channels; k++) {
            if (strcmp(ch->channel_name, img->names[k]) == 0) {
                ch->decode_to_ptr = (uint8_t *)(img->planes[k] + (size_t)y0 * (size_t)w + (size_t)x0);
                break;
            }
        }
        ch->user_data_type = EXR_PIXEL_FLOAT; /* half and uint convert to float */
        ch->user_bytes_per_element = 4;
        ch->user_pixel_stride = 4;
        ch->user_line_stride = 4 * w;
    }
    return 0;
}

/* ---- OpenEXR: DWAA/DWAB decompression -------------------------------------------------------- */

/* OpenEXR 3.1's C core cannot decompress DWAA/DWAB ("not yet implemented"), a common compression
 * for environment maps (Blender's bundled studio lights use it). So the decoder below replaces the
 * pipeline's decompress step for those parts; the library still reads the chunks and converts the
 * result. It follows the format as OpenEXR writes it, and matches OpenEXR's C++ decoder up to the
 * rounding of the last bit of some coded values:
 *   - 11 little-endian uint64 counters, then (version 2) the channel classification rules;
 *   - then four sections: "unknown" channels (zlib, verbatim), the AC coefficients (OpenEXR's
 *     Huffman code or zlib), the DC coefficients (zlib after the ZIP codec's byte predictor), and
 *     alpha-like channels (zlib, then OpenEXR's byte RLE, bytes split into planes);
 *   - lossy channels are 8x8 DCT blocks of half-float values in a perceptual (gamma / log)
 *     encoding, R, G, B of one layer coded together as Y'CbCr (Rec. 709). */

enum { DWA_UNKNOWN = 0, DWA_LOSSY_DCT = 1, DWA_RLE = 2 };
enum { DWA_VERSION, DWA_UNKNOWN_RAW, DWA_UNKNOWN_PACKED, DWA_AC_PACKED, DWA_DC_PACKED, DWA_RLE_PACKED,
       DWA_RLE_UNPACKED, DWA_RLE_RAW, DWA_AC_COUNT, DWA_DC_COUNT, DWA_AC_CODING, DWA_COUNTERS };

static uint64_t le64(const uint8_t *p) {
    uint64_t v = 0;
    for (int i = 7; i >= 0; i--) v = v << 8 | p[i];
    return v;
}

static uint32_t le32(const uint8_t *p) {
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static float half_to_float(uint16_t h) {
    int exponent = (h >> 10) & 0x1f, mantissa = h & 0x3ff;
    float v = exponent == 0    ? ldexpf((float)mantissa, -24)
              : exponent == 31 ? (mantissa ? NAN : INFINITY)
                               : ldexpf((float)(mantissa | 0x400), exponent - 25);
    return (h & 0x8000) ? -v : v;
}

/* Round to nearest, ties to even, as OpenEXR's converter. */
static uint16_t float_to_half(float f) {
    uint32_t x;
    memcpy(&x, &f, sizeof x);
    uint16_t sign = (uint16_t)((x >> 16) & 0x8000);
    uint32_t ax = x & 0x7fffffffu;
    if (ax >= 0x7f800000u) return (uint16_t)(sign | 0x7c00 | (ax > 0x7f800000u ? 0x200 : 0));
    if (ax >= 0x477ff000u) return (uint16_t)(sign | 0x7c00); /* rounds to infinity */
    if (ax < 0x38800000u) {                                  /* a half subnormal (or zero) */
        float a;
        memcpy(&a, &ax, sizeof a);
        return (uint16_t)(sign | (uint16_t)rintf(a * 16777216.0f));
    }
    uint32_t h = ((ax >> 23) - 112) << 10 | (ax & 0x7fffff) >> 13, rest = ax & 0x1fff;
    if (rest > 0x1000 || (rest == 0x1000 && (h & 1))) h++;
    return (uint16_t)(sign | h);
}

/* The lossy channels store values v' with v = v'^2.2 up to 1 and e^(2.2 (v' - 1)) above; a table
 * over all half values, built once. */
static uint16_t dwa_to_linear[65536];
static once_flag dwa_to_linear_once = ONCE_FLAG_INIT;

static void dwa_build_to_linear(void) {
    uint16_t *table = dwa_to_linear;
    for (uint32_t i = 0; i < 65536; i++) {
        uint16_t h = (uint16_t)i;
        if (h == 0 || (h & 0x7c00) == 0x7c00) {
            table[i] = 0;
            continue;
        }
        float f = half_to_float(h), sign = f < 0.0f ? -1.0f : 1.0f;
        f = fabsf(f);
        float z = f <= 1.0f ? powf(f, 2.2f) : powf(9.02501329156f, f - 1.0f);
        table[i] = float_to_half(sign * z);
    }
}

/* OpenEXR's Huffman code (as in PIZ): a header (min and max symbol, bit count), the code lengths
 * packed 6 bits each with runs of zeros, then the bit stream, most significant bit first. Codes
 * are canonical with longer codes numerically smaller; the symbol after the largest one marks a
 * run: the next 8 bits repeat the previous symbol that many times. */
static int huf_decode(const uint8_t *in, uint64_t size, uint16_t *out, uint64_t count) {
    enum { MAX_LEN = 58, SYMBOLS = 65537 };
    if (size < 20) return -1;
    uint32_t lo = le32(in), hi = le32(in + 4), nbits = le32(in + 12);
    if (lo > hi || hi >= SYMBOLS) return -1;
    uint8_t *len = calloc(SYMBOLS, 1);
    uint32_t *sorted = malloc(sizeof(uint32_t) * SYMBOLS);
    int status = len && sorted ? 0 : -1;

    /* The code length table. */
    const uint8_t *p = in + 20, *end = in + size;
    uint64_t bits = 0, avail = 0; /* bit buffer */
#define HUF_NEED(n)                                         \
    while (status == 0 && avail < (n)) {                    \
        if (p >= end) status = -1;                          \
        else bits = bits << 8 | *p++, avail += 8;           \
    }
    for (uint32_t s = lo; s <= hi && status == 0; s++) {
        HUF_NEED(6);
        if (status) break;
        uint32_t l = (uint32_t)(bits >> (avail -= 6)) & 63, run = 0;
        if (l == 63) {
            HUF_NEED(8);
            if (status) break;
            run = ((uint32_t)(bits >> (avail -= 8)) & 255) + 6;
        } else if (l >= 59) {
            run = l - 59 + 2;
        } else {
            len[s] = (uint8_t)l;
        }
        if (run) {
            if ((uint64_t)s + run > (uint64_t)hi + 1) status = -1;
            s += run - 1;
        }
    }
#undef HUF_NEED
    if (status == 0 && nbits > 8 * (uint64_t)(end - p)) status = -1;

    uint64_t first[MAX_LEN + 1] = {0}, num[MAX_LEN + 1] = {0}, offset[MAX_LEN + 1] = {0};
    if (status == 0) {
        for (uint32_t s = lo; s <= hi; s++) num[len[s]]++;
        uint64_t c = 0;
        for (int l = MAX_LEN; l > 0; l--) {
            first[l] = c;
            c = (c + num[l]) >> 1;
        }
        for (int l = 1; l <= MAX_LEN; l++) offset[l] = offset[l - 1] + (l > 1 ? num[l - 1] : 0);
        uint64_t fill[MAX_LEN + 1];
        memcpy(fill, offset, sizeof fill);
        for (uint32_t s = lo; s <= hi; s++)
            if (len[s]) sorted[fill[len[s]]++] = s;
    }

    /* The bit stream. */
    uint64_t n = 0, q = 0, code = 0;
    int l = 0;
    while (status == 0 && q < nbits) {
        code = code << 1 | ((p[q >> 3] >> (7 - (q & 7))) & 1);
        q++;
        if (++l > MAX_LEN) {
            status = -1;
            break;
        }
        if (!num[l] || code < first[l] || code - first[l] >= num[l]) continue;
        uint32_t sym = sorted[offset[l] + (code - first[l])];
        code = 0;
        l = 0;
        if (sym == hi) { /* run of the previous symbol */
            if (q + 8 > nbits || n == 0) {
                status = -1;
                break;
            }
            uint64_t run = 0;
            for (int k = 0; k < 8; k++, q++) run = run << 1 | ((p[q >> 3] >> (7 - (q & 7))) & 1);
            if (n + run > count) {
                status = -1;
                break;
            }
            for (uint64_t k = 0; k < run; k++, n++) out[n] = out[n - 1];
        } else if (n < count) {
            out[n++] = (uint16_t)sym;
        } else {
            status = -1;
        }
    }
    if (l != 0 || n != count) status = -1;
    free(len);
    free(sorted);
    return status;
}

/* zlib into exactly size bytes. */
static int dwa_inflate(const uint8_t *in, uint64_t in_size, uint8_t *out, uint64_t size) {
    if (in_size > ULONG_MAX || size > ULONG_MAX) return -1;
    uLongf got = (uLongf)size;
    return uncompress(out, &got, in, (uLong)in_size) == Z_OK && got == size ? 0 : -1;
}

/* OpenEXR's byte RLE: a signed count n, then -n literal bytes (n < 0) or one byte n + 1 times. */
static int rle_decode(const uint8_t *in, uint64_t n, uint8_t *out, uint64_t size) {
    uint64_t i = 0, o = 0;
    while (i < n) {
        int c = in[i] < 128 ? in[i] : in[i] - 256;
        i++;
        uint64_t k = c < 0 ? (uint64_t)-c : (uint64_t)c + 1;
        if (o + k > size || (c < 0 ? i + k > n : i >= n)) return -1;
        if (c < 0) {
            memcpy(out + o, in + i, (size_t)k);
            i += k;
        } else {
            memset(out + o, in[i++], (size_t)k);
        }
        o += k;
    }
    return o == size ? 0 : -1;
}

/* Which scheme the rules give a channel, and (for R, G, B) its place in a colour triple. */
typedef struct {
    char suffix[130];
    int scheme, csc, nocase, type;
} dwa_rule;

static int dwa_read_rules(const uint8_t *p, uint64_t n, dwa_rule **rules, int *count) {
    *rules = NULL;
    *count = 0;
    dwa_rule *r = malloc(sizeof(dwa_rule) * (size_t)(n / 3 + 1));
    if (!r) return -1;
    int k = 0;
    while (n > 0) {
        const uint8_t *nul = memchr(p, 0, (size_t)(n < 129 ? n : 129));
        if (!nul || (uint64_t)(nul - p) + 3 > n) {
            free(r);
            return -1;
        }
        size_t slen = (size_t)(nul - p);
        memcpy(r[k].suffix, p, slen + 1);
        uint8_t value = nul[1], type = nul[2];
        r[k].csc = (value >> 4) - 1;
        r[k].scheme = (value >> 2) & 3;
        r[k].nocase = value & 1;
        r[k].type = type;
        if (r[k].csc > 2 || r[k].scheme > DWA_RLE || type > EXR_PIXEL_FLOAT) {
            free(r);
            return -1;
        }
        k++;
        p += slen + 3;
        n -= slen + 3;
    }
    *rules = r;
    *count = k;
    return 0;
}

/* Rules implied by files older than version 2. */
static int dwa_legacy_rules(dwa_rule **rules, int *count) {
    static const struct {
        const char *suffix;
        int scheme, csc;
    } legacy[] = {{"r", 1, 0}, {"red", 1, 0}, {"g", 1, 1}, {"grn", 1, 1}, {"green", 1, 1}, {"b", 1, 2},
                  {"blu", 1, 2}, {"blue", 1, 2}, {"y", 1, -1}, {"by", 1, -1}, {"ry", 1, -1}, {"a", 2, -1}};
    int n = 0;
    dwa_rule *r = malloc(sizeof(dwa_rule) * 3 * (sizeof legacy / sizeof legacy[0]));
    if (!r) return -1;
    for (size_t i = 0; i < sizeof legacy / sizeof legacy[0]; i++)
        for (int type = EXR_PIXEL_UINT; type <= EXR_PIXEL_FLOAT; type++) {
            if (legacy[i].scheme == DWA_LOSSY_DCT && type == EXR_PIXEL_UINT) continue;
            snprintf(r[n].suffix, sizeof r[n].suffix, "%s", legacy[i].suffix);
            r[n].scheme = legacy[i].scheme;
            r[n].csc = legacy[i].csc;
            r[n].nocase = 1;
            r[n].type = type;
            n++;
        }
    *rules = r;
    *count = n;
    return 0;
}

/* The part of a channel name after its last '.', which the rules classify. */
static const char *dwa_suffix(const char *name) {
    const char *dot = strrchr(name, '.');
    return dot ? dot + 1 : name;
}

static int ascii_caseeq(const char *a, const char *b) {
    for (; *a && *b; a++, b++) {
        int ca = *a >= 'A' && *a <= 'Z' ? *a + 32 : *a, cb = *b >= 'A' && *b <= 'Z' ? *b + 32 : *b;
        if (ca != cb) return 0;
    }
    return *a == *b;
}

typedef struct {
    const uint16_t *ac, *dc;
    uint64_t ac_count, ac_pos, dc_count, dc_pos;
    const uint16_t *to_linear;
    float basis[8][8]; /* basis[k][n] = C(k) cos((2n + 1) k pi / 16), the orthonormal DCT */
    int zigzag[64];    /* natural (row-major) index -> position in the coded zig-zag order */
} dwa_state;

static void dwa_state_init(dwa_state *st) {
    for (int k = 0; k < 8; k++)
        for (int n = 0; n < 8; n++)
            st->basis[k][n] = (float)((k == 0 ? 0.5 / sqrt(2.0) : 0.5) * cos((2 * n + 1) * k * 3.14159265358979 / 16));
    int z = 0;
    for (int s = 0; s < 15; s++) { /* JPEG order: anti-diagonals, alternating direction */
        int r0 = s < 8 ? 0 : s - 7, r1 = s < 8 ? s : 7;
        for (int i = 0; i <= r1 - r0; i++) {
            int r = s % 2 ? r0 + i : r1 - i;
            st->zigzag[r * 8 + (s - r)] = z++;
        }
    }
}

/* Decodes n (1, or 3 for an R, G, B triple) lossy channels of a w x h chunk into the unpacked
 * rows (row stride bytes apart, channel c starting at offset[c] of a row). */
static int dwa_lossy(dwa_state *st, const exr_decode_pipeline_t *dec, const int *chans, int n, int linear,
                     uint8_t *out, size_t stride, const size_t *offset) {
    int w = dec->chunk.width, h = dec->chunk.height, nbx = (w + 7) / 8, nby = (h + 7) / 8;
    uint64_t blocks = (uint64_t)nbx * (uint64_t)nby;
    if (st->dc_pos + (uint64_t)n * blocks > st->dc_count) return -1;
    for (int k = 0; k < n; k++) {
        int type = dec->channels[chans[k]].data_type;
        if (type != EXR_PIXEL_HALF && type != EXR_PIXEL_FLOAT) return -1;
    }
    for (int by = 0; by < nby; by++)
        for (int bx = 0; bx < nbx; bx++) {
            float px[3][64];
            for (int k = 0; k < n; k++) {
                uint16_t zz[64] = {0};
                zz[0] = st->dc[st->dc_pos + (uint64_t)k * blocks + (uint64_t)by * (uint64_t)nbx + (uint64_t)bx];
                /* AC: values, 0xffNN = NN zeros, 0xff00 = the rest are zero */
                for (int i = 1; i < 64;) {
                    if (st->ac_pos >= st->ac_count) return -1;
                    uint16_t v = st->ac[st->ac_pos++];
                    if (v == 0xff00)
                        i = 64;
                    else if ((v >> 8) == 0xff)
                        i += v & 0xff;
                    else
                        zz[i++] = v;
                }
                float coef[64], tmp[64];
                for (int i = 0; i < 64; i++) coef[i] = half_to_float(zz[st->zigzag[i]]);
                for (int r = 0; r < 8; r++) /* rows, then columns */
                    for (int x = 0; x < 8; x++) {
                        float s = 0.0f;
                        for (int u = 0; u < 8; u++) s += coef[r * 8 + u] * st->basis[u][x];
                        tmp[r * 8 + x] = s;
                    }
                for (int y = 0; y < 8; y++)
                    for (int x = 0; x < 8; x++) {
                        float s = 0.0f;
                        for (int v = 0; v < 8; v++) s += tmp[v * 8 + x] * st->basis[v][y];
                        px[k][y * 8 + x] = s;
                    }
            }
            if (n == 3)
                for (int i = 0; i < 64; i++) { /* Y'CbCr to R'G'B' */
                    float y = px[0][i], cb = px[1][i], cr = px[2][i];
                    px[0][i] = y + 1.5747f * cr;
                    px[1][i] = y - 0.1873f * cb - 0.4682f * cr;
                    px[2][i] = y + 1.8556f * cb;
                }
            for (int k = 0; k < n; k++) {
                const exr_coding_channel_info_t *ch = &dec->channels[chans[k]];
                for (int y = 0; y < 8 && by * 8 + y < h; y++)
                    for (int x = 0; x < 8 && bx * 8 + x < w; x++) {
                        uint16_t v = float_to_half(px[k][y * 8 + x]);
                        if (!linear) v = st->to_linear[v];
                        uint8_t *dst = out + (size_t)(by * 8 + y) * stride + offset[chans[k]] +
                                       (size_t)(bx * 8 + x) * (size_t)ch->bytes_per_element;
                        if (ch->data_type == EXR_PIXEL_HALF) {
                            dst[0] = (uint8_t)v;
                            dst[1] = (uint8_t)(v >> 8);
                        } else {
                            float f = half_to_float(v);
                            uint32_t b;
                            memcpy(&b, &f, sizeof b);
                            for (int i = 0; i < 4; i++) dst[i] = (uint8_t)(b >> (8 * i));
                        }
                    }
            }
        }
    st->dc_pos += (uint64_t)n * blocks;
    return 0;
}

static exr_result_t dwa_decompress_chunk(exr_decode_pipeline_t *dec) {
    const uint8_t *in = dec->packed_buffer;
    uint8_t *out = dec->unpacked_buffer;
    uint64_t in_size = dec->chunk.packed_size, out_size = dec->chunk.unpacked_size;
    if (!in || !out) return EXR_ERR_INVALID_ARGUMENT;
    if (in_size == out_size) { /* stored raw: compression would not have paid */
        if (out != in) memcpy(out, in, (size_t)out_size);
        return EXR_ERR_SUCCESS;
    }
    uint64_t n[DWA_COUNTERS];
    if (in_size < sizeof n) return EXR_ERR_CORRUPT_CHUNK;
    call_once(&dwa_to_linear_once, dwa_build_to_linear);
    for (int i = 0; i < DWA_COUNTERS; i++) n[i] = le64(in + 8 * i);
    if (n[DWA_VERSION] > 2 || n[DWA_AC_CODING] > 1) return EXR_ERR_CORRUPT_CHUNK;
    uint64_t pos = sizeof n;

    int nchan = dec->channel_count, w = dec->chunk.width, h = dec->chunk.height, nrules = 0;
    if (nchan <= 0 || w <= 0 || h <= 0) return EXR_ERR_CORRUPT_CHUNK;
    dwa_rule *rules = NULL;
    if (n[DWA_VERSION] == 2) {
        if (in_size - pos < 2) return EXR_ERR_CORRUPT_CHUNK;
        uint64_t rules_size = (uint64_t)in[pos] | (uint64_t)in[pos + 1] << 8;
        if (rules_size < 2 || rules_size > in_size - pos) return EXR_ERR_CORRUPT_CHUNK;
        if (dwa_read_rules(in + pos + 2, rules_size - 2, &rules, &nrules) != 0) return EXR_ERR_CORRUPT_CHUNK;
        pos += rules_size;
    } else if (dwa_legacy_rules(&rules, &nrules) != 0) {
        return EXR_ERR_OUT_OF_MEMORY;
    }

    /* Classify the channels; R, G, B sharing a layer prefix form a colour triple. */
    int *scheme = calloc((size_t)nchan, sizeof(int)), *group = calloc((size_t)nchan, sizeof(int));
    int (*triple)[3] = malloc(sizeof(int[3]) * (size_t)nchan);
    size_t *offset = calloc((size_t)nchan, sizeof(size_t));
    int *done = calloc((size_t)nchan, sizeof(int));
    int ngroups = 0, status = scheme && group && triple && offset && done ? 0 : -1;
    uint64_t unknown_bytes = 0, rle_bytes = 0, dc_needed = 0;
    size_t stride = 0;
    uint64_t blocks = (uint64_t)((w + 7) / 8) * (uint64_t)((h + 7) / 8);
    for (int c = 0; c < nchan && status == 0; c++) {
        const exr_coding_channel_info_t *ch = &dec->channels[c];
        if (ch->width != w || ch->height != h || (ch->bytes_per_element != 2 && ch->bytes_per_element != 4)) {
            status = -1;
            break;
        }
        const char *suffix = dwa_suffix(ch->channel_name);
        size_t plen = (size_t)(suffix - ch->channel_name);
        int g = 0;
        for (; g < ngroups; g++) {
            const char *other = dec->channels[group[g]].channel_name;
            if ((size_t)(dwa_suffix(other) - other) == plen && strncmp(other, ch->channel_name, plen) == 0) break;
        }
        if (g == ngroups) { /* group[g] is the first channel with this layer prefix */
            group[g] = c;
            triple[g][0] = triple[g][1] = triple[g][2] = -1;
            ngroups++;
        }
        scheme[c] = DWA_UNKNOWN;
        for (int r = 0; r < nrules; r++) {
            if (rules[r].type != ch->data_type) continue;
            if (!(rules[r].nocase ? ascii_caseeq(suffix, rules[r].suffix) : strcmp(suffix, rules[r].suffix) == 0))
                continue;
            scheme[c] = rules[r].scheme; /* the last matching rule decides */
            if (rules[r].csc >= 0) triple[g][rules[r].csc] = c;
        }
        uint64_t bytes = (uint64_t)w * (uint64_t)h * (uint64_t)ch->bytes_per_element;
        if (scheme[c] == DWA_UNKNOWN) unknown_bytes += bytes;
        if (scheme[c] == DWA_RLE) rle_bytes += bytes;
        if (scheme[c] == DWA_LOSSY_DCT) dc_needed += blocks;
        offset[c] = stride;
        stride += (size_t)w * (size_t)ch->bytes_per_element;
    }
    free(rules);
    if (status == 0 && (uint64_t)stride * (uint64_t)h != out_size) status = -1;

    /* The four sections. */
    const uint8_t *sec = in + pos;
    uint64_t left = in_size - pos, sizes[4] = {n[DWA_UNKNOWN_PACKED], n[DWA_AC_PACKED], n[DWA_DC_PACKED],
                                                n[DWA_RLE_PACKED]};
    const uint8_t *start[4];
    for (int i = 0; i < 4 && status == 0; i++) {
        if (sizes[i] > left) status = -1;
        start[i] = sec;
        sec += sizes[i];
        left -= sizes[i];
    }
    if (status == 0 && (n[DWA_UNKNOWN_RAW] != unknown_bytes || n[DWA_RLE_RAW] != rle_bytes ||
                        n[DWA_DC_COUNT] != dc_needed || n[DWA_AC_COUNT] > dc_needed * 63 ||
                        n[DWA_RLE_UNPACKED] > out_size * 2 + 16))
        status = -1;
    uint8_t *unknown = NULL, *rle = NULL, *rle_packed = NULL, *dc_bytes = NULL;
    uint16_t *ac = NULL, *dc = NULL;
    if (status == 0 && unknown_bytes) {
        unknown = malloc((size_t)unknown_bytes);
        status = unknown ? dwa_inflate(start[0], sizes[0], unknown, unknown_bytes) : -1;
    }
    if (status == 0 && n[DWA_AC_COUNT]) {
        ac = malloc(sizeof(uint16_t) * (size_t)n[DWA_AC_COUNT]);
        if (!ac)
            status = -1;
        else if (n[DWA_AC_CODING] == 0)
            status = huf_decode(start[1], sizes[1], ac, n[DWA_AC_COUNT]);
        else if ((status = dwa_inflate(start[1], sizes[1], (uint8_t *)ac, 2 * n[DWA_AC_COUNT])) == 0)
            for (uint64_t i = 0; i < n[DWA_AC_COUNT]; i++) /* little-endian bytes to values */
                ac[i] = (uint16_t)(((const uint8_t *)&ac[i])[0] | ((const uint8_t *)&ac[i])[1] << 8);
    }
    if (status == 0 && dc_needed) {
        uint64_t nb = 2 * dc_needed;
        dc_bytes = malloc((size_t)nb);
        dc = malloc((size_t)nb);
        status = dc_bytes && dc ? dwa_inflate(start[2], sizes[2], dc_bytes, nb) : -1;
        if (status == 0) {
            /* The ZIP codec's preprocessing: byte deltas, then the two halves interleaved. */
            for (uint64_t i = 1; i < nb; i++) dc_bytes[i] = (uint8_t)(dc_bytes[i - 1] + dc_bytes[i] - 128);
            uint8_t *d = (uint8_t *)dc;
            for (uint64_t i = 0; i < nb; i++) d[i] = i % 2 ? dc_bytes[(nb + 1) / 2 + i / 2] : dc_bytes[i / 2];
            for (uint64_t i = 0; i < dc_needed; i++) dc[i] = (uint16_t)(d[2 * i] | d[2 * i + 1] << 8);
        }
    }
    if (status == 0 && rle_bytes) {
        rle_packed = malloc((size_t)n[DWA_RLE_UNPACKED] + 1);
        rle = malloc((size_t)rle_bytes);
        status = rle_packed && rle ? dwa_inflate(start[3], sizes[3], rle_packed, n[DWA_RLE_UNPACKED]) : -1;
        if (status == 0) status = rle_decode(rle_packed, n[DWA_RLE_UNPACKED], rle, rle_bytes);
    }

    /* Colour triples first, then the other channels in order, as they were coded. */
    dwa_state *st = status == 0 ? malloc(sizeof *st) : NULL;
    if (status == 0 && !st) status = -1;
    if (st) {
        dwa_state_init(st);
        st->ac = ac;
        st->dc = dc;
        st->ac_count = n[DWA_AC_COUNT];
        st->dc_count = dc_needed;
        st->ac_pos = st->dc_pos = 0;
        st->to_linear = dwa_to_linear;
    }
    for (int g = 0; g < ngroups && status == 0; g++) {
        const int *t = triple[g];
        if (t[0] < 0 || t[1] < 0 || t[2] < 0) continue;
        if (scheme[t[0]] != DWA_LOSSY_DCT || scheme[t[1]] != DWA_LOSSY_DCT || scheme[t[2]] != DWA_LOSSY_DCT) {
            status = -1;
            break;
        }
        status = dwa_lossy(st, dec, t, 3, 0, out, stride, offset);
        done[t[0]] = done[t[1]] = done[t[2]] = 1;
    }
    uint64_t unknown_pos = 0, rle_pos = 0;
    for (int c = 0; c < nchan && status == 0; c++) {
        if (done[c]) continue;
        const exr_coding_channel_info_t *ch = &dec->channels[c];
        size_t row = (size_t)w * (size_t)ch->bytes_per_element;
        if (scheme[c] == DWA_LOSSY_DCT) {
            status = dwa_lossy(st, dec, &c, 1, ch->p_linear, out, stride, offset);
        } else if (scheme[c] == DWA_RLE) { /* byte planes: all first bytes, all second bytes, ... */
            size_t plane = (size_t)w * (size_t)h;
            for (int y = 0; y < h; y++)
                for (int x = 0; x < w; x++)
                    for (int b = 0; b < ch->bytes_per_element; b++)
                        out[(size_t)y * stride + offset[c] + (size_t)x * (size_t)ch->bytes_per_element + (size_t)b] =
                            rle[rle_pos + (size_t)b * plane + (size_t)y * (size_t)w + (size_t)x];
            rle_pos += row * (size_t)h;
        } else {
            for (int y = 0; y < h; y++)
                memcpy(out + (size_t)y * stride + offset[c], unknown + unknown_pos + (size_t)y * row, row);
            unknown_pos += row * (size_t)h;
        }
    }
    if (status == 0 && st && (st->ac_pos != st->ac_count || st->dc_pos != st->dc_count)) status = -1;
    free(st);
    free(unknown);
    free(rle);
    free(rle_packed);
    free(dc_bytes);
    free(dc);
    free(ac);
    free(scheme);
    free(group);
    free(triple);
    free(offset);
    free(done);
    return status == 0 ? EXR_ERR_SUCCESS : EXR_ERR_CORRUPT_CHUNK;
}

/* The pipeline's decompress step for DWAA/DWAB parts. */
static exr_result_t dwa_decompress(exr_decode_pipeline_t *dec) {
    exr_result_t rv = dwa_decompress_chunk(dec);
    if (rv != EXR_ERR_SUCCESS && exr_sink && !exr_sink->msg[0])
        snprintf(exr_sink->msg, sizeof exr_sink->msg, "corrupt DWA-compressed data (chunk at x %d, y %d)",
                 dec->chunk.start_x, dec->chunk.start_y);
    return rv;
}

/* Decodes the selected channels of one part, over its data window, into img (already holding
 * names and zeroed planes of w x h). */
static int exr_decode_part(exr_context_t ctx, int part, exr_storage_t storage, exr_attr_box2i_t dw, exr_image *img,
                           const char *path, const exr_errbox *box, char *err, size_t errlen) {
    int w = img->width, h = img->height;
    exr_decode_pipeline_t dec = EXR_DECODE_PIPELINE_INITIALIZER;
    int status = 0, tiles_x = 1, tiles_y = 1, tile_w = 0, tile_h = 0, lines = 1, chunks = 0;
    exr_compression_t compression = EXR_COMPRESSION_NONE;
    exr_result_t rv = exr_get_compression(ctx, part, &compression);
    if (rv != EXR_ERR_SUCCESS) return exr_fail(err, errlen, path, "incomplete header", rv, box);
    int dwa = compression == EXR_COMPRESSION_DWAA || compression == EXR_COMPRESSION_DWAB;
    if (storage == EXR_STORAGE_TILED) {
        int32_t tw = 0, th = 0;
        rv = exr_get_tile_sizes(ctx, part, 0, 0, &tw, &th);
        if (rv != EXR_ERR_SUCCESS) return exr_fail(err, errlen, path, "cannot read tile layout", rv, box);
        if (tw <= 0 || th <= 0) return fail(err, errlen, path, "invalid tile size %dx%d", (int)tw, (int)th);
        tile_w = tw;
        tile_h = th;
        tiles_x = (int)((w + (int64_t)tw - 1) / tw);
        tiles_y = (int)((h + (int64_t)th - 1) / th);
        chunks = tiles_x * tiles_y;
    } else {
        int32_t spc = 0;
        rv = exr_get_scanlines_per_chunk(ctx, part, &spc);
        if (rv != EXR_ERR_SUCCESS) return exr_fail(err, errlen, path, "cannot read chunk layout", rv, box);
        if (spc <= 0) return fail(err, errlen, path, "invalid scanlines per chunk (%d)", (int)spc);
        lines = spc;
        chunks = (int)((h + (int64_t)spc - 1) / spc);
    }
    /* One chunk's worth of rows, at the planes' line stride, for the channels not wanted. */
    int64_t scratch_rows = storage == EXR_STORAGE_TILED ? tile_h : lines;
    if (scratch_rows > h) scratch_rows = h;
    float *scratch = calloc((size_t)scratch_rows * (size_t)w, sizeof(float));
    if (!scratch) return fail(err, errlen, path, "out of memory");

    for (int i = 0; i < chunks && status == 0; i++) {
        exr_chunk_info_t ci;
        int x0, y0;
        if (storage == EXR_STORAGE_TILED) {
            int tx = i % tiles_x, ty = i / tiles_x;
            rv = exr_read_tile_chunk_info(ctx, part, tx, ty, 0, 0, &ci);
            x0 = tx * tile_w;
            y0 = ty * tile_h;
        } else {
            rv = exr_read_scanline_chunk_info(ctx, part, dw.min.y + i * lines, &ci);
            x0 = 0;
            y0 = ci.start_y - dw.min.y;
        }
        if (rv != EXR_ERR_SUCCESS) {
            status = exr_fail(err, errlen, path, "corrupt or truncated file", rv, box);
            break;
        }
        /* The library validated the chunk against the header; this guards our own arithmetic. */
        if (x0 < 0 || y0 < 0 || ci.width < 0 || ci.height < 0 || (int64_t)x0 + ci.width > w ||
            (int64_t)y0 + ci.height > h) {
            status = fail(err, errlen, path, "chunk %d lies outside the data window", i);
            break;
        }
        rv = i == 0 ? exr_decoding_initialize(ctx, part, &ci, &dec) : exr_decoding_update(ctx, part, &ci, &dec);
        if (rv != EXR_ERR_SUCCESS) {
            status = exr_fail(err, errlen, path, "cannot decode", rv, box);
            break;
        }
        if (bind_decode_channels(&dec, img, scratch, w, x0, y0) != 0) {
            status = fail(err, errlen, path, "chunk %d has an unexpected size", i);
            break;
        }
        /* The default routines depend on the output layout, so they are chosen again per chunk. */
        rv = exr_decoding_choose_default_routines(ctx, part, &dec);
        if (rv == EXR_ERR_SUCCESS && dwa) dec.decompress_fn = dwa_decompress;
        if (rv == EXR_ERR_SUCCESS) rv = exr_decoding_run(ctx, part, &dec);
        if (rv != EXR_ERR_SUCCESS) status = exr_fail(err, errlen, path, "corrupt or truncated file", rv, box);
    }
    exr_decoding_destroy(ctx, &dec);
    free(scratch);
    return status;
}

/* Re-frames img from its data window onto the display window: pixels outside the data window are
 * zero (as EXR defines them), data outside the display window is dropped. */
static int exr_to_display_window(exr_image *img, exr_attr_box2i_t dw, exr_attr_box2i_t disp) {
    int dispw = (int)box_width(disp), disph = (int)box_height(disp);
    for (int k = 0; k < img->num_channels; k++) {
        float *dst = calloc((size_t)dispw * (size_t)disph, sizeof(float));
        if (!dst) return -1;
        const float *src = img->planes[k];
        int64_t x_lo = dw.min.x > disp.min.x ? dw.min.x : disp.min.x;
        int64_t x_hi = dw.max.x < disp.max.x ? dw.max.x : disp.max.x;
        for (int64_t y = disp.min.y; y <= disp.max.y && x_lo <= x_hi; y++) {
            if (y < dw.min.y || y > dw.max.y) continue;
            memcpy(dst + (size_t)(y - disp.min.y) * (size_t)dispw + (size_t)(x_lo - disp.min.x),
                   src + (size_t)(y - dw.min.y) * (size_t)img->width + (size_t)(x_lo - dw.min.x),
                   sizeof(float) * (size_t)(x_hi - x_lo + 1));
        }
        free(img->planes[k]);
        img->planes[k] = dst;
    }
    img->width = dispw;
    img->height = disph;
    return 0;
}

/* Reads the first image (non-deep) part of the EXR open on fd. */
static int exr_read(const char *path, int fd, int64_t size, exr_select select, exr_image *out, int *lossy_dct,
                    char *err, size_t errlen) {
    memset(out, 0, sizeof *out);
    if (lossy_dct) *lossy_dct = 0;
    unsigned char magic[4] = {0};
    if (size == 0) return fail(err, errlen, path, "empty file");
    if (read_at(fd, magic, 4, 0) != 4 || memcmp(magic, exr_magic, 4) != 0)
        return fail(err, errlen, path, "not an OpenEXR file");

    exr_errbox box = {""};
    exr_source src = {fd, size};
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = exr_on_error;
    init.user_data = &src;
    init.read_fn = exr_source_read;
    init.size_fn = exr_source_size;
    init.max_image_width = MAX_IMAGE_DIM;
    init.max_image_height = MAX_IMAGE_DIM;
    exr_context_t ctx = NULL;
    int status = 0;
    exr_sink = &box;

    exr_result_t rv = exr_start_read(&ctx, path, &init);
    if (rv != EXR_ERR_SUCCESS) {
        status = exr_fail(err, errlen, path, "not a readable OpenEXR file", rv, &box);
        goto done;
    }
    int nparts = 0, part = -1;
    exr_storage_t storage = EXR_STORAGE_SCANLINE;
    exr_get_count(ctx, &nparts);
    for (int p = 0; p < nparts && part < 0; p++) {
        if (exr_get_storage(ctx, p, &storage) == EXR_ERR_SUCCESS &&
            (storage == EXR_STORAGE_SCANLINE || storage == EXR_STORAGE_TILED))
            part = p;
    }
    if (part < 0) {
        status = fail(err, errlen, path, "no flat image part (deep data is not supported)");
        goto done;
    }
    exr_attr_box2i_t dw, disp;
    const exr_attr_chlist_t *chans = NULL;
    if ((rv = exr_get_data_window(ctx, part, &dw)) != EXR_ERR_SUCCESS ||
        (rv = exr_get_display_window(ctx, part, &disp)) != EXR_ERR_SUCCESS ||
        (rv = exr_get_channels(ctx, part, &chans)) != EXR_ERR_SUCCESS || !chans) {
        status = exr_fail(err, errlen, path, "incomplete header", rv, &box);
        goto done;
    }
    if (!size_ok(box_width(dw), box_height(dw)) || !size_ok(box_width(disp), box_height(disp))) {
        status = fail(err, errlen, path, "unsupported image size (data window %lldx%lld, display window %lldx%lld)",
                      (long long)box_width(dw), (long long)box_height(dw), (long long)box_width(disp),
                      (long long)box_height(disp));
        goto done;
    }

    /* Subsampled channels come from luminance/chroma images, which would need reconstructing to
     * RGB; the library's fast unpackers also mishandle them next to full-resolution ones. */
    for (int i = 0; i < chans->num_channels; i++) {
        if (chans->entries[i].x_sampling != 1 || chans->entries[i].y_sampling != 1) {
            status = fail(err, errlen, path, "channel %s is subsampled (luminance/chroma images are not supported)",
                          chans->entries[i].name.str);
            goto done;
        }
    }

    /* Choose the channels: indices into the channel list, in output order. */
    int *pick = malloc(sizeof(int) * (size_t)(chans->num_channels > 0 ? chans->num_channels : 1));
    int npick = 0;
    if (!pick) {
        status = fail(err, errlen, path, "out of memory");
        goto done;
    }
    if (select == EXR_SELECT_RGB) {
        int r = chlist_find(chans, "R"), g = chlist_find(chans, "G"), b = chlist_find(chans, "B");
        int y = chlist_find(chans, "Y");
        if (r >= 0 && g >= 0 && b >= 0) {
            pick[0] = r, pick[1] = g, pick[2] = b, npick = 3;
        } else if (y >= 0) {
            pick[0] = y, npick = 1;
        }
    } else {
        for (int i = 0; i < chans->num_channels; i++) pick[npick++] = i;
    }
    if (npick == 0) {
        free(pick);
        status = fail(err, errlen, path, select == EXR_SELECT_RGB ? "no R, G, B or Y channel" : "no channels");
        goto done;
    }

    out->width = (int)box_width(dw);
    out->height = (int)box_height(dw);
    out->names = calloc((size_t)npick, sizeof(char *));
    out->planes = calloc((size_t)npick, sizeof(float *));
    int oom = !out->names || !out->planes;
    for (int k = 0; k < npick && !oom; k++) {
        out->names[k] = strdup(chans->entries[pick[k]].name.str);
        out->planes[k] = calloc((size_t)out->width * (size_t)out->height, sizeof(float));
        out->num_channels = k + 1;
        oom = !out->names[k] || !out->planes[k];
    }
    free(pick);
    if (oom) {
        status = fail(err, errlen, path, "out of memory for a %dx%d image", out->width, out->height);
        goto done;
    }
    status = exr_decode_part(ctx, part, storage, dw, out, path, &box, err, errlen);
    exr_compression_t compression;
    if (lossy_dct && exr_get_compression(ctx, part, &compression) == EXR_ERR_SUCCESS)
        *lossy_dct = compression == EXR_COMPRESSION_DWAA || compression == EXR_COMPRESSION_DWAB;
    if (status == 0 && memcmp(&dw, &disp, sizeof dw) != 0 && exr_to_display_window(out, dw, disp) != 0)
        status = fail(err, errlen, path, "out of memory");

done:
    if (ctx) exr_finish(&ctx);
    exr_sink = NULL;
    if (status != 0) image_free_partial(out);
    return status;
}

int exr_image_load(const char *path, exr_image *out, char *err, size_t errlen) {
    memset(out, 0, sizeof *out);
    int64_t size = 0;
    int fd = open_input(path, &size, err, errlen);
    if (fd < 0) return -1;
    int status = exr_read(path, fd, size, EXR_SELECT_ALL, out, NULL, err, errlen);
    close(fd);
    return status;
}

void exr_image_free(exr_image *img) {
    if (img) image_free_partial(img);
}

const float *exr_image_channel(const exr_image *img, const char *name) {
    for (int i = 0; img && name && i < img->num_channels; i++)
        if (strcmp(img->names[i], name) == 0) return img->planes[i];
    return NULL;
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

static int load_exr_rgb(const char *path, int fd, int64_t size, image_rgb *out, char *err, size_t errlen) {
    exr_image ex;
    int lossy_dct = 0;
    if (exr_read(path, fd, size, EXR_SELECT_RGB, &ex, &lossy_dct, err, errlen) != 0) return -1;
    size_t n = (size_t)ex.width * (size_t)ex.height;
    float *rgb = malloc(sizeof(float) * 3 * n);
    if (!rgb) {
        exr_image_free(&ex);
        return fail(err, errlen, path, "out of memory");
    }
    for (int c = 0; c < 3; c++) {
        const float *plane = ex.planes[ex.num_channels == 3 ? c : 0]; /* Y: gray */
        for (size_t i = 0; i < n; i++) rgb[3 * i + (size_t)c] = plane[i];
    }
    /* DWA's DCT rings slightly below zero next to dark texels (even in Blender's own studio
     * lights); those are coding noise, not data, so they read as zero. */
    if (lossy_dct)
        for (size_t i = 0; i < 3 * n; i++)
            if (rgb[i] < 0.0f) rgb[i] = 0.0f;
    out->width = ex.width;
    out->height = ex.height;
    out->rgb = rgb;
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
    else if (got >= 2 && magic[0] == '#' && magic[1] == '?')
        status = load_hdr_rgb(path, fd, size, out, err, errlen);
    else
        status = fail(err, errlen, path, "not an OpenEXR or Radiance HDR image");
    close(fd);
    if (status == 0 && check_texels(path, out, err, errlen) != 0) status = -1;
    if (status != 0) image_rgb_free(out);
    return status;
}

void image_rgb_free(image_rgb *img) {
    if (!img) return;
    free(img->rgb);
    memset(img, 0, sizeof *img);
}

/* ---- OpenEXR: writing ------------------------------------------------------------------------ */

/* OpenEXR 3.1's ZIP encoder keeps its zlib output when that is exactly as long as the raw chunk,
 * and every reader then takes it for raw pixels (OpenEXR issue #2306): noisy renders hit this.
 * In that case the raw bytes are stored instead, as the format prescribes when compression does
 * not pay. The library's own compressor is called first; it is the same for every chunk. */
static _Thread_local exr_result_t (*exr_zip_compress)(exr_encode_pipeline_t *);

static exr_result_t exr_zip_compress_or_store(exr_encode_pipeline_t *enc) {
    exr_result_t rv = exr_zip_compress(enc);
    if (rv == EXR_ERR_SUCCESS && enc->compressed_bytes == enc->packed_bytes && enc->compressed_buffer &&
        enc->packed_buffer && enc->compressed_buffer != enc->packed_buffer)
        memcpy(enc->compressed_buffer, enc->packed_buffer, enc->packed_bytes);
    return rv;
}

/* Encodes the layers as a ZIP-compressed scanline EXR into buf. */
static int exr_encode(const char *path, int width, int height, const exr_layer *layers, int num_layers, char **names,
                      membuf *buf, char *err, size_t errlen) {
    exr_errbox box = {""};
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = exr_on_error;
    init.user_data = buf;
    init.write_fn = exr_membuf_write; /* the file name is then only used in messages */
    exr_context_t ctx = NULL;
    exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
    int have_enc = 0, part = 0, status = 0, nchan = 3 * num_layers;
    const char *what = "cannot write OpenEXR";
    exr_sink = &box;

    exr_result_t rv = exr_start_write(&ctx, path, EXR_WRITE_FILE_DIRECTLY, &init);
    if (rv == EXR_ERR_SUCCESS) rv = exr_add_part(ctx, NULL, EXR_STORAGE_SCANLINE, &part);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_initialize_required_attr_simple(ctx, part, width, height, EXR_COMPRESSION_ZIP);
    int longest = 0;
    for (int k = 0; k < nchan; k++)
        if ((int)strlen(names[k]) > longest) longest = (int)strlen(names[k]);
    if (rv == EXR_ERR_SUCCESS && longest > 31) rv = exr_set_longname_support(ctx, 1);
    /* The library keeps the channel list sorted by name, as the format requires; the encoder's
     * channels follow that order, so they are bound by name below, not by position. */
    for (int k = 0; k < nchan && rv == EXR_ERR_SUCCESS; k++)
        rv = exr_add_channel(ctx, part, names[k], EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1);
    if (rv == EXR_ERR_SUCCESS) rv = exr_write_header(ctx);
    int32_t lines = 0;
    if (rv == EXR_ERR_SUCCESS) rv = exr_get_scanlines_per_chunk(ctx, part, &lines);
    if (rv == EXR_ERR_SUCCESS && lines <= 0) rv = EXR_ERR_UNKNOWN;

    for (int y = 0; y < height && rv == EXR_ERR_SUCCESS; y += lines) {
        exr_chunk_info_t ci;
        what = "cannot encode OpenEXR";
        rv = exr_write_scanline_chunk_info(ctx, part, y, &ci);
        if (rv != EXR_ERR_SUCCESS) break;
        rv = have_enc ? exr_encoding_update(ctx, part, &ci, &enc) : exr_encoding_initialize(ctx, part, &ci, &enc);
        have_enc = 1;
        if (rv != EXR_ERR_SUCCESS) break;
        for (int c = 0; c < enc.channel_count; c++) {
            exr_coding_channel_info_t *ch = &enc.channels[c];
            int k = 0;
            while (k < nchan && strcmp(names[k], ch->channel_name) != 0) k++;
            if (k == nchan) {
                rv = EXR_ERR_UNKNOWN;
                break;
            }
            ch->encode_from_ptr =
                (const uint8_t *)(layers[k / 3].rgb + 3 * ((size_t)ci.start_y * (size_t)width) + (size_t)(k % 3));
            ch->user_data_type = EXR_PIXEL_FLOAT;
            ch->user_bytes_per_element = 4;
            ch->user_pixel_stride = 3 * 4;
            ch->user_line_stride = 3 * 4 * width;
        }
        if (rv == EXR_ERR_SUCCESS) rv = exr_encoding_choose_default_routines(ctx, part, &enc);
        if (rv == EXR_ERR_SUCCESS && enc.compress_fn && enc.compress_fn != exr_zip_compress_or_store) {
            exr_zip_compress = enc.compress_fn;
            enc.compress_fn = exr_zip_compress_or_store;
        }
        if (rv == EXR_ERR_SUCCESS) rv = exr_encoding_run(ctx, part, &enc);
    }
    if (have_enc) exr_encoding_destroy(ctx, &enc);
    if (rv != EXR_ERR_SUCCESS) {
        status = buf->failed ? fail(err, errlen, path, "out of memory") : exr_fail(err, errlen, path, what, rv, &box);
    }
    if (ctx) {
        /* finish writes the chunk offset table, so its result matters. */
        exr_result_t frv = exr_finish(&ctx);
        if (status == 0 && frv != EXR_ERR_SUCCESS)
            status = buf->failed ? fail(err, errlen, path, "out of memory") : exr_fail(err, errlen, path, what, frv, &box);
    }
    if (status == 0 && buf->failed) status = fail(err, errlen, path, "out of memory");
    exr_sink = NULL;
    return status;
}

int exr_save_layers(const char *path, int width, int height, const exr_layer *layers, int num_layers, write_mode mode,
                    char *err, size_t errlen) {
    if (!path || !path[0]) return fail(err, errlen, path ? path : "", "empty file name");
    if (width <= 0 || height <= 0 || width > MAX_IMAGE_DIM || height > MAX_IMAGE_DIM)
        return fail(err, errlen, path, "invalid image size %dx%d", width, height);
    if (!layers || num_layers <= 0 || num_layers > 1000) return fail(err, errlen, path, "no layers to write");
    for (int l = 0; l < num_layers; l++) {
        if (!layers[l].prefix || !layers[l].rgb) return fail(err, errlen, path, "layer %d has no name or pixels", l);
        for (int m = 0; m < l; m++)
            if (strcmp(layers[l].prefix, layers[m].prefix) == 0)
                return fail(err, errlen, path, "layer name '%s' used twice", layers[l].prefix);
    }
    int nchan = 3 * num_layers;
    char **names = calloc((size_t)nchan, sizeof(char *));
    int status = names ? 0 : fail(err, errlen, path, "out of memory");
    for (int k = 0; k < nchan && status == 0; k++) {
        const char *prefix = layers[k / 3].prefix;
        size_t len = strlen(prefix) + 3;
        names[k] = malloc(len);
        if (!names[k]) {
            status = fail(err, errlen, path, "out of memory");
            break;
        }
        if (prefix[0])
            snprintf(names[k], len, "%s.%c", prefix, "RGB"[k % 3]);
        else
            snprintf(names[k], len, "%c", "RGB"[k % 3]);
    }
    membuf buf = {0};
    if (status == 0) status = exr_encode(path, width, height, layers, num_layers, names, &buf, err, errlen);
    if (status == 0) status = write_file_atomic(path, buf.data, buf.size, mode, err, errlen);
    free(buf.data);
    for (int k = 0; names && k < nchan; k++) free(names[k]);
    free(names);
    return status;
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

int write_file_atomic(const char *path, const void *data, size_t size, write_mode mode, char *err, size_t errlen) {
    if (!path || !path[0]) return fail(err, errlen, path ? path : "", "empty file name");
    if (!data && size > 0) return fail(err, errlen, path, "no data to write");
    /* Only a regular file is ever replaced: renaming over a device (--stats /dev/null), a
     * directory or a FIFO would destroy it (a session once turned /dev/null into a file). */
    struct stat existing;
    if (mode == WRITE_REPLACE && lstat(path, &existing) == 0 && !S_ISREG(existing.st_mode) && !S_ISLNK(existing.st_mode))
        return fail(err, errlen, path, "not a regular file; not replacing it");
    /* The temporary file is created next to the target (so rename and link stay within one file
     * system), named after it with ".tmp-" so a leftover is recognisable. mkstemp is not used
     * because it creates files with mode 0600; this honours the umask like any other output. */
    size_t tmplen = strlen(path) + 16;
    char *tmp = malloc(tmplen);
    if (!tmp) return fail(err, errlen, path, "out of memory");
    int fd = -1;
    for (int attempt = 0; attempt < 100 && fd < 0; attempt++) {
        char suffix[7];
        temp_suffix(suffix);
        snprintf(tmp, tmplen, "%s.tmp-%s", path, suffix);
        fd = open(tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd < 0 && errno != EEXIST) break;
    }
    if (fd < 0) {
        int e = errno;
        char dir[1024];
        parent_dir(path, dir, sizeof dir);
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
            if (link(tmp, path) != 0)
                status = errno == EEXIST ? fail(err, errlen, path, "file exists")
                                         : fail(err, errlen, path, "cannot create: %s", strerror(errno));
        } else if (rename(tmp, path) != 0) {
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
        parent_dir(path, dir, sizeof dir);
        int dfd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
        if (dfd >= 0) {
            fsync(dfd);
            close(dfd);
        }
    }
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
