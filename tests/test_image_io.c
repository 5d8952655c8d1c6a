/* Image reading against expectations that do not come from image_io.c itself: EXR files written
 * with OpenEXR's C++ library (exr_writer.cpp: every compression, DWAA/DWAB, PIZ and B44 included;
 * tiled; half, float and uint channels; offset data windows), values that are a closed-form
 * function of the pixel, reference texels of the shared env maps, and image sizes read from the
 * files' own headers. Also our own EXRs' bit-exact round trip, and that broken, truncated and
 * hostile files fail with one line instead of crashing or allocating without bound (this test
 * runs under ASan/UBSan). And the film's running means. The writing side: test_image_io_write.c. */
#define _POSIX_C_SOURCE 200809L

#include <dirent.h>
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>

#include "check.h"
#include "exr_writer.h"
#include "film.h"
#include "image_io.h"
#include "scratch.h"

/* ---- values for the EXR files written with OpenEXR's C++ library (exr_writer.cpp) -------------- */

/* Channel c's value at absolute pixel (x, y): multiples of 1/4 below 16, exact in half floats. */
static float half_value(int c, int x, int y) { return (float)(((x * 7 + y * 13 + c * 5) % 64 + 64) % 64) * 0.25f; }
static uint32_t uint_value(int x, int y) { return (uint32_t)((x + 100) * 1000 + (y + 100)); }
/* half_value, but a uint channel 3. */
static float tiled_value(int c, int x, int y) { return c == 3 ? (float)uint_value(x, y) : half_value(c, x, y); }

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
        CHECK(im.width == W && im.height == H && bad == 0, "layered file: %dx%d, %d wrong values", im.width, im.height,
              bad);
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
    const test_chan chans[4] = {
        {"B", EXR_PIXEL_HALF, 0}, {"G", EXR_PIXEL_HALF, 0}, {"R", EXR_PIXEL_HALF, 0}, {"id", EXR_PIXEL_UINT, 0}};
    exr_attr_box2i_t dw = box(5, -3, 5 + 40 - 1, -3 + 30 - 1); /* 40x30 at (5, -3) */
    exr_attr_box2i_t disp = box(0, 0, 41, 19);                 /* 42x20 at the origin */
    path_in(path, sizeof path, "tiled.exr");
    CHECK(write_test_exr(path, EXR_STORAGE_TILED, EXR_COMPRESSION_PIZ, chans, 4, dw, disp, tiled_value) == 0,
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
    CHECK(write_test_exr(path, EXR_STORAGE_SCANLINE, EXR_COMPRESSION_NONE, y_only, 1, win, win, half_value) == 0,
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
    const test_chan rgba[4] = {
        {"A", EXR_PIXEL_HALF, 0}, {"B", EXR_PIXEL_HALF, 0}, {"G", EXR_PIXEL_HALF, 0}, {"R", EXR_PIXEL_HALF, 0}};
    exr_attr_box2i_t rgba_win = box(0, 0, 30, 20);
    path_in(path, sizeof path, "rgba.exr");
    CHECK(write_test_exr(path, EXR_STORAGE_SCANLINE, EXR_COMPRESSION_ZIPS, rgba, 4, rgba_win, rgba_win, half_value) ==
              0,
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
    CHECK(write_test_exr(path, EXR_STORAGE_SCANLINE, EXR_COMPRESSION_NONE, yc, 3, yc_win, yc_win, half_value) == 0,
          "writing the luminance/chroma test file");
    rc = image_rgb_load(path, &im, err, sizeof err);
    CHECK(rc == -1 && strstr(err, path) && strstr(err, "subsampled"), "luminance/chroma file: '%s'", err);
    rc = exr_image_load(path, &img, err, sizeof err);
    CHECK(rc == -1 && strstr(err, path) && strstr(err, "subsampled"), "luminance/chroma file: '%s'", err);

    /* Scanline RLE with a data window inside a larger display window; no RGB, no Y. */
    const test_chan other[2] = {{"Z", EXR_PIXEL_FLOAT, 0}, {"depth.V", EXR_PIXEL_HALF, 0}};
    exr_attr_box2i_t inner = box(2, 3, 9, 40), outer = box(0, 0, 11, 49);
    path_in(path, sizeof path, "window.exr");
    CHECK(write_test_exr(path, EXR_STORAGE_SCANLINE, EXR_COMPRESSION_RLE, other, 2, inner, outer, half_value) == 0,
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

/* ---- every compression, read back ------------------------------------------------------------ */

static const char *const codec_names[] = {"none", "rle", "zips", "zip", "piz", "pxr24", "b44", "b44a", "dwaa", "dwab"};

/* Channel c of codec_chans at (x, y): A steps (DWA codes it by RLE), B, G, R smooth ramps on a
 * grid of 1/256 (exact in half floats; smooth, as the lossy codecs want), Z floats exact in 32 bits
 * but not in PXR24's 24, id integers. */
static const test_chan codec_chans[6] = {{"A", EXR_PIXEL_HALF, 0},  {"B", EXR_PIXEL_HALF, 0},
                                         {"G", EXR_PIXEL_HALF, 0},  {"R", EXR_PIXEL_HALF, 0},
                                         {"Z", EXR_PIXEL_FLOAT, 0}, {"id", EXR_PIXEL_UINT, 0}};
static float codec_value(int c, int x, int y) {
    if (c == 0) return x < 6 ? 1.0f : (x < 13 ? 0.5f : 0.0f);
    if (c == 4) return (float)(x * 1000 + y) + 0.125f;
    if (c == 5) return (float)uint_value(x, y);
    return roundf(256.0f * (0.05f + 0.2f * (float)c + 3.0f * (float)x / 36.0f * (float)(y + 2) / 22.0f)) / 256.0f;
}

/* Files written by OpenEXR's C++ library in every compression, scanline and tiled, read back:
 * exact where the codec is lossless for the channel's type, within 3% where it is lossy (B44 for
 * half channels, DWA for R, G, B), 24-bit floats for PXR24's Z. */
static void test_compressions(void) {
    enum { W = 37, H = 21 };
    const exr_attr_box2i_t win = box(0, 0, W - 1, H - 1);
    char path[1200], err[512] = "";
    for (int comp = EXR_COMPRESSION_NONE; comp <= EXR_COMPRESSION_DWAB; comp++)
        for (int tiled = 0; tiled < 2; tiled++) {
            char name[64];
            snprintf(name, sizeof name, "%s-%s.exr", codec_names[comp], tiled ? "tiled" : "lines");
            path_in(path, sizeof path, name);
            CHECK(write_test_exr(path, tiled ? EXR_STORAGE_TILED : EXR_STORAGE_SCANLINE, (exr_compression_t)comp,
                                 codec_chans, 6, win, win, codec_value) == 0,
                  "writing %s", name);
            int b44 = comp == EXR_COMPRESSION_B44 || comp == EXR_COMPRESSION_B44A;
            int dwa = comp == EXR_COMPRESSION_DWAA || comp == EXR_COMPRESSION_DWAB;
            exr_image img;
            int rc = exr_image_load(path, &img, err, sizeof err);
            CHECK(rc == 0 && img.width == W && img.height == H && img.num_channels == 6, "%s: %s", name, err);
            const float *rgb[3] = {NULL, NULL, NULL};
            for (int c = 0; rc == 0 && c < 6; c++) {
                const float *p = exr_image_channel(&img, codec_chans[c].name);
                if (c >= 1 && c <= 3) rgb[3 - c] = p;
                int lossy = (b44 && c <= 3) || (dwa && c >= 1 && c <= 3), bad = 0;
                double worst = 0.0;
                for (int i = 0; p && i < W * H; i++) {
                    double e = codec_value(c, i % W, i / W), d = fabs(p[i] - e);
                    double tol = lossy ? 0.03 * e + 1e-3 : comp == EXR_COMPRESSION_PXR24 && c == 4 ? e / 32768 : 0.0;
                    bad += !(d <= tol);
                    worst = d > worst ? d : worst;
                }
                CHECK(p && bad == 0, "%s, channel %s: %d values off (worst by %g)", name, codec_chans[c].name, bad,
                      worst);
            }
            /* image_rgb_load: the same R, G, B (DWA's undershoot below zero would read as zero). */
            image_rgb im;
            int rc2 = image_rgb_load(path, &im, err, sizeof err);
            CHECK(rc2 == 0 && im.width == W && im.height == H, "image_rgb_load of %s: %s", name, err);
            int bad = 0;
            for (int i = 0; rc == 0 && rc2 == 0 && rgb[0] && rgb[1] && rgb[2] && i < 3 * W * H; i++)
                bad += !bits_equal(im.rgb[i], dwa && rgb[i % 3][i / 3] < 0.0f ? 0.0f : rgb[i % 3][i / 3]);
            CHECK(bad == 0, "image_rgb_load of %s: %d values differ from exr_image_load's", name, bad);
            if (rc2 == 0) image_rgb_free(&im);
            if (rc == 0) exr_image_free(&img);
        }
}

/* Damaged copies of the tiled DWAB file (the codec with the most to go wrong: counters, Huffman
 * tables, RLE and DCT data): every 4th byte of the first KiB (header, offsets) and every 16th of
 * the rest in turn, two ways. Each load fails with a message or yields some image; under ASan,
 * none may touch memory it should not. Every truncation fails. */
static void test_damaged_dwab(void) {
    char path[1200], copy[1200], err[512] = "";
    path_in(path, sizeof path, "dwab-tiled.exr");
    path_in(copy, sizeof copy, "damaged.exr");
    size_t size = 0;
    unsigned char *file = get_file(path, &size);
    CHECK(file && size > 500, "reading %s", path);
    int loaded = 0, failed = 0, silent = 0, rc;
    exr_image img;
    for (size_t k = 0; file && k < size; k += k < 1024 ? 4 : 16) {
        for (int flip = 0; flip < 2; flip++) {
            file[k] ^= flip ? 0xff : 0x10;
            put_file(copy, file, size);
            file[k] ^= flip ? 0xff : 0x10;
            err[0] = '\0';
            rc = exr_image_load(copy, &img, err, sizeof err);
            if (rc == 0) {
                loaded++;
                exr_image_free(&img);
            } else {
                failed++;
                silent += !(strstr(err, copy) && one_line(err));
            }
        }
    }
    CHECK(silent == 0, "%d damaged DWAB files failed without a proper message", silent);
    printf("damaged DWAB copies: %d loaded, %d refused\n", loaded, failed);
    for (size_t cut = 0; file && cut < size; cut += 97) {
        put_file(copy, file, cut);
        err[0] = '\0';
        rc = exr_image_load(copy, &img, err, sizeof err);
        CHECK(rc == -1 && strstr(err, copy) && one_line(err), "DWAB file cut to %zu bytes: rc %d '%s'", cut, rc, err);
        if (rc == 0) exr_image_free(&img);
    }
    free(file);
}

/* ---- headers that declare absurd sizes ------------------------------------------------------- */

/* Appends an attribute: name, type, the declared size (little-endian, as on this machine), value. */
static size_t put_attr(unsigned char *b, size_t n, const char *name, const char *type, int32_t size, const void *value,
                       size_t len) {
    n += (size_t)sprintf((char *)b + n, "%s", name) + 1;
    n += (size_t)sprintf((char *)b + n, "%s", type) + 1;
    memcpy(b + n, &size, 4);
    memcpy(b + n + 4, value, len);
    return n + 4 + len;
}

/* An uncompressed EXR header no writer would produce: a w x h image of nchan half channels (R, G,
 * B, c3, c4, ...), in tw x th tiles if tw > 0, with a string attribute declaring str_size bytes
 * if that is not 0; then an offset table of `chunks` zeros (missing chunks) and no pixels. */
static unsigned char *hostile_exr(size_t *size, int w, int h, int nchan, int tw, int th, int32_t str_size, int chunks) {
    unsigned char *b = calloc(1, 4096 + 20 * (size_t)nchan + 8 * (size_t)chunks), ch[20 * 64 + 1];
    memcpy(b, "\x76\x2f\x31\x01\x02\x00\x00\x00", 8);
    b[5] = tw > 0 ? 0x02 : 0x00; /* the tiled flag */
    size_t m = 0;
    for (int c = 0; c < nchan; c++) {
        const int32_t desc[4] = {1 /* half */, 0 /* linear, reserved */, 1, 1 /* sampling */};
        m += (size_t)(c < 3 ? sprintf((char *)ch + m, "%c", "RGB"[c]) : sprintf((char *)ch + m, "c%d", c)) + 1;
        memcpy(ch + m, desc, 16);
        m += 16;
    }
    ch[m++] = 0;
    const int32_t window[4] = {0, 0, w - 1, h - 1};
    const uint32_t tiles[3] = {(uint32_t)tw, (uint32_t)th, 0 /* one level */};
    const float one = 1.0f, center[2] = {0.0f, 0.0f};
    const unsigned char zero = 0;
    size_t n = put_attr(b, 8, "channels", "chlist", (int32_t)m, ch, m);
    n = put_attr(b, n, "compression", "compression", 1, &zero, 1);
    n = put_attr(b, n, "dataWindow", "box2i", 16, window, 16);
    n = put_attr(b, n, "displayWindow", "box2i", 16, window, 16);
    n = put_attr(b, n, "lineOrder", "lineOrder", 1, &zero, 1);
    n = put_attr(b, n, "pixelAspectRatio", "float", 4, &one, 4);
    n = put_attr(b, n, "screenWindowCenter", "v2f", 8, center, 8);
    n = put_attr(b, n, "screenWindowWidth", "float", 4, &one, 4);
    if (tw > 0) n = put_attr(b, n, "tiles", "tiledesc", 9, tiles, 9);
    if (str_size) n = put_attr(b, n, "comments", "string", str_size, "abc", 3);
    *size = n + 1 + 8 * (size_t)chunks;
    return b;
}

static long max_rss_kb(void) {
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return ru.ru_maxrss;
}

/* Each fails with one line (exr_image_load's naming the problem) at a small cost in memory. */
static void test_hostile_headers(void) {
    static const struct {
        int w, h, nchan, tw, th;
        int32_t str_size;
        int chunks;
        const char *problem;
    } cases[] = {
        {16, 16, 3, 0, 0, INT32_MAX, 16, "more than the file holds"}, /* a 2 GB string */
        {200000, 4, 3, 0, 0, 0, 4, "unsupported image size"},         /* too wide */
        {16384, 16384, 64, 0, 0, 0, 16384, "unsupported image size"}, /* 64 GB of planes */
        {131072, 2, 64, 0, 0, 0, 2, "unsupported image size"},        /* 4 GB for 256 lines */
        {16, 16, 3, 65536, 65536, 0, 1, "unsupported image size"},    /* a 24 GB tile */
        {16384, 16384, 3, 1, 1, 0, 0, "not a readable OpenEXR file"}, /* 2 GB of tile offsets */
        {16384, 16384, 3, 0, 0, 0, 16384, "unsupported image size"},  /* 3 GB of planes */
        {16384, 2, 40, 0, 0, 0, 2, "unsupported image size"},         /* 320 MB for 256 lines */
        {16384, 8192, 3, 0, 0, 0, 8192, "corrupt or truncated file"}, /* just no pixels */
    };
    char path[1200], err[512];
    path_in(path, sizeof path, "hostile.exr");
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        size_t size = 0;
        unsigned char *b = hostile_exr(&size, cases[k].w, cases[k].h, cases[k].nchan, cases[k].tw, cases[k].th,
                                       cases[k].str_size, cases[k].chunks);
        put_file(path, b, size);
        free(b);
        long rss = max_rss_kb();
        exr_image img;
        err[0] = '\0';
        int rc = exr_image_load(path, &img, err, sizeof err);
        CHECK(rc == -1 && strstr(err, path) && one_line(err) && strstr(err, cases[k].problem),
              "hostile header %zu: rc %d, '%s'", k, rc, err);
        image_rgb im;
        err[0] = '\0';
        rc = image_rgb_load(path, &im, err, sizeof err);
        CHECK(rc == -1 && strstr(err, path) && one_line(err), "hostile header %zu, as RGB: rc %d, '%s'", k, rc, err);
        CHECK(max_rss_kb() - rss < 256 * 1024, "hostile header %zu took %ld MB", k, (max_rss_kb() - rss) / 1024);
        if (k == 0) printf("hostile header: %s\n", err);
    }
}

/* A channel list whose declared size leaves out its terminator: OpenEXR's reader reads on to its
 * own end, out of step with the declared sizes, and found a 1.7 GB string size there (a fuzzer's
 * find). Every attribute the library reads by its own layout must fill its declared size. */
static void test_attribute_layouts(void) {
    char path[1200], err[512];
    path_in(path, sizeof path, "hostile-chlist.exr");
    size_t size = 0;
    unsigned char *b = hostile_exr(&size, 16, 16, 3, 0, 0, 0, 16);
    CHECK(memcmp(b + 8, "channels\0chlist\0", 16) == 0, "the channel list is the first attribute");
    b[24]--; /* its size, little-endian, below 256 */
    put_file(path, b, size);
    free(b);
    exr_image img;
    int rc = exr_image_load(path, &img, err, sizeof err);
    CHECK(rc == -1 && strstr(err, path) && one_line(err) && strstr(err, "is not a valid chlist"), "rc %d, '%s'", rc,
          err);
    printf("hostile channel list: %s\n", err);
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
 * exrmaketiled -z none): channel means and a few texels. glint reads them through that library
 * now, and agrees to the digits; but DWA is lossy, and other decoders (OpenEXR's own from 3.2 on)
 * round differently in the last place of the coded half values, so texels get 1% (a few such
 * steps). */
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
    /* A few bytes declaring 88898 x 898 pixels (found by the fuzzer: stb decoded all 80 million
     * past the data's end, a gigabyte and seconds) are refused from the header. */
    static const char huge[] = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 898 +X 88898\n\x88\x80";
    put_file(path, huge, sizeof huge - 1);
    expect_load_error(path, "88898x898 pixels need at least");
    static const char wide[] = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 4000 +X 4000\n\x02\x02\x0f\xa0";
    put_file(path, wide, sizeof wide - 1);
    expect_load_error(path, "4000x4000 pixels need at least");

    /* A directory, and a file in a format it does not read (by content, whatever the name: a PNG). */
    expect_load_error(scratch_dir, NULL);
    char renamed[1200];
    path_in(renamed, sizeof renamed, "png-in-disguise.exr");
    const unsigned char px[3] = {1, 2, 3};
    CHECK(png_save_rgb8(renamed, 1, 1, px, WRITE_NO_REPLACE, err, sizeof err) == 0, "png_save_rgb8: %s", err);
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

/* Finite samples whose sum is not: two components each at 3/4 of FLT_MAX (an environment map's
 * texels near the top of float's range do this). Each component's mean is finite; the image,
 * their sum, would be Inf as a float: the film writes the largest float and counts it. */
static void test_film_finite(void) {
    film f;
    CHECK(film_init(&f, 2, 1) == 0, "film_init");
    const float big = 0.75f * FLT_MAX;
    float a[COMP_COUNT][3] = {{big, -big, 1}, {big, -big, 1}, {0, 0, 0}};
    film_add(&f, 0, (const float(*)[3])a);
    film_add(&f, 1, (const float(*)[3])a);
    film_end_pass(&f);
    float rgb[6];
    size_t clamped = film_resolve(&f, COMP_MASK_ALL, rgb);
    CHECK(clamped == 4 && rgb[0] == FLT_MAX && rgb[1] == -FLT_MAX && rgb[2] == 2.0f,
          "the sum past float's range: %zu clamped, (%g %g %g)", clamped, (double)rgb[0], (double)rgb[1],
          (double)rgb[2]);
    clamped = film_resolve(&f, 1u << COMP_DIRECT, rgb);
    CHECK(clamped == 0 && rgb[0] == big && rgb[1] == -big, "one component alone is in range: %zu clamped", clamped);
    size_t counted = film_count_clamped(&f, (1u << COMP_DIRECT) | (1u << COMP_INDIRECT));
    CHECK(counted == 4, "film_count_clamped: %zu, expected the image's 4 (the layers are in range)", counted);
    film_deinit(&f);
}

/* Files made by OpenEXR's own tools (the openexr package): a scanline file turned into tiled PIZ
 * and tiled DWAA by exrmaketiled, and the two combined into one multi-part file by exrmultipart
 * (its first part read). Each loads as an image and as an environment map with the values the
 * scanline file holds (DWA's half channels within its loss). */
static void test_openexr_tools(void) {
    enum { W = 37, H = 21 };
    const exr_attr_box2i_t win = box(0, 0, W - 1, H - 1);
    char src[1200], piz[1200], dwaa[1200], multi[1200], cmd[8192], err[512] = "";
    path_in(src, sizeof src, "tools-source.exr");
    path_in(piz, sizeof piz, "tools-piz-tiled.exr");
    path_in(dwaa, sizeof dwaa, "tools-dwaa-tiled.exr");
    path_in(multi, sizeof multi, "tools-multipart.exr");
    CHECK(write_test_exr(src, EXR_STORAGE_SCANLINE, EXR_COMPRESSION_NONE, codec_chans, 6, win, win, codec_value) == 0,
          "writing the source");
    snprintf(cmd, sizeof cmd,
             "exrmaketiled -z piz '%s' '%s' >/dev/null && exrmaketiled -z dwaa '%s' '%s' >/dev/null && "
             "exrmultipart -combine -i '%s' '%s' -o '%s' >/dev/null",
             src, piz, src, dwaa, piz, dwaa, multi);
    int rc = system(cmd);
    CHECK(rc == 0, "OpenEXR's tools (the openexr package) failed or are missing: %s", cmd);
    if (rc != 0) return;
    const char *files[3] = {piz, dwaa, multi};
    for (int f = 0; f < 3; f++) {
        int dwa = f == 1;
        exr_image img;
        int ok = exr_image_load(files[f], &img, err, sizeof err) == 0;
        CHECK(ok && img.width == W && img.height == H, "%s: %s", files[f], err);
        image_rgb im;
        int ok_rgb = image_rgb_load(files[f], &im, err, sizeof err) == 0;
        CHECK(ok_rgb && im.width == W && im.height == H, "%s as an environment map: %s", files[f], err);
        int bad = 0;
        for (int c = 0; ok && c < 6; c++) {
            const float *p = exr_image_channel(&img, codec_chans[c].name);
            int lossy = dwa && c >= 1 && c <= 3;
            for (int i = 0; i < W * H; i++) {
                double e = codec_value(c, i % W, i / W);
                bad += !p || !(fabs(p[i] - e) <= (lossy ? 0.03 * e + 1e-3 : 0.0));
                /* B, G, R are channels 1..3: the environment map's rgb in reverse */
                if (ok_rgb && c >= 1 && c <= 3)
                    bad += !(fabs(im.rgb[3 * i + (size_t)(3 - c)] - fmax(e, 0.0)) <= (lossy ? 0.03 * e + 1e-3 : 0.0));
            }
        }
        CHECK(bad == 0, "%s: %d values differ from the source's", files[f], bad);
        if (ok) exr_image_free(&img);
        if (ok_rgb) image_rgb_free(&im);
    }
}

int main(void) {
    if (scratch_open("test_image_io") != 0) return 1;
    test_openexr_tools();
    test_exr_roundtrip();
    test_exr_foreign();
    test_compressions();
    test_damaged_dwab();
    test_hostile_headers();
    test_attribute_layouts();
    test_shared_env_maps();
    test_errors();
    test_film_means();
    test_film_finite();
    CHECK(stray_temp_files(scratch_dir) == 0, "temporary files left behind");
    return scratch_close(check_exit("test_image_io"));
}
