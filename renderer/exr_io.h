/* glint — OpenEXR files through OpenEXR's C++ library (exr_io.cpp), for image_io.c: reading,
 * writing, and the string attributes of a header. The C++ library decodes every compression the
 * format has, DWAA/DWAB included, which OpenEXR 3.1's C core cannot. No exception leaves these
 * functions: every failure is a one-line message. */
#ifndef GLINT_EXR_IO_H
#define GLINT_EXR_IO_H

#include <stddef.h>
#include <stdint.h>

#include "image_io.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Guards against corrupt headers that claim absurd sizes: allocation would fail (or, under
 * ASan, abort) long before any pixel data is read. 16k x 16k is far above anything glint uses. */
#define MAX_IMAGE_DIM (1 << 17)
#define MAX_IMAGE_PIXELS ((int64_t)1 << 28)

typedef enum {
    EXR_READ_ALL, /* every channel, in the file's (sorted) order */
    /* R, G, B, else Y three times, interleaved in one plane "RGB" of 3 floats a pixel, for an
     * environment map: DWA's slightly negative texels read as zero, and any other negative or
     * non-finite texel fails the read */
    EXR_READ_RGB_INTERLEAVED,
} exr_read_select;

/* Reads the first flat (not deep) part of the EXR file open on fd (size bytes; path is used in
 * messages) into out: one float plane per selected channel over the display window, zero where
 * the data window does not cover it. *lossy_dct (if not NULL) tells whether the part is DWAA or
 * DWAB compressed. Returns 0, or -1 with "PATH: problem" in err and out cleared. */
int exr_read_fd(const char *path, int fd, int64_t size, exr_read_select select, exr_image *out, int *lossy_dct,
                char *err, size_t errlen);

/* Reads the string attribute name from the header of the first flat part of the EXR file open on
 * fd, as exr_header_string (image_io.h) does. */
int exr_read_string_fd(const char *path, int fd, int64_t size, const char *name, char **value, size_t *len, char *err,
                       size_t errlen);

/* Encodes the layers and attributes (arguments checked by the caller, exr_save_layers_attrs) as
 * a ZIP-compressed scanline EXR of 32-bit float channels in memory: *data (malloc'ed; the caller
 * writes and frees it) of *size bytes. The file is written by image_io.c (write_file_atomic):
 * this file reads and encodes, and calls nothing of image_io.c's. Returns 0, or -1 with "PATH:
 * problem" in err (path is used in messages only). */
int exr_encode_layers(const char *path, int width, int height, const exr_layer *layers, int num_layers,
                      const exr_text_attr *attrs, int num_attrs, void **data, size_t *size, char *err, size_t errlen);

#ifdef __cplusplus
}
#endif

#endif
