/* glint — the C seam around tinygltf (gltf_import.cpp is the only file that sees C++). */
#ifndef GLINT_GLTF_IMPORT_H
#define GLINT_GLTF_IMPORT_H

#include <stddef.h>

#include "scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Reads a .gltf or .glb (recognised by content) into s through the scene_add_* calls. Returns 0,
 * or -1 with err = "NAME: problem". Does not finalize the scene. */
int gltf_import_file(scene *s, const char *path, char *err, size_t errlen);
/* The same from memory; base_dir resolves relative URIs, name appears in messages. */
int gltf_import_memory(scene *s, const void *data, size_t size, const char *base_dir, const char *name, char *err,
                       size_t errlen);

#ifdef __cplusplus
}
#endif

#endif
