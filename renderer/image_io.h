/* glint — image files: OpenEXR and Radiance HDR in, OpenEXR and PNG out, and the one atomic file
 * writer every export goes through.
 *
 * Errors: functions that can fail return 0 on success and -1 on failure, with a one-line message
 * in err (at most errlen bytes, "PATH: problem", no trailing newline, no "glint: error:" prefix).
 * Pixel arrays are row-major, top row first. */
#ifndef GLINT_IMAGE_IO_H
#define GLINT_IMAGE_IO_H

#include <stddef.h>
#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Interleaved linear RGB float image (3 floats per pixel). */
typedef struct {
    int width, height;
    float *rgb; /* owned: free with image_rgb_free */
} image_rgb;

/* Loads a linear RGB image: .exr through OpenEXR's C++ library (every compression, DWAA/DWAB
 * included; half, float or uint channels; R,G,B or a single Y channel; alpha ignored), .hdr
 * through stb_image. The format is recognised by the file's magic bytes, not its name.
 * Non-finite or negative texels are an error, except slightly negative texels of DWA's lossy
 * DCT, which are coding noise and read as zero. */
int image_rgb_load(const char *path, image_rgb *out, char *err, size_t errlen);
void image_rgb_free(image_rgb *img);

/* A multi-channel float image as read from an EXR: one plane of width*height floats per channel,
 * over the display window (zero where the data window does not cover it); every channel of the
 * first flat part, converted to float. */
typedef struct {
    int width, height;
    int num_channels;
    char **names;   /* owned, e.g. "R", "G", "B", "direct.R", ... */
    float **planes; /* owned, one per channel */
} exr_image;

int exr_image_load(const char *path, exr_image *out, char *err, size_t errlen);

/* Opens path for reading only when it is a regular file, without blocking on a FIFO (every input
 * file glint reads is one): NULL with errno set, EINVAL when it is not a regular file, which
 * open_regular_problem words. */
FILE *open_regular_file(const char *path);
const char *open_regular_problem(int e);
void exr_image_free(exr_image *img);
/* The plane of the named channel, or NULL. */
const float *exr_image_channel(const exr_image *img, const char *name);
/* The layer prefix.R, .G, .B ("" for R, G, B) interleaved, 3 floats a pixel (malloc'ed: free it),
 * or NULL when a channel is missing or out of memory. */
float *exr_image_layer_rgb(const exr_image *img, const char *prefix);

/* One RGB layer to write: prefix "" writes R,G,B; prefix "direct" writes direct.R, direct.G, direct.B. */
typedef struct {
    const char *prefix;
    const float *rgb; /* interleaved width*height*3 floats */
} exr_layer;

/* How an export treats an existing file at its path. */
typedef enum {
    WRITE_REPLACE,    /* the user named this output: replace it */
    WRITE_NO_REPLACE, /* fail with "PATH: file exists" rather than replace */
} write_mode;

/* A string attribute for an EXR header. The name must not be one of the format's own (channels,
 * compression, dataWindow, ...); the value is text (it cannot hold a NUL). */
typedef struct {
    const char *name;
    const char *value;
} exr_text_attr;

/* Writes a scanline EXR of 32-bit float channels (ZIP compression) atomically, through
 * OpenEXR's C++ library, with the string attributes attrs (NULL when num_attrs is 0) in its
 * header. */
int exr_save_layers_attrs(const char *path, int width, int height, const exr_layer *layers, int num_layers,
                          const exr_text_attr *attrs, int num_attrs, write_mode mode, char *err, size_t errlen);
/* The same without attributes. */
int exr_save_layers(const char *path, int width, int height, const exr_layer *layers, int num_layers, write_mode mode,
                    char *err, size_t errlen);

/* Reads the string attribute name from the header of the EXR file's first flat part (the part
 * exr_image_load reads). Returns 0 with *value a malloc'ed copy (free it; NUL-terminated, *len
 * bytes before the terminator, which may include NULs the file holds), 1 when the header has no
 * attribute of that name, or -1 with err ("PATH: problem") when the file is unreadable or the
 * attribute is not a string. */
int exr_header_string(const char *path, const char *name, char **value, size_t *len, char *err, size_t errlen);

/* Writes 8-bit sRGB (already encoded) RGB pixels as PNG atomically. */
int png_save_rgb8(const char *path, int width, int height, const unsigned char *rgb, write_mode mode, char *err,
                  size_t errlen);

/* Writes size bytes to path atomically: a temporary file in the same directory, fsync, then
 * rename (WRITE_REPLACE) or link (WRITE_NO_REPLACE, so an existing file is never replaced even
 * in a race). Never leaves a partial file at path, and removes its temporary file on failure.
 * Replaces only a regular file; a symbolic link is written through (its target replaced, the
 * link kept), and refused when it leads nowhere or to anything but a regular file. */
int write_file_atomic(const char *path, const void *data, size_t size, write_mode mode, char *err, size_t errlen);

/* Finds a free name for an export that must never overwrite: "dir/stem.ext" if it does not
 * exist, else "dir/stem-1.ext", "dir/stem-2.ext", ... Writes the chosen path to out. Returns 0,
 * or -1 when none is free or out is too small. (Write with WRITE_NO_REPLACE: a race with another
 * writer then fails instead of overwriting.) */
int unique_path(const char *path, char *out, size_t outlen);

#ifdef __cplusplus
}
#endif

#endif
