/* glint tests — small textured glTF files the tests write themselves: one square, x and y in
 * [0, 1] at z = 0 facing +z, with uv0 = (x, 1 - y) (an image laid on it upright) and uv1 =
 * (1 - x, y), and images given as RGBA texels, embedded as PNG data URIs. */
#ifndef GLINT_GLTF_TEXTURED_H
#define GLINT_GLTF_TEXTURED_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stb/stb_image_write.h>

#include "scratch.h"

typedef struct {
    int w, h;
    const unsigned char *rgba;
} gt_image;

typedef struct {
    unsigned char *data;
    size_t len;
} gt_bytes;

static inline void gt_collect(void *ctx, void *data, int size) {
    gt_bytes *b = ctx;
    unsigned char *p = realloc(b->data, b->len + (size_t)size);
    if (!p) abort();
    memcpy(p + b->len, data, (size_t)size);
    b->data = p;
    b->len += (size_t)size;
}

/* Appends text to the growing string *s (of length *n). */
static inline void gt_cat(char **s, size_t *n, const char *text) {
    size_t k = strlen(text);
    char *p = realloc(*s, *n + k + 1);
    if (!p) abort();
    memcpy(p + *n, text, k + 1);
    *s = p;
    *n += k;
}

/* gt_gltf with the nodes array and the scene's root nodes given (JSON text). */
static inline char *gt_gltf_nodes(const char *nodes, const char *roots, const char *materials, const char *textures,
                                  const char *samplers, const gt_image *images, int num_images, const char *prim_extra,
                                  const char *top_extra);

/* The glTF's JSON (malloc'd): the square as mesh 0 in node 0, its primitive using material 0
 * plus prim_extra (members added verbatim, e.g. "\"extensions\":{...}", or ""), the materials,
 * textures and samplers arrays as given (NULL: none), the images, and top_extra (more top-level
 * members, or ""). */
static inline char *gt_gltf(const char *materials, const char *textures, const char *samplers, const gt_image *images,
                            int num_images, const char *prim_extra, const char *top_extra) {
    return gt_gltf_nodes("[{\"mesh\":0}]", "[0]", materials, textures, samplers, images, num_images, prim_extra,
                         top_extra);
}

static inline char *gt_gltf_nodes(const char *nodes, const char *roots, const char *materials, const char *textures,
                                  const char *samplers, const gt_image *images, int num_images, const char *prim_extra,
                                  const char *top_extra) {
    float pos[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, nrm[12], uv0[8], uv1[8];
    for (int i = 0; i < 4; i++) {
        nrm[3 * i] = 0, nrm[3 * i + 1] = 0, nrm[3 * i + 2] = 1;
        uv0[2 * i] = pos[3 * i], uv0[2 * i + 1] = 1.0f - pos[3 * i + 1];
        uv1[2 * i] = 1.0f - pos[3 * i], uv1[2 * i + 1] = pos[3 * i + 1];
    }
    uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
    unsigned char bin[172];
    memcpy(bin, pos, 48);
    memcpy(bin + 48, nrm, 48);
    memcpy(bin + 96, uv0, 32);
    memcpy(bin + 128, uv1, 32);
    memcpy(bin + 160, idx, 12);
    char b64[240], line[1024];
    base64(bin, sizeof bin, b64);
    char *s = NULL;
    size_t n = 0;
    gt_cat(&s, &n, "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":");
    gt_cat(&s, &n, roots);
    gt_cat(&s, &n, "}],\"nodes\":");
    gt_cat(&s, &n, nodes);
    snprintf(line, sizeof line,
             ",\"buffers\":[{\"byteLength\":172,\"uri\":\"data:application/octet-stream;base64,%s\"}],", b64);
    gt_cat(&s, &n, line);
    gt_cat(&s, &n,
           "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":48},"
           "{\"buffer\":0,\"byteOffset\":48,\"byteLength\":48},{\"buffer\":0,\"byteOffset\":96,\"byteLength\":32},"
           "{\"buffer\":0,\"byteOffset\":128,\"byteLength\":32},{\"buffer\":0,\"byteOffset\":160,\"byteLength\":12}],"
           "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\",\"min\":[0,0,0],"
           "\"max\":[1,1,0]},{\"bufferView\":1,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
           "{\"bufferView\":2,\"componentType\":5126,\"count\":4,\"type\":\"VEC2\"},"
           "{\"bufferView\":3,\"componentType\":5126,\"count\":4,\"type\":\"VEC2\"},"
           "{\"bufferView\":4,\"componentType\":5123,\"count\":6,\"type\":\"SCALAR\"}],"
           "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"TEXCOORD_0\":2,"
           "\"TEXCOORD_1\":3},\"indices\":4,\"material\":0");
    if (prim_extra && prim_extra[0]) {
        gt_cat(&s, &n, ",");
        gt_cat(&s, &n, prim_extra);
    }
    gt_cat(&s, &n, "}]}],\"materials\":");
    gt_cat(&s, &n, materials ? materials : "[{}]");
    if (textures) {
        gt_cat(&s, &n, ",\"textures\":");
        gt_cat(&s, &n, textures);
    }
    if (samplers) {
        gt_cat(&s, &n, ",\"samplers\":");
        gt_cat(&s, &n, samplers);
    }
    if (num_images > 0) {
        gt_cat(&s, &n, ",\"images\":[");
        for (int i = 0; i < num_images; i++) {
            gt_bytes png = {0};
            if (!stbi_write_png_to_func(gt_collect, &png, images[i].w, images[i].h, 4, images[i].rgba, 4 * images[i].w))
                abort();
            char *uri = malloc(4 * (png.len / 3 + 1) + 64);
            if (!uri) abort();
            strcpy(uri, i ? ",{\"uri\":\"data:image/png;base64," : "{\"uri\":\"data:image/png;base64,");
            base64(png.data, png.len, uri + strlen(uri));
            free(png.data);
            gt_cat(&s, &n, uri);
            gt_cat(&s, &n, "\"}");
            free(uri);
        }
        gt_cat(&s, &n, "]");
    }
    if (top_extra && top_extra[0]) {
        gt_cat(&s, &n, ",");
        gt_cat(&s, &n, top_extra);
    }
    gt_cat(&s, &n, "}");
    return s;
}

#endif
