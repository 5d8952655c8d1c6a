/* glint — writes the EXR seeds of the image fuzzer into a folder: tiny images in each storage,
 * compression and pixel type, windows that differ, a luminance-only and a subsampled image (both
 * through the tests' own writer), and a reference as glint writes it (two layers, a glint.reference
 * header attribute). make_loader_seeds.py runs it and writes the rest (HDR, multi-part). */
#include <stdio.h>
#include <string.h>

#include "exr_writer.h"
#include "image_io.h"

static float ramp(int c, int x, int y) { return 0.25f * (float)(c + 1) + 0.125f * (float)x + 0.0625f * (float)y; }

static int write_one(const char *dir, const char *name, exr_storage_t storage, exr_compression_t comp,
                     const test_chan *chans, int nchan, exr_attr_box2i_t dw, exr_attr_box2i_t disp) {
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    return write_test_exr(path, storage, comp, chans, nchan, dw, disp, ramp);
}

int main(int argc, char **argv) {
    if (argc != 2) return fprintf(stderr, "usage: make_exr_seeds DIR\n"), 2;
    const char *dir = argv[1];
    const test_chan half_rgb[] = {{"B", EXR_PIXEL_HALF, 0}, {"G", EXR_PIXEL_HALF, 0}, {"R", EXR_PIXEL_HALF, 0}};
    const test_chan float_rgba[] = {
        {"A", EXR_PIXEL_FLOAT, 0}, {"B", EXR_PIXEL_FLOAT, 0}, {"G", EXR_PIXEL_FLOAT, 0}, {"R", EXR_PIXEL_FLOAT, 0}};
    const test_chan uint_y[] = {{"Y", EXR_PIXEL_UINT, 0}};
    const test_chan subsampled[] = {{"BY", EXR_PIXEL_HALF, 2}, {"RY", EXR_PIXEL_HALF, 2}, {"Y", EXR_PIXEL_HALF, 0}};
    const exr_attr_box2i_t box = {.min.x = 0, .min.y = 0, .max.x = 7, .max.y = 3};
    const exr_attr_box2i_t shifted = {.min.x = -2, .min.y = 1, .max.x = 5, .max.y = 6};
    const exr_attr_box2i_t inside = {.min.x = 1, .min.y = 1, .max.x = 5, .max.y = 2};
    static const struct {
        const char *name;
        exr_compression_t comp;
    } comps[] = {{"none", EXR_COMPRESSION_NONE}, {"rle", EXR_COMPRESSION_RLE},   {"zips", EXR_COMPRESSION_ZIPS},
                 {"zip", EXR_COMPRESSION_ZIP},   {"piz", EXR_COMPRESSION_PIZ},   {"pxr24", EXR_COMPRESSION_PXR24},
                 {"b44", EXR_COMPRESSION_B44},   {"b44a", EXR_COMPRESSION_B44A}, {"dwaa", EXR_COMPRESSION_DWAA},
                 {"dwab", EXR_COMPRESSION_DWAB}};
    int bad = 0;
    char name[256];
    for (size_t k = 0; k < sizeof comps / sizeof comps[0]; k++) {
        snprintf(name, sizeof name, "scanline-%s-half.exr", comps[k].name);
        bad |= write_one(dir, name, EXR_STORAGE_SCANLINE, comps[k].comp, half_rgb, 3, box, box);
    }
    bad |= write_one(dir, "scanline-zip-float-rgba.exr", EXR_STORAGE_SCANLINE, EXR_COMPRESSION_ZIP, float_rgba, 4, box,
                     box);
    bad |= write_one(dir, "scanline-piz-uint-y.exr", EXR_STORAGE_SCANLINE, EXR_COMPRESSION_PIZ, uint_y, 1, box, box);
    bad |= write_one(dir, "scanline-none-windows.exr", EXR_STORAGE_SCANLINE, EXR_COMPRESSION_NONE, half_rgb, 3, shifted,
                     box);
    bad |=
        write_one(dir, "scanline-zip-inside.exr", EXR_STORAGE_SCANLINE, EXR_COMPRESSION_ZIP, half_rgb, 3, inside, box);
    bad |= write_one(dir, "tiled-rle-y-inside.exr", EXR_STORAGE_TILED, EXR_COMPRESSION_RLE, uint_y, 1, inside, box);
    bad |= write_one(dir, "scanline-zip-subsampled.exr", EXR_STORAGE_SCANLINE, EXR_COMPRESSION_ZIP, subsampled, 3, box,
                     box);
    bad |= write_one(dir, "tiled-none-float.exr", EXR_STORAGE_TILED, EXR_COMPRESSION_NONE, float_rgba, 4, box, box);
    bad |= write_one(dir, "tiled-zip-half.exr", EXR_STORAGE_TILED, EXR_COMPRESSION_ZIP, half_rgb, 3, box, box);
    bad |= write_one(dir, "tiled-piz-windows.exr", EXR_STORAGE_TILED, EXR_COMPRESSION_PIZ, half_rgb, 3, shifted, box);
    bad |= write_one(dir, "tiled-dwaa-half.exr", EXR_STORAGE_TILED, EXR_COMPRESSION_DWAA, half_rgb, 3, box, box);

    /* A reference as glint render writes one: the image, a second layer, its description. */
    float rgb[8 * 4 * 3];
    for (int i = 0; i < 8 * 4 * 3; i++) rgb[i] = ramp(i % 3, (i / 3) % 8, i / 24);
    const exr_layer layers[] = {{"", rgb}, {"direct", rgb}};
    const exr_text_attr attr = {"glint.reference", "{\"glint_reference\": 1, \"width\": 8, \"height\": 4}"};
    char path[4096], err[1024];
    snprintf(path, sizeof path, "%s/glint-reference.exr", dir);
    if (exr_save_layers_attrs(path, 8, 4, layers, 2, &attr, 1, WRITE_REPLACE, err, sizeof err) != 0) {
        fprintf(stderr, "%s\n", err);
        bad = 1;
    }
    return bad ? 1 : 0;
}
