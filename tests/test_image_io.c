/* Image I/O against expectations that do not come from image_io.c itself: EXR files written here
 * with OpenEXR's C API directly (tiled, half and uint channels, offset data windows), values that
 * are a closed-form function of the pixel, a DWAB file and reference texels produced by OpenEXR's
 * C++ library, image sizes read from the files' own headers, and PNGs decoded by stb_image. Also
 * the atomic writer's guarantees (no replace, no partial file, no temporary left behind) and that
 * broken files fail with a message instead of crashing (this test runs under ASan/UBSan). And the
 * film's running means. */
#define _POSIX_C_SOURCE 200809L

#include <dirent.h>
#include <errno.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <openexr.h>
#include <stb/stb_image.h>

#include "check.h"
#include "film.h"
#include "image_io.h"

static char dir[1024]; /* this run's scratch directory */

/* ---- small file helpers ---------------------------------------------------------------------- */

static void path_in(char *out, size_t outlen, const char *name) { snprintf(out, outlen, "%s/%s", dir, name); }

static int put_file(const char *path, const void *data, size_t size) {
    FILE *f = fopen(path, "wb");
    if (!f) return -1;
    size_t n = size ? fwrite(data, 1, size, f) : 0;
    return fclose(f) == 0 && n == size ? 0 : -1;
}

/* Reads a whole file (malloc'd, *size set), or NULL. */
static unsigned char *get_file(const char *path, size_t *size) {
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    unsigned char *buf = NULL;
    size_t cap = 0, len = 0;
    for (;;) {
        if (len == cap) {
            cap = cap ? 2 * cap : 65536;
            unsigned char *p = realloc(buf, cap);
            if (!p) break;
            buf = p;
        }
        size_t n = fread(buf + len, 1, cap - len, f);
        len += n;
        if (n == 0) break;
    }
    fclose(f);
    *size = len;
    return buf;
}

static int file_exists(const char *path) {
    struct stat st;
    return lstat(path, &st) == 0;
}

/* Files in the scratch directory whose name marks them as the atomic writer's temporaries. */
static int stray_temp_files(const char *where) {
    DIR *d = opendir(where);
    int n = 0;
    struct dirent *e;
    while (d && (e = readdir(d)))
        if (strstr(e->d_name, ".tmp")) {
            fprintf(stderr, "stray temporary file: %s/%s\n", where, e->d_name);
            n++;
        }
    if (d) closedir(d);
    return n;
}

static void remove_tree(const char *path) {
    struct stat st;
    if (lstat(path, &st) != 0) return;
    if (S_ISDIR(st.st_mode)) {
        DIR *d = opendir(path);
        struct dirent *e;
        while (d && (e = readdir(d))) {
            if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
            char sub[2048];
            snprintf(sub, sizeof sub, "%s/%s", path, e->d_name);
            remove_tree(sub);
        }
        if (d) closedir(d);
        rmdir(path);
    } else {
        unlink(path);
    }
}

static int one_line(const char *s) { return s[0] && !strchr(s, '\n') && !strchr(s, '\r'); }

/* ---- an independent EXR writer (OpenEXR C API, used directly) -------------------------------- */

typedef struct {
    const char *name;
    exr_pixel_type_t type;
    int sampling; /* x and y subsampling; 0 means 1 */
} test_chan;

/* Channel c's value at absolute pixel (x, y): multiples of 1/4 below 16, exact in half floats. */
static float half_value(int c, int x, int y) { return (float)(((x * 7 + y * 13 + c * 5) % 64 + 64) % 64) * 0.25f; }
static uint32_t uint_value(int x, int y) { return (uint32_t)((x + 100) * 1000 + (y + 100)); }

/* Writes an EXR of the given storage and compression whose channels hold half_value (float and
 * half channels) or uint_value (uint channels) over the data window dw. */
static int write_test_exr(const char *path, exr_storage_t storage, exr_compression_t comp, const test_chan *chans,
                          int nchan, exr_attr_box2i_t dw, exr_attr_box2i_t disp) {
    int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
    float *planes[8] = {0};
    uint32_t *uplanes[8] = {0};
    for (int c = 0; c < nchan; c++) {
        planes[c] = malloc(sizeof(float) * (size_t)w * (size_t)h);
        uplanes[c] = malloc(sizeof(uint32_t) * (size_t)w * (size_t)h);
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                planes[c][y * w + x] = half_value(c, dw.min.x + x, dw.min.y + y);
                uplanes[c][y * w + x] = uint_value(dw.min.x + x, dw.min.y + y);
            }
    }
    exr_context_t ctx = NULL;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    int part = 0;
    exr_attr_v2f_t center;
    center.x = center.y = 0.0f;
    exr_result_t rv = exr_start_write(&ctx, path, EXR_WRITE_FILE_DIRECTLY, &init);
    if (!rv) rv = exr_add_part(ctx, "main", storage, &part);
    if (!rv)
        rv = exr_initialize_required_attr(ctx, part, &disp, &dw, 1.0f, &center, 1.0f, EXR_LINEORDER_INCREASING_Y, comp);
    const int tw = 16, th = 8;
    if (!rv && storage == EXR_STORAGE_TILED)
        rv = exr_set_tile_descriptor(ctx, part, tw, th, EXR_TILE_ONE_LEVEL, EXR_TILE_ROUND_DOWN);
    for (int c = 0; c < nchan && !rv; c++)
        rv = exr_add_channel(ctx, part, chans[c].name, chans[c].type, EXR_PERCEPTUALLY_LOGARITHMIC,
                             chans[c].sampling ? chans[c].sampling : 1, chans[c].sampling ? chans[c].sampling : 1);
    if (!rv) rv = exr_write_header(ctx);
    int32_t lines = 1;
    if (!rv && storage == EXR_STORAGE_SCANLINE) rv = exr_get_scanlines_per_chunk(ctx, part, &lines);
    int nx = storage == EXR_STORAGE_TILED ? (w + tw - 1) / tw : 1;
    int ny = storage == EXR_STORAGE_TILED ? (h + th - 1) / th : (h + lines - 1) / lines;
    exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
    for (int i = 0; i < nx * ny && !rv; i++) {
        exr_chunk_info_t ci;
        int x0 = 0, y0;
        if (storage == EXR_STORAGE_TILED) {
            x0 = (i % nx) * tw;
            y0 = (i / nx) * th;
            rv = exr_write_tile_chunk_info(ctx, part, i % nx, i / nx, 0, 0, &ci);
        } else {
            rv = exr_write_scanline_chunk_info(ctx, part, dw.min.y + i * lines, &ci);
            y0 = ci.start_y - dw.min.y;
        }
        if (!rv) rv = i == 0 ? exr_encoding_initialize(ctx, part, &ci, &enc) : exr_encoding_update(ctx, part, &ci, &enc);
        for (int k = 0; k < enc.channel_count && !rv; k++) {
            exr_coding_channel_info_t *ch = &enc.channels[k];
            int c = 0;
            while (c < nchan && strcmp(chans[c].name, ch->channel_name)) c++;
            int is_uint = chans[c].type == EXR_PIXEL_UINT;
            const void *base = is_uint ? (const void *)(uplanes[c] + y0 * w + x0) : (const void *)(planes[c] + y0 * w + x0);
            ch->encode_from_ptr = base;
            ch->user_data_type = (uint16_t)(is_uint ? EXR_PIXEL_UINT : EXR_PIXEL_FLOAT);
            ch->user_bytes_per_element = 4;
            ch->user_pixel_stride = 4;
            ch->user_line_stride = 4 * w; /* subsampled channels just take fewer samples of the plane */
        }
        if (!rv) rv = exr_encoding_choose_default_routines(ctx, part, &enc);
        if (!rv) rv = exr_encoding_run(ctx, part, &enc);
    }
    exr_encoding_destroy(ctx, &enc);
    exr_result_t frv = exr_finish(&ctx);
    for (int c = 0; c < nchan; c++) {
        free(planes[c]);
        free(uplanes[c]);
    }
    return rv || frv ? -1 : 0;
}

/* ---- EXR round trip through exr_save_layers / exr_image_load --------------------------------- */

/* Layer l, component c at (x, y): a mix of ordinary, negative, denormal, tiny and huge floats. */
static float layer_value(int l, int c, int x, int y) {
    static const float specials[] = {1e-30f, 6e4f, 1e30f, -3.25f, 1e-40f, 0.0f, 65504.0f, 3.4e38f};
    int k = (x * 31 + y * 17 + l * 7 + c * 3) % 11;
    if (k < 8) return specials[k];
    return (float)(x - 2 * y) * 0.1f + (float)l + (float)c * 1e-3f;
}

static exr_attr_box2i_t box(int x0, int y0, int x1, int y1) {
    exr_attr_box2i_t b;
    b.min.x = x0, b.min.y = y0, b.max.x = x1, b.max.y = y1;
    return b;
}

static int bits_equal(float a, float b) { return memcmp(&a, &b, sizeof a) == 0; }

static void test_exr_roundtrip(void) {
    enum { W = 37, H = 23, L = 3 };
    const char *prefixes[L] = {"", "direct", "indirect"};
    float *rgb[L];
    exr_layer layers[L];
    for (int l = 0; l < L; l++) {
        rgb[l] = malloc(sizeof(float) * 3 * W * H);
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++)
                for (int c = 0; c < 3; c++) rgb[l][3 * (y * W + x) + c] = layer_value(l, c, x, y);
        layers[l] = (exr_layer){prefixes[l], rgb[l]};
    }
    char path[1200], err[512] = "";
    path_in(path, sizeof path, "layers.exr");
    int rc = exr_save_layers(path, W, H, layers, L, WRITE_NO_REPLACE, err, sizeof err);
    CHECK(rc == 0, "exr_save_layers: %s", err);
    exr_image img;
    rc = exr_image_load(path, &img, err, sizeof err);
    CHECK(rc == 0, "exr_image_load of our own file: %s", err);
    if (rc == 0) {
        CHECK(img.width == W && img.height == H, "size %dx%d", img.width, img.height);
        CHECK(img.num_channels == 3 * L, "%d channels", img.num_channels);
        int mismatches = 0;
        for (int l = 0; l < L; l++)
            for (int c = 0; c < 3; c++) {
                char name[32];
                snprintf(name, sizeof name, "%s%s%c", prefixes[l], prefixes[l][0] ? "." : "", "RGB"[c]);
                const float *p = exr_image_channel(&img, name);
                CHECK(p != NULL, "channel %s missing", name);
                for (int i = 0; p && i < W * H; i++)
                    if (!bits_equal(p[i], layer_value(l, c, i % W, i / W))) {
                        if (mismatches++ < 5)
                            fprintf(stderr, "%s (%d, %d): %g, expected %g\n", name, i % W, i / W, p[i],
                                    layer_value(l, c, i % W, i / W));
                    }
            }
        CHECK(mismatches == 0, "%d values differ after the round trip", mismatches);
        CHECK(exr_image_channel(&img, "A") == NULL && exr_image_channel(&img, "direct") == NULL,
              "exr_image_channel finds channels that are not there");
        exr_image_free(&img);
        CHECK(img.planes == NULL && img.num_channels == 0, "exr_image_free leaves the struct set");
    }

    /* The values include negatives: image_rgb_load must refuse them, naming the file. */
    image_rgb im;
    rc = image_rgb_load(path, &im, err, sizeof err);
    CHECK(rc == -1 && strstr(err, path) && strstr(err, "negative"), "negative texels accepted: %s", err);
    CHECK(im.rgb == NULL, "failed load left pixels");

    /* Non-negative layers: image_rgb_load picks the unprefixed R, G, B, not direct.*. */
    for (int l = 0; l < L; l++)
        for (int i = 0; i < 3 * W * H; i++) rgb[l][i] = (float)(l * 1000 + i);
    path_in(path, sizeof path, "positive.exr");
    rc = exr_save_layers(path, W, H, layers, L, WRITE_NO_REPLACE, err, sizeof err);
    CHECK(rc == 0, "exr_save_layers: %s", err);
    rc = image_rgb_load(path, &im, err, sizeof err);
    CHECK(rc == 0, "image_rgb_load of a layered file: %s", err);
    if (rc == 0) {
        int bad = 0;
        for (int i = 0; i < 3 * W * H; i++) bad += im.rgb[i] != (float)i;
        CHECK(im.width == W && im.height == H && bad == 0, "layered file: %dx%d, %d wrong values", im.width,
              im.height, bad);
        image_rgb_free(&im);
    }

    /* Truncations of a file we wrote fail cleanly. */
    size_t size = 0;
    unsigned char *bytes = get_file(path, &size);
    CHECK(bytes && size > 1000, "reading back %s", path);
    const size_t cuts[] = {3, 4, 10, 100, 1000, size / 2, size > 0 ? size - 1 : 0};
    for (size_t k = 0; bytes && k < sizeof cuts / sizeof cuts[0]; k++) {
        char cut[1200];
        path_in(cut, sizeof cut, "cut.exr");
        put_file(cut, bytes, cuts[k]);
        err[0] = '\0';
        rc = exr_image_load(cut, &img, err, sizeof err);
        CHECK(rc == -1 && strstr(err, cut) && one_line(err), "exr truncated to %zu bytes: rc %d, '%s'", cuts[k], rc,
              err);
        CHECK(img.num_channels == 0 && img.planes == NULL, "failed load left channels");
        err[0] = '\0';
        rc = image_rgb_load(cut, &im, err, sizeof err);
        CHECK(rc == -1 && strstr(err, cut), "image_rgb_load of exr truncated to %zu bytes: rc %d, '%s'", cuts[k], rc,
              err);
    }
    free(bytes);
    for (int l = 0; l < L; l++) free(rgb[l]);
}

/* ---- EXR files written independently: tiled, half, uint, windows, Y only --------------------- */

static void test_exr_foreign(void) {
    char path[1200], err[512] = "";
    /* Tiled, PIZ, half R, G, B and a uint channel; the data window is offset from the display
     * window and overlaps it only partly, so loading must pad with zeros and crop. */
    const test_chan chans[4] = {{"B", EXR_PIXEL_HALF, 0}, {"G", EXR_PIXEL_HALF, 0}, {"R", EXR_PIXEL_HALF, 0},
                                {"id", EXR_PIXEL_UINT, 0}};
    exr_attr_box2i_t dw = box(5, -3, 5 + 40 - 1, -3 + 30 - 1); /* 40x30 at (5, -3) */
    exr_attr_box2i_t disp = box(0, 0, 41, 19);                  /* 42x20 at the origin */
    path_in(path, sizeof path, "tiled.exr");
    CHECK(write_test_exr(path, EXR_STORAGE_TILED, EXR_COMPRESSION_PIZ, chans, 4, dw, disp) == 0,
          "writing the tiled test file");
    exr_image img;
    int rc = exr_image_load(path, &img, err, sizeof err);
    CHECK(rc == 0, "exr_image_load of a tiled file: %s", err);
    if (rc == 0) {
        CHECK(img.width == 42 && img.height == 20, "tiled: size %dx%d, expected the display window 42x20", img.width,
              img.height);
        int bad = 0;
        for (int c = 0; c < 4 && img.width == 42 && img.height == 20; c++) {
            const float *p = exr_image_channel(&img, chans[c].name);
            CHECK(p != NULL, "tiled: channel %s missing", chans[c].name);
            for (int y = 0; p && y < 20; y++)
                for (int x = 0; x < 42; x++) {
                    int inside = x >= dw.min.x && x <= dw.max.x && y >= dw.min.y && y <= dw.max.y;
                    float expect = !inside ? 0.0f : c == 3 ? (float)uint_value(x, y) : half_value(c, x, y);
                    if (p[y * 42 + x] != expect && bad++ < 5)
                        fprintf(stderr, "tiled %s (%d, %d) = %g, expected %g\n", chans[c].name, x, y, p[y * 42 + x],
                                expect);
                }
        }
        CHECK(bad == 0, "tiled: %d wrong values", bad);
        exr_image_free(&img);
    }
    image_rgb im;
    rc = image_rgb_load(path, &im, err, sizeof err);
    CHECK(rc == 0 && im.width == 42 && im.height == 20, "image_rgb_load of a tiled file: %s", err);
    if (rc == 0) {
        int bad = 0;
        for (int i = 0; i < 42 * 20; i++) {
            int x = i % 42, y = i / 42, inside = x >= 5 && y <= 26;
            for (int c = 0; c < 3; c++) /* channel order in chans[] is B, G, R */
                bad += im.rgb[3 * i + c] != (inside ? half_value(2 - c, x, y) : 0.0f);
        }
        CHECK(bad == 0, "image_rgb_load of a tiled file: %d wrong values", bad);
        image_rgb_free(&im);
    }

    /* Scanline, uncompressed, luminance only: loads as gray. */
    const test_chan y_only[1] = {{"Y", EXR_PIXEL_HALF, 0}};
    exr_attr_box2i_t win = box(0, 0, 12, 6);
    path_in(path, sizeof path, "gray.exr");
    CHECK(write_test_exr(path, EXR_STORAGE_SCANLINE, EXR_COMPRESSION_NONE, y_only, 1, win, win) == 0,
          "writing the Y test file");
    rc = image_rgb_load(path, &im, err, sizeof err);
    CHECK(rc == 0 && im.width == 13 && im.height == 7, "image_rgb_load of a Y file: %s", err);
    if (rc == 0) {
        int bad = 0;
        for (int i = 0; i < 13 * 7; i++)
            for (int c = 0; c < 3; c++) bad += im.rgb[3 * i + c] != half_value(0, i % 13, i / 13);
        CHECK(bad == 0, "Y file: %d wrong values", bad);
        image_rgb_free(&im);
    }

    /* Half RGBA, the commonest HDR download: alpha is skipped, R, G, B come out exact. */
    const test_chan rgba[4] = {{"A", EXR_PIXEL_HALF, 0}, {"B", EXR_PIXEL_HALF, 0}, {"G", EXR_PIXEL_HALF, 0},
                               {"R", EXR_PIXEL_HALF, 0}};
    exr_attr_box2i_t rgba_win = box(0, 0, 30, 20);
    path_in(path, sizeof path, "rgba.exr");
    CHECK(write_test_exr(path, EXR_STORAGE_SCANLINE, EXR_COMPRESSION_ZIPS, rgba, 4, rgba_win, rgba_win) == 0,
          "writing the RGBA test file");
    rc = image_rgb_load(path, &im, err, sizeof err);
    CHECK(rc == 0 && im.width == 31 && im.height == 21, "image_rgb_load of a half RGBA file: %s", err);
    if (rc == 0) {
        int bad = 0;
        for (int i = 0; i < 31 * 21; i++)
            for (int c = 0; c < 3; c++) bad += im.rgb[3 * i + c] != half_value(3 - c, i % 31, i / 31);
        CHECK(bad == 0, "half RGBA file: %d wrong values", bad);
        image_rgb_free(&im);
    }

    /* Luminance/chroma (subsampled RY, BY) is refused with a message, not misread. */
    const test_chan yc[3] = {{"BY", EXR_PIXEL_HALF, 2}, {"RY", EXR_PIXEL_HALF, 2}, {"Y", EXR_PIXEL_HALF, 0}};
    exr_attr_box2i_t yc_win = box(0, 0, 19, 9);
    path_in(path, sizeof path, "yc.exr");
    CHECK(write_test_exr(path, EXR_STORAGE_SCANLINE, EXR_COMPRESSION_NONE, yc, 3, yc_win, yc_win) == 0,
          "writing the luminance/chroma test file");
    rc = image_rgb_load(path, &im, err, sizeof err);
    CHECK(rc == -1 && strstr(err, path) && strstr(err, "subsampled"), "luminance/chroma file: '%s'", err);
    rc = exr_image_load(path, &img, err, sizeof err);
    CHECK(rc == -1 && strstr(err, path) && strstr(err, "subsampled"), "luminance/chroma file: '%s'", err);

    /* Scanline RLE with a data window inside a larger display window; no RGB, no Y. */
    const test_chan other[2] = {{"Z", EXR_PIXEL_FLOAT, 0}, {"depth.V", EXR_PIXEL_HALF, 0}};
    exr_attr_box2i_t inner = box(2, 3, 9, 40), outer = box(0, 0, 11, 49);
    path_in(path, sizeof path, "window.exr");
    CHECK(write_test_exr(path, EXR_STORAGE_SCANLINE, EXR_COMPRESSION_RLE, other, 2, inner, outer) == 0,
          "writing the window test file");
    rc = exr_image_load(path, &img, err, sizeof err);
    CHECK(rc == 0 && img.width == 12 && img.height == 50 && img.num_channels == 2, "window file: %s", err);
    if (rc == 0) {
        int bad = 0;
        for (int c = 0; c < 2; c++) {
            const float *p = exr_image_channel(&img, other[c].name);
            for (int i = 0; p && i < 12 * 50; i++) {
                int x = i % 12, y = i / 12, inside = x >= 2 && x <= 9 && y >= 3 && y <= 40;
                bad += p[i] != (inside ? half_value(c, x, y) : 0.0f);
            }
            bad += p == NULL;
        }
        CHECK(bad == 0, "window file: %d wrong values", bad);
        exr_image_free(&img);
    }
    rc = image_rgb_load(path, &im, err, sizeof err);
    CHECK(rc == -1 && strstr(err, path) && strstr(err, "channel"), "a file without R, G, B or Y: '%s'", err);
}

/* ---- DWA compression (decoded by image_io.c itself: OpenEXR 3.1's C library cannot) ---------- */

/* A 19x11 tiled (16x16) DWAB file written by OpenEXR's C++ library (exrmaketiled -z dwab) from
 * an image of dwa_value(): channels A (half, coded by DWA's RLE), B, G, R (half, lossy, one
 * colour triple), Y (float, lossy on its own) and Z (float, kept verbatim). */
static const char *const dwab_tiled_hex[] = {
    "762f3101020200006368616e6e656c730063686c697374006d0000004100010000000000000001000000010000004200",
    "010000000000000001000000010000004700010000000000000001000000010000005200010000000000000001000000",
    "010000005900020000000000000001000000010000005a0002000000000000000100000001000000006368756e6b436f",
    "756e7400696e74000400000002000000636f6d7072657373696f6e00636f6d7072657373696f6e000100000009646174",
    "6157696e646f7700626f78326900100000000000000000000000120000000a000000646973706c617957696e646f7700",
    "626f78326900100000000000000000000000120000000a0000006c696e654f72646572006c696e654f72646572000100",
    "000000706978656c417370656374526174696f00666c6f617400040000000000803f73637265656e57696e646f774365",
    "6e746572007632660008000000000000000000000073637265656e57696e646f77576964746800666c6f617400040000",
    "000000803f74696c65730074696c656465736300090000001000000010000000007479706500737472696e67000a0000",
    "0074696c6564696d61676500cc01000000000000d30700000000000000000000000000000000000000000000f3050000",
    "0200000000000000c002000000000000b801000000000000910300000000000029000000000000001300000000000000",
    "460000000000000060010000000000005101000000000000100000000000000000000000000000001600520014014700",
    "240142003401590004024100080178da15d2bf2bc4711cc7f1b7cbf05596bb4d19b86e20066420e27bfa7e3f7dc5800c",
    "c8806e400664f06bf8d00da70c4706ca806ea00cc8400ce886530664f06b4037500664f06bf0fcfc018fe1d9eb252235",
    "628d3b92f9e3c874952bbe7157c2cbae4c1db8727ceb4ac68fab57b295b673957e28525a57299dd7a0f45187d25dfd4a",
    "245e2b1e3e849fc707f0f5f819fc293e0b9fc03bf8343e8a0fe193f888f1962d31bc835fc307f1cdf839fc05de8f5fc7",
    "7bf8677c0c5f804fe17b8df76c49e123f81d7c19be1dbf84bfc1e7e037f18df857fc2cbe187f861f303e6a8b35e14814",
    "7f82afc377e357f18ff87cfc16be09ff868fe34bf0e7f841e313b678f804fe12df82efc36fe05ff085f85d7c2bfe13bf",
    "802fc75fe1478c4fd28f4fe29ff03df821fc36fe1d5f8adfc3b7e1bff08bf80afc357ed4f834fdf834fe033f8c1fc3ef",
    "e3bff195f8437c27fe0fbf8cafc6dfe3278df785c59a64ff5f477cd5ae4ce3a7f0c7f88c3bbe803fc277e1a558e915bc",
    "8d7fc06be30361f1f0217c003f8f9fc19fe2b3f0f5f8243e82cfc427f00e3e8d8f1a1f0c4b0cefe083f835fc1cfe02ef",
    "c737e353f85ebc855fc77bf8677cac5ffd036430f608000000000cff000080020000e30700000000000013ffffffffff",
    "fffffffffffffffffffffffffffffffffffffffffffeb85ffffffffffffea23ffffffffffffa84ffffff423fffffd05f",
    "fe48ffe46ffe49ffe45fde49fde47ffe46fce48fee48fce48fee47fce49fce49fce49fce49fde48fce49fce49fce49fe",
    "e49fce48fee48fde49fffffffff3c9fd649ffa49fc248fde48fd248fe648fda48fffffa823ffffed08fe148fffff3423",
    "f2923fffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffff",
    "ffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffff",
    "ffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffff",
    "fffffffffffffffffffffffffffffffff2717ffffffffffffa87ffffffffffffea13fffffd08ffffff417ff91fff91bf",
    "f923ff917f791ff791ff7923f791bf7923f791ff7923f791bf791bf791ff3923f391ff3923f391ff3923f391ff3923f3",
    "91fff91ff1923f5923f0923f291ff1923f1923f1923f1923f3923f1923f5923f1923f391ff3923f1923fd923f5923f59",
    "23f3923f8123f9123f1923f2923f0923f9923f5923f1923f3923fb123f111ff5123ffffffff6723ffffc308fffff0e23",
    "f4723ffffdb88fc048fe0c8feec8fc4c8fffff5223f4d23fff23fbc23fc723ffffffffffffffffffffffffffffffffff",
    "ffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffff",
    "fffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffe",
    "81001c80081bb200208048436232dcd03c0858b01360e819534226bf299b94ebc75f366eb00d0c2eebf9b277bbc180ad",
    "60ed3b2795cef444b3b12645aa41078cd56a97e1dd93a4979e4b259d1dfca4e17ced6d757553fbc3c40286b66aed4f4c",
    "153e323d711035a0fbc055ad4aaca425e53d6dd9f2e5d9bee03211b2166ac01ce6597ba877898e3cebcf6bfae6b949fa",
    "38c20404c63c14564f2de5ac3259a03ba756ded80516acb6756be1c3a16ae73c0797a320c42cd8c00e164b60de0dbc41",
    "39a11065337295ef4249331185b3a186b13d801b4192c9b4bea6cb2b1dfd2850e8bcdce60059042f3d762d7a9b4a57b3",
    "772f7c97a28b9f8f111772a282307973f0e6e6aab47de0785e7b21705af4e5c9aa0333febcb159e3c6b342a1a9bee97d",
    "5d53354b6d53cdb486864600236210ca78daab67d06760b561b360a2880400ec60063a01000000000000000000000000",
    "000000100200000000000000008e39c739003a283b613b9a3b613c7d3c9a3c5bb0a53f943ea93fcdccac3f80007a4640",
    "d0844640a08c46000000000000553bab3b003c773ca23ccd3c443d6f3d9a3d2222c23f7877c73fcdcccc3f80047a4640",
    "d2844640a28c460000000000008e3cc73c003d5b3d943dcd3d283e613e9a3eea93de3f5bb0e53fcdccec3f80087a4640",
    "d4844640a48c46000000000000723db93d003e3f3e863ecd3e0b3f523f9a3fb105fb3f9ff4014066660640800c7a4640",
    "d6844640a68c46000000000000553eab3e003f223f773fcd3fef3f22404d40bcbb0b40111111406666164080107a4640",
    "d8844640a88c46000000000000393f9c3f004003403540664069409b40cd40a0f41940822d20406666264080147a4640",
    "da844640aa8c460000000000000e40474080407540ae40e640db4014414d41832d2840f4492f406666364080187a4640",
    "dc844640ac8c460000000000008040c0400041e640264166414d418d41cd416666364066663e4066664640801c7a4640",
    "de844640ae8c46000000000000f2403941804158419f41e641bf4106424d424a9f4440d8824d406666564080207a4640",
    "e0844640b08c460000000000006441b2410042ca411842664230427f42cd422ed852404a9f5c406666664080247a4640",
    "e2844640b28c46000000000000d5412b4280423c429142e642a242f7424d4312116140bcbb6b406666764080287a4640",
    "e4844640b48c46"};

static float dwa_value(int c, int x, int y) { /* c: 0 A, 1 B, 2 G, 3 R, 4 Y, 5 Z */
    if (c == 0) return x < 6 ? 1.0f : (x < 13 ? 0.5f : 0.0f);
    if (c == 5) return (float)(x * 1000 + y) + 0.125f;
    return 0.05f + 0.2f * (float)c + 3.0f * (float)x / 18.0f * (float)(y + 2) / 12.0f;
}

/* The bytes spelled by lines of hexadecimal digits. */
static unsigned char *hex_bytes(const char *const *lines, size_t count, size_t *size) {
    size_t n = 0;
    for (size_t l = 0; l < count; l++) n += strlen(lines[l]) / 2;
    unsigned char *b = malloc(n), *o = b;
    for (size_t l = 0; b && l < count; l++)
        for (const char *h = lines[l]; h[0] && h[1]; h += 2) {
            unsigned v = 0;
            sscanf(h, "%2x", &v);
            *o++ = (unsigned char)v;
        }
    *size = n;
    return b;
}

static void test_dwa(void) {
    size_t size = 0;
    unsigned char *file = hex_bytes(dwab_tiled_hex, sizeof dwab_tiled_hex / sizeof dwab_tiled_hex[0], &size);
    char path[1200], err[512] = "";
    path_in(path, sizeof path, "dwab.exr");
    CHECK(file && put_file(path, file, size) == 0, "writing %s", path);
    exr_image img;
    int rc = exr_image_load(path, &img, err, sizeof err);
    CHECK(rc == 0, "exr_image_load of a DWAB file: %s", err);
    if (rc == 0) {
        static const char *names[6] = {"A", "B", "G", "R", "Y", "Z"};
        CHECK(img.width == 19 && img.height == 11 && img.num_channels == 6, "DWAB file: %dx%d, %d channels",
              img.width, img.height, img.num_channels);
        for (int c = 0; c < 6 && img.width == 19 && img.height == 11; c++) {
            const float *p = exr_image_channel(&img, names[c]);
            CHECK(p != NULL, "DWAB file: channel %s missing", names[c]);
            int bad = 0;
            double worst = 0.0;
            for (int i = 0; p && i < 19 * 11; i++) {
                float expect = dwa_value(c, i % 19, i / 19);
                /* lossless for A and Z; the lossy channels' worst error here is 2% */
                double tol = c == 0 || c == 5 ? 0.0 : 0.03 * expect + 1e-3;
                double e = fabs(p[i] - expect);
                bad += !(e <= tol);
                if (e > worst) worst = e;
            }
            CHECK(bad == 0, "DWAB channel %s: %d values off (worst by %g)", names[c], bad, worst);
        }
        exr_image_free(&img);
    }
    image_rgb im;
    rc = image_rgb_load(path, &im, err, sizeof err);
    CHECK(rc == 0 && im.width == 19 && im.height == 11, "image_rgb_load of a DWAB file: %s", err);
    if (rc == 0) {
        int bad = 0;
        for (int i = 0; i < 19 * 11; i++)
            for (int c = 0; c < 3; c++) {
                float expect = dwa_value(3 - c, i % 19, i / 19);
                bad += !(fabs(im.rgb[3 * i + c] - expect) <= 0.03 * expect + 1e-3);
            }
        CHECK(bad == 0, "image_rgb_load of a DWAB file: %d values off", bad);
        image_rgb_free(&im);
    }

    /* Damage every fourth byte in turn (header, offsets, counters, Huffman tables, data): each
     * load fails with a message or yields some image; under ASan, none may touch memory it
     * should not. The truncations must all fail. */
    int loaded = 0, failed = 0, silent = 0;
    for (size_t k = 0; file && k < size; k += 4) {
        for (int flip = 0; flip < 2; flip++) {
            unsigned char *copy = malloc(size);
            memcpy(copy, file, size);
            copy[k] ^= flip ? 0xff : 0x10;
            put_file(path, copy, size);
            free(copy);
            err[0] = '\0';
            rc = exr_image_load(path, &img, err, sizeof err);
            if (rc == 0) {
                loaded++;
                exr_image_free(&img);
            } else {
                failed++;
                silent += !(strstr(err, path) && one_line(err));
            }
        }
    }
    CHECK(silent == 0, "%d damaged DWAB files failed without a proper message", silent);
    printf("damaged DWAB copies: %d loaded, %d refused\n", loaded, failed);
    for (size_t cut = 0; file && cut < size; cut += 97) {
        put_file(path, file, cut);
        err[0] = '\0';
        rc = exr_image_load(path, &img, err, sizeof err);
        CHECK(rc == -1 && strstr(err, path), "DWAB file cut to %zu bytes: rc %d '%s'", cut, rc, err);
        if (rc == 0) exr_image_free(&img);
    }
    free(file);
}

/* ---- atomic writes --------------------------------------------------------------------------- */

static void test_write_modes(void) {
    char path[1200], err[512] = "";
    path_in(path, sizeof path, "atomic.bin");
    CHECK(write_file_atomic(path, "first", 5, WRITE_NO_REPLACE, err, sizeof err) == 0, "first write: %s", err);
    err[0] = '\0';
    int rc = write_file_atomic(path, "second", 6, WRITE_NO_REPLACE, err, sizeof err);
    CHECK(rc == -1, "WRITE_NO_REPLACE replaced an existing file");
    char expect[1300];
    snprintf(expect, sizeof expect, "%s: file exists", path);
    CHECK(strcmp(err, expect) == 0, "error '%s', expected '%s'", err, expect);
    size_t size = 0;
    unsigned char *got = get_file(path, &size);
    CHECK(got && size == 5 && memcmp(got, "first", 5) == 0, "the refused write changed the file");
    free(got);

    CHECK(write_file_atomic(path, "third!", 6, WRITE_REPLACE, err, sizeof err) == 0, "replace: %s", err);
    got = get_file(path, &size);
    CHECK(got && size == 6 && memcmp(got, "third!", 6) == 0, "WRITE_REPLACE did not replace");
    free(got);

    /* Only regular files are replaced: a FIFO (like a device such as /dev/null) stays what it is. */
    path_in(path, sizeof path, "fifo");
    CHECK(mkfifo(path, 0666) == 0, "mkfifo: %s", strerror(errno));
    err[0] = '\0';
    CHECK(write_file_atomic(path, "data", 4, WRITE_REPLACE, err, sizeof err) == -1, "a FIFO was replaced");
    snprintf(expect, sizeof expect, "%s: not a regular file; not replacing it", path);
    CHECK(strcmp(err, expect) == 0, "error '%s', expected '%s'", err, expect);
    struct stat fifo_st;
    CHECK(lstat(path, &fifo_st) == 0 && S_ISFIFO(fifo_st.st_mode), "the FIFO is gone");
    unlink(path);

    /* An empty file is a valid output; so is a large one written in one go. */
    path_in(path, sizeof path, "empty.bin");
    CHECK(write_file_atomic(path, "", 0, WRITE_NO_REPLACE, err, sizeof err) == 0, "empty write: %s", err);
    got = get_file(path, &size);
    CHECK(got && size == 0, "empty file");
    free(got);
    size_t big = (size_t)3 << 20;
    unsigned char *data = malloc(big);
    for (size_t i = 0; i < big; i++) data[i] = (unsigned char)(i * 2654435761u >> 13);
    path_in(path, sizeof path, "big.bin");
    CHECK(write_file_atomic(path, data, big, WRITE_REPLACE, err, sizeof err) == 0, "big write: %s", err);
    got = get_file(path, &size);
    CHECK(got && size == big && memcmp(got, data, big) == 0, "big file content");
    free(got);
    free(data);

    /* New files get the usual permissions (umask), not a temporary file's 0600. */
    mode_t mask = umask(022);
    path_in(path, sizeof path, "perm.bin");
    write_file_atomic(path, "x", 1, WRITE_NO_REPLACE, err, sizeof err);
    struct stat st;
    CHECK(stat(path, &st) == 0 && (st.st_mode & 0777) == 0644, "mode %o, expected 644", (unsigned)(st.st_mode & 0777));
    umask(mask);

    /* A missing directory: an error naming it, and nothing created. */
    path_in(path, sizeof path, "no-such-dir/out.exr");
    err[0] = '\0';
    rc = write_file_atomic(path, "x", 1, WRITE_REPLACE, err, sizeof err);
    CHECK(rc == -1 && strstr(err, path) && strstr(err, "no-such-dir") && one_line(err), "missing dir: '%s'", err);
    float px[3] = {1, 2, 3};
    exr_layer layer = {"", px};
    err[0] = '\0';
    rc = exr_save_layers(path, 1, 1, &layer, 1, WRITE_REPLACE, err, sizeof err);
    CHECK(rc == -1 && strstr(err, path), "exr into a missing dir: '%s'", err);
    unsigned char rgb8[3] = {1, 2, 3};
    path_in(path, sizeof path, "no-such-dir/out.png");
    err[0] = '\0';
    rc = png_save_rgb8(path, 1, 1, rgb8, WRITE_NO_REPLACE, err, sizeof err);
    CHECK(rc == -1 && strstr(err, path), "png into a missing dir: '%s'", err);

    /* Replacing a directory fails, and leaves no temporary behind. */
    path_in(path, sizeof path, "a-directory");
    mkdir(path, 0777);
    err[0] = '\0';
    rc = write_file_atomic(path, "x", 1, WRITE_REPLACE, err, sizeof err);
    CHECK(rc == -1 && strstr(err, path), "replacing a directory: '%s'", err);
    rc = exr_save_layers(path, 1, 1, &layer, 1, WRITE_NO_REPLACE, err, sizeof err);
    CHECK(rc == -1 && strstr(err, "file exists"), "exr over a directory, no replace: '%s'", err);

    /* Invalid arguments are errors, not crashes. */
    path_in(path, sizeof path, "invalid.exr");
    CHECK(exr_save_layers(path, 0, 5, &layer, 1, WRITE_REPLACE, err, sizeof err) == -1, "zero width accepted");
    exr_layer twice[2] = {{"x", px}, {"x", px}};
    CHECK(exr_save_layers(path, 1, 1, twice, 2, WRITE_REPLACE, err, sizeof err) == -1 && strstr(err, "twice"),
          "duplicate layer names accepted: '%s'", err);
    CHECK(!file_exists(path), "an invalid save created a file");

    /* A tiny error buffer is filled, truncated and terminated (ASan watches the bounds). */
    char small[8];
    memset(small, 'x', sizeof small);
    path_in(path, sizeof path, "atomic.bin");
    CHECK(write_file_atomic(path, "y", 1, WRITE_NO_REPLACE, small, sizeof small) == -1 && small[7] == '\0',
          "short error buffer");

    CHECK(stray_temp_files(dir) == 0, "temporary files left behind");
}

/* ---- unique_path ----------------------------------------------------------------------------- */

static void test_unique_path(void) {
    char path[1200], out[1200], expect[1300];
    path_in(path, sizeof path, "render.png");
    CHECK(unique_path(path, out, sizeof out) == 0 && strcmp(out, path) == 0, "free name: %s", out);
    put_file(path, "", 0);
    snprintf(expect, sizeof expect, "%s/render-1.png", dir);
    CHECK(unique_path(path, out, sizeof out) == 0 && strcmp(out, expect) == 0, "got %s, expected %s", out, expect);
    put_file(expect, "", 0);
    snprintf(expect, sizeof expect, "%s/render-2.png", dir);
    CHECK(unique_path(path, out, sizeof out) == 0 && strcmp(out, expect) == 0, "got %s, expected %s", out, expect);

    /* No extension, a dot in the directory name, a hidden file. */
    char sub[1100];
    path_in(sub, sizeof sub, "out.d");
    mkdir(sub, 0777);
    snprintf(path, sizeof path, "%s/name", sub);
    put_file(path, "", 0);
    snprintf(expect, sizeof expect, "%s/name-1", sub);
    CHECK(unique_path(path, out, sizeof out) == 0 && strcmp(out, expect) == 0, "got %s, expected %s", out, expect);
    snprintf(path, sizeof path, "%s/.hidden", sub);
    put_file(path, "", 0);
    snprintf(expect, sizeof expect, "%s/.hidden-1", sub);
    CHECK(unique_path(path, out, sizeof out) == 0 && strcmp(out, expect) == 0, "got %s, expected %s", out, expect);
    snprintf(path, sizeof path, "%s/a.b.exr", sub);
    put_file(path, "", 0);
    snprintf(expect, sizeof expect, "%s/a.b-1.exr", sub);
    CHECK(unique_path(path, out, sizeof out) == 0 && strcmp(out, expect) == 0, "got %s, expected %s", out, expect);

    /* An output buffer too small for the name. */
    path_in(path, sizeof path, "render.png");
    char tiny[10];
    CHECK(unique_path(path, tiny, sizeof tiny) == -1, "unique_path overflowed a small buffer");
    CHECK(unique_path("x.png", tiny, 5) == -1, "no room for the terminator");
}

/* ---- PNG ------------------------------------------------------------------------------------- */

static void test_png(void) {
    enum { W = 4, H = 3 };
    unsigned char px[W * H * 3];
    for (int i = 0; i < W * H * 3; i++) px[i] = (unsigned char)(i * 37 + 11);
    px[0] = 0;
    px[1] = 255;
    char path[1200], err[512] = "";
    path_in(path, sizeof path, "small.png");
    CHECK(png_save_rgb8(path, W, H, px, WRITE_NO_REPLACE, err, sizeof err) == 0, "png_save_rgb8: %s", err);
    size_t size = 0;
    unsigned char *file = get_file(path, &size);
    CHECK(file && size > 8 && memcmp(file, "\x89PNG\r\n\x1a\n", 8) == 0, "PNG signature");
    int w = 0, h = 0, n = 0;
    unsigned char *back = file ? stbi_load_from_memory(file, (int)size, &w, &h, &n, 0) : NULL;
    CHECK(back && w == W && h == H && n == 3, "decoded %dx%d with %d channels", w, h, n);
    if (back && w == W && h == H && n == 3) CHECK(memcmp(back, px, sizeof px) == 0, "PNG pixels differ");
    stbi_image_free(back);
    free(file);
    CHECK(png_save_rgb8(path, W, H, px, WRITE_NO_REPLACE, err, sizeof err) == -1 && strstr(err, "file exists"),
          "png over an existing file: '%s'", err);
    CHECK(stray_temp_files(dir) == 0, "temporary files left behind");
}

/* ---- the shared environment maps ------------------------------------------------------------- */

static uint32_t le32(const unsigned char *p) {
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* The display window from an EXR header, read by hand: attribute name, type, size, value. */
static int exr_header_size(const unsigned char *b, size_t n, int *w, int *h) {
    static const char key[] = "displayWindow\0box2i";
    for (size_t i = 8; i + sizeof key + 4 + 16 <= n; i++) {
        if (memcmp(b + i, key, sizeof key) != 0) continue;
        const unsigned char *v = b + i + sizeof key;
        if (le32(v) != 16) return -1;
        int32_t x0 = (int32_t)le32(v + 4), y0 = (int32_t)le32(v + 8), x1 = (int32_t)le32(v + 12),
                y1 = (int32_t)le32(v + 16);
        *w = x1 - x0 + 1;
        *h = y1 - y0 + 1;
        return 0;
    }
    return -1;
}

/* The size from a Radiance header: the line after the blank line, e.g. "-Y 512 +X 1024". */
static int hdr_header_size(const unsigned char *b, size_t n, int *w, int *h) {
    for (size_t i = 0; i + 1 < n && i < 4096; i++) {
        if (b[i] != '\n' || b[i + 1] != '\n') continue;
        char line[64] = "";
        size_t k = 0;
        for (size_t j = i + 2; j < n && b[j] != '\n' && k + 1 < sizeof line; j++) line[k++] = (char)b[j];
        return sscanf(line, "-Y %d +X %d", h, w) == 2 ? 0 : -1;
    }
    return -1;
}

/* Reference values for the shared DWAB env maps, decoded by OpenEXR's C++ library (3.1.5,
 * exrmaketiled -z none): channel means and a few texels. DWA is lossy and its decoders round
 * differently in the last place of the coded half values, so texels get 1% (a few such steps). */
typedef struct {
    const char *file;
    double mean[3];
    struct {
        int x, y;
        float rgb[3];
    } texel[8];
} env_reference;

static const env_reference env_references[] = {
    {"blender_studio.exr",
     {0.229647201, 0.259988394, 0.27869762},
     {{0, 0, {0.00218200684f, 0.00269508362f, 0.00328636169f}},
      {1023, 511, {0.200317383f, 0.24621582f, 0.259277344f}},
      {512, 256, {0.0224914551f, 0.0275115967f, 0.0185089111f}},
      {100, 50, {0.00167655945f, 0.00205230713f, 0.0025844574f}},
      {700, 200, {0.0132522583f, 0.0138473511f, 0.0157623291f}},
      {333, 444, {0.146728516f, 0.178833008f, 0.195800781f}},
      {901, 77, {0.00112915039f, 0.0013961792f, 0.00157546997f}},
      {7, 300, {0.0013217926f, 0.00161170959f, 0.0020904541f}}}},
    {"blender_interior.exr",
     {1.08281871, 0.955802898, 0.813453851},
     {{0, 0, {0.455810547f, 0.373535156f, 0.319335938f}},
      {1023, 511, {0.252685547f, 0.169311523f, 0.0836181641f}},
      {512, 256, {0.139282227f, 0.0999755859f, 0.0645751953f}},
      {100, 50, {0.522949219f, 0.39453125f, 0.298339844f}},
      {700, 200, {2.38671875f, 3.0234375f, 4.44140625f}},
      {333, 444, {0.133178711f, 0.0949707031f, 0.0602111816f}},
      {901, 77, {0.485839844f, 0.391357422f, 0.338623047f}},
      {7, 300, {0.490722656f, 0.427001953f, 0.423583984f}}}},
};

static void check_env_reference(const char *path, const image_rgb *im, const double mean[3]) {
    const char *base = strrchr(path, '/') ? strrchr(path, '/') + 1 : path;
    for (size_t r = 0; r < sizeof env_references / sizeof env_references[0]; r++) {
        const env_reference *ref = &env_references[r];
        if (strcmp(base, ref->file) != 0) continue;
        for (int c = 0; c < 3; c++)
            CHECK_NEAR(mean[c], ref->mean[c], 1e-4 * ref->mean[c], "%s: mean of channel %c", base, "RGB"[c]);
        for (int k = 0; k < 8 && im->width == 1024 && im->height == 512; k++)
            for (int c = 0; c < 3; c++)
                CHECK_NEAR(im->rgb[3 * (ref->texel[k].y * 1024 + ref->texel[k].x) + c], ref->texel[k].rgb[c],
                           0.01 * ref->texel[k].rgb[c], "%s: texel (%d, %d) channel %c", base, ref->texel[k].x,
                           ref->texel[k].y, "RGB"[c]);
        return;
    }
}

static void check_env_map(const char *path, int is_exr) {
    size_t size = 0;
    unsigned char *bytes = get_file(path, &size);
    int hw = 0, hh = 0;
    int hrc = bytes ? (is_exr ? exr_header_size(bytes, size, &hw, &hh) : hdr_header_size(bytes, size, &hw, &hh)) : -1;
    CHECK(hrc == 0 && hw > 0 && hh > 0, "%s: cannot read the size from the header", path);

    char err[512] = "";
    image_rgb im;
    int rc = image_rgb_load(path, &im, err, sizeof err);
    CHECK(rc == 0, "image_rgb_load: %s", err);
    if (rc == 0) {
        CHECK(im.width == hw && im.height == hh, "%s: %dx%d, header says %dx%d", path, im.width, im.height, hw, hh);
        size_t n = 3 * (size_t)im.width * (size_t)im.height, bad = 0;
        double sum = 0.0;
        for (size_t i = 0; i < n; i++) {
            bad += !(isfinite(im.rgb[i]) && im.rgb[i] >= 0.0f);
            sum += im.rgb[i];
        }
        double mean = sum / (double)n;
        CHECK(bad == 0, "%s: %zu texels not finite or negative", path, bad);
        CHECK(mean > 1e-3 && mean < 1e4, "%s: implausible mean %g", path, mean);
        printf("%s: %dx%d, mean %.4g\n", path, im.width, im.height, mean);

        if (is_exr) {
            /* The general loader sees the same R, G, B planes, except that image_rgb_load reads
             * DWA's slight undershoot below zero as zero. */
            exr_image ex;
            rc = exr_image_load(path, &ex, err, sizeof err);
            CHECK(rc == 0, "exr_image_load: %s", err);
            if (rc == 0) {
                const char *names[3] = {"R", "G", "B"};
                size_t diff = 0;
                double means[3] = {0, 0, 0};
                for (int c = 0; c < 3; c++) {
                    const float *p = exr_image_channel(&ex, names[c]);
                    for (size_t i = 0; p && i < n / 3; i++) {
                        diff += !bits_equal(p[i] < 0.0f ? 0.0f : p[i], im.rgb[3 * i + (size_t)c]);
                        means[c] += p[i] / (double)(n / 3);
                    }
                    diff += p == NULL;
                }
                CHECK(ex.width == im.width && ex.height == im.height && diff == 0,
                      "exr_image_load and image_rgb_load disagree at %zu texels", diff);
                check_env_reference(path, &im, means);
                exr_image_free(&ex);
            }
            /* Saved as float EXR and loaded again: bit for bit the same image. */
            char copy[1200];
            path_in(copy, sizeof copy, "envcopy.exr");
            exr_layer layer = {"", im.rgb};
            rc = exr_save_layers(copy, im.width, im.height, &layer, 1, WRITE_REPLACE, err, sizeof err);
            CHECK(rc == 0, "saving the env map: %s", err);
            image_rgb again;
            rc = image_rgb_load(copy, &again, err, sizeof err);
            CHECK(rc == 0, "reloading the saved env map: %s", err);
            if (rc == 0) {
                CHECK(again.width == im.width && again.height == im.height &&
                          memcmp(again.rgb, im.rgb, sizeof(float) * n) == 0,
                      "the env map changed through save and load");
                image_rgb_free(&again);
            }
        }
        image_rgb_free(&im);
    }

    /* Truncated and damaged copies fail with a message, or (damage the codec cannot detect) load
     * as some image; they never crash. */
    const size_t cuts[] = {1000, size / 3, size - 1};
    char cut[1200];
    path_in(cut, sizeof cut, is_exr ? "envcut.exr" : "envcut.hdr");
    for (size_t k = 0; bytes && k < sizeof cuts / sizeof cuts[0]; k++) {
        put_file(cut, bytes, cuts[k]);
        err[0] = '\0';
        rc = image_rgb_load(cut, &im, err, sizeof err);
        CHECK(rc == -1 && strstr(err, cut) && one_line(err), "%s truncated to %zu bytes: rc %d '%s'", path, cuts[k], rc,
              err);
        if (rc == 0) image_rgb_free(&im);
        if (k == 0) printf("truncated %s: %s\n", is_exr ? "exr" : "hdr", err);
    }
    for (int k = 0; bytes && k < 8; k++) {
        unsigned char *damaged = malloc(size);
        memcpy(damaged, bytes, size);
        uint32_t s = 12345u + (uint32_t)k * 7919u;
        size_t from = size / 2 + (size_t)k * 97;
        for (size_t i = from; i < from + 64 && i < size; i++) {
            s = s * 1664525u + 1013904223u;
            damaged[i] = (unsigned char)(s >> 24);
        }
        put_file(cut, damaged, size);
        free(damaged);
        err[0] = '\0';
        rc = image_rgb_load(cut, &im, err, sizeof err);
        CHECK(rc == 0 || (rc == -1 && strstr(err, cut) && one_line(err)), "damaged %s: rc %d '%s'", path, rc, err);
        if (rc == 0) image_rgb_free(&im);
    }
    free(bytes);
}

static void test_shared_env_maps(void) {
    const char *shared = getenv("GLINT_SHARED_SCENES");
    char envdir[1100];
    snprintf(envdir, sizeof envdir, "%s/envmaps", shared ? shared : "");
    DIR *d = shared ? opendir(envdir) : NULL;
    if (!d) {
        printf("test_image_io: no shared env maps (GLINT_SHARED_SCENES=%s), skipping those checks\n",
               shared ? shared : "(unset)");
        return;
    }
    int exr = 0, hdr = 0;
    struct dirent *e;
    while ((e = readdir(d))) {
        size_t len = strlen(e->d_name);
        if (len < 5) continue;
        const char *ext = e->d_name + len - 4;
        int is_exr = strcmp(ext, ".exr") == 0;
        if (!is_exr && strcmp(ext, ".hdr") != 0) continue;
        char path[2200];
        snprintf(path, sizeof path, "%s/%s", envdir, e->d_name);
        check_env_map(path, is_exr);
        exr += is_exr;
        hdr += !is_exr;
    }
    closedir(d);
    CHECK(exr > 0 && hdr > 0, "%s: found %d .exr and %d .hdr env maps", envdir, exr, hdr);
}

/* ---- broken inputs --------------------------------------------------------------------------- */

static void expect_load_error(const char *path, const char *must_contain) {
    char err[512] = "";
    image_rgb im;
    int rc = image_rgb_load(path, &im, err, sizeof err);
    CHECK(rc == -1 && strstr(err, path) && one_line(err) && (!must_contain || strstr(err, must_contain)),
          "image_rgb_load(%s): rc %d, '%s'", path, rc, err);
    CHECK(im.rgb == NULL && im.width == 0, "failed load left an image");
    exr_image ex;
    err[0] = '\0';
    rc = exr_image_load(path, &ex, err, sizeof err);
    CHECK(rc == -1 && strstr(err, path) && one_line(err), "exr_image_load(%s): rc %d, '%s'", path, rc, err);
    CHECK(ex.planes == NULL && ex.num_channels == 0, "failed load left channels");
}

static void test_errors(void) {
    char path[1200], err[512] = "";
    path_in(path, sizeof path, "missing.exr");
    image_rgb im;
    CHECK(image_rgb_load(path, &im, err, sizeof err) == -1, "missing file loaded");
    char expect[1300];
    snprintf(expect, sizeof expect, "%s: %s", path, strerror(ENOENT));
    CHECK(strcmp(err, expect) == 0, "missing file: '%s', expected '%s'", err, expect);
    exr_image ex;
    CHECK(exr_image_load(path, &ex, err, sizeof err) == -1 && strcmp(err, expect) == 0, "missing exr: '%s'", err);

    path_in(path, sizeof path, "empty.exr");
    put_file(path, "", 0);
    expect_load_error(path, "empty");

    unsigned char junk[4096];
    uint32_t s = 99;
    for (size_t i = 0; i < sizeof junk; i++) {
        s = s * 1664525u + 1013904223u;
        junk[i] = (unsigned char)(s >> 24);
    }
    junk[0] = 'j';
    path_in(path, sizeof path, "junk.exr");
    put_file(path, junk, sizeof junk);
    expect_load_error(path, NULL);

    /* The right magic numbers followed by junk. */
    static const unsigned char magic[4] = {0x76, 0x2f, 0x31, 0x01};
    memcpy(junk, magic, 4);
    path_in(path, sizeof path, "junk-magic.exr");
    put_file(path, junk, sizeof junk);
    expect_load_error(path, NULL);
    memcpy(junk, magic, 4);
    junk[4] = 2; /* version 2, no flags: the header parser then reads junk as attributes */
    junk[5] = junk[6] = junk[7] = 0;
    put_file(path, junk, sizeof junk);
    expect_load_error(path, NULL);
    path_in(path, sizeof path, "junk.hdr");
    static const char radiance[] = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 64 +X 96\n";
    memcpy(junk, radiance, sizeof radiance - 1);
    put_file(path, junk, sizeof junk);
    expect_load_error(path, NULL);
    put_file(path, "#?", 2);
    expect_load_error(path, NULL);

    /* A directory, and a file in a format it does not read (by content, whatever the name: the
     * PNG written by test_png). */
    expect_load_error(dir, NULL);
    path_in(path, sizeof path, "small.png");
    char renamed[1200];
    path_in(renamed, sizeof renamed, "png-in-disguise.exr");
    size_t size = 0;
    unsigned char *png = get_file(path, &size);
    if (png) put_file(renamed, png, size);
    free(png);
    expect_load_error(renamed, "not an OpenEXR");
}

/* The film's means: components sum, zero samples count, a dropped sample leaves the mean over
 * the pixel's good samples, a clear starts over. Values chosen so the means are exact. */
static void test_film_means(void) {
    film f;
    CHECK(film_init(&f, 2, 1) == 0, "film_init");
    float a[COMP_COUNT][3] = {{1, 2, 4}, {0.5f, 0, 0}, {0, 0, 0}}, zero[COMP_COUNT][3] = {{0}};
    film_add(&f, 0, (const float(*)[3])a);
    film_add(&f, 1, (const float(*)[3])a);
    film_end_pass(&f);
    film_add(&f, 0, (const float(*)[3])zero);
    film_reject(&f, 1);
    film_end_pass(&f);
    float rgb[6];
    film_resolve(&f, COMP_MASK_ALL, rgb);
    CHECK(rgb[0] == 0.75f && rgb[1] == 1.0f && rgb[2] == 2.0f, "pixel 0 mean (%g %g %g), expected (0.75 1 2)",
          (double)rgb[0], (double)rgb[1], (double)rgb[2]);
    CHECK(rgb[3] == 1.5f && rgb[4] == 2.0f && rgb[5] == 4.0f, "pixel 1 mean over its good sample (%g %g %g)",
          (double)rgb[3], (double)rgb[4], (double)rgb[5]);
    film_resolve(&f, 1u << COMP_INDIRECT, rgb);
    CHECK(rgb[0] == 0.25f && rgb[3] == 0.5f, "indirect component alone: %g %g", (double)rgb[0], (double)rgb[3]);
    film_clear(&f);
    film_resolve(&f, COMP_MASK_ALL, rgb);
    CHECK(rgb[0] == 0.0f && rgb[5] == 0.0f, "a cleared film is not black");
    film_deinit(&f);
}

int main(void) {
    const char *base = getenv("GLINT_TEST_TMP");
    snprintf(dir, sizeof dir, "%s/test_image_io.%ld", base && base[0] ? base : "/tmp", (long)getpid());
    remove_tree(dir);
    if (mkdir(dir, 0777) != 0) {
        fprintf(stderr, "test_image_io: cannot create %s: %s\n", dir, strerror(errno));
        return 1;
    }
    test_exr_roundtrip();
    test_exr_foreign();
    test_dwa();
    test_write_modes();
    test_unique_path();
    test_png();
    test_shared_env_maps();
    test_errors();
    test_film_means();
    CHECK(stray_temp_files(dir) == 0, "temporary files left behind");
    int status = check_exit("test_image_io");
    if (status == 0) remove_tree(dir); /* a failed run keeps its files to look at */
    return status;
}
