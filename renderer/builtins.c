/* The built-in scenes: glTF files under assets/scenes/ compiled into the program (the list in
 * renderer/CMakeLists.txt embeds each as glint_scene_NAME_gltf), loaded as builtin:NAME. */
#include <string.h>

#include "scene.h"

#define EMBEDDED(name)                                                                                                 \
    extern const unsigned char glint_scene_##name##_gltf[];                                                            \
    extern const size_t glint_scene_##name##_gltf_size;
EMBEDDED(atelier)
EMBEDDED(doorway)
EMBEDDED(showcase)
EMBEDDED(bay)
#undef EMBEDDED

/* The first is the default scene. */
static const builtin_scene builtins[] = {
    {"atelier", "lit only by an uplighter: a bright ceiling, brass reflectors in the beam, glossy floor, metals",
     glint_scene_atelier_gltf, &glint_scene_atelier_gltf_size},
    {"doorway", "lit through a doorway from a second room; polished stone floor, a steel panel in the beam",
     glint_scene_doorway_gltf, &glint_scene_doorway_gltf_size},
    {"showcase", "a small room of facing metals, a ceiling panel and a spot (the former default)",
     glint_scene_showcase_gltf, &glint_scene_showcase_gltf_size},
    {"bay", "a ceiling panel lights half the room; a walled-off bay beside it is lit only indirectly",
     glint_scene_bay_gltf, &glint_scene_bay_gltf_size},
};

const builtin_scene *scene_builtins(int *count) {
    *count = (int)(sizeof builtins / sizeof builtins[0]);
    return builtins;
}

const char *scene_builtin_name(const char *path) {
    static const char prefix[] = "builtin:";
    return strncmp(path, prefix, sizeof prefix - 1) == 0 ? path + sizeof prefix - 1 : NULL;
}

const builtin_scene *scene_builtin_find(const char *name) {
    for (size_t i = 0; i < sizeof builtins / sizeof builtins[0]; i++)
        if (strcmp(builtins[i].name, name) == 0) return &builtins[i];
    return NULL;
}
