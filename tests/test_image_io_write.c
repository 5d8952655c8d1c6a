/* The writing side of image I/O: the atomic writer's guarantees (no replace, no partial file, no
 * temporary left behind, only regular files replaced, links written through, the umask honoured), errors that name the
 * path, free names for exports, string attributes in EXR headers as written and read back,
 * PNGs as stb_image decodes them, and the sRGB bytes they and the viewer's display hold. */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <stb/stb_image.h>

#include "check.h"
#include "film.h"
#include "image_io.h"
#include "scratch.h"

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

    /* A symbolic link is written through: its target gets the data, the link stays a link. A link
     * to nothing or to a FIFO is refused and left as it was. */
    char target[1200], link_path[1200];
    path_in(target, sizeof target, "link-target.bin");
    path_in(link_path, sizeof link_path, "link.bin");
    write_file_atomic(target, "old", 3, WRITE_REPLACE, err, sizeof err);
    CHECK(symlink(target, link_path) == 0, "symlink: %s", strerror(errno));
    CHECK(write_file_atomic(link_path, "new!", 4, WRITE_REPLACE, err, sizeof err) == 0, "through a link: %s", err);
    struct stat link_st;
    CHECK(lstat(link_path, &link_st) == 0 && S_ISLNK(link_st.st_mode), "the link was replaced by a file");
    got = get_file(target, &size);
    CHECK(got && size == 4 && memcmp(got, "new!", 4) == 0, "the link's target did not get the data");
    free(got);
    unlink(target);
    err[0] = '\0';
    CHECK(write_file_atomic(link_path, "x", 1, WRITE_REPLACE, err, sizeof err) == -1 && strstr(err, link_path) &&
              one_line(err),
          "a link to nothing: '%s'", err);
    CHECK(lstat(link_path, &link_st) == 0 && S_ISLNK(link_st.st_mode) && !file_exists(target),
          "a dangling link was replaced or followed");
    unlink(link_path);
    path_in(target, sizeof target, "fifo-target");
    CHECK(mkfifo(target, 0666) == 0 && symlink(target, link_path) == 0, "fifo and link: %s", strerror(errno));
    err[0] = '\0';
    CHECK(write_file_atomic(link_path, "x", 1, WRITE_REPLACE, err, sizeof err) == -1 && strstr(err, "not a regular"),
          "a link to a FIFO: '%s'", err);
    CHECK(lstat(link_path, &link_st) == 0 && S_ISLNK(link_st.st_mode) && lstat(target, &link_st) == 0 &&
              S_ISFIFO(link_st.st_mode),
          "the link or its FIFO changed");
    unlink(link_path);
    unlink(target);

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

    CHECK(stray_temp_files(scratch_dir) == 0, "temporary files left behind");
}

/* ---- unique_path ----------------------------------------------------------------------------- */

static void test_unique_path(void) {
    char path[1200], out[1200], expect[1300];
    path_in(path, sizeof path, "render.png");
    CHECK(unique_path(path, out, sizeof out) == 0 && strcmp(out, path) == 0, "free name: %s", out);
    put_file(path, "", 0);
    snprintf(expect, sizeof expect, "%s/render-1.png", scratch_dir);
    CHECK(unique_path(path, out, sizeof out) == 0 && strcmp(out, expect) == 0, "got %s, expected %s", out, expect);
    put_file(expect, "", 0);
    snprintf(expect, sizeof expect, "%s/render-2.png", scratch_dir);
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

/* ---- EXR header attributes ------------------------------------------------------------------- */

static void test_exr_attributes(void) {
    enum { W = 5, H = 3 };
    float px[3 * W * H];
    for (int i = 0; i < 3 * W * H; i++) px[i] = (float)i * 0.5f;
    /* A layer name past the format's 31 short characters needs its long-name flag. */
    const char *long_name = "a-layer-name-longer-than-thirty-one-characters";
    exr_layer layers[2] = {{"", px}, {long_name, px}};
    /* Text as a reference's: several lines, quotes, UTF-8; and a value long enough that the
     * header is larger than any buffer the writer might start with. */
    const char *json = "{\n  \"glint_reference\": 1,\n  \"scene\": \"caf\xc3\xa9 \\\"x\\\".gltf\"\n}\n";
    size_t big_len = (size_t)3 << 20;
    char *big = malloc(big_len + 1);
    for (size_t i = 0; i < big_len; i++) big[i] = (char)('a' + i % 26);
    big[big_len] = '\0';
    exr_text_attr attrs[3] = {{"glint.reference", json}, {"empty", ""}, {"big", big}};
    char path[1200], err[512] = "";
    path_in(path, sizeof path, "attrs.exr");
    CHECK(exr_save_layers_attrs(path, W, H, layers, 2, attrs, 3, WRITE_NO_REPLACE, err, sizeof err) == 0,
          "exr_save_layers_attrs: %s", err);
    for (int k = 0; k < 3; k++) {
        char *value = NULL;
        size_t len = 0;
        int rc = exr_header_string(path, attrs[k].name, &value, &len, err, sizeof err);
        CHECK(rc == 0 && value && len == strlen(attrs[k].value) && strcmp(value, attrs[k].value) == 0,
              "attribute %s: rc %d, %zu bytes, '%s'", attrs[k].name, rc, len, rc == 0 ? "" : err);
        free(value);
    }
    free(big);
    exr_image img;
    CHECK(exr_image_load(path, &img, err, sizeof err) == 0, "pixels beside attributes: %s", err);
    char name[64];
    snprintf(name, sizeof name, "%s.G", long_name);
    const float *g = exr_image_channel(&img, name);
    CHECK(img.num_channels == 6 && g && g[W * H - 1] == px[3 * (W * H - 1) + 1], "the long-named layer: %d channels",
          img.num_channels);
    exr_image_free(&img);

    /* No such attribute: 1; one of another type: an error naming the file and the type. */
    char *value = (char *)"untouched";
    size_t len = 7;
    CHECK(exr_header_string(path, "nosuch", &value, &len, err, sizeof err) == 1 && value == NULL && len == 0,
          "a missing attribute");
    err[0] = '\0';
    CHECK(exr_header_string(path, "compression", &value, &len, err, sizeof err) == -1 && strstr(err, path) &&
              strstr(err, "not string") && one_line(err),
          "a compression attribute read as a string: '%s'", err);
    /* Not an EXR, or no file: errors naming it. */
    char other[1200];
    path_in(other, sizeof other, "not-an.exr");
    put_file(other, "hello", 5);
    CHECK(exr_header_string(other, "glint.reference", &value, &len, err, sizeof err) == -1 && strstr(err, other) &&
              strstr(err, "not an OpenEXR file"),
          "a text file: '%s'", err);
    path_in(other, sizeof other, "missing.exr");
    CHECK(exr_header_string(other, "glint.reference", &value, &len, err, sizeof err) == -1 && strstr(err, other),
          "a missing file: '%s'", err);
    /* Written without attributes: none. */
    path_in(other, sizeof other, "plain.exr");
    CHECK(exr_save_layers(other, W, H, layers, 1, WRITE_NO_REPLACE, err, sizeof err) == 0, "plain: %s", err);
    CHECK(exr_header_string(other, "glint.reference", &value, &len, err, sizeof err) == 1, "plain file: '%s'", err);

    /* The format's own names, a name given twice, no name: refused before any file appears. */
    path_in(other, sizeof other, "refused.exr");
    const char *reserved[] = {"channels", "compression", "dataWindow", "type", "tiles"};
    for (size_t k = 0; k < sizeof reserved / sizeof reserved[0]; k++) {
        exr_text_attr a = {reserved[k], "x"};
        err[0] = '\0';
        CHECK(exr_save_layers_attrs(other, W, H, layers, 1, &a, 1, WRITE_REPLACE, err, sizeof err) == -1 &&
                  strstr(err, other) && strstr(err, reserved[k]) && one_line(err),
              "attribute %s accepted: '%s'", reserved[k], err);
    }
    exr_text_attr twice[2] = {{"note", "a"}, {"note", "b"}};
    CHECK(exr_save_layers_attrs(other, W, H, layers, 1, twice, 2, WRITE_REPLACE, err, sizeof err) == -1 &&
              strstr(err, "twice"),
          "an attribute given twice: '%s'", err);
    exr_text_attr unnamed = {"", "x"};
    CHECK(exr_save_layers_attrs(other, W, H, layers, 1, &unnamed, 1, WRITE_REPLACE, err, sizeof err) == -1,
          "an attribute without a name accepted");
    CHECK(!file_exists(other), "a refused save created a file");
    CHECK(stray_temp_files(scratch_dir) == 0, "temporary files left behind");
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
    CHECK(stray_temp_files(scratch_dir) == 0, "temporary files left behind");
}

/* ---- sRGB bytes ------------------------------------------------------------------------------ */

static float float_of(uint32_t b) {
    float x;
    memcpy(&x, &b, sizeof x);
    return x;
}

/* The tables' byte is the formula's, (uint8_t)(srgb_encode(x) * 255 + 0.5): at every third float
 * of (0, 1) from 2^-16 on, at every float within 64 of each byte's first, and at the edges; and the
 * formula is the standard's (IEC 61966-2-1) at values worked by hand. */
static void test_srgb_bytes(void) {
    long long wrong = 0;
    uint32_t lo, hi;
    float a = ldexpf(1.0f, -16), one = 1.0f;
    memcpy(&lo, &a, sizeof lo);
    memcpy(&hi, &one, sizeof hi);
    for (uint32_t b = lo; b < hi; b += 3) {
        float x = float_of(b);
        if (srgb8_of(x) != (uint8_t)(srgb_encode(x) * 255.0f + 0.5f) && wrong++ < 5)
            fprintf(stderr, "  x = %.9g: %d, the formula %d\n", (double)x, srgb8_of(x),
                    (uint8_t)(srgb_encode(x) * 255.0f + 0.5f));
    }
    for (int k = 1; k < 256; k++) { /* where byte k begins, found here by bisection on the formula */
        uint32_t l = 0, h = hi;
        while (l < h) {
            uint32_t m = l + (h - l) / 2;
            if ((uint8_t)(srgb_encode(float_of(m)) * 255.0f + 0.5f) >= k)
                h = m;
            else
                l = m + 1;
        }
        for (uint32_t b = l >= 64 ? l - 64 : 0; b <= l + 64 && b < hi; b++)
            if (srgb8_of(float_of(b)) != (uint8_t)(srgb_encode(float_of(b)) * 255.0f + 0.5f)) wrong++;
    }
    CHECK(wrong == 0, "%lld floats whose byte is not the formula's", wrong);
    const float edge[] = {0.0f, -0.0f, -1.0f, NAN, -INFINITY, 1e-45f, 1.0f, 1.5f, INFINITY};
    const int edge_byte[] = {0, 0, 0, 0, 0, 0, 255, 255, 255};
    for (int i = 0; i < 9; i++)
        CHECK(srgb8_of(edge[i]) == edge_byte[i], "x = %g: %d, expected %d", (double)edge[i], srgb8_of(edge[i]),
              edge_byte[i]);
    /* 0.5 -> 1.055 * 0.5^(1/2.4) - 0.055 = 0.73536 -> 187.5 (188); 0.18 -> 0.46135 -> 117.6 (118);
     * 0.002 -> 12.92 * 0.002 = 0.02584 -> 6.59 (7) */
    CHECK(srgb8_of(0.5f) == 188 && srgb8_of(0.18f) == 118 && srgb8_of(0.002f) == 7,
          "sRGB of 0.5, 0.18, 0.002: %d %d %d", srgb8_of(0.5f), srgb8_of(0.18f), srgb8_of(0.002f));
}

int main(void) {
    if (scratch_open("test_image_io_write") != 0) return 1;
    test_srgb_bytes();
    test_write_modes();
    test_unique_path();
    test_exr_attributes();
    test_png();
    CHECK(stray_temp_files(scratch_dir) == 0, "temporary files left behind");
    return scratch_close(check_exit("test_image_io_write"));
}
