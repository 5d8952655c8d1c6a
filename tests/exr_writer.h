/* glint tests — EXR files written with OpenEXR's C++ library (exr_writer.cpp), independently of
 * image_io.c: scanline or tiled (16x8 tiles), every compression the format has (DWAA/DWAB, PIZ,
 * B44 included), half, float or uint channels, subsampling, any data and display windows. */
#ifndef GLINT_TEST_EXR_WRITER_H
#define GLINT_TEST_EXR_WRITER_H

#include <openexr.h> /* for the names of storages, compressions, pixel types and boxes */

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
    const char *name;
    exr_pixel_type_t type;
    int sampling; /* x and y subsampling; 0 means 1 */
} test_chan;

/* The value of channel c (its index in the list) at absolute pixel (x, y); uint channels take it
 * converted to an integer. */
typedef float (*test_value_fn)(int c, int x, int y);

/* Writes path; returns 0, or -1 after printing the library's message. */
int write_test_exr(const char *path, exr_storage_t storage, exr_compression_t comp, const test_chan *chans, int nchan,
                   exr_attr_box2i_t dw, exr_attr_box2i_t disp, test_value_fn value);

#ifdef __cplusplus
}
#endif

#endif
