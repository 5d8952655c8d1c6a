/* What rendering needs, built from the scene's data (scene.c): finishing a scene (its extent,
 * geometric normals, the BVH with its alpha filters, emissive powers, the light distributions);
 * light edits and material variants, which change the data and build again what depends on it;
 * loading (the file's data, then finishing); and freeing the scene with all built from it. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gltf_import.h"
#include "lights.h"
#include "scene_parts.h"

void scene_destroy(scene *s) {
    if (!s) return;
    scene_bvh_free(s);
    if (s->device) rtcReleaseDevice(s->device);
    free(s->positions);
    free(s->normals);
    free(s->tangents);
    free(s->uv0);
    free(s->uv1);
    free(s->indices);
    free(s->tri_material);
    free(s->tri_normal);
    free(s->tri_light);
    free(s->tri_emit_tex);
    scene_variants_free(s);
    free(s->materials);
    for (int i = 0; i < s->num_images; i++) free(s->images[i].rgba);
    free(s->images);
    free(s->textures);
    free(s->lights);
    free(s->cameras);
    env_map_destroy(s->env);
    dist1d_deinit(&s->light_dist);
    dist1d_deinit(&s->nee_dist);
    free(((scene_box *)s)->gains);
    free(((scene_box *)s)->gain_bases);
    free((scene_box *)s);
}

/* ---- finalize ------------------------------------------------------------------------------ */

/* The scene's size from its triangles: bounds, diagonal, and the ray offset that scales with it.
 * Returns 0, or -1 when the scene has no (finite) extent. */
static int update_extent(scene *s) {
    bounds3 b = bounds_empty();
    for (int t = 0; t < s->num_triangles; t++)
        for (int c = 0; c < 3; c++) b = bounds_add(b, s->positions[s->indices[3 * t + c]]);
    float diag = bounds_diagonal(b);
    if (!(diag > 0.0f) || !isfinite(diag)) return -1;
    s->bounds = b;
    s->diag = diag;
    s->ray_eps = 1e-5f * diag;
    return 0;
}

static void warn_if_unlit(scene *s) {
    if (s->num_lights == 0)
        scene_warn(s,
                   "%s: no light (no punctual light, no emissive material): the image is black without an "
                   "environment map",
                   s->path);
}

int scene_finalize(scene *s, char *err, size_t errlen) {
    if (s->num_triangles == 0) return snprintf(err, errlen, "%s: no triangles to render", s->path), -1;
    if (update_extent(s) != 0) return snprintf(err, errlen, "%s: scene has no extent", s->path), -1;

    /* Pad the vertex array for Embree (the slot exists: positions has one spare element). */
    s->positions[s->num_vertices] = v3(0, 0, 0);

    /* Hits need the geometric normal, which moving a light (a translation) never changes. */
    free(s->tri_normal);
    if (!(s->tri_normal = malloc((size_t)s->num_triangles * sizeof(vec3))))
        return snprintf(err, errlen, "%s: out of memory", s->path), -1;
    for (int t = 0; t < s->num_triangles; t++) {
        const uint32_t *v = &s->indices[3 * t];
        vec3 p0 = s->positions[v[0]];
        s->tri_normal[t] = normalize3(cross3(sub3(s->positions[v[1]], p0), sub3(s->positions[v[2]], p0)));
    }

    s->coincident = scene_count_coincident(s);
    if (s->coincident < 0) return snprintf(err, errlen, "%s: out of memory", s->path), -1;
    if (s->coincident > 0)
        scene_warn(s,
                   "%s: %ld triangles repeat another's three corners: they add nothing to the image and slow "
                   "every ray through them",
                   s->path, s->coincident);
    /* The BVH first: it decides which triangles no ray can see (alpha), and those emit nothing. */
    if (scene_build_bvh(s, err, errlen) != 0 || scene_emissive_analyse(s, err, errlen) != 0 ||
        scene_build_lights(s, err, errlen) != 0)
        return -1;
    /* A material variant may bring its own: scene_set_variant warns then. */
    if (!scene_variants_emit(s)) warn_if_unlit(s);
    return 0;
}

/* ---- light edits and variants: the data changed, what depends on it built again ----------- */

/* Group g, or -1 with err set. */
static int find_group(const scene *s, int g, light_group *out, char *err, size_t errlen) {
    int n = scene_light_groups(s, NULL, 0);
    if (n < 0) return snprintf(err, errlen, "out of memory"), -1;
    if (g < 0 || g >= n) return snprintf(err, errlen, "no light %d (the scene has %d)", g, n), -1;
    /* Punctual groups come first and are cheap; an area group needs the list up to it. */
    light_group *all = malloc(sizeof(light_group) * (size_t)(g + 1));
    int status = all && scene_light_groups(s, all, g + 1) > g ? 0 : -1;
    if (status == 0)
        *out = all[g];
    else
        snprintf(err, errlen, "out of memory");
    free(all);
    return status;
}

int scene_move_light(scene *s, int g, vec3 delta, char *err, size_t errlen) {
    light_group lg;
    if (find_group(s, g, &lg, err, errlen) != 0) return -1;
    /* Beyond a thousand scene sizes, float positions lose the scene's detail: a typo, not a move. */
    if (!is_finite3(delta) || length3(delta) > 1e3f * s->diag)
        return snprintf(err, errlen, "light %d: move too large or not finite", g), -1;
    if (lg.type == LIGHT_DIRECTIONAL)
        return snprintf(err, errlen, "light %d (%s) is directional: it has no position", g, lg.name), -1;
    if (lg.type != LIGHT_TRIANGLE) {
        s->lights[lg.index].position = add3(s->lights[lg.index].position, delta);
        return 0; /* a punctual light's power does not depend on where it is */
    }
    /* The material's vertices, each once (triangles share them). No other material's triangle
     * uses them: every mesh brings its own vertices and has one material. */
    uint8_t *moved = calloc((size_t)s->num_vertices, 1);
    if (!moved) return snprintf(err, errlen, "out of memory"), -1;
    for (int t = 0; t < s->num_triangles; t++) {
        if (s->tri_material[t] != lg.index) continue;
        for (int c = 0; c < 3; c++) {
            uint32_t v = s->indices[3 * t + c];
            if (!moved[v]) s->positions[v] = add3(s->positions[v], delta);
            moved[v] = 1;
        }
    }
    free(moved);
    update_extent(s); /* cannot fail: the moved triangles keep their (non-zero) areas */
    /* The vertex buffer is shared with Embree: mark it changed and rebuild the BVH. */
    if (scene_bvh_vertices_moved(s) != 0) return snprintf(err, errlen, "rebuilding the BVH failed"), -1;
    /* Bounds feed the directional and environment powers: the selection distribution follows. */
    return scene_build_lights(s, err, errlen);
}

int scene_set_light_gain(scene *s, int g, float gain, char *err, size_t errlen) {
    light_group lg;
    if (find_group(s, g, &lg, err, errlen) != 0) return -1;
    if (!(gain >= 1e-6f && gain <= 1e6f))
        return snprintf(err, errlen, "light %d: intensity %g out of range", g, (double)gain), -1;
    scene_box *box = (scene_box *)s;
    if (!box->gains) {
        int n = scene_light_groups(s, NULL, 0); /* more than g (find_group found it), or -1 */
        light_group *all = n > g ? malloc(sizeof(light_group) * (size_t)n) : NULL;
        box->gains = n > g ? malloc(sizeof(float) * (size_t)n) : NULL;
        box->gain_bases = n > g ? malloc(sizeof(vec3) * (size_t)n) : NULL;
        if (!all || !box->gains || !box->gain_bases || scene_light_groups(s, all, n) != n) {
            free(all);
            free(box->gains);
            free(box->gain_bases);
            box->gains = NULL;
            box->gain_bases = NULL;
            return snprintf(err, errlen, "out of memory"), -1;
        }
        for (int i = 0; i < n; i++) {
            box->gains[i] = 1.0f;
            const light_group *gi = &all[i];
            box->gain_bases[i] =
                gi->type == LIGHT_TRIANGLE ? s->materials[gi->index].emission : s->lights[gi->index].color;
        }
        box->num_gains = n;
        free(all);
    }
    vec3 value = scale3(box->gain_bases[g], gain);
    if (lg.type == LIGHT_TRIANGLE)
        s->materials[lg.index].emission = value;
    else
        s->lights[lg.index].color = value;
    box->gains[g] = gain;
    /* Powers and the selection distribution follow the new intensity. */
    return scene_build_lights(s, err, errlen);
}

int scene_set_variant(scene *s, int v, char *err, size_t errlen) {
    if (v < -1 || v >= scene_num_variants(s))
        return snprintf(err, errlen, "%s: no material variant %d (the scene has %d)", s->path, v,
                        scene_num_variants(s)),
               -1;
    /* Light groups follow the materials: intensities go back to the file's before they change. */
    scene_box *box = (scene_box *)s;
    for (int g = 0; g < box->num_gains; g++)
        if (box->gains[g] != 1.0f && scene_set_light_gain(s, g, 1.0f, err, errlen) != 0) return -1;
    if (scene_apply_variant(s, v) != 0) return snprintf(err, errlen, "%s: out of memory", s->path), -1;
    free(box->gains);
    free(box->gain_bases);
    box->gains = NULL;
    box->gain_bases = NULL;
    box->num_gains = 0;
    if (!s->rtc) return 0; /* not finalized yet: scene_finalize builds the rest */
    if (scene_build_bvh(s, err, errlen) != 0 || scene_emissive_analyse(s, err, errlen) != 0 ||
        scene_build_lights(s, err, errlen) != 0)
        return -1;
    warn_if_unlit(s);
    return 0;
}

int scene_select_variant(scene *s, const char *name, char *err, size_t errlen) {
    int v = scene_variant_find(s, name);
    if (v >= 0) return scene_set_variant(s, v, err, errlen);
    int n = scene_num_variants(s);
    int len = snprintf(err, errlen, "%s: no material variant '%s' (%s", s->path, name,
                       n ? "the scene has: " : "the scene has none");
    for (int i = 0; i < n && len >= 0 && (size_t)len < errlen; i++)
        len += snprintf(err + len, errlen - (size_t)len, "%s'%s'", i ? ", " : "", scene_variant_name(s, i));
    if (len >= 0 && (size_t)len < errlen) snprintf(err + len, errlen - (size_t)len, ")");
    return -1;
}

/* ---- loading ------------------------------------------------------------------------------- */

static scene *finish_load(scene *s, int status, char *err, size_t errlen) {
    if (status == 0 && scene_finalize(s, err, errlen) == 0) return s;
    scene_destroy(s);
    return NULL;
}

static scene *load_builtin(const char *path, scene_warn_fn warn, void *warn_user, char *err, size_t errlen) {
    const builtin_scene *b = scene_builtin_find(scene_builtin_name(path));
    if (b) return scene_load_memory(b->gltf, *b->size, "", path, warn, warn_user, err, errlen);
    char names[256] = "";
    int n;
    const builtin_scene *all = scene_builtins(&n);
    for (int i = 0; i < n; i++) {
        if (i) strncat(names, ", ", sizeof names - strlen(names) - 1);
        strncat(names, all[i].name, sizeof names - strlen(names) - 1);
    }
    snprintf(err, errlen, "%s: no such built-in scene (have: %s)", path, names);
    return NULL;
}

scene *scene_load(const char *path, scene_warn_fn warn, void *warn_user, char *err, size_t errlen) {
    if (scene_builtin_name(path)) return load_builtin(path, warn, warn_user, err, errlen);
    scene *s = scene_create(warn, warn_user);
    if (!s) return snprintf(err, errlen, "%s: out of memory", path), NULL;
    snprintf(s->path, sizeof s->path, "%s", path);
    return finish_load(s, gltf_import_file(s, path, err, errlen), err, errlen);
}

scene *scene_load_memory(const void *data, size_t size, const char *base_dir, const char *name, scene_warn_fn warn,
                         void *warn_user, char *err, size_t errlen) {
    scene *s = scene_create(warn, warn_user);
    if (!s) return snprintf(err, errlen, "%s: out of memory", name), NULL;
    snprintf(s->path, sizeof s->path, "%s", name);
    return finish_load(s, gltf_import_memory(s, data, size, base_dir, name, err, errlen), err, errlen);
}

scene *scene_load_default(scene_warn_fn warn, void *warn_user, char *err, size_t errlen) {
    int n;
    char path[64];
    snprintf(path, sizeof path, "builtin:%s", scene_builtins(&n)[0].name);
    return scene_load(path, warn, warn_user, err, errlen);
}
